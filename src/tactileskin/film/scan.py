"""Scanned pressure film -> pressure image -> profile along the strip.

Grayscale convention: 0 = black, 255 = white (the paper's). Image reading (pixel scale of
8/16/32-bit and float images, BT.601 luma for colour, the pixel cap) is in ``film.image``.

The strip runs along image x (columns) by default (``axis="x"``); the profile is the mean
pressure across the strip width (rows of the region; the strip's own rows averaged before the
calibration's zero below the threshold, STRIP_ROWS) at each column, against the distance
s in mm from an origin: the peak (sub-pixel), the middle of the half-maximum extent, or a
position given in mm from the image's left (or top) edge. Pixel j's centre sits at
(j + 0.5) / px_per_mm mm. Without a box the activated strip is found on the scan
(``film.region``) and the box used is logged and written to summary.json.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np

from tactileskin import fileio, outdir, staging
from tactileskin.errors import ParameterError
from tactileskin.film import region as strip_region
from tactileskin.film.calibration import Calibration, paper_eq8
from tactileskin.film.image import LUMINANCE_NOTE, file_px_per_mm, load_grayscale, luminance, read_scan  # noqa: F401
from tactileskin.film.inputs import finite
from tactileskin.results import auc, fold_profile, peak, span  # noqa: F401  (fold_profile: film's API)

log = logging.getLogger(__name__)

PX_PER_MM = 8.0          # the paper's scans (Sec. IV-B: 160 x 80 px for 20 x 10 mm)
# 0.01 px/mm (a pixel per 10 cm) to 10^4 px/mm (0.1 um pixels) spans every scanner and
# microscope by far; outside it a typo is likelier than a scale.
PX_PER_MM_RANGE = (0.01, 1e4)
SCALE_TOL = 0.01         # the scale given and the file's may differ by 1 % (dpi rounding in PNG's pHYs)
PEAK_WINDOW = 0.8        # parabola fitted to the samples >= 80 % of the maximum around it
# the profile averages across the strip, so the pressure must be nearly uniform across it: an
# automatically found strip whose variation across (pressure-weighted mean of sd / mean over its
# activated columns) is above AXIS_CV and AXIS_RATIO x that of the strip found along the other
# axis runs the other way (a transposed scan read along x: 18 % against 2.6 %, peak 17 % low)
AXIS_CV, AXIS_RATIO = 0.1, 2.0
# an inverted scan (a light strip on dark film): the region's ends and the image's edges read
# alike (within this share) as its highest pressure, and the region dips below that by more
# (a 0.05 MPa/mm press inverted dipped 3 %; 8-bit noise moves a column mean by < 0.5 %)
INVERTED = 0.02
ANALYZE_NAMES = ("profile.csv", "summary.json", "pressure_map.png")
COMPARE_NAMES = ("comparison.json", "overlay.png")


def _box_numbers(name: str, box, px_per_mm: float | None) -> tuple[int, int, int, int]:
    """Four finite numbers -> pixel box; mm are rounded to pixel edges, pixels must be whole."""
    try:
        vals = list(box)
    except TypeError:
        raise ParameterError(name, box, "four numbers x0, y0, x1, y1") from None
    if len(vals) != 4:
        raise ParameterError(name, tuple(vals), "four numbers x0, y0, x1, y1")
    out = []
    for v in vals:
        f = finite(name, v)
        if px_per_mm is not None:
            px = f * px_per_mm
            # past the float range (1e308 mm at 8 px/mm) the exact product: round(inf) overflows,
            # and the box stays ordered, so the range check names it as outside the image
            f = round(px) if math.isfinite(px) else round(Fraction(f) * Fraction(px_per_mm))
        elif f != int(f):
            raise ParameterError(name, tuple(vals), "whole pixel numbers x0, y0, x1, y1")
        out.append(int(f))
    return tuple(out)


def select_region(gray: np.ndarray, *, box_px=None, box_mm=None, px_per_mm: float = PX_PER_MM):
    """Crop to a box (x0, y0, x1, y1): pixels (half-open) or mm (rounded to pixel edges).

    x runs along columns from the left edge, y along rows from the top. Returns the crop
    and the box in pixels. No box: the whole image.
    """
    h, w = gray.shape
    if box_px is not None and box_mm is not None:
        raise ParameterError("box", "both box_px and box_mm", "one of them")
    name = "box_mm" if box_mm is not None else "box_px"
    if box_mm is not None:
        box_px = _box_numbers(name, box_mm, px_per_mm)
    elif box_px is not None:
        box_px = _box_numbers(name, box_px, None)
    else:
        box_px = (0, 0, w, h)
    x0, y0, x1, y1 = box_px
    if not (0 <= x0 < x1 <= w and 0 <= y0 < y1 <= h):
        why = ("x1 <= x0 or y1 <= y0" if (x1 <= x0 or y1 <= y0) else "region outside the image")
        if box_mm is not None:  # the range in the option's unit: the image's size in mm
            wm, hm = (f"{v / px_per_mm:.4g}" for v in (w, h))
            given = tuple(float(v) for v in box_mm)
            if given[0] < given[2] and given[1] < given[3] and (x1 <= x0 or y1 <= y0):
                # ordered as asked, but under a pixel: 'x1 <= x0' named what the user did not give
                why = (f"--box-mm is rounded to pixel edges ({1 / px_per_mm:.4g} mm at {px_per_mm:g} px/mm): "
                       f"this box is x {x0}-{x1}, y {y0}-{y1} px, empty")
            raise ParameterError(name, tuple(box_mm), f"0 <= x0 < x1 <= {wm}, 0 <= y0 < y1 <= {hm} mm, "
                                 f"x1 - x0 and y1 - y0 >= {1 / px_per_mm:.4g} mm (a pixel; the image is {wm} x "
                                 f"{hm} mm: {w} x {h} px at {px_per_mm:g} px/mm)", hint=why)
        raise ParameterError(name, tuple(box_px), f"0 <= x0 < x1 <= {w}, 0 <= y0 < y1 <= {h} px "
                             f"(the image is {w} x {h} px)", hint=why)
    return gray[y0:y1, x0:x1], (x0, y0, x1, y1)


def profile_metrics(s, p) -> dict:
    """peak, span (10 % of peak) and AUC with the simulation's definitions (tactileskin.results)."""
    s = np.asarray(s, float)
    p = np.asarray(p, float)
    return {"peak": float(peak(s, p)), "span_mm": float(span(s, p)), "auc": float(auc(s, p))}


# A flat top: the samples within FLAT_TOP of the maximum span more than FLAT_SPAN of the
# window >= PEAK_WINDOW; a rounded (parabolic) peak's 2 % band spans about a third of it.
FLAT_TOP, FLAT_SPAN = 0.02, 0.6


