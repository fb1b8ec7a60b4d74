"""Film calibration: mean grayscale (GS, 0 = black .. 255 = white) -> pressure.

Calibration presses give P = F / A (paper Eq. 7, MPa) against the mean grayscale of the
pressed film. We fit P(GS) by least squares (``models``), report the linear fit with its
90 % confidence bounds and residuals, fit the alternatives and select one by AICc.

Conversion rule (``Calibration.pressure``), in words:
- inside the calibrated grayscale range ``gs_range`` the fitted function is used;
- darker than the darkest press (the high-pressure end) the film is treated as saturated:
  the pressure is held at its value at that end (no extrapolation beyond what was measured);
- lighter than the lightest press the function is continued along its tangent, down to
  zero (unactivated film reads zero);
- the result is clipped to the activation range ``p_range`` (the film's stated range).

Units. A calibration fitted from presses yields MPa (Eq. 7). The paper's own Eq. 8 is
stated in "MPa/mm" ("pressure per unit length"; Sec. IV-B says it divided Eq. 7 by the
indented length Y = 10 mm). The paper then plots those numbers on the same axis as its
plane-strain simulation pressures (Fig. 11), i.e. it compares them numerically as if
1 MPa/mm of film reading were 1 MPa of simulated mean pressure (plane strain, per mm of
depth). We keep the unit string of each calibration, carry it to every output, and compare
numbers with the simulation's MPa the same way, flagging the unit in the comparison.
"""

from __future__ import annotations

import csv
import json
import logging
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactileskin.errors import ParameterError
from tactileskin.film import models
from tactileskin.film._io import atomic_write_text

log = logging.getLogger(__name__)

FORMAT = "tactileskin.film.calibration/1"
CRITERION = ("AICc (small-sample corrected Akaike information criterion, k = parameters + 1 "
             "for the error variance); the lowest AICc wins, but any model within 2 AICc units "
             "of it counts as equally supported and the one with fewest parameters is taken "
             "(linear first). AICc rather than adjusted R^2 because it penalises extra "
             "parameters properly for the few presses a calibration has and compares the "
             "nonlinear models on the same likelihood scale. Needs n >= p + 3 points; with "
             "fewer, the linear fit (the paper's choice) is used.")
AICC_TIE = 2.0
MIN_POINTS = 3
_MONO_GRID = 1001


