"""Scanned pressure film -> pressure image -> profile along the strip.

Grayscale convention: 0 = black, 255 = white (the paper's). Colour scans are converted
to luminance with ITU-R BT.601 luma, Y = 0.299 R + 0.587 G + 0.114 B (the weights
Pillow's "L" mode uses), computed in floating point without rounding; alpha is ignored.
16-bit images are scaled by 255/65535.

The strip runs along image x (columns) by default (``axis="x"``); the profile is the mean
pressure across the strip width (rows of the region) at each column, against the distance
s in mm from an origin: the peak (sub-pixel), the middle of the half-maximum extent, or a
position given in mm from the image's left (or top) edge. Pixel j's centre sits at
(j + 0.5) / px_per_mm mm.
"""

from __future__ import annotations

import json
import logging
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactileskin.errors import ParameterError, check_range
from tactileskin.film._io import staged_dir
from tactileskin.film.calibration import Calibration, paper_eq8
from tactileskin.results import auc, peak, span

log = logging.getLogger(__name__)

PX_PER_MM = 8.0          # the paper's scans (Sec. IV-B: 160 x 80 px for 20 x 10 mm)
LUMA_BT601 = (0.299, 0.587, 0.114)
LUMINANCE_NOTE = "ITU-R BT.601 luma Y = 0.299 R + 0.587 G + 0.114 B (float, alpha ignored)"
PEAK_WINDOW = 0.8        # parabola fitted to the samples >= 80 % of the maximum around it


def luminance(rgb: np.ndarray) -> np.ndarray:
    """BT.601 luma of an (..., 3) RGB array, in the array's own scale."""
    return np.asarray(rgb, float)[..., :3] @ np.asarray(LUMA_BT601)


def load_grayscale(path) -> np.ndarray:
    """Read a PNG/TIFF (any Pillow mode) as a float (H, W) array on the 0-255 scale."""
    from PIL import Image, UnidentifiedImageError

    path = Path(path)
    valid = "a readable, non-empty PNG or TIFF image"
    try:
        with Image.open(path) as im:
            im.load()
            if getattr(im, "n_frames", 1) > 1:
                log.warning("%s has %d frames; using the first", path, im.n_frames)
            mode = im.mode
            if mode == "L":
                arr = np.asarray(im, float)
            elif mode.startswith("I"):           # 16/32-bit integer grayscale
                arr = np.asarray(im, float) * (255.0 / 65535.0)
            elif mode == "F":
                arr = np.asarray(im, float)
            elif mode in ("LA", "La"):
                arr = np.asarray(im.getchannel(0), float)
            else:                                # 1, P, RGB, RGBA, CMYK, YCbCr, ...
                arr = luminance(np.asarray(im.convert("RGB"), float))
    except FileNotFoundError:
        raise ParameterError("scan", str(path), valid, hint="file not found") from None
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError) as e:
        raise ParameterError("scan", str(path), valid, hint=f"unreadable: {e}") from None
    if arr.ndim != 2 or arr.size == 0:
        raise ParameterError("scan", str(path), valid, hint=f"image shape {arr.shape}")
    if not np.all(np.isfinite(arr)) or arr.min() < 0 or arr.max() > 255:
        raise ParameterError("scan", str(path), valid,
                             hint=f"values must be finite on 0-255, got [{arr.min()}, {arr.max()}]")
    return arr


def select_region(gray: np.ndarray, *, box_px=None, box_mm=None, px_per_mm: float = PX_PER_MM):
    """Crop to a box (x0, y0, x1, y1): pixels (half-open) or mm (rounded to pixel edges).

    x runs along columns from the left edge, y along rows from the top. Returns the crop
    and the box in pixels.
    """
    h, w = gray.shape
    if box_px is not None and box_mm is not None:
        raise ParameterError("box", "both box_px and box_mm", "one of them")
    name = "box_px"
    if box_mm is not None:
        name = "box_mm"
        box_px = tuple(int(round(float(v) * px_per_mm)) for v in box_mm)
    if box_px is None:
        box_px = (0, 0, w, h)
    if len(box_px) != 4:
        raise ParameterError(name, box_px, "four numbers x0, y0, x1, y1")
    x0, y0, x1, y1 = (int(v) for v in box_px)
    if not (0 <= x0 < x1 <= w and 0 <= y0 < y1 <= h):
        given = box_mm if box_mm is not None else box_px
        unit = f" mm at {px_per_mm:g} px/mm" if box_mm is not None else " px"
        raise ParameterError(name, tuple(given), f"0 <= x0 < x1 <= {w}, 0 <= y0 < y1 <= {h} px "
                             f"(the image is {w} x {h} px)",
                             hint=f"region outside the image; box given in{unit}")
    return gray[y0:y1, x0:x1], (x0, y0, x1, y1)


def profile_metrics(s, p) -> dict:
    """peak, span (10 % of peak) and AUC with the simulation's definitions (tactileskin.results)."""
    s = np.asarray(s, float)
    p = np.asarray(p, float)
    return {"peak": float(peak(s, p)), "span_mm": float(span(s, p)), "auc": float(auc(s, p))}