def _peak_position(x, p) -> float:
    """Sub-sample position of the maximum: LSQ parabola over the contiguous samples >= 80 %
    of the maximum around the argmax (at least its neighbours), vertex kept in that window;
    a flat top's middle, between the window's interpolated edges (FLAT_TOP, FLAT_SPAN)."""
    i = int(np.argmax(p))
    thr = PEAK_WINDOW * p[i]
    a = i
    while a > 0 and p[a - 1] >= thr:
        a -= 1
    b = i
    while b < p.size - 1 and p[b + 1] >= thr:
        b += 1
    edges = a, b  # the window itself: p[a - 1] < thr <= p[a] (if a > 0), likewise at b
    a, b = min(a, max(i - 1, 0)), max(b, min(i + 1, p.size - 1))
    if b - a < 2:
        return float(x[i])
    top = np.flatnonzero(p[a:b + 1] >= (1.0 - FLAT_TOP) * p[i]) + a
    if x[top[-1]] - x[top[0]] > FLAT_SPAN * (x[b] - x[a]):
        # a flat top (a plate's press, a saturated film): the argmax is wherever the noise puts
        # it and a parabola has no vertex to find; the middle of the top is the centre, between
        # the window's interpolated edges (the outermost samples within 2 % of the maximum moved
        # with the noise: 3 GS put a 5 mm punch's centre 0.19 mm off, its fold's asymmetry 0.90)
        a, b = edges
        xa = x[a] if a == 0 else np.interp(thr, [p[a - 1], p[a]], [x[a - 1], x[a]])
        xb = x[b] if b == p.size - 1 else np.interp(thr, [p[b + 1], p[b]], [x[b + 1], x[b]])
        return float(0.5 * (xa + xb))
    c2, c1, _ = np.polyfit(x[a:b + 1] - x[i], p[a:b + 1], 2)
    if c2 >= 0:  # noisy: no interior maximum
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
    pressure: np.ndarray        # mean across the strip width (rows='centre': the row through the peak)
    pressure_sd: np.ndarray | None  # standard deviation across the width (None for one row: rows='centre')
    band_lo: np.ndarray | None  # calibration 90 % band, mean across the width like pressure
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
    region: dict = field(default_factory=dict)   # how box_px was chosen
    image_note: str = ""                           # pixel scale applied when reading
    warnings: list = field(default_factory=list)   # what makes the profile suspect
    coverage: dict = field(default_factory=dict)   # pixels beyond the calibrated grayscale range
    file_px_per_mm: float | None = None            # the scale the image file records, if any
    cut_ends: list = field(default_factory=list)   # region ends where P is still >= 10 % of its peak

    def summary(self) -> dict:
        cal = self.calibration
        return {
            "warnings": list(self.warnings),
            "source": self.source, "unit": self.unit, "px_per_mm": self.px_per_mm,
            "box_px": list(self.box_px), "region": self.region, "axis": self.axis,
            "file_px_per_mm": self.file_px_per_mm,
            "centre": self.centre, "origin_mm": self.origin_mm, "luminance": LUMINANCE_NOTE,
            "pixel_scale": self.image_note,
            "calibration": {"name": cal.name, "model": cal.model, "params": list(cal.params),
                            "gs_range": list(cal.gs_range), "activation_range": list(cal.p_range),
                            "unit": cal.unit},
            "n_columns": int(self.s_mm.size), "width_px": int(self.pressure_map.shape[0]),
            "saturated_fraction": self.saturated_fraction,
            "inactive_fraction": self.inactive_fraction,
            "beyond_calibration": self.coverage,
            "cut_ends": list(self.cut_ends),
            "metrics_two_sided": self.metrics,
            "metrics_folded": self.folded["metrics"],
            "asymmetry": self.folded["asymmetry"],
            "definitions": {
                "peak": "max of the profile", "span_mm": "extent of s where P >= 10 % of peak",
                "auc": "trapezoid integral of P over s (unit x mm)",
                "folded": "two-sided profile folded about the origin: mean of P(+s), P(-s)"},
        }

    def write(self, out, *, cmap: str = "viridis") -> dict[str, Path]:
        """Write profile.csv, summary.json and pressure_map.png into ``out``.

        ``out`` must be new, empty or a `film analyze` folder (outdir.claim_dir), and no other
        run may be writing into it (its run lock; OutputError, the folder left as it is). The
        files are staged and moved in together (staging.staged_files): a failed write leaves the
        folder as it was. A comparison left there by an earlier `film compare` is removed: it
        describes the previous profile.
        """
        from tactileskin.film import plots

        plots._check_cmap(cmap)
        out = outdir.claim_dir(out, "film-analyze")
        with outdir.run_lock(out, "out"):
            return self.write_owned(out, cmap=cmap)

    def write_owned(self, out, *, cmap: str = "viridis") -> dict[str, Path]:
        """`write` into a folder the caller has claimed and holds the run lock of (the CLI's
        outdir.claimed): the lock is not taken again, as a second flock would be refused."""
        from tactileskin.film import plots

        plots._check_cmap(cmap)
        out = Path(out)
        names = {"profile": "profile.csv", "summary": "summary.json", "map": "pressure_map.png"}
        # the calibration's unit in every pressure column (MPa/mm under Eq. 8, MPa under a press
        # calibration) and the status on every row, as the solver's profile.csv has it
        u = unit_suffix(self.unit)
        lines = [f"s_mm,pressure_{u},pressure_sd_{u},band90_lo_{u},band90_hi_{u},status"]
        status = "ok" if not self.warnings else "suspect: " + "; ".join(str(w) for w in self.warnings)
        cell = '"' + status.replace('"', '""') + '"' if any(c in status for c in ',"\n') else status
        for k in range(self.s_mm.size):
            lo = f"{self.band_lo[k]:.6g}" if self.band_lo is not None else ""
            hi = f"{self.band_hi[k]:.6g}" if self.band_hi is not None else ""
            sd = f"{self.pressure_sd[k]:.6g}" if self.pressure_sd is not None else ""
            lines.append(f"{self.s_mm[k]:.6g},{self.pressure[k]:.6g},{sd},{lo},{hi},{cell}")
        with staging.staged_files(out, ANALYZE_NAMES + COMPARE_NAMES, last=names["summary"]) as tmp:
            fileio.atomic_write_text(tmp / names["profile"], "\n".join(lines) + "\n")
            fileio.atomic_write_json(tmp / names["summary"], self.summary())
            plots.pressure_map(self, tmp / names["map"], cmap=cmap)
        return {k: out / v for k, v in names.items()}


def area_unit(unit: str) -> str:
    """The unit of a pressure in `unit` integrated over s (mm): 'MPa' -> 'MPa mm', the paper's
    'MPa/mm' -> 'MPa' (written as 'MPa/mm mm' it read as MPa/mm^2)."""
    import re

    base = re.sub(r"\s*/\s*mm$", "", str(unit).strip())
    return base if base != str(unit).strip() else f"{base} mm"


def unit_suffix(unit: str) -> str:
    """A unit as a column-name suffix: 'MPa' -> 'mpa', 'MPa/mm' -> 'mpa_per_mm'."""
    import re

    return re.sub(r"[^a-z0-9]+", "_", str(unit).lower().replace("/", "_per_")).strip("_") or "unitless"


def _scan_array(scan) -> tuple[str, np.ndarray, str]:
    if isinstance(scan, (str, Path)):
        gray, note = read_scan(scan)
        return str(scan), gray, note
    gray = np.asarray(scan, float)
    if gray.ndim == 3:
        gray = luminance(gray)
    if gray.ndim != 2 or gray.size == 0 or not np.all(np.isfinite(gray)):
        raise ParameterError("scan", f"array {gray.shape}", "a finite, non-empty 2-D array")
    if gray.min() < 0 or gray.max() > 255:
        raise ParameterError("scan", f"array [{gray.min():g}, {gray.max():g}]",
                             "grayscale values in [0, 255]")
    return "<array>", gray, "array: read as 0-255"


SPAN_LEVEL = 0.1  # the span's threshold as a fraction of the peak (tactileskin.results.span)
# folded asymmetry (fold_profile: max |P(+s) - P(-s)| / peak) above which the fold is flagged: twice
# the film's +-10 % accuracy, as the discrimination threshold (a twin-peaked press centred on one
# peak by --centre peak read 1.0, with a span 50 % long; noise and blur read below 0.05)
ASYMMETRY = 0.2
PLATEAU = 0.9     # a given region whose every column reads >= this x the peak lies inside the press
# both ends of the profile above zero: the unpressed film reads as pressure (scanned darker than the
# calibration's zero), a baseline in every column; flagged when it makes more than this share of the
# area (half the film's +-10 %): white film at GS 228 under Eq. 8 (zero at 230.1) read 0.0089 MPa/mm,
# 2 % of the peak, and the folded area +21 % over a 30 mm strip
BASELINE = 0.05
# a strip tilted on the scan: averaging across its width smears the profile over the drift of its
# centre across the width; flagged above this share of the span (a Gaussian's peak reads ~5 % low
# there): 6 mm wide at 10 degrees read a 0.5 peak (sd 0.5 mm) as 0.430 and its span +17 %
TILT = 0.25