@dataclass(frozen=True)
class Calibration:
    """A grayscale -> pressure map. Evaluate with ``pressure(gs)``; invert with ``grayscale(p)``."""

    name: str
    model: str
    params: tuple[float, ...]
    gs_range: tuple[float, float]      # calibrated grayscale range (lo < hi)
    p_range: tuple[float, float]       # activation range: outputs are clipped to it
    unit: str = "MPa"
    cov: tuple[tuple[float, ...], ...] | None = None   # parameter covariance, if fitted
    dof: int | None = None
    report: dict = field(default_factory=dict, compare=False)

    # -- evaluation -------------------------------------------------------------------
    def _f(self, g):
        return models.MODELS[self.model].f(np.asarray(g, float), np.asarray(self.params, float))

    def _ends(self):
        g0, g1 = self.gs_range
        f0, f1 = float(self._f(g0)), float(self._f(g1))
        # (saturating end, extrapolating end)
        return (g0, g1) if f0 > f1 else (g1, g0)

    def pressure(self, gs) -> np.ndarray:
        """Pressure (``unit``) for grayscale values (any shape); see module docstring."""
        gs = np.asarray(gs, float)
        if not np.all(np.isfinite(gs)):
            raise ParameterError("grayscale", "non-finite values", "finite numbers in [0, 255]")
        g0, g1 = self.gs_range
        _, g_ext = self._ends()
        p = self._f(np.clip(gs, g0, g1))
        # tangent continuation beyond the light end (one-sided difference inside the range)
        h = 1e-6 * (g1 - g0)
        inward = h if g_ext == g0 else -h
        slope = float((self._f(g_ext + inward) - self._f(g_ext)) / inward)
        beyond = (gs < g0) if g_ext == g0 else (gs > g1)
        p = np.where(beyond, float(self._f(g_ext)) + slope * (gs - g_ext), p)
        return np.clip(p, *self.p_range)

    def band(self, gs) -> tuple[np.ndarray, np.ndarray] | None:
        """90 % confidence band of the calibration at gs (clipped like ``pressure``), or None."""
        if self.cov is None or not self.dof:
            return None
        gs = np.asarray(gs, float)
        hw = models.band_halfwidth(self.model, self.params, self.cov, self.dof,
                                   np.clip(gs, *self.gs_range))
        p = self.pressure(gs)
        return np.clip(p - hw, *self.p_range), np.clip(p + hw, *self.p_range)

    def grayscale(self, p) -> np.ndarray:
        """Inverse map: the grayscale that reads as pressure p (for rendering synthetic scans).

        Pressures at or beyond the activation range map to the grayscale where the reading
        first reaches that bound (film saturation / activation threshold).
        """
        p = np.asarray(p, float)
        lo, hi = np.zeros_like(p), np.full_like(p, 255.0)
        decreasing = self._ends()[0] == self.gs_range[0]
        for _ in range(60):  # bisection: 255 / 2^60 is far below one gray level
            mid = 0.5 * (lo + hi)
            pm = self.pressure(mid)
            go_right = pm > p if decreasing else pm < p
            lo = np.where(go_right, mid, lo)
            hi = np.where(go_right, hi, mid)
        return 0.5 * (lo + hi)

    @property
    def saturation_gs(self) -> float:
        """Grayscale beyond which (darker, for a decreasing map) the reading is clipped high."""
        return float(self.grayscale(self.p_range[1]))

    @property
    def threshold_gs(self) -> float:
        """Grayscale beyond which (lighter) the reading is clipped low (unactivated film)."""
        return float(self.grayscale(self.p_range[0]))

    # -- persistence ------------------------------------------------------------------
    def to_dict(self) -> dict:
        return {
            "format": FORMAT, "name": self.name, "model": self.model,
            "formula": models.MODELS[self.model].formula,
            "param_names": list(models.MODELS[self.model].param_names),
            "params": list(self.params), "gs_range": list(self.gs_range),
            "p_range": list(self.p_range), "unit": self.unit,
            "cov": [list(r) for r in self.cov] if self.cov is not None else None,
            "dof": self.dof, "confidence": models.CONFIDENCE, "report": self.report,
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Calibration":
        if d.get("format") != FORMAT:
            raise ParameterError("calibration format", d.get("format"), FORMAT)
        if d.get("model") not in models.MODELS:
            raise ParameterError("calibration model", d.get("model"), ", ".join(models.MODELS))
        cov = d.get("cov")
        return cls(name=d["name"], model=d["model"], params=tuple(map(float, d["params"])),
                   gs_range=tuple(map(float, d["gs_range"])),
                   p_range=tuple(map(float, d["p_range"])), unit=d.get("unit", "MPa"),
                   cov=tuple(tuple(map(float, r)) for r in cov) if cov is not None else None,
                   dof=d.get("dof"), report=d.get("report", {}))

    def save(self, path) -> Path:
        path = Path(path)
        atomic_write_text(path, json.dumps(self.to_dict(), indent=2, default=_json_default))
        return path


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(type(o))


def load_calibration(path) -> Calibration:
    """Load a calibration JSON file, or the built-in one by name (``paper_eq8``)."""
    if str(path) == "paper_eq8":
        return paper_eq8()
    path = Path(path)
    try:
        d = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        raise ParameterError("calibration", str(path),
                             "a calibration JSON written by `film calibrate`, or 'paper_eq8'",
                             hint=str(e)) from None
    return Calibration.from_dict(d)


def paper_eq8() -> Calibration:
    """The paper's Eq. 8, P = -0.00425*GS + 0.978 (MPa/mm as the paper states it).

    The paper gives no calibrated grayscale range, confidence bounds or residuals. We take
    the whole grayscale range and the activation range [0, 0.978]: the reading Eq. 8 gives
    between black (GS = 0) and the grayscale where it reaches zero (GS = 0.978/0.00425 =
    230.1); lighter pixels read as unactivated film (0).
    """
    return Calibration(
        name="paper_eq8", model="linear", params=(-0.00425, 0.978), gs_range=(0.0, 255.0),
        p_range=(0.0, 0.978), unit="MPa/mm",
        report={"source": "Cabibihan et al., Sec. IV-B, Eq. 8 (Pressurex-micro film, 8 px/mm)",
                "note": "pressure per unit length as stated by the paper; no CI given"})


# -- fitting --------------------------------------------------------------------------

def _direction(model: str, params, gs_range) -> int:
    """+1 / -1 if the model is strictly increasing / decreasing on gs_range, else 0."""
    g = np.linspace(*gs_range, _MONO_GRID)
    d = np.diff(models.MODELS[model].f(g, np.asarray(params, float)))
    if np.all(d > 0):
        return 1
    if np.all(d < 0):
        return -1
    return 0


def fit_calibration(gray, pressure, *, model: str = "auto", name: str = "fitted",
                    unit: str = "MPa", activation_range=None, extra_points: dict | None = None
                    ) -> Calibration:
    """Fit P(GS) to calibration presses and return a ``Calibration``.

    model: "auto" (select by AICc, see CRITERION) or one of models.MODELS.
    activation_range: (lo, hi) clip range; default (0, reading at the darkest press).
    Raises ParameterError for < 3 points, non-finite data, a trend indistinguishable from
    zero, or a selected fit that is not strictly monotonic over the calibrated range.
    """
    x = np.asarray(gray, float).ravel()
    y = np.asarray(pressure, float).ravel()
    n = x.size
    if n != y.size:
        raise ParameterError("calibration points", f"{n} grayscale vs {y.size} pressures",
                             "equal counts")
    if n < MIN_POINTS:
        raise ParameterError("calibration points", n, f">= {MIN_POINTS} presses",
                             hint="a line with confidence bounds needs at least three")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
        raise ParameterError("calibration points", "non-finite values", "finite GS and P")
    if np.any((x < 0) | (x > 255)):
        raise ParameterError("calibration gray", f"[{x.min():g}, {x.max():g}]", "[0, 255]")
    if np.ptp(x) == 0:
        raise ParameterError("calibration gray", f"all {x[0]:g}", "at least two distinct values")
    if model != "auto" and model not in models.MODELS:
        raise ParameterError("model", model, "auto, " + ", ".join(models.MODELS))
    gs_range = (float(x.min()), float(x.max()))

    fits = {m: models.fit(m, x, y) for m in models.MODELS}
    lin = fits["linear"]
    ci = lin.param_ci()
    if ci is not None and ci[0, 0] <= 0 <= ci[0, 1]:
        raise ParameterError(
            "calibration", f"slope {lin.params[0]:.4g} (90% CI [{ci[0, 0]:.4g}, {ci[0, 1]:.4g}])",
            "a grayscale-pressure slope whose 90 % confidence interval excludes zero",
            hint="the presses do not define a monotonic grayscale-to-pressure map")

    alternatives = []
    for m, fr in fits.items():
        mono = _direction(m, fr.params, gs_range) if fr.ok else 0
        alternatives.append({
            "model": m, "formula": models.MODELS[m].formula, "ok": fr.ok, "reason": fr.reason,
            "params": fr.params.tolist(), "ssr": fr.ssr if fr.ok else None,
            "r2": fr.r2 if fr.ok else None, "r2_adj": fr.r2_adj if fr.ok else None,
            "aicc": fr.aicc, "monotonic": bool(mono != 0)})

    if model == "auto":
        scored = [a for a in alternatives if a["ok"] and a["aicc"] is not None]
        if not scored:
            chosen = "linear"
            why = f"AICc undefined with n = {n} < 5 points; linear (the paper's choice)"
        else:
            best = min(a["aicc"] for a in scored)
            near = [a for a in scored if a["aicc"] <= best + AICC_TIE]
            order = list(models.MODELS)
            near.sort(key=lambda a: (models.MODELS[a["model"]].n_params, order.index(a["model"])))
            chosen = near[0]["model"]
            why = f"lowest AICc within {AICC_TIE:g} units of the best ({best:.3f}), fewest parameters"
    else:
        chosen, why = model, "requested"
    fr = fits[chosen]
    if not fr.ok:
        raise ParameterError("model", chosen, "a model that can fit these presses", hint=fr.reason)
    direction = _direction(chosen, fr.params, gs_range)
    if direction == 0:
        raise ParameterError(
            "calibration", f"{chosen} fit", "a fit strictly monotonic over the calibrated "
            f"grayscale range [{gs_range[0]:g}, {gs_range[1]:g}]",
            hint="the best description of the presses is non-monotonic, so grayscale does "
                 "not determine pressure uniquely")
    if direction > 0:
        log.warning("calibration %s: pressure increases with grayscale; film darkens with "
                    "pressure, so the scan may be inverted", name)

    p_ends = models.MODELS[chosen].f(np.asarray(gs_range), fr.params)
    if activation_range is None:
        activation_range = (0.0, float(np.max(p_ends)))
    lo, hi = map(float, activation_range)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
        raise ParameterError("activation_range", activation_range, "0 <= lo < hi, finite")

    lin_ci = lin.param_ci()
    report = {
        "n_points": n, "criterion": CRITERION, "selected": chosen, "selected_because": why,
        "confidence": models.CONFIDENCE,
        "linear": {"params": lin.params.tolist(),
                   "param_ci90": lin_ci.tolist() if lin_ci is not None else None,
                   "r2": lin.r2, "r2_adj": lin.r2_adj, "aicc": lin.aicc,
                   "residual_sd": math.sqrt(lin.ssr / lin.dof) if lin.dof > 0 else None,
                   "residuals": lin.residuals.tolist()},
        "selected_fit": {"params": fr.params.tolist(),
                         "param_ci90": (fr.param_ci().tolist() if fr.cov is not None else None),
                         "residuals": fr.residuals.tolist(), "r2": fr.r2, "aicc": fr.aicc},
        "alternatives": alternatives,
        "points": {"gray": x.tolist(), "pressure": y.tolist(), **(extra_points or {})},
        "activation_range_note": "default: 0 up to the reading at the darkest press",
    }
    cov = tuple(tuple(r) for r in fr.cov.tolist()) if fr.cov is not None else None
    log.info("calibration %s: %s %s, AICc %s", name, chosen, fr.params, fr.aicc)
    return Calibration(name=name, model=chosen, params=tuple(fr.params.tolist()),
                       gs_range=gs_range, p_range=(lo, hi), unit=unit, cov=cov,
                       dof=fr.dof, report=report)


# -- CSV input ------------------------------------------------------------------------

def read_calibration_csv(path) -> dict[str, np.ndarray]:
    """Read presses: columns force_n, area_mm2 and gray, or image (path relative to the CSV).

    Optional x0, y0, x1, y1 columns crop each image (pixels, half-open); otherwise the
    whole image is averaged, so each image should show the pressed area only.
    Returns arrays force_n, area_mm2, pressure (Eq. 7, MPa) and gray.
    """
    from tactileskin.film.scan import load_grayscale  # local: keeps Pillow off this path

    path = Path(path)
    try:
        with path.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise ParameterError("calibration CSV", str(path), "a readable CSV file",
                             hint=str(e)) from None
    if not rows:
        raise ParameterError("calibration CSV", str(path), f">= {MIN_POINTS} data rows")
    rows = [{(k or "").strip().lower(): (v or "").strip() for k, v in r.items()} for r in rows]
    cols = set(rows[0])
    for c in ("force_n", "area_mm2"):
        if c not in cols:
            raise ParameterError("calibration CSV column", c, "present (columns: force_n, "
                                 "area_mm2 and gray or image)", hint=f"found {sorted(cols)}")
    if "gray" not in cols and "image" not in cols:
        raise ParameterError("calibration CSV column", "gray|image", "one of them present",
                             hint=f"found {sorted(cols)}")
    force, area, gray = [], [], []
    for i, r in enumerate(rows, start=2):  # line numbers as an editor shows them
        try:
            f_n, a = float(r["force_n"]), float(r["area_mm2"])
        except ValueError:
            raise ParameterError(f"calibration CSV line {i}", r, "numeric force_n, area_mm2") from None
        if not (f_n > 0 and math.isfinite(f_n)):
            raise ParameterError(f"force_n (line {i})", f_n, "> 0 N")
        if not (a > 0 and math.isfinite(a)):
            raise ParameterError(f"area_mm2 (line {i})", a, "> 0 mm^2")
        if r.get("gray"):
            try:
                g = float(r["gray"])
            except ValueError:
                raise ParameterError(f"gray (line {i})", r["gray"], "a number in [0, 255]") from None
        elif r.get("image"):
            img = load_grayscale(path.parent / r["image"])
            box = [r.get(k) for k in ("x0", "y0", "x1", "y1")]
            if all(box):
                from tactileskin.film.scan import select_region
                img, _ = select_region(img, box_px=tuple(int(float(b)) for b in box))
            g = float(img.mean())
        else:
            raise ParameterError(f"calibration CSV line {i}", "no gray and no image",
                                 "a gray value or an image path")
        force.append(f_n)
        area.append(a)
        gray.append(g)
    force, area = np.array(force), np.array(area)
    return {"force_n": force, "area_mm2": area, "pressure": force / area, "gray": np.array(gray)}


def calibrate_csv(path, *, model: str = "auto", activation_range=None,
                  name: str | None = None) -> Calibration:
    """Read a calibration CSV (see ``read_calibration_csv``) and fit it (Eq. 7 -> MPa)."""
    d = read_calibration_csv(path)
    return fit_calibration(d["gray"], d["pressure"], model=model, unit="MPa",
                           name=name or Path(path).stem, activation_range=activation_range,
                           extra_points={"force_n": d["force_n"].tolist(),
                                         "area_mm2": d["area_mm2"].tolist()})