def fold_profile(s, p):
    """Fold a two-sided profile about s = 0 onto s >= 0 (to compare with the half model).

    On the grid s_k = k*ds (ds the profile's median spacing) up to max |s|, the folded value
    is the mean of P(+s_k) and P(-s_k) (linear interpolation) where both sides are measured,
    else the one that is. Returns (s_half, p_half, asymmetry) with asymmetry =
    max |P(+s) - P(-s)| / max P over the overlap (0 for a symmetric profile).
    """
    s = np.asarray(s, float)
    p = np.asarray(p, float)
    ds = float(np.median(np.diff(s)))
    smax = max(abs(s[0]), abs(s[-1]))
    sh = np.arange(int(np.floor(smax / ds + 1e-9)) + 1) * ds
    tol = 1e-9 * ds
    right = np.where(sh <= s[-1] + tol, np.interp(sh, s, p), np.nan)
    left = np.where(-sh >= s[0] - tol, np.interp(-sh, s, p), np.nan)
    both = np.isfinite(right) & np.isfinite(left)
    ph = np.where(both, 0.5 * (right + left), np.where(np.isfinite(right), right, left))
    top = float(np.max(p)) if p.size else 0.0
    asym = float(np.max(np.abs(right[both] - left[both])) / top) if both.any() and top > 0 else 0.0
    return sh, ph, asym


def _peak_position(x, p) -> float:
    """Sub-sample position of the maximum: LSQ parabola over the contiguous samples >= 80 %
    of the maximum around the argmax (at least its neighbours), vertex kept in that window."""
    i = int(np.argmax(p))
    thr = PEAK_WINDOW * p[i]
    a = i
    while a > 0 and p[a - 1] >= thr:
        a -= 1
    b = i
    while b < p.size - 1 and p[b + 1] >= thr:
        b += 1
    a, b = min(a, max(i - 1, 0)), max(b, min(i + 1, p.size - 1))
    if b - a < 2:
        return float(x[i])
    c2, c1, _ = np.polyfit(x[a:b + 1] - x[i], p[a:b + 1], 2)
    if c2 >= 0:  # flat or noisy: no interior maximum
        return float(x[i])
    return float(np.clip(x[i] - c1 / (2 * c2), x[a], x[b]))


def _midspan_position(x, p, fraction=0.5) -> float:
    """Middle of the outermost crossings of fraction*max (linear interpolation)."""
    thr = fraction * float(np.max(p))
    idx = np.flatnonzero(p >= thr)
    a, b = idx[0], idx[-1]
    xa = x[a] if a == 0 else np.interp(thr, [p[a - 1], p[a]], [x[a - 1], x[a]])
    xb = x[b] if b == p.size - 1 else np.interp(thr, [p[b + 1], p[b]], [x[b + 1], x[b]])
    return float(0.5 * (xa + xb))


@dataclass
class FilmProfile:
    """Result of ``analyze_scan``. Pressures in ``unit`` (the calibration's)."""

    s_mm: np.ndarray            # distance from the origin along the strip
    pressure: np.ndarray        # mean across the strip width
    pressure_sd: np.ndarray     # standard deviation across the width
    band_lo: np.ndarray | None  # calibration 90 % band at the column-mean grayscale
    band_hi: np.ndarray | None
    pressure_map: np.ndarray    # (width, length) region, strip along axis 1
    gray: np.ndarray            # the same region's grayscale
    box_px: tuple
    px_per_mm: float
    axis: str
    origin_mm: float            # origin along the strip, mm from the image edge
    centre: str
    unit: str
    calibration: Calibration
    saturated_fraction: float
    inactive_fraction: float
    source: str = ""
    metrics: dict = field(default_factory=dict)
    folded: dict = field(default_factory=dict)

    def summary(self) -> dict:
        cal = self.calibration
        return {
            "source": self.source, "unit": self.unit, "px_per_mm": self.px_per_mm,
            "box_px": list(self.box_px), "axis": self.axis, "centre": self.centre,
            "origin_mm": self.origin_mm, "luminance": LUMINANCE_NOTE,
            "calibration": {"name": cal.name, "model": cal.model, "params": list(cal.params),
                            "gs_range": list(cal.gs_range), "activation_range": list(cal.p_range),
                            "unit": cal.unit},
            "n_columns": int(self.s_mm.size), "width_px": int(self.pressure_map.shape[0]),
            "saturated_fraction": self.saturated_fraction,
            "inactive_fraction": self.inactive_fraction,
            "metrics_two_sided": self.metrics,
            "metrics_folded": self.folded["metrics"],
            "asymmetry": self.folded["asymmetry"],
            "definitions": {
                "peak": "max of the profile", "span_mm": "extent of s where P >= 10 % of peak",
                "auc": "trapezoid integral of P over s (unit x mm)",
                "folded": "two-sided profile folded about the origin: mean of P(+s), P(-s)"},
        }

    def write(self, out, *, cmap: str = "viridis") -> dict[str, Path]:
        """Write profile.csv, summary.json and pressure_map.png into ``out`` (atomically)."""
        from tactileskin.film import plots

        out = Path(out)
        names = {"profile": "profile.csv", "summary": "summary.json", "map": "pressure_map.png"}
        with staged_dir(out) as tmp:
            lines = ["s_mm,pressure,pressure_sd,band90_lo,band90_hi"]
            for k in range(self.s_mm.size):
                lo = f"{self.band_lo[k]:.6g}" if self.band_lo is not None else ""
                hi = f"{self.band_hi[k]:.6g}" if self.band_hi is not None else ""
                lines.append(f"{self.s_mm[k]:.6g},{self.pressure[k]:.6g},"
                             f"{self.pressure_sd[k]:.6g},{lo},{hi}")
            (tmp / names["profile"]).write_text("\n".join(lines) + "\n")
            (tmp / names["summary"]).write_text(json.dumps(self.summary(), indent=2))
            plots.pressure_map(self, tmp / names["map"], cmap=cmap)
        return {k: out / v for k, v in names.items()}