def _tilt(pmap: np.ndarray) -> tuple[float, int]:
    """(drift of the pressure centroid along the strip per row across it, in columns per row;
    the rows that carry pressure, first to last): a line fitted to each row's centroid of the
    pixels >= 10 % of the largest; (0, 0) if undefined."""
    w = np.where(pmap >= SPAN_LEVEL * pmap.max(), pmap, 0.0)
    ws = w.sum(axis=1)
    rows = np.flatnonzero(ws > 0)
    if rows.size < 3:
        return 0.0, 0
    c = (w[rows] @ np.arange(pmap.shape[1])) / ws[rows]
    return float(np.polyfit(rows, c, 1)[0]), int(rows[-1] - rows[0])


def calibration_coverage(cal: Calibration, gray: np.ndarray, pmap: np.ndarray) -> dict:
    """Pixels of a region outside the calibration's grayscale range (the presses' range):
    held_fraction, beyond the highest-pressure press and read as its pressure although the
    activation range goes higher (a silent clip, unlike saturation at the activation range's
    top); extrapolated_fraction, activated pixels beyond the lowest-pressure press, read on the
    fit's tangent; and the two ends' grayscale and pressure."""
    g_hi, g_lo = cal._ends()          # (the high-pressure end, the low-pressure end)
    lo, hi = cal.p_range
    p_hi = float(np.clip(cal._f(g_hi), lo, hi))
    p_lo = float(np.clip(cal._f(g_lo), lo, hi))
    gs0, gs1 = cal.gs_range
    past_hi = (gray < gs0) if g_hi == gs0 else (gray > gs1)
    past_lo = (gray > gs1) if g_lo == gs1 else (gray < gs0)
    return {"gs_range": [float(gs0), float(gs1)],
            "high_end_gs": float(g_hi), "high_end_pressure": p_hi,
            "low_end_gs": float(g_lo), "low_end_pressure": p_lo,
            "held_fraction": float(np.mean(past_hi & (pmap < hi))),
            "extrapolated_fraction": float(np.mean(past_lo & (pmap > lo)))}


def _looks_inverted(cal: Calibration, gray: np.ndarray, pmaps) -> str:
    """The warning for a scan whose surroundings read as pressure and whose strip reads less
    (white on black, or unpressed film that is not white), else "", judged on each pressure map
    of `pmaps` (the region's; found automatically, also the whole image's: the region found
    may be a band of the background). Such a scan read its dark background as the profile, and
    the reason given was 'widen the region' or 'try --axis y'."""
    edges = np.concatenate([gray[0], gray[-1], gray[:, 0], gray[:, -1]])
    g = float(np.median(edges))  # a real scan's edges: white film or the scanner's lid
    p_edge = float(cal.pressure(g))
    if p_edge <= 0:
        return ""
    for m in (m for pm in pmaps for m in (pm.mean(axis=0), pm.mean(axis=1))):  # along, across
        top = float(m.max())
        # the region's ends read as the surroundings, nothing in it darker, and a lighter dip
        if (min(m[0], m[-1]) >= (1 - INVERTED) * top and top <= (1 + INVERTED) * p_edge
                and float(m.min()) < (1 - INVERTED) * top):
            return (f"the scan looks inverted (white on black) or its unpressed film is not white: the image's "
                    f"edges (median GS {g:.0f}) are darker than the activation threshold (GS "
                    f"{cal.threshold_gs:.4g}) and read as pressure, the region is lighter inside than at its "
                    "ends; the numbers describe the background, not the press. No option inverts a scan "
                    "(0 = black): save it as dark film on white, or give --box-px/--box-mm on the film if only "
                    "its surroundings are dark")
    return ""


def _variation(pmap: np.ndarray) -> float:
    """Pressure-weighted mean over the columns of the std / mean across the rows (axis 0), over
    the columns whose mean is at least 10 % of the largest."""
    m = pmap.mean(axis=0)
    top = float(m.max()) if m.size else 0.0
    keep = m >= 0.1 * top if top > 0 else np.zeros(m.shape, bool)
    if not keep.any():
        return 0.0
    return float(np.sum(pmap.std(axis=0)[keep]) / np.sum(m[keep]))


# The strip's rows (mean pressure >= STRIP_ROWS x the largest row's) are averaged at each column
# before the calibration's low rule (a mean below the threshold reads 0), as a press is read at
# its mean grayscale: zeroing each pixel first rectified the scan noise about the threshold and
# a weak profile read high (peak 0.02 MPa/mm, 4 GS noise: area 0.121 for 0.100, +20 %). Rows
# beside the strip (a box wider than it) are white film, read per pixel as before: unactivated,
# 0, not the tangent's negative pressure (averaged in, they took 71 % of such a box's area).
STRIP_ROWS = 0.5


def _across(cal: Calibration, region: np.ndarray, pmap: np.ndarray):
    """(profile, band or None): the mean across the rows at each column; see STRIP_ROWS. The
    band is the calibration's at the strip's mean reading and each other pixel's, averaged alike
    (its error is one for every pixel, its parameters; at the column-mean grayscale it missed
    the profile of a box with white rows: P 0.171, band 0.132-0.139)."""
    rows = pmap.mean(axis=1)
    strip = rows >= STRIP_ROWS * rows.max()
    n_s, n = int(strip.sum()), region.shape[0]
    mean = cal.reading(region[strip]).mean(axis=0)
    p_s = np.where(mean < cal.p_range[0], 0.0, mean)
    prof = (n_s * p_s + pmap[~strip].sum(axis=0)) / n
    hw = cal.halfwidth(region)
    if hw is None:
        return prof, None
    lo_s, hi_s = cal.band_at(p_s, hw[strip].mean(axis=0))
    lo_o, hi_o = cal.band_at(pmap[~strip], hw[~strip])
    return prof, ((n_s * lo_s + lo_o.sum(axis=0)) / n, (n_s * hi_s + hi_o.sum(axis=0)) / n)


# A box the user gives with rows beside the strip (mean pressure < STRIP_ROWS x the largest row's: white
# film, blurred edges) averages them into the profile: a 5 mm strip in a 7 mm box read its 0.5 peak as
# 0.357, in a 9 mm box 0.278, with no word. Flagged when they lower it by more than this share of the
# strip's own rows' reading, half the film's +-10 %, as BASELINE (a box exactly on a 5-8 mm strip under
# 1-1.5 px blur and 3 GS noise: <= 3.6 % at 0.1-0.9 MPa/mm; 2 white rows each side of 40: 9 %; the
# blurred edge rows of a weak narrow strip do read below half: 2 mm at 0.05 MPa/mm, 10-14 %)
DILUTION = 0.05


def _ranges(idx, offset: int) -> str:
    """Sorted indices -> 'a-b, c, d-e' (inclusive) shifted by offset."""
    out, start = [], idx[0]
    for k in range(1, len(idx) + 1):
        if k == len(idx) or idx[k] != idx[k - 1] + 1:
            a, b = start + offset, idx[k - 1] + offset
            out.append(f"{a}" if a == b else f"{a}-{b}")
            if k < len(idx):
                start = idx[k]
    return ", ".join(out)


def _diluted(pmap: np.ndarray, box, axis: str) -> str:
    """The warning for a region whose rows beside the strip (STRIP_ROWS) lower the profile by more
    than DILUTION, naming them and the box on the strip's rows, else ""."""
    rows = pmap.mean(axis=1)
    strip = rows >= STRIP_ROWS * rows.max()
    low = np.flatnonzero(~strip)
    if low.size == 0:
        return ""
    share = 1.0 - float(rows.mean() / rows[strip].mean())
    if share <= DILUTION:
        return ""
    x0, y0, x1, y1 = box
    a, b = (int(i) for i in np.flatnonzero(strip)[[0, -1]])
    across, off, lines = ("y", y0, "rows") if axis == "x" else ("x", x0, "columns")
    fix = (x0, y0 + a, x1, y0 + b + 1) if axis == "x" else (x0 + a, y0, x0 + b + 1, y1)
    return (f"{low.size} of the region's {rows.size} {lines} across the strip ({across} {_ranges(low, off)} px) read "
            f"below {STRIP_ROWS:.0%} of its strongest one's mean pressure (white film beside the press or its blurred "
            f"edge): averaged in, they lower the profile (peak, area) {share:.0%} below the strip's own {lines}' "
            f"reading; narrow the box to the strip's {lines}: --box-px {' '.join(str(int(v)) for v in fix)}")


