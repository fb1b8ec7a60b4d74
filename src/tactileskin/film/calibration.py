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
- the result is clipped to the activation range ``p_range`` (the film's stated range); a
  reading below its bottom is unactivated film and reads zero (not the bottom: white film
  read as the threshold pressure added it to every column of the profile).
``film.scan.analyze_scan`` flags a profile read on either continuation (summary.json
``beyond_calibration`` and ``warnings``): pixels held at the darkest press below the
activation range's top (a lower bound), and a span whose 10 % level lies below the lightest
press (read on the tangent).

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
import io
import json
import logging
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactileskin import fileio
from tactileskin.errors import ParameterError
from tactileskin.film import models
from tactileskin.film.inputs import finite, read_text

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
MAX_PRESSES = 10_000    # a calibration is tens of presses; more is a wrong file
# P = F/A of a press (MPa): pressure films read 0.005-300 MPa; past these a unit is wrong (a force
# of 1e308 N overflowed the fit, an area of 1e308 mm^2 fitted 4e-307 MPa and was written)
PRESS_P_RANGE = (1e-6, 1e4)
MAX_ABS_PRESSURE = 1e100  # fit_calibration, any unit: J^T J of the fit stays finite (1e160 overflowed)


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

    def __post_init__(self):
        """Refuse a calibration that cannot be evaluated (or written as strict JSON)."""
        if self.model not in models.MODELS:
            raise ParameterError("calibration model", self.model, ", ".join(models.MODELS))
        n_p = models.MODELS[self.model].n_params
        params = _floats("calibration params", self.params, n_p)
        g0, g1 = _floats("calibration gs_range", self.gs_range, 2)
        if not 0 <= g0 < g1 <= 255:
            raise ParameterError("calibration gs_range", list(self.gs_range),
                                 "lo < hi within [0, 255]",
                                 hint="inverted" if g0 >= g1 else "outside the grayscale scale")
        p0, p1 = _floats("calibration activation range", self.p_range, 2)
        if not 0 <= p0 < p1:
            raise ParameterError("calibration activation range", list(self.p_range),
                                 "0 <= lo < hi", hint="inverted" if p0 >= p1 else "negative")
        cov = self.cov
        if cov is not None:
            try:
                rows = [tuple(r) for r in cov]
            except TypeError:
                rows = None
            if rows is None or len(rows) != n_p:
                raise ParameterError("calibration cov", cov, f"a {n_p} x {n_p} matrix or null")
            cov = tuple(_floats("calibration cov", r, n_p) for r in rows)
        dof = self.dof
        if dof is not None and (isinstance(dof, bool) or not isinstance(dof, int) or dof < 1):
            raise ParameterError("calibration dof", dof, "an integer >= 1 or null")
        if not isinstance(self.name, str) or not isinstance(self.unit, str):
            raise ParameterError("calibration name/unit", (self.name, self.unit), "text")
        if not isinstance(self.report, dict):
            raise ParameterError("calibration report", type(self.report).__name__, "a table")
        object.__setattr__(self, "params", params)
        object.__setattr__(self, "gs_range", (g0, g1))
        object.__setattr__(self, "p_range", (p0, p1))
        object.__setattr__(self, "cov", cov)

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
        p = self.reading(gs)
        return np.where(p < self.p_range[0], 0.0, p)  # below the threshold: unactivated

    def reading(self, gs) -> np.ndarray:
        """``pressure`` before its low rule: lighter than the threshold the tangent goes on
        below it (negative). A mean of these across a strip, set to 0 below the threshold
        after averaging, keeps the scan noise about the threshold zero-mean (film.scan)."""
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
        return np.minimum(p, self.p_range[1])

    def band(self, gs) -> tuple[np.ndarray, np.ndarray] | None:
        """90 % confidence band of the calibration at gs (clipped like ``pressure``), or None."""
        hw = self.halfwidth(gs)
        return None if hw is None else self.band_at(self.pressure(gs), hw)

    def halfwidth(self, gs) -> np.ndarray | None:
        """Half-width of the 90 % band at gs (in the calibrated range), or None (no covariance)."""
        if self.cov is None or not self.dof:
            return None
        return models.band_halfwidth(self.model, self.params, self.cov, self.dof,
                                     np.clip(np.asarray(gs, float), *self.gs_range))

    def band_at(self, p, hw) -> tuple[np.ndarray, np.ndarray]:
        """The band p -/+ hw of pressures p (as ``pressure`` gives them), clipped like them."""
        floor = np.where(p > 0, self.p_range[0], 0.0)  # unactivated film (0): no threshold under it
        return np.clip(p - hw, floor, self.p_range[1]), np.clip(p + hw, floor, self.p_range[1])

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
            "dof": self.dof, "confidence": models.CONFIDENCE, "report": _plain(self.report),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Calibration":
        """Build from ``to_dict`` output; every field is type-checked (ParameterError)."""
        if not isinstance(d, dict):
            raise ParameterError("calibration", type(d).__name__, "a JSON object (table)")
        if d.get("format") != FORMAT:
            raise ParameterError("calibration format", d.get("format"), FORMAT)
        missing = [k for k in ("name", "model", "params", "gs_range", "p_range") if k not in d]
        if missing:
            raise ParameterError("calibration keys", ", ".join(missing), "present",
                                 hint="required: name, model, params, gs_range, p_range")
        if d["model"] not in models.MODELS:
            raise ParameterError("calibration model", d["model"], ", ".join(models.MODELS))
        # the level of the bands, which are computed from cov and dof at models.CONFIDENCE
        # whatever the file says: a file claiming another level would be read wrongly
        if "confidence" in d and not (type(d["confidence"]) in (int, float)
                                      and d["confidence"] == models.CONFIDENCE):
            raise ParameterError("calibration confidence", d["confidence"], f"{models.CONFIDENCE:g} or absent",
                                 hint="the confidence level of the bands tactileskin computes from cov and dof; "
                                      "not a setting")
        return cls(name=d["name"], model=d["model"], params=d["params"],
                   gs_range=d["gs_range"], p_range=d["p_range"], unit=d.get("unit", "MPa"),
                   cov=d.get("cov"), dof=d.get("dof"), report=d.get("report", {}))

    def save(self, path) -> Path:
        """Strict JSON (no NaN/Infinity tokens), written atomically."""
        return fileio.atomic_write_json(path, self.to_dict())


def _floats(name: str, values, n: int) -> tuple[float, ...]:
    """n finite numbers (not booleans, not text) as floats, else ParameterError(name)."""
    if isinstance(values, (str, bytes, dict)) or not hasattr(values, "__len__") \
            or len(values) != n:
        raise ParameterError(name, values, f"a list of {n} finite numbers")
    out = []
    for v in values:
        if isinstance(v, (bool, str, bytes)) or not isinstance(v, (int, float, np.number)) \
                or not math.isfinite(float(v)):
            raise ParameterError(name, list(values), f"a list of {n} finite numbers")
        out.append(float(v))
    return tuple(out)


def _plain(o):
    """Report data as strict-JSON values: numpy -> Python; NaN/inf (a statistic undefined
    for these points, e.g. adjusted R^2 with no degrees of freedom left) -> None."""
    if isinstance(o, dict):
        return {str(k): _plain(v) for k, v in o.items()}
    if isinstance(o, (list, tuple, np.ndarray)):
        return [_plain(v) for v in o]
    if isinstance(o, np.generic):
        o = o.item()
    if isinstance(o, float) and not math.isfinite(o):
        return None
    return o


def _reject_constant(token: str):
    raise ValueError(f"{token} is not a number in strict JSON")


def load_calibration(path) -> Calibration:
    """Load a calibration JSON file, or the built-in one by name (``paper_eq8``)."""
    if str(path) == "paper_eq8":
        return paper_eq8()
    path = Path(path)
    valid = "a calibration JSON written by `film calibrate`, or 'paper_eq8'"
    text = read_text(path, "calibration", valid)
    try:
        d = json.loads(text, parse_constant=_reject_constant)
    except ValueError as e:
        raise ParameterError("calibration", str(path), valid, hint=f"not JSON: {e}") from None
    try:
        return Calibration.from_dict(d)
    except ParameterError as e:
        raise ParameterError("calibration", str(path), valid, hint=str(e)) from None


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


MIN_GRAY_SPAN = 2.0  # gray levels the presses must span: a scan quantises to 1


def fit_calibration(gray, pressure, *, model: str = "auto", name: str = "fitted",
                    unit: str = "MPa", activation_range=None, extra_points: dict | None = None
                    ) -> Calibration:
    """Fit P(GS) to calibration presses and return a ``Calibration``.

    model: "auto" (select by AICc, see CRITERION) or one of models.MODELS.
    activation_range: (lo, hi) clip range; default (0, reading at the darkest press).
    Raises ParameterError for < 3 points, non-finite data, a trend indistinguishable from
    zero, or a selected fit that is not strictly monotonic over the calibrated range.
    """
    if activation_range is not None:
        activation_range = _activation_range(activation_range)
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
    if np.max(np.abs(y)) > MAX_ABS_PRESSURE:  # any unit here (the CSV path checks MPa)
        raise ParameterError("calibration pressure", f"{np.max(np.abs(y)):g} {unit}",
                             f"|P| <= {MAX_ABS_PRESSURE:g} in any unit",
                             hint="the fit's normal equations square the pressures: 1e200 overflowed, "
                                  "1e160 gave a band of zero width")
    if np.ptp(x) == 0:
        raise ParameterError("calibration gray", f"all {x[0]:g}", "at least two distinct values",
                             hint="every press has the same grayscale")
    if np.ptp(x) < MIN_GRAY_SPAN:  # a scan resolves one gray level: the slope would be noise
        raise ParameterError("calibration gray", f"[{x.min():.8g}, {x.max():.8g}]",
                             f"a span of at least {MIN_GRAY_SPAN:g} gray levels (8-bit scans step by 1)",
                             hint="the presses are indistinguishable on a scan; press harder or softer")
    if np.ptp(y) == 0:
        raise ParameterError("calibration pressure", f"all {y[0]:g} {unit}",
                             "at least two distinct pressures",
                             hint="every press has the same force per area")
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
        top = float(np.max(p_ends))
        if not (math.isfinite(top) and top > 0):
            raise ParameterError("calibration", f"{chosen} fit reads {top:g} at the darkest "
                                 "press", "a positive pressure there",
                                 hint="give --activation-range LO HI")
        activation_range = (0.0, top)
    lo, hi = activation_range
    if not all(np.all(np.isfinite(a)) for a in (fr.params, fr.cov if fr.cov is not None else 0)):
        raise ParameterError("calibration", f"{chosen} fit", "finite parameters and covariance",
                             hint="the presses are degenerate for this model")

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

def _activation_range(r) -> tuple[float, float]:
    try:
        lo, hi = r
    except (TypeError, ValueError):
        raise ParameterError("activation_range", r, "two numbers LO HI") from None
    lo = finite("activation_range LO", lo, 0, unit="(pressure unit)")
    hi = finite("activation_range HI", hi, 0, unit="(pressure unit)")
    if not lo < hi:
        raise ParameterError("activation_range", (lo, hi), "LO < HI, both finite and >= 0",
                             hint="inverted: give LO first" if lo > hi else "empty range")
    return lo, hi


def read_calibration_csv(path) -> dict[str, np.ndarray]:
    """Read presses: columns force_n, area_mm2 and gray, or image (path relative to the CSV).

    Optional x0, y0, x1, y1 columns crop each image (pixels, half-open); otherwise the
    whole image is averaged, so each image should show the pressed area only.
    Returns arrays force_n, area_mm2, pressure (Eq. 7, MPa) and gray.
    """
    from tactileskin.film.image import load_grayscale  # local: keeps Pillow off this path
    from tactileskin.film.scan import select_region

    path = Path(path)
    valid = "a CSV with columns force_n, area_mm2 and gray or image"
    text = read_text(path, "calibration CSV", valid)
    try:
        raw = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as e:
        raise ParameterError("calibration CSV", str(path), valid, hint=str(e)) from None
    raw = [(i, r) for i, r in enumerate(raw, start=1) if any(c.strip() for c in r)]
    if len(raw) < 2:
        raise ParameterError("calibration CSV", str(path), f"a header and >= {MIN_POINTS} data rows")
    if len(raw) - 1 > MAX_PRESSES:
        raise ParameterError("calibration CSV", str(path), f"at most {MAX_PRESSES} presses",
                             hint=f"{len(raw) - 1} rows")
    header = [c.strip().lower() for c in raw[0][1]]
    cols = set(header)
    for c in ("force_n", "area_mm2"):
        if c not in cols:
            raise ParameterError("calibration CSV column", c, "present (columns: force_n, "
                                 "area_mm2 and gray or image)", hint=f"{path}: found {sorted(cols)}")
    if "gray" not in cols and "image" not in cols:
        raise ParameterError("calibration CSV column", "gray|image", "one of them present",
                             hint=f"{path}: found {sorted(cols)}")
    force, area, gray = [], [], []
    for i, cells in raw[1:]:  # line numbers as an editor shows them
        where = f"{path.name} line {i}"
        if len(cells) > len(header):
            raise ParameterError(f"calibration CSV ({where})", ",".join(cells),
                                 f"at most {len(header)} fields, as in the header")
        r = dict(zip(header, (c.strip() for c in cells)))
        f_n = _csv_number(f"force_n ({where})", r.get("force_n"), "> 0 N")
        a = _csv_number(f"area_mm2 ({where})", r.get("area_mm2"), "> 0 mm^2")
        if not f_n > 0:
            raise ParameterError(f"force_n ({where})", f_n, "> 0 N")
        if not a > 0:
            raise ParameterError(f"area_mm2 ({where})", a, "> 0 mm^2")
        lo, hi = PRESS_P_RANGE
        if not lo <= f_n / a <= hi:
            raise ParameterError(f"force_n/area_mm2 ({where})", f"{f_n:g} N / {a:g} mm^2 = {f_n / a:g} MPa",
                                 f"[{lo:g}, {hi:g}] MPa (a press on film; check the units: N and mm^2)")
        if r.get("gray") and r.get("image"):  # the gray value won and the image was never read
            raise ParameterError(f"calibration CSV ({where})", f"gray {r['gray']} and image {r['image']}",
                                 "a gray value or an image path, not both",
                                 "leave one of the two cells empty")
        if r.get("gray"):
            g = _csv_number(f"gray ({where})", r["gray"], "a number in [0, 255]")
            if not 0 <= g <= 255:
                raise ParameterError(f"gray ({where})", g, "a number in [0, 255]")
        elif r.get("image"):
            img = load_grayscale(path.parent / r["image"])
            box = [r.get(k) for k in ("x0", "y0", "x1", "y1")]
            if any(box):
                img, _ = select_region(img, box_px=tuple(
                    _csv_number(f"crop x0,y0,x1,y1 ({where})", b, "whole pixel numbers")
                    for b in box))
            g = float(img.mean())
        else:
            raise ParameterError(f"calibration CSV ({where})", "no gray and no image",
                                 "a gray value or an image path")
        force.append(f_n)
        area.append(a)
        gray.append(g)
    force, area = np.array(force), np.array(area)
    return {"force_n": force, "area_mm2": area, "pressure": force / area, "gray": np.array(gray)}


def _csv_number(name: str, cell, valid: str) -> float:
    if cell is None or cell == "":
        raise ParameterError(name, "missing", valid)
    try:
        v = float(cell)
    except ValueError:
        raise ParameterError(name, cell, valid) from None
    if not math.isfinite(v):
        raise ParameterError(name, cell, valid)
    return v


def calibrate_csv(path, *, model: str = "auto", activation_range=None,
                  name: str | None = None) -> Calibration:
    """Read a calibration CSV (see ``read_calibration_csv``) and fit it (Eq. 7 -> MPa)."""
    d = read_calibration_csv(path)
    return fit_calibration(d["gray"], d["pressure"], model=model, unit="MPa",
                           name=name or Path(path).stem, activation_range=activation_range,
                           extra_points={"force_n": d["force_n"].tolist(),
                                         "area_mm2": d["area_mm2"].tolist()})