def analyze_scan(scan, calibration: Calibration | None = None, *, px_per_mm: float = PX_PER_MM,
                 box_px=None, box_mm=None, axis: str = "x", centre="peak") -> FilmProfile:
    """Scan (path or (H, W) grayscale array) -> FilmProfile.

    calibration: default ``paper_eq8``. centre: "peak", "midspan" or a number (origin in
    mm from the image's left edge for axis "x", top edge for "y").
    """
    cal = calibration or paper_eq8()
    px_per_mm = check_range("px_per_mm", px_per_mm, 0, None, lo_open=True, unit="px/mm")
    if axis not in ("x", "y"):
        raise ParameterError("axis", axis, "'x' (strip along columns) or 'y' (along rows)")
    if isinstance(scan, (str, Path)):
        source, gray = str(scan), load_grayscale(scan)
    else:
        source, gray = "<array>", np.asarray(scan, float)
        if gray.ndim == 3:
            gray = luminance(gray)
        if gray.ndim != 2 or gray.size == 0 or not np.all(np.isfinite(gray)):
            raise ParameterError("scan", f"array {gray.shape}", "a finite, non-empty 2-D array")
    region, box = select_region(gray, box_px=box_px, box_mm=box_mm, px_per_mm=px_per_mm)
    start = box[0] if axis == "x" else box[1]
    if axis == "y":
        region = region.T
    if region.shape[1] < 3:
        raise ParameterError("region length", region.shape[1], ">= 3 px along the strip")

    pmap = cal.pressure(region)
    lo, hi = cal.p_range
    sat = float(np.mean(pmap >= hi))
    inactive = float(np.mean(pmap <= lo))
    if inactive == 1.0:
        raise ParameterError("scan region", "blank strip", f"some pixels darker than the "
                             f"activation threshold GS {cal.threshold_gs:.1f} "
                             f"(calibration {cal.name})",
                             hint=f"region grayscale {region.min():.1f}-{region.max():.1f}")
    if sat == 1.0:
        raise ParameterError("scan region", "fully saturated strip", f"some pixels lighter "
                             f"than the saturation grayscale {cal.saturation_gs:.1f} "
                             f"(calibration {cal.name})",
                             hint=f"region grayscale {region.min():.1f}-{region.max():.1f}")
    if sat > 0:
        log.warning("%.1f %% of the region is at the film's saturation (%g %s)",
                    100 * sat, hi, cal.unit)
    prof = pmap.mean(axis=0)
    sd = pmap.std(axis=0)
    band = cal.band(region.mean(axis=0))
    x_mm = (start + np.arange(region.shape[1]) + 0.5) / px_per_mm   # pixel centres
    if isinstance(centre, str):
        if centre == "peak":
            origin = _peak_position(x_mm, prof)
        elif centre == "midspan":
            origin = _midspan_position(x_mm, prof)
        else:
            raise ParameterError("centre", centre, "'peak', 'midspan' or an origin in mm")
    else:
        origin = check_range("centre", centre, unit="mm")
    s = x_mm - origin
    sh, ph, asym = fold_profile(s, prof)
    fp = FilmProfile(
        s_mm=s, pressure=prof, pressure_sd=sd,
        band_lo=band[0] if band else None, band_hi=band[1] if band else None,
        pressure_map=pmap, gray=region, box_px=box, px_per_mm=px_per_mm, axis=axis,
        origin_mm=float(origin), centre=str(centre), unit=cal.unit, calibration=cal,
        saturated_fraction=sat, inactive_fraction=inactive, source=source,
        metrics=profile_metrics(s, prof),
        folded={"s_mm": sh, "pressure": ph, "asymmetry": asym,
                "metrics": profile_metrics(sh, ph)})
    for k, v in fp.metrics.items():
        if not math.isfinite(v):  # pragma: no cover - inputs are checked finite above
            raise ParameterError(f"metric {k}", v, "finite")
    log.info("film profile %s: peak %.4g %s, span %.3g mm", source, fp.metrics["peak"],
             cal.unit, fp.metrics["span_mm"])
    return fp