# A press that is not uniform across the strip (a round one: a sphere, a Braille dot) has rows that read
# 50-100 % of its middle row, and their mean is read as the profile: a Gaussian spot's 0.5 peak read 0.41
# (its 3D section's centre line reads the 0.5), status ok. Flagged when the outer half of the strip's
# rows (STRIP_ROWS; by distance from their middle) reads below this share of the inner half: a contrast
# of two means of many rows, so row noise does not trigger it. Under 3 GS noise and 0-2 px blur (5 seeds,
# 0.05-0.9 MPa/mm) strips 5-10 mm wide read >= 0.898 (in a box exactly on them; found automatically
# >= 0.941), round spots with >= 4 rows (Gaussian sd 0.5-3 mm, Hertzian a 0.75-3 mm, 0.1-0.9 MPa/mm)
# <= 0.808; Hertzian dots of a = 0.5 mm (4-6 rows at 8 px/mm) <= 0.884, 76 of 80 flagged (the 4 others:
# 4 rows, 1-2 px blur, 0.1-0.2 MPa/mm). A narrow strip's blurred edge rows fall off too (2 mm in a box on it
# under >= 1 px blur: its mean 7-13 % below its middle rows; found automatically, its edges are dropped)
ROUND = 0.87


def _not_uniform(pmap: np.ndarray, box, axis: str) -> str:
    """The warning for a strip whose rows' mean pressure falls off from its middle (ROUND), naming
    the shortfall of their mean against the middle quarter's and a box on those rows, else ""."""
    rows = pmap.mean(axis=1)
    idx = np.flatnonzero(rows >= STRIP_ROWS * rows.max())
    if idx.size < 4:  # a row or three: read as the centre line already
        return ""
    dist = np.abs(idx - 0.5 * (idx[0] + idx[-1]))
    order = idx[np.argsort(dist, kind="stable")]
    # the nearer half by distance, the two rows at a distance on one side: split by count, a pair was
    # parted and a dot of 5 rows (radius 0.5 mm at 8 px/mm) read 0.873 for its tie-free 0.80
    inner = dist <= np.sort(dist)[idx.size // 2 - 1]
    ratio = float(rows[idx[~inner]].mean() / rows[idx[inner]].mean())
    if ratio >= ROUND:
        return ""
    mid = np.sort(order[:max(idx.size // 4, 1)])
    short = 1.0 - float(rows[idx].mean() / rows[mid].mean())
    x0, y0, x1, y1 = box
    a, b = int(mid[0]), int(mid[-1])
    across, off, lines = ("y", y0, "rows") if axis == "x" else ("x", x0, "columns")
    fix = (x0, y0 + a, x1, y0 + b + 1) if axis == "x" else (x0 + a, y0, x0 + b + 1, y1)
    return (f"the pressure is not uniform across the strip: the outer half of its {idx.size} {lines} ({across} "
            f"{idx[0] + off}-{idx[-1] + off} px) reads {ratio:.0%} of the inner half, as a round press (a sphere, a "
            f"dot) or a narrow strip's blurred edges, not a line uniform along its length; the profile, their mean, "
            f"reads {short:.0%} below its middle {lines}' (a section's centre line): for the centre line read --rows "
            f"centre (the row through the peak) or a box on those, --box-px {' '.join(str(int(v)) for v in fix)}")


# One row (rows="centre") keeps its pixels' noise, and the peak, the largest of the samples near it, reads
# high by up to (90 % of the time) the sd x _row_reach(n) of the n samples within 3 sd of it, at least twice
# the sd (a round press's few top samples; a uniform strip's flat top, ~90 samples: ~3 sd, and a 5 mm strip
# at 0.3 MPa/mm under 3 GS, its sd 4 % of the peak, read +11 to +13 % unflagged): flagged where that reach
# is above twice this share of the peak, the film's +-10 %, i.e. where the sd is above it (Hertzian spots under
# 3 GS: 0.1 MPa/mm read up to +32 %, 0.2 up to +15 %, 0.5 up to +5.5 %). Over Hertzian spots a = 0.5-3 mm,
# 0.05-0.9 MPa/mm, 0-3 GS, 0-2 px blur, 3 seeds, 8 px/mm and 300 dpi: of the peaks read > 10 % above the
# same spot's noise-free reading 270 of 271 flagged, 5-10 % 56 of 117, < 5 % 30 of 331; noise-free 1 of
# 360 (0.05 MPa/mm, a = 0.5 mm under 2 px blur: its 8-bit steps are 6 % of its blurred peak)
ROW_NOISE = 0.05
# A strip found a row to three wide (an elongated press with no flat top across, an ellipse along the strip
# trimmed to its middle rows, or a narrow strip whose noisy rows were taken for blurred edges) is read as
# its rows' mean, which keeps their pixel noise / sqrt(n): judged as one row is (Hertzian ellipses along x of
# aspect 1.5-3, b = 0.75-3 mm: a 0.2 MPa/mm one under 3 GS read +15 % on 1-2 rows, status ok; 2-3 mm strips
# trimmed to 1-3 rows under 3-7.65 GS read up to +144 %, told only 'not symmetric'). Not a box the user
# gives: its rows beside may be white film (a sharp strip's edge row read as noisy). Four rows or more are
# judged by the round-press check (_not_uniform) instead
FEW_ROWS = 3


# A press a few pixels wide (a line 0.3-0.5 mm wide at 8 px/mm, a dot) is spread by the scanner's blur into
# the white film beside it, and its profile reads low with no other sign: lines under 1-1.5 px blur read their
# peak and area 14-69 % low, status ok. Judged on its half-maximum width in px (the blur is not known) across the
# strip (the rows' mean over the columns of the profile's peak, on the whole scan) and along it (the profile):
# flagged below RESOLUTION_PX across, ALONG_PX along (a round spot loses to the blur both ways, a press narrow
# along only one), or below FLAT_RESOLUTION_PX where the top is flat (its width at 90 % of the maximum
# >= FLAT_SHARE x that at half: the press spans the blur, its middle rows read the full pressure). Measured
# over lines 0.2-3 mm wide (a Gaussian sd 1 mm along), presses sd 0.1-0.5 mm along a 5 mm strip, Hertzian and
# Gaussian spots a = 0.2-3 mm read --rows centre, at 4, 8, 11.8 (300 dpi) and 16 px/mm, 0-2 px blur, 0/3 GS,
# 0.2-0.9 MPa/mm: of the readings > 10 % low (peak or area) all 344 lines, 300 of 306 narrow presses and 397 of
# 417 spots are flagged (not: 16 spots 12-15 px wide and 6 presses 10-12 px wide under 2 px blur, 10-15 % low:
# that wide they read within 1 % on a sharp scan); of those within 10 % and unwarned, 209 of 615 lines, 179 of
# 275 narrow presses and 261 of 1152 spots are flagged, 92 % of them under <= 1 px blur (a press this narrow
# reads right only on a sharp scan). Flat-topped readings > 10 % low were < 3.6 px wide, round-topped ones up
# to 15 px. Uniform 5-10 mm strips: none flagged (1200)
RESOLUTION_PX, ALONG_PX, FLAT_RESOLUTION_PX, FLAT_SHARE = 12.0, 10.0, 6.0, 0.65
# Wider than those a round-topped press still read low unwarned (Gaussian spots 12-15 px wide and presses 10-11 px
# along under 2 px blur, 10-15 % low): it is judged on the share of its peak a blur of BLUR_PX (the set's largest)
# takes off, or the less its edges on the scan allow (_blur_bound; a Gaussian has no sharp edge, a Hertzian spot
# does), flagged above BLUR_LOSS (9 %: the Gaussian reading of a pixel-sampled spot's width put 10.2-10.5 % low at
# 9.9 %). benchmarks/film_resolution.py: readings > 10 % low unflagged 20 -> 2 of 1139, within 10 % flagged 774 ->
# 856 of 2245 (12 more on sharp scans); the noise check's sets are unchanged (benchmarks/film_row_noise.py)
BLUR_PX, BLUR_LOSS = 2.0, 0.09


def _run_width(v: np.ndarray, i: int, frac: float) -> float | None:
    """Width in samples (linear interpolation) of the contiguous run about sample i at >= frac * v[i], or None
    if it reaches either end (the press's extent there is not seen)."""
    thr = frac * v[i]
    a, b = i, i
    while a > 0 and v[a - 1] >= thr:
        a -= 1
    while b < v.size - 1 and v[b + 1] >= thr:
        b += 1
    if a == 0 or b == v.size - 1:
        return None
    return float((b - a) + (v[a] - thr) / (v[a] - v[a - 1]) + (v[b] - thr) / (v[b] - v[b + 1]))


def _blur_bound(g: np.ndarray, v: np.ndarray, i: int) -> float:
    """An upper bound (px) on the sd of the scan's Gaussian blur from a grayscale profile g darkest near sample
    i (v: its pressure): blurred, an edge rising by dG from the press to the white film beside it is nowhere
    steeper than dG / (sd sqrt(2 pi)) (its steepest blurred step), whatever the press's own shape; the smaller of
    the two sides' dG / (steepest step x sqrt(2 pi)), each over the press's own edge (_own_edge: a darker press or
    a pen mark further on the scan has steeper steps under the same blur). inf where neither side rises."""
    out = math.inf
    for gs, vs in ((g[i::-1], v[i::-1]), (g[i:], v[i:])):  # from the press outwards
        side = gs[:_own_edge(gs, vs)]
        if side.size < 2:
            continue
        rise = float(side.max() - side[0])
        step = float(np.max(np.diff(side)))
        if rise > 0 and step > 0:
            out = min(out, rise / (step * math.sqrt(2 * math.pi)))
    return out


def _own_edge(g: np.ndarray, v: np.ndarray) -> int:
    """How many samples of a gray profile g (pressure v) from a press outwards are its own edge: up to the first
    one, past where v first reads 0 (the film beside it), that is activated again or darker than the lightest
    gray before it by half the rise to that (another press, a pen mark); all of them where v never reads 0."""
    zero = np.flatnonzero(v <= 0)
    if zero.size == 0:
        return g.size
    top = np.maximum.accumulate(g)
    other = (np.arange(g.size) > zero[0]) & ((v > 0) | (top - g > 0.5 * (top - g[0])))
    return int(np.argmax(other)) if other.any() else g.size


# a Gaussian's sd over its width at half its maximum, and at 90 % of it
SD_PER_W50, SD_PER_W90 = (1.0 / (2.0 * math.sqrt(2.0 * math.log(1.0 / f))) for f in (0.5, 0.9))


def _blur_loss(widths, blur: float) -> float:
    """The share a blur of sd `blur` px takes off the peak of a round-topped press whose blurred widths at half
    and 90 % of its maximum are `widths` px ((w50, w90) across and along; None where its top is flat or its
    extent unseen), read as Gaussian in each: its own sd sqrt(s^2 - blur^2) of the s read, the peak down by
    their ratio in each direction. s is the larger of the two widths' sd: a Hertzian top is wider at 90 % than
    a Gaussian's of its half width (its curvature, which the blur acts on; the Gaussian's read 2 x its loss)."""
    keep = 1.0
    for w in widths:
        if w is not None:
            s = max(w[0] * SD_PER_W50, w[1] * SD_PER_W90)
            keep *= math.sqrt(max(0.0, 1.0 - (blur / s) ** 2))
    return 1.0 - keep


def _narrow(across: np.ndarray, k: int, prof: np.ndarray, px_per_mm: float, axis: str, grays=None) -> str:
    """The warning for a press too few pixels wide across the strip (the row means `across`, peak row k) or
    along it (the profile) for the scan's blur (RESOLUTION_PX), naming its width and the dpi that would give
    enough pixels, else "". grays: the same two profiles in grayscale, for the blur the press's edges
    allow (BLUR_PX, BLUR_LOSS)."""
    ends = {}
    for where, v, i, rounded in (("across", across, k, RESOLUTION_PX), ("along", prof, int(np.argmax(prof)), ALONG_PX)):
        if v[i] <= 0:
            continue
        w50, w90 = _run_width(v, i, 0.5), _run_width(v, i, 0.9)
        if w50 is None:
            continue
        flat = w90 is not None and w90 >= FLAT_SHARE * w50
        ends[where] = i, (w50, w90 if w90 is not None else 0.0), flat, v
        need = FLAT_RESOLUTION_PX if flat else rounded
        if w50 < need:
            return _narrow_text(where, w50, need, px_per_mm * need / w50, px_per_mm, axis)
    if grays is None or not ends:
        return ""
    # wider than those: a round-topped press still reads low where the blur is a large part of its width (a
    # Gaussian spot 12-15 px wide under 2 px blur, 10-15 % low); the blur is BLUR_PX at most, less where a
    # steep edge on the scan bounds it
    blur = min([BLUR_PX] + [_blur_bound(np.asarray(g, float), ends[w][3], ends[w][0])
                            for w, g in zip(("across", "along"), grays) if w in ends])
    widths = [None if ends.get(w, (0, 0, True))[2] else ends[w][1] for w in ("across", "along")]
    loss = _blur_loss(widths, blur)
    if loss <= BLUR_LOSS:
        return ""
    lo, hi = 1.0, 4.0  # the scale (px/mm x) that brings the loss to BLUR_LOSS
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        scaled = [None if w is None else (mid * w[0], mid * w[1]) for w in widths]
        lo, hi = (mid, hi) if _blur_loss(scaled, blur) > BLUR_LOSS else (lo, mid)
    where = "along" if widths[1] is not None and (widths[0] is None or widths[1][0] < widths[0][0]) else "across"
    w50 = ends[where][1][0]
    return _narrow_text(where, w50, hi * w50, px_per_mm * hi, px_per_mm, axis,
                        why=f" (a blur of up to {blur:.2g} px, as its edges allow, takes about {loss:.0%} off its peak)")


def _narrow_text(where, w50, need, ppm, px_per_mm, axis, why="") -> str:
    # the width needed rounded up, and the width read to as many decimals as keep it printed under that (both
    # to the nearest 0.1 px read "11.3 px wide ... under the 11.3 px")
    need = math.ceil(need * 10.0 - 1e-9) / 10.0
    digits = next((d for d in range(1, 4) if round(w50, d) < need), 4)
    return (f"the scan's resolution is too coarse for this press: it is {w50:.{digits}f} px ({w50 / px_per_mm:.3g} mm) "
            f"wide {where} the strip ({'y' if (where == 'across') == (axis == 'x') else 'x'}) at half its "
            f"maximum, under the {need:g} px a reading within the film's 10 % needs{why} (the scanner's blur "
            f"spreads a narrower press into the film beside it: 0.3-0.5 mm lines at 8 px/mm read 14-69 % "
            f"low), so the peak and area may read low{' and the span long' if where == 'along' else ''} (by "
            f"how much depends on the scanner's blur, which a scan does not tell); scan at {math.ceil(25.4 * ppm)} dpi or more ({ppm:.3g} px/mm: "
            f"{need:.3g} px over it; give the new scan's scale with --px-per-mm)")


def _row_reach(n: int) -> float:
    """How many sd the largest of n samples of one noise reads above their common level, at most
    (90 % of the time: the normal quantile 0.9 ** (1 / n)), and at least 2."""
    from scipy.special import ndtri

    return max(2.0, float(ndtri(0.9 ** (1.0 / max(n, 1)))))


def _flat_ends(cal: Calibration) -> tuple[float, float]:
    """The readings a clipped pixel holds: the activation range's bottom and the lower of its top and the
    calibration's darkest press (darker pixels are held there: calibration.Calibration.reading), for _row_noise."""
    lo, hi = cal.p_range
    # a hair under it: a transcendental model may round a 0-d and an array evaluation an ulp apart
    return lo, min(hi, float(cal.pressure(cal._ends()[0])) * (1.0 - 1e-12))


SHAPE_COLUMNS = 10  # _row_noise(shape=True): the fewest columns to fit a press's edge step over


def _roughness(row: np.ndarray, keep: np.ndarray) -> float | None:
    """The pixel noise (sd) of a row from its second differences along it over runs of kept columns (a smooth
    profile's nearly vanish; independent noise's have variance 6 sd^2), their mean (the curvature) taken out;
    None under 3 of them."""
    j = np.flatnonzero(keep[:-2] & keep[1:-1] & keep[2:])
    if j.size < 3:
        return None
    return float(np.std(row[j] - 2.0 * row[j + 1] + row[j + 2]) / math.sqrt(6.0))


def _row_noise(pmap: np.ndarray, k: int, shape: bool = False, clip=None, how: list | None = None) -> float | None:
    """The pixel noise (sd) of row k: the spread of the row less its neighbours' mean over the columns at
    >= SPAN_LEVEL of its largest (the curvature across, nearly constant along them, drops out of the
    spread), / sqrt(1 + 1/n) for the neighbours' own noise; None without a neighbour or 3 such columns.
    clip: the (lowest, highest) reading (_flat_ends): a column where the row or both neighbours read one is left out
    (a dot's edge whose neighbours read 0: the difference there is the row itself, not noise).
    shape: less first the part of that difference proportional to the neighbours' mean (a press a few
    pixels wide: its neighbours are its blurred edges, whose step below it scales with the profile along
    it, and was read as noise: a noise-free 0.3 mm line at 8 px/mm, 5 % of its peak); a row whose neighbours read
    under STRIP_ROWS of it is the press alone across, judged on its roughness along it (_roughness; "rough" is then
    appended to `how`, for the warning's words)."""
    nb = [j for j in (k - 1, k + 1) if 0 <= j < pmap.shape[0]]
    row = pmap[k]
    keep = row >= SPAN_LEVEL * row.max()
    if shape and nb and pmap[nb][:, keep].mean(axis=0).sum() < STRIP_ROWS * row[keep].sum():
        # the row stands alone (a line a pixel wide): the rows beside are white film and its blur, the row less
        # them its own height along its profile (a noise-free 0.2 mm line at 4 px/mm: 6 % of its peak), not noise
        unclipped = keep if clip is None else keep & (row > clip[0]) & (row < clip[1])
        rough = _roughness(row, unclipped)
        if rough is not None:
            if how is not None:
                how.append("rough")
            return rough
    if clip is not None and nb:  # (one neighbour clipped still holds the other's reading and the row's noise)
        inside = (pmap[[k] + nb] > clip[0]) & (pmap[[k] + nb] < clip[1])
        keep &= inside[0] & inside[1:].any(axis=0)
    if not nb or keep.sum() < 3:
        return None
    m = pmap[nb][:, keep].mean(axis=0)
    d = row[keep] - m
    if shape and d.size >= SHAPE_COLUMNS:  # the residual of a line fitted to d against m, its 2 parameters
        # taken from the count
        if np.ptp(m) > 1e-9 * np.abs(m).max():
            fit, dof = np.polyval(np.polyfit(m, d, 1), m), 2
        else:  # a constant m (a uniform line's edges, one gray level): the step is a constant
            fit, dof = d.mean(), 1  # (polyfit warned, 'poorly conditioned', on the CLI's stderr)
        return float(np.std(d - fit) * np.sqrt(d.size / (d.size - dof)) / np.sqrt(1 + 1 / len(nb)))
    spread = float(np.std(d))  # less the step as a constant
    if shape:  # a dot's few columns: a line's two parameters took real noise with them; the step as a share
        # of m instead where that leaves less (a round press's rows beside its centre are a share of it: a
        # Gaussian's exactly), one parameter either way
        c = float(m @ d / (m @ m)) if m @ m > 0 else 0.0
        spread = min(spread, float(np.sqrt(np.mean((d - c * m) ** 2))))
    return spread / float(np.sqrt(1 + 1 / len(nb)))


def analyze_scan(scan, calibration: Calibration | None = None, *, px_per_mm: float = PX_PER_MM,
                 box_px=None, box_mm=None, axis: str = "x", centre="peak", rows: str = "all") -> FilmProfile:
    """Scan (path or (H, W) grayscale array) -> FilmProfile.

    calibration: default ``paper_eq8``. box_px / box_mm: the region (x0, y0, x1, y1);
    neither: the activated strip is found automatically (``film.region``; refused if
    ambiguous). centre: "peak", "midspan" or a number (origin in mm from the image's left
    edge for axis "x", top edge for "y", inside the image). rows: "all" (the profile is the
    mean across the region's rows) or "centre" (the one row through the peak of the rows' mean
    pressures, a flat top's middle row: a round press's centre line; one row's noise is not averaged down).
    """
    cal = calibration or paper_eq8()
    lo_s, hi_s = PX_PER_MM_RANGE
    px_per_mm = finite("px_per_mm", px_per_mm, 0, lo_open=True, unit="px/mm")
    if not lo_s <= px_per_mm <= hi_s:
        raise ParameterError("px_per_mm", px_per_mm, f"[{lo_s:g}, {hi_s:g}] px/mm")
    if axis not in ("x", "y"):
        raise ParameterError("axis", axis, "'x' (strip along columns) or 'y' (along rows)")
    if rows not in ("all", "centre"):
        raise ParameterError("rows", rows, "'all' (their mean) or 'centre' (the row through the peak)")
    if isinstance(centre, str):
        if centre not in ("peak", "midspan"):
            raise ParameterError("centre", centre, "'peak', 'midspan' or an origin in mm")
    else:
        centre = finite("centre", centre, unit="mm")
    source, gray, note = _scan_array(scan)
    file_ppm = file_px_per_mm(scan) if isinstance(scan, (str, Path)) else None
    length_mm = gray.shape[1 if axis == "x" else 0] / px_per_mm
    if not isinstance(centre, str) and not 0 <= centre <= length_mm:
        raise ParameterError("centre", centre, f"[0, {length_mm:g}] mm (inside the image, "
                             f"{'left' if axis == 'x' else 'top'} edge = 0)")
    if box_px is None and box_mm is None:
        oriented = gray if axis == "x" else gray.T
        p_all = cal.pressure(oriented)
        c0, r0, c1, r1 = strip_region.find_strip(p_all, cal.p_range[0], px_per_mm)
        box = (c0, r0, c1, r1) if axis == "x" else (r0, c0, r1, c1)
        region_info = {"method": "auto", "rule": strip_region.RULE}
        # the variation across the strip found along the other axis, for the orientation check
        try:
            o0, q0, o1, q1 = strip_region.find_strip(p_all.T, cal.p_range[0], px_per_mm)
            across_other = _variation(p_all.T[q0:q1, o0:o1])
        except ParameterError:
            across_other = None
        log.info("no region given: analysing the activated strip found at x %d-%d, "
                 "y %d-%d px (pass --box-px/--box-mm to choose another)",
                 box[0], box[2], box[1], box[3])
    else:
        across_other = None  # the user's box: its orientation is theirs
        _, box = select_region(gray, box_px=box_px, box_mm=box_mm, px_per_mm=px_per_mm)
        region_info = {"method": "box_mm" if box_mm is not None else "box_px",
                       "given": [float(v) for v in (box_mm if box_mm is not None else box_px)]}
    x0, y0, x1, y1 = box
    region = gray[y0:y1, x0:x1]
    start = box[0] if axis == "x" else box[1]
    if axis == "y":
        region = region.T
    if region.shape[1] < 3:
        if region_info["method"] == "box_mm":  # the option's unit, not the 'region length' it came to
            raise ParameterError("box_mm", tuple(region_info["given"]), f"a box >= {3 / px_per_mm:.4g} mm along the "
                                 f"strip ({axis}): 3 px at {px_per_mm:g} px/mm",
                                 hint=f"--box-mm is rounded to pixel edges: this box is {region.shape[1]} px along it")
        if region_info["method"] == "box_px":
            raise ParameterError("box_px", tuple(int(v) for v in region_info["given"]),
                                 f"a box >= 3 px along the strip ({axis})")
        raise ParameterError("region length", region.shape[1], ">= 3 px along the strip")

    pmap = cal.pressure(region)
    full = pmap  # the strip's orientation and an inverted scan are judged on all its rows
    row_noise = None  # the pixel noise of a profile read from a row or a few (FEW_ROWS), else not judged
    alone = []  # "rough": its row stands alone across (a line a pixel wide), its noise read along it
    if rows == "centre" or (pmap.shape[0] <= FEW_ROWS and region_info["method"] == "auto"):
        # a round press read across its rows averages its fall-off (a Hertzian spot's mean 9 % below its
        # centre line): the row through the peak of the row means, found as the peak along the strip is
        # (a parabola over the rows >= 80 % of the largest; a flat top's middle). Their largest alone picked
        # the first of a uniform strip's equal rows, its edge, whose neighbour is white film (exit 3)
        k = int(np.rint(_peak_position(np.arange(pmap.shape[0], dtype=float), pmap.mean(axis=1))))
        oriented, r = (gray, y0 + k) if axis == "x" else (gray.T, x0 + k)  # its row in the image
        c_lo, c_hi = (x0, x1) if axis == "x" else (y0, y1)
        # the rows beside it on the image (the region found may be a row or two), for its noise
        beside = cal.pressure(oriented[max(r - 1, 0):r + 2, c_lo:c_hi]), r - max(r - 1, 0)
        row_noise = _row_noise(*beside, clip=_flat_ends(cal))
        near = max(r - 2, 0), min(r + 3, oriented.shape[0])  # 5 rows about it: their mean's noise / sqrt(5)
    if rows == "centre":
        region, pmap = region[k:k + 1], pmap[k:k + 1]
        x0, y0, x1, y1 = box = (x0, y0 + k, x1, y0 + k + 1) if axis == "x" else (x0 + k, y0, x0 + k + 1, y1)
        region_info = {**region_info, "rows": f"centre: the row through the peak, {'y' if axis == 'x' else 'x'} "
                                              f"{(y0 if axis == 'x' else x0)} px"}
    elif row_noise is not None:  # their mean: one row's noise / sqrt(n)
        row_noise /= math.sqrt(pmap.shape[0])
    lo, hi = cal.p_range
    sat = float(np.mean(pmap >= hi))
    inactive = float(np.mean(pmap <= lo))
    if inactive == 1.0:
        raise ParameterError("scan region", "blank strip", f"some pixels darker than the "
                             f"activation threshold GS {cal.threshold_gs:.1f} "
                             f"(calibration {cal.name})",
                             hint=f"region grayscale {region.min():.1f}-{region.max():.1f}")
    # a press darkens an area: activated pixels that no 3 x 3 block of them holds are scan noise, dust
    # or a scratch (blank film with one dust speck read as a 0.60 MPa/mm profile 0.23 mm long, 'ok')
    if not strip_region.pressed(cal.pressure(gray), lo)[y0:y1, x0:x1].any():
        raise ParameterError("scan region", "blank strip", "an activated area: a 3 x 3 px block darker than "
                             f"the activation threshold GS {cal.threshold_gs:.1f} (calibration {cal.name})",
                             hint=f"only {round((1 - inactive) * pmap.size)} isolated activated pixel(s): scan "
                                  "noise, dust or a scratch, no press")
    if sat == 1.0:
        raise ParameterError("scan region", "fully saturated strip", f"some pixels lighter "
                             f"than the saturation grayscale {cal.saturation_gs:.1f} "
                             f"(calibration {cal.name})",
                             hint=f"region grayscale {region.min():.1f}-{region.max():.1f}")
    warnings = []
    if file_ppm is not None and abs(px_per_mm / file_ppm - 1.0) > SCALE_TOL:
        warnings.append(f"the image file records {25.4 * file_ppm:.4g} dpi = {file_ppm:.4g} px/mm but was read at "
                        f"{px_per_mm:g} px/mm: every length (s, span, area, a box in mm) is off by a factor "
                        f"{file_ppm / px_per_mm:.3g}; pass --px-per-mm {file_ppm:.4g} if the file is right")
    if sat > 0:
        warnings.append(f"{100 * sat:.1f} % of the region is at the film's saturation ({hi:g} {cal.unit})")
    coverage = calibration_coverage(cal, region, pmap)
    if coverage["held_fraction"] > 0:
        g_end, p_end = coverage["high_end_gs"], coverage["high_end_pressure"]
        warnings.append(f"{100 * coverage['held_fraction']:.1f} % of the region is beyond the calibration's "
                        f"highest-pressure press (GS {g_end:.4g}): read as {p_end:.4g} {cal.unit}, the calibrated "
                        f"maximum, below the activation range's top ({hi:g} {cal.unit}); the pressure there "
                        "is a lower bound (calibrate to higher pressures)")
    inverted = _looks_inverted(cal, gray, [full] + ([p_all] if region_info["method"] == "auto" else []))
    if inverted:
        warnings.append(inverted)
    across = _variation(full)
    wrong_axis = (not inverted and across_other is not None and across > AXIS_CV
                  and across > AXIS_RATIO * across_other)
    if wrong_axis:
        other = "y" if axis == "x" else "x"
        warnings.append(f"the pressure varies across the strip by {across:.0%} of its mean, across a strip along "
                        f"{other} by {across_other:.0%}: the strip seems to run along {other}; try --axis {other}")
    for w in warnings:
        log.warning("%s", w)
    prof, band = _across(cal, region, pmap)
    # the strip found automatically is its rows; a box the user gives may hold white rows beside it
    diluted = _diluted(pmap, box, axis) if region_info["method"] != "auto" and not inverted else ""
    if diluted:
        warnings.append(diluted)
        log.warning("%s", diluted)
    round_ = _not_uniform(pmap, box, axis) if not wrong_axis and not inverted else ""
    if round_:
        warnings.append(round_)
        log.warning("%s", round_)
    # the press's width across from the whole scan (the region found may be its middle rows), over the
    # columns of its peak (>= PEAK_WINDOW of it: a round press's section through its centre, not the mean of
    # its narrower chords, which put a = 1 mm at 8 px/mm 11.6 px for its 13.9), about the region's strongest row
    oriented = gray if axis == "x" else gray.T
    c_lo = x0 if axis == "x" else y0
    r_lo = y0 if axis == "x" else x0
    cols = np.flatnonzero(prof >= PEAK_WINDOW * float(np.max(prof))) + c_lo
    across_rows = cal.pressure(oriented[:, cols]).mean(axis=1)
    k_across = r_lo + int(np.argmax(across_rows[r_lo:r_lo + pmap.shape[0]]))
    # the same in grayscale, where the scanner blurs (its edges bound the blur: _blur_bound)
    grays = oriented[:, cols].mean(axis=1), region.mean(axis=0)
    narrow = _narrow(across_rows, k_across, prof, px_per_mm, axis, grays)
    if narrow:
        warnings.append(narrow)
        log.warning("%s", narrow)
        if row_noise is not None and " wide across " in narrow:
            # the rows beside a press this narrow are its blurred edges: their step, not noise (the
            # resolution warning says why it reads wrong); the noise left once that step is fitted out
            shaped = _row_noise(*beside, shape=True, clip=_flat_ends(cal), how=alone)
            row_noise = None if shaped is None else shaped / math.sqrt(pmap.shape[0])  # one row or their mean
    top = float(np.max(prof))
    noise_how = "against the rows beside it" + (f", / sqrt({pmap.shape[0]}) for the mean"
                                               if rows != "centre" and pmap.shape[0] > 1 else "")
    if row_noise is not None and alone:
        noise_how = "from its roughness along it (the rows beside it are white film)"
    flat = _flat_ends(cal)
    if row_noise is not None and top >= flat[1]:
        # a peak at the top clip (saturated, or held at the darkest press): the rows beside a held top step
        # by its shape, not noise, but noise may have lifted a pixel under the clip to it (a 0.26 MPa/mm
        # spot under a 0.3 top, 5 GS, read 0.30: +15 %); judged on the profile's roughness along it over
        # its unclipped columns, which a smooth held top's flanks nearly lack
        row_noise = _roughness(prof, (prof >= SPAN_LEVEL * top) & (prof > flat[0]) & (prof < flat[1]))
        noise_how = "from its roughness along it, its clipped top left out"
    n_top = int(np.sum(prof >= top - 3.0 * row_noise)) if row_noise is not None else 0
    if n_top and row_noise * _row_reach(n_top) > 2.0 * ROW_NOISE * top:
        fix = (x0, near[0], x1, near[1]) if axis == "x" else (near[0], y0, near[1], y1)
        n = pmap.shape[0]
        what = ("one row (--rows centre) whose pixel noise" if rows == "centre" else
                f"the mean of the strip's {n} rows found, whose pixel noise" if n > 1 else
                "the strip's one row found, whose pixel noise")
        how = noise_how
        warnings.append(f"the profile is {what}, {row_noise:.2g} {cal.unit} ({how}), "
                        f"is {row_noise / top:.0%} of its peak: the peak, the largest of "
                        f"its {n_top} samples within 3 sd of it, reads high by up to about {_row_reach(n_top):.1f} x "
                        f"that; average a few rows through it: --box-px {' '.join(str(int(v)) for v in fix)}")
        log.warning("%s", warnings[-1])
    # one row has no spread across the width: its column is left empty, not a row of zeros
    sd = pmap.std(axis=0) if pmap.shape[0] > 1 else None
    x_mm = (start + np.arange(region.shape[1]) + 0.5) / px_per_mm   # pixel centres
    if centre == "peak":
        origin = _peak_position(x_mm, prof)
    elif centre == "midspan":
        origin = _midspan_position(x_mm, prof)
    else:
        origin = centre
    s = x_mm - origin
    sh, ph, asym = fold_profile(s, prof)
    if asym > ASYMMETRY and not wrong_axis and not inverted:  # the root cause, said already
        hint = ""
        if centre != "midspan":
            other = fold_profile(x_mm - _midspan_position(x_mm, prof), prof)[2]
            if other < 0.5 * asym:
                hint = f" (about the middle of its half-maximum extent it is {other:.2f}: --centre midspan)"
        warnings.append(f"the profile is not symmetric about its origin at {origin:.3f} mm: |P(+s) - P(-s)| reaches "
                        f"{asym:.2f} of the peak (> {ASYMMETRY:g}), so the folded profile (and a comparison with a "
                        f"half model) averages unlike sides{hint}")
        log.warning("%s", warnings[-1])
    level = SPAN_LEVEL * float(np.max(prof))
    ends = [name for name, v in (("start", prof[0]), ("end", prof[-1])) if level > 0 and v >= level]
    # a region the user put inside the pressed area (every column within 10 % of the peak) is read
    # as given: it has no profile to cut (the span is the region, plainly); summary.json cut_ends
    plateau = region_info["method"] != "auto" and float(np.min(prof)) >= PLATEAU * float(np.max(prof))
    if ends and not plateau and not inverted:  # 'widen the region' would not help an inverted scan
        warnings.append(f"the profile is still at {max(prof[0], prof[-1]) / np.max(prof):.0%} of its peak at the "
                        f"region's {' and '.join(ends)} ({'x' if axis == 'x' else 'y'} "
                        f"{x_mm[0] - 0.5 / px_per_mm:.4g}-{x_mm[-1] + 0.5 / px_per_mm:.4g} mm): the span and area "
                        "are cut there (lower bounds); widen the region")
        log.warning("%s", warnings[-1])
    # over the rows that carry pressure, not the whole region: a box wider than the strip
    # made a 3-degree tilt of a 2 mm strip in an 18 mm box read 48 % of the span
    slope, rows = _tilt(pmap)
    smear = abs(slope) * rows / px_per_mm
    span_two = float(span(x_mm, prof))
    if not wrong_axis and not inverted and span_two > 0 and smear > TILT * span_two:
        angle = np.degrees(np.arctan(abs(slope)))
        warnings.append(f"the strip is tilted on the scan by {angle:.1f} degrees: its centre moves {smear:.3g} mm "
                        f"along it across the region's width, {smear / span_two:.0%} of the span, so the mean across "
                        "the width is smeared (the peak reads low, the span long); rotate the scan to align the strip "
                        "or narrow the region across it")
        log.warning("%s", warnings[-1])
    base = float(min(prof[0], prof[-1]))
    area = float(auc(x_mm, prof))
    if (not ends and not plateau and not inverted and base > 0 and area > 0
            and base * (x_mm[-1] - x_mm[0]) > BASELINE * area):
        warnings.append(f"the profile does not return to zero: both ends of the region read >= {base:.4g} {cal.unit} "
                        f"({base / np.max(prof):.1%} of the peak), {base * (x_mm[-1] - x_mm[0]) / area:.0%} of the "
                        "area over its length: the unpressed film reads as pressure (scanned darker than the "
                        f"calibration's zero, GS {cal.threshold_gs:.4g}?); the area includes that baseline")
        log.warning("%s", warnings[-1])
    if cal.p_range[0] > 0 and level < cal.p_range[0]:
        warnings.append(f"the span's 10 % level ({level:.4g} {cal.unit}) is below the film's activation threshold "
                        f"({cal.p_range[0]:.4g} {cal.unit}: unactivated film reads 0): the span ends at the "
                        "threshold, a lower bound")
        log.warning("%s", warnings[-1])
    if coverage["extrapolated_fraction"] > 0 and level < coverage["low_end_pressure"]:
        warnings.append(f"the span's 10 % level ({level:.4g} {cal.unit}) is below the calibration's lowest "
                        f"press ({coverage['low_end_pressure']:.4g} {cal.unit}, GS {coverage['low_end_gs']:.4g}): "
                        "the span ends where the pressure is extrapolated on the fit's tangent "
                        f"({100 * coverage['extrapolated_fraction']:.1f} % of the region's pixels lie beyond that "
                        "press; calibrate to lower pressures)")
        log.warning("%s", warnings[-1])
    fp = FilmProfile(
        s_mm=s, pressure=prof, pressure_sd=sd,
        band_lo=band[0] if band else None, band_hi=band[1] if band else None,
        pressure_map=pmap, gray=region, box_px=tuple(int(v) for v in box),
        px_per_mm=px_per_mm, axis=axis,
        origin_mm=float(origin), centre=str(centre), unit=cal.unit, calibration=cal,
        saturated_fraction=sat, inactive_fraction=inactive, source=source,
        metrics=profile_metrics(s, prof),
        folded={"s_mm": sh, "pressure": ph, "asymmetry": asym,
                "metrics": profile_metrics(sh, ph)}, region=region_info, image_note=note, warnings=warnings,
        coverage=coverage, file_px_per_mm=file_ppm, cut_ends=ends)
    for k, v in fp.metrics.items():
        if not math.isfinite(v):  # pragma: no cover - inputs are checked finite above
            raise ParameterError(f"metric {k}", v, "finite")
    log.info("film profile %s: peak %.4g %s, span %.3g mm", source, fp.metrics["peak"],
             cal.unit, fp.metrics["span_mm"])
    return fp
