"""Fit any registered law to a uniaxial test: nominal stress (MPa) against stretch.

`fit(law, stretch, stress, nu=None, terms=None) -> Fit` (scipy.optimize.least_squares on
the absolute stress residuals, i.e. it minimises the RMSE the report states):
- nu=None: incompressible kinematics (J = 1, lateral stretch l^(-1/2)); the nominal stress
  is (sigma_1 - sigma_3)/l, independent of the volumetric term. The fitted law gets the
  bulk modulus of `NU_INCOMPRESSIBLE` (kappa = 2 mu0 (1 + nu)/(3 (1 - 2 nu))), the usual
  near-incompressible silicone value; hyperfoam has no incompressible form and needs nu.
- nu given: the lateral stretch is solved so that the lateral stress vanishes (vectorised
  Newton), with kappa from nu (hyperfoam: nu is its own parameter).
Quality: R^2, RMSE (MPa) and the largest relative error over the points whose |stress| is
at least 5 % of the largest (relative error near zero stress means nothing).
Indentation tests (sphere on a bonded layer, depth-force): materials/indentation.py.
Bad data (fewer points than parameters + 3, NaN/inf, stretch <= 0, stretch not strictly
monotone, no point away from stretch 1) raise `FitDataError` naming the column and what
is wrong.
"""

from __future__ import annotations

import csv
import io
import logging
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactileskin.errors import ParameterError, TactileSkinError, range_text
from tactileskin.materials.laws import get_law

log = logging.getLogger(__name__)

__all__ = ["Fit", "FitDataError", "FitError", "fit", "read_uniaxial_csv", "uniaxial_nominal",
           "NU_INCOMPRESSIBLE"]

NU_INCOMPRESSIBLE = 0.49   # bulk modulus given to a law fitted as incompressible (K/mu0 = 49.7)
REL_FLOOR = 0.05           # relative errors only where |stress| >= 5 % of the largest
MAX_CSV_BYTES = 10 << 20   # a test file is at most a few 10k rows
# Checks of what the fit's R^2 does not see (Fit.quality["warnings"]): the small-strain modulus,
# which shallow indentation reads, against the data's from its points within SMALL_STRAIN of
# stretch 1 (least-squares slope through (1, 0): 5-8 % below the tangent for rubber, hence the
# loose MODULUS_RATIO); and with no compression in the data, the law's stress at
# COMPRESSION_STRETCH against its own small-strain slope (neo-Hookean: 1.27x, Ogden and Yeoh
# fits of rubber 1.1-1.6x), outside COMPRESSION_RATIO an extrapolation artefact
SMALL_STRAIN = 0.15
MODULUS_RATIO = 1.5
COMPRESSION_STRETCH = 0.8
COMPRESSION_RATIO = (0.5, 2.5)
# a law that misses a test point by more than this (relative, where |stress| >= REL_FLOOR of the
# largest) does not describe the test, however high its R^2 (a neo-Hookean on a stiffening
# silicone to stretch 3: R^2 0.965, 28 % off): ten times the 1 % scatter of a tensile test,
# five times the presets' 2 % peak error
MAX_REL_ERR = 0.10
# skins are soft elastomers (silicones 0.01-1 MPa, polyurethanes to ~10 MPa shear modulus):
# a fit far stiffer is most often stress in kPa (1000x) read as MPa
SOFT_MU_MAX = 30.0


class FitDataError(ParameterError):
    """The test data cannot be fitted (too few points, NaN, non-monotone stretch, ...)."""


class FitError(TactileSkinError):
    """The least-squares fit did not give an admissible law."""


def uniaxial_nominal(law, stretch, nu=None):
    """Nominal (first Piola-Kirchhoff) stress of uniaxial tension/compression at `stretch`.
    nu=None: incompressible kinematics; else the lateral stress is made zero."""
    lam = np.asarray(stretch, dtype=float)
    if nu is None:
        lt2 = 1.0 / lam
        C = np.zeros(lam.shape + (3, 3))
        C[..., 0, 0], C[..., 1, 1], C[..., 2, 2] = lam**2, lt2, lt2
        S, ok = law.pk2(C)
        return (lam**2 * S[..., 0, 0] - lt2 * S[..., 2, 2]) / lam, ok
    lt = lam ** (-float(nu))   # the small-strain lateral stretch as the start
    scale = max(law.mu0, law.K0)
    for _ in range(50):
        C = np.zeros(lam.shape + (3, 3))
        C[..., 0, 0], C[..., 1, 1], C[..., 2, 2] = lam**2, lt**2, lt**2
        S, D, ok = law.pk2_tangent(C)
        r = S[..., 1, 1]
        # dS22/dl = (D2222 + D2233)/2 * 2 l (C22 and C33 both move with l)
        slope = (D[..., 1, 1, 1, 1] + D[..., 1, 1, 2, 2]) * lt
        step = r / np.where(slope != 0.0, slope, 1.0)
        lt = np.clip(lt - step, 0.5 * lt, 2.0 * lt)
        if np.all(np.abs(r) <= 1e-12 * scale):
            break
    C = np.zeros(lam.shape + (3, 3))
    C[..., 0, 0], C[..., 1, 1], C[..., 2, 2] = lam**2, lt**2, lt**2
    S, ok = law.pk2(C)
    return lam * S[..., 0, 0], ok & (np.abs(S[..., 1, 1]) <= 1e-9 * scale)


@dataclass
class Fit:
    law: object
    stretch: np.ndarray
    stress: np.ndarray
    predicted: np.ndarray
    nu: float | None
    quality: dict = field(default_factory=dict)

    def material(self, name: str, source: str = ""):
        from tactileskin.materials.presets import Material
        from tactileskin.materials.prony import Prony

        return Material(name=name, law=self.law, prony=Prony.elastic(), source=source)

    @property
    def warnings(self) -> list[str]:
        """What makes the fit suspect beyond its R^2 (empty: none found)."""
        return list(self.quality.get("warnings", ()))

    def describe(self) -> str:
        q = self.quality
        return (f"{self.law.law}: {self.law.to_dict()}; R^2 = {q['r2']:.5f}, RMSE = {q['rmse_mpa']:.3g} MPa, "
                f"max relative error {100 * q['max_rel_err']:.2f} % ({q['n_points']} points, "
                f"{'incompressible' if self.nu is None else f'nu = {self.nu:g}'})"
                + "".join(f"\n  suspect fit: {w}" for w in self.warnings))


def _quality(stress, pred, n_params) -> dict:
    res = pred - stress
    ss_res = float(np.sum(res**2))
    ss_tot = float(np.sum((stress - stress.mean()) ** 2))
    big = np.abs(stress) >= REL_FLOOR * np.abs(stress).max()
    return {"r2": 1.0 - ss_res / ss_tot if ss_tot > 0 else float("nan"),
            "rmse_mpa": float(np.sqrt(ss_res / len(stress))),
            "max_rel_err": float(np.max(np.abs(res[big]) / np.abs(stress[big]))),
            "n_points": int(len(stress)), "n_params": int(n_params)}


# Stretches of a uniaxial test: soft elastomers break at about 10 (900 % elongation, the
# softest silicones); beyond 50 the strain column is surely in percent.
PLAUSIBLE_STRETCH, MAX_STRETCH = 10.0, 50.0
# What no uniaxial test of an elastomer leaves, so that a value outside is a slip (a typo, a
# unit), refused naming it; the fit's powers of the stretch overflow on one (1e-300, 1e308).
# Stretch from 0.001 (99.9 % compression: foams densify by 0.05-0.1); nominal stress within
# +-1e4 MPa, 100x the breaking stress of the strongest elastomers (~100 MPa).
MIN_STRETCH = 1e-3
MAX_STRESS_MPA = 1e4


def check_data(stretch, stress, n_params: int):
    """(stretch, stress) as float arrays ordered by increasing stretch, or FitDataError."""
    try:
        lam = np.asarray(stretch, dtype=float).ravel()
        P = np.asarray(stress, dtype=float).ravel()
    except (TypeError, ValueError):
        raise FitDataError("data", "non-numeric values", "numbers (stretch, nominal stress MPa)") from None
    if lam.shape != P.shape:
        raise FitDataError("stress", f"{P.size} values", f"{lam.size} values (one per stretch)")
    need = max(5, n_params + 3)
    if lam.size < need:
        raise FitDataError("data", f"{lam.size} points", f">= {need} points",
                           f"{n_params} parameters need more points than that")
    for name, x in (("stretch", lam), ("stress", P)):
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            raise FitDataError(name, f"non-finite value at row {bad[0] + 1}", "finite numbers")
    if np.any(lam <= 0.0):
        raise FitDataError("stretch", float(lam[lam <= 0.0][0]), "> 0 (stretch = 1 + engineering strain)")
    if np.any(lam < MIN_STRETCH):
        i = int(np.flatnonzero(lam < MIN_STRETCH)[0])
        raise FitDataError("stretch", f"{lam[i]:g} at row {i + 1}", range_text(MIN_STRETCH, MAX_STRETCH))
    if np.any(np.abs(P) > MAX_STRESS_MPA):
        i = int(np.flatnonzero(np.abs(P) > MAX_STRESS_MPA)[0])
        raise FitDataError("stress", f"{P[i]:g} at row {i + 1}", range_text(-MAX_STRESS_MPA, MAX_STRESS_MPA, unit="MPa"),
                           "a stress in kPa or Pa? give MPa")
    d = np.diff(lam)
    if not (np.all(d > 0) or np.all(d < 0)):
        i = int(np.flatnonzero(np.sign(d) != np.sign(d[0]))[0]) if np.any(d) else 0
        raise FitDataError("stretch", f"not strictly monotone at row {i + 2}",
                           "strictly increasing or decreasing (one loading branch, no repeats)")
    if np.max(np.abs(lam - 1.0)) < 1e-4:
        raise FitDataError("stretch", "all within 1e-4 of 1", "a test beyond 0.01 % strain")
    if lam.max() > MAX_STRETCH:
        raise FitDataError("stretch", float(lam.max()), f"<= {MAX_STRETCH:g} (stretch = 1 + strain)",
                           "a strain column in percent? give it as a fraction (0.5 for 50 %)")
    if lam.max() > PLAUSIBLE_STRETCH:
        log.warning("stretch up to %.3g: beyond the break of soft elastomers (about %g); is the strain a "
                    "fraction (0.5 for 50 %%)?", lam.max(), PLAUSIBLE_STRETCH)
    if not np.any(P != 0.0):
        raise FitDataError("stress", "all zero", "the measured nominal stresses (MPa), not all zero")
    # an elastomer pulls back: positive nominal stress in tension, negative in compression
    wrong = int(np.sum(P * (lam - 1.0) < 0.0))
    if wrong > lam.size // 2:
        hint = "is the stress column the nominal stress of this test, with its sign?"
        if np.all(lam <= 1.0) and np.all(P >= 0.0):
            # what two unnamed columns (read as stretch, stress) of a tension test look like
            hint = ("the stretch column is at or below 1 throughout under positive stress: is it a strain without its "
                    "'strain' header, are the columns swapped (stretch first), or is this a compression test "
                    "whose stress needs its minus sign?")
        raise FitDataError("stress", f"of the wrong sign at {wrong} of {lam.size} points",
                           "positive in tension (stretch > 1), negative in compression (MPa)", hint)
    order = np.argsort(lam)
    return lam[order], P[order]


def fit(law: str, stretch, stress, *, nu: float | None = None, terms: int | None = None) -> Fit:
    """Least-squares fit of law `law` (a name of materials.laws) to uniaxial nominal stress.

    terms: number of terms for yeoh (1-3, default 3), ogden and hyperfoam (1-3, default 2)."""
    from scipy.optimize import least_squares

    cls = get_law(law)
    from tactileskin.materials.laws import MAX_BULK_OVER_SHEAR as r

    # at most the nu0 a material file may have (laws.law_from_dict: K0 / mu0 <= 5000, nu0 =
    # 0.49990001, stated to 4 digits): nu = 0.49999 was fitted and written, and the file then
    # refused by every solve
    nu_max = math.floor(1e4 * (3 * r - 2) / (2 * (3 * r + 1))) / 1e4
    if nu is not None:
        from tactileskin.errors import check_range

        nu = check_range("nu", nu, -1.0, nu_max, lo_open=True)
    elif law == "hyperfoam":  # the same range as a given nu's, not the (-1, 0.5) it was refused in
        raise ParameterError("nu", None, f"(-1, {nu_max:g}]", "hyperfoam has no incompressible form: give nu")
    if law in ("ogden", "hyperfoam"):
        terms = 2 if terms is None else terms
        if not (isinstance(terms, int) and 1 <= terms <= 3):
            raise ParameterError("terms", terms, "1, 2 or 3")
        start = lambda mu0: cls.fit_start(mu0, terms)  # noqa: E731
        n_params = 2 * terms
    elif law == "yeoh":
        terms = 3 if terms is None else terms
        if not (isinstance(terms, int) and 1 <= terms <= 3):
            raise ParameterError("terms", terms, "1, 2 or 3")
        start = lambda mu0: _cut(cls.fit_start(mu0), terms)  # noqa: E731
        n_params = terms
    else:
        if terms is not None:
            raise ParameterError("terms", terms, f"not given ({law} has a fixed number of parameters)")
        start = cls.fit_start
        n_params = len(cls.fit_names)
    lam, P = check_data(stretch, stress, n_params)

    # start: the neo-Hookean shear modulus of the data, P = mu (l - l^-2)
    f = lam - lam**-2.0
    mu0 = max(float(np.sum(P * f) / np.sum(f * f)), 1e-6 * float(np.abs(P).max()) + 1e-300)
    x0, bounds = start(mu0)
    scale = float(np.abs(P).max())
    vol = NU_INCOMPRESSIBLE if nu is None else nu

    def predict(x):
        mat = cls.from_fit(x, vol)
        pred, ok = uniaxial_nominal(mat, lam, nu)
        return mat, pred, ok

    def residual(x):
        try:
            _, pred, ok = predict(x)
        except (ParameterError, FloatingPointError, OverflowError):
            return np.full(lam.size, 1e3)
        if not np.all(ok) or not np.all(np.isfinite(pred)):
            return np.full(lam.size, 1e3)
        return (pred - P) / scale

    starts = [x0]
    if law in ("ogden", "hyperfoam"):
        # stretch exponents make the cost multi-modal: a few seeds, the best fit kept
        starts += [np.concatenate([x0[:terms], a]) for a in _alpha_seeds(terms)]
    with np.errstate(all="ignore"):
        sol = None
        for xs in starts:
            s = least_squares(residual, xs, bounds=bounds, x_scale="jac", xtol=1e-14, ftol=1e-14,
                              gtol=1e-14, max_nfev=2000)
            if sol is None or s.cost < sol.cost:
                sol = s
        try:
            mat, pred, ok = predict(sol.x)
        except ParameterError as e:
            raise FitError(f"fit of {law} gave inadmissible parameters ({e})") from None
    if not np.all(ok) or not np.all(np.isfinite(pred)):
        raise FitError(f"fit of {law} did not converge to an admissible law ({sol.message})")
    q = _quality(P, pred, n_params)
    if not q["r2"] > 0.0:  # worse than the data's mean: the law does not describe this test
        raise FitError(f"fit of {law} explains none of the data (R^2 = {q['r2']:.3g}, RMSE "
                       f"{q['rmse_mpa']:.3g} MPa): try another law, or check the data's columns and units")
    _check_stable(law, mat, lam, nu)
    _check_loadable(law, mat, lam)
    q["nfev"] = int(sol.nfev)
    q["warnings"] = extrapolation_warnings(mat, lam, P, nu)
    miss = misfit_warning(P, pred, lam, "stretch", "",
                          "it does not describe this material over the test's range; try a law with more "
                          "terms (yeoh, ogden) or fit the range the skin reaches")
    if miss:
        q["warnings"].append(miss)
    if mat.mu0 > SOFT_MU_MAX:
        q["warnings"].append(f"shear modulus {mat.mu0:.4g} MPa: stiffer than the soft elastomers of skins "
                             f"(up to about {SOFT_MU_MAX:g} MPa); is the stress column in kPa or Pa? MPa is expected")
    for w in q["warnings"]:  # shown by describe() (the CLI prints it and exits 3)
        log.info("fit of %s: %s", law, w)
    return Fit(law=mat, stretch=lam, stress=P, predicted=pred, nu=nu, quality=q)


def misfit_warning(measured, predicted, x, x_name: str, x_unit: str, remedy: str) -> str | None:
    """The suspect-fit warning of every test kind the fitter takes when the law misses a point by
    more than MAX_REL_ERR (relative, over the points _quality weighs), naming where; else None."""
    y, res = np.asarray(measured, float), np.asarray(predicted, float) - np.asarray(measured, float)
    big = np.abs(y) >= REL_FLOOR * np.abs(y).max()
    rel = np.abs(res[big]) / np.abs(y[big])
    i = int(np.argmax(rel))
    if not rel[i] > MAX_REL_ERR:
        return None
    return (f"the law misses the test by up to {100 * rel[i]:.3g} % (at {x_name} {np.asarray(x)[big][i]:.4g}"
            f"{' ' + x_unit if x_unit else ''}; more than {MAX_REL_ERR:.0%}): {remedy}")


def _slope_at_one(mat, nu) -> float:
    """dP/dstretch of the law's uniaxial nominal stress at stretch 1 (MPa): E, or 3 mu0."""
    h = 1e-4
    with np.errstate(all="ignore"):
        P, _ = uniaxial_nominal(mat, np.array([1.0 - h, 1.0 + h]), nu)
    return float((P[1] - P[0]) / (2.0 * h))


def extrapolation_warnings(mat, lam, P, nu) -> list[str]:
    """Where a fitted law that matches the test's points would still mislead a solve: its
    small-strain modulus off the data's, or (no compression in the data) a compression
    response its small-strain modulus does not explain (see SMALL_STRAIN above)."""
    out = []
    e_fit = _slope_at_one(mat, nu)
    near = (np.abs(lam - 1.0) <= SMALL_STRAIN) & (lam != 1.0)
    if np.count_nonzero(near) >= 2:
        x = lam[near] - 1.0
        e_data = float(np.sum(P[near] * x) / np.sum(x * x))
        ratio = e_fit / e_data if e_data > 0 else np.inf
        if not 1.0 / MODULUS_RATIO <= ratio <= MODULUS_RATIO:
            out.append(f"small-strain modulus off the data's: the fit's slope at stretch 1 is {e_fit:.4g} MPa, the "
                       f"data's {e_data:.4g} MPa ({ratio:.3g}x; from its {np.count_nonzero(near)} points within "
                       f"{SMALL_STRAIN:.0%} of stretch 1); a shallow indentation reads this modulus: try another "
                       "law or fewer terms")
    if float(lam.min()) > 1.0 - 0.05 and e_fit > 0:  # a tension test: compression is extrapolated
        with np.errstate(all="ignore"):
            pc, ok = uniaxial_nominal(mat, np.array([COMPRESSION_STRETCH]), nu)
        r = float(pc[0] / (e_fit * (COMPRESSION_STRETCH - 1.0))) if bool(ok[0]) else np.inf
        lo, hi = COMPRESSION_RATIO
        if not (np.isfinite(r) and lo <= r <= hi):
            out.append(f"compression extrapolated: the data have no compression, and at stretch "
                       f"{COMPRESSION_STRETCH:g} the fitted law's stress is {r:.3g}x what its small-strain modulus "
                       f"gives (neo-Hookean 1.27x; {lo:g}-{hi:g}x expected); an indented skin is compressed: add "
                       "compression data, or fit fewer terms or a simpler law")
    return out


STABLE_RANGE = (0.7, 1.5)  # uniaxial stretches over which a law's stress must rise with stretch


def unstable_stretch(mat, nu=None, lo: float = STABLE_RANGE[0], hi: float = STABLE_RANGE[1]) -> float | None:
    """The uniaxial stretch in [lo, hi] (81 points) nearest 1 where `mat`'s nominal stress does not
    rise with stretch or is not finite, or None: a law whose stress falls with stretch (a negative
    c01, a wrong-signed Ogden term) has no stable solution there, and a solve with it does not
    converge (3D) or converges to a wrong state (2D)."""
    grid = np.linspace(lo, hi, 81)
    with np.errstate(all="ignore"):
        try:
            P, ok = uniaxial_nominal(mat, grid, nu)
        except (ParameterError, FloatingPointError, OverflowError):
            P, ok = np.full(grid.shape, np.nan), np.zeros(grid.shape, bool)
    bad = ~(np.asarray(ok) & np.isfinite(P))
    bad[1:] |= np.diff(P) <= 0.0
    return float(grid[bad][np.argmin(np.abs(grid[bad] - 1.0))]) if np.any(bad) else None


def _check_stable(law: str, mat, lam, nu) -> None:
    """FitError unless the fitted law stiffens with stretch in uniaxial tension and compression
    over the data's range and a margin (STABLE_RANGE at least)."""
    stretch = min(STABLE_RANGE[0], float(lam.min())), max(STABLE_RANGE[1], float(lam.max()))
    at = unstable_stretch(mat, nu, *stretch)
    if at is not None:
        raise FitError(f"the fitted {law} law is not stable: its uniaxial stress does not rise with stretch "
                       f"at stretch {at:.3g} ({mat.to_dict() if hasattr(mat, 'to_dict') else mat}); "
                       + (_nu_hint(mat, stretch) if nu is not None else "") + "try another law or fewer terms")


def _nu_hint(mat, stretch) -> str:
    """'give a larger --nu, at least X; or ' where a larger bulk modulus makes the fitted law
    stable over `stretch` (the range _check_stable checks; a small --nu gives kappa << mu,
    unstable in compression), else ''."""
    from tactileskin.materials import laws

    if not hasattr(mat, "K0") or not hasattr(mat, "law"):
        return ""
    lo, _ = laws.bulk_range(mat, stretch)
    if lo is None:
        return ""
    nu = lo if mat.law == "hyperfoam" else laws._nu_of(lo / mat.mu0)
    return f"give a larger --nu, at least {laws._sig(nu, True, 3):g}; or "


def _check_loadable(law: str, mat, lam) -> None:
    """Refuse a fitted law whose small-strain moduli a material file may not hold
    (laws.law_from_dict): written, it would be refused by every solve that reads it. lam: the
    uniaxial test's stretches (None: an indentation test)."""
    from tactileskin.materials.laws import MAX_BULK_OVER_SHEAR, MU0_RANGE

    lo, hi = MU0_RANGE
    if not lo <= mat.mu0 <= hi:
        test = ("the test's stretch runs " f"{float(lam.min()):.4g}-{float(lam.max()):.4g}: check the columns and "
                "units (stretch = 1 + strain, stress in MPa), or fit a simpler law") if lam is not None else \
            "check the columns and units (depth in mm, force in N)"
        raise FitError(f"the fitted {law} law's small-strain shear modulus mu0 = {mat.mu0:.3g} MPa is outside "
                       f"[{lo:g}, {hi:g}] MPa, which a material file may hold ({test})")
    if not mat.K0 / mat.mu0 <= MAX_BULK_OVER_SHEAR:
        raise FitError(f"the fitted {law} law's K0 / mu0 = {mat.K0 / mat.mu0:.4g} is above the "
                       f"{MAX_BULK_OVER_SHEAR:g} a material file may hold: give a smaller --nu")


def _alpha_seeds(terms):
    seeds = {1: [(5.0,), (-2.0,), (10.0,)], 2: [(2.0, 6.0), (-2.0, 6.0), (5.0, 10.0)],
             3: [(2.0, -2.0, 8.0), (1.0, 4.0, 10.0)]}
    return [np.array(a) for a in seeds[terms]]


def _cut(start, terms):
    x0, (lo, hi) = start
    return x0[:terms], (lo[:terms], hi[:terms])


_STRETCH = ("stretch", "lambda")
_STRAIN = ("strain",)
_STRESS = ("nominal_stress_mpa", "stress_mpa", "nominal_stress", "stress")


def read_uniaxial_csv(path) -> tuple[np.ndarray, np.ndarray]:
    """(stretch, nominal stress MPa) from a CSV with a header naming a stretch column
    (stretch | lambda, or strain: engineering strain, stretch = 1 + strain) and a stress
    column (nominal_stress_mpa | stress_mpa | nominal_stress | stress; MPa), or from two
    unnamed numeric columns (stretch, stress)."""
    path = Path(path)
    lines, rows = zip(*_csv_numbered_rows(path, "stretch and stress"))
    rows = list(rows)
    head = [c.strip().lower() for c in rows[0]]

    def col(names):
        return next((head.index(n) for n in names if n in head), None)

    if _is_number(rows[0][0]):
        i_s, i_p, strain, body = 0, 1, False, rows
    else:
        i_s, strain = col(_STRETCH), False
        if i_s is None:
            i_s, strain = col(_STRAIN), True
        i_p = col(_STRESS)
        if i_s is None or i_p is None:
            from tactileskin.materials.indentation import _DEPTH, _FORCE  # it imports this module

            # a sphere indentation's file given without --test indentation (both of its columns:
            # a depth column alone would be refused again with the option)
            both = col(_DEPTH) is not None and col(_FORCE) is not None
            hint = "an indentation test's columns: add --test indentation" if both else ""
            raise FitDataError("data header", ",".join(head),
                               "a stretch (or strain) column and a stress column (nominal_stress_mpa)", hint)
        body = rows[1:]
    lam, P = [], []
    named = body is not rows
    # the stretch bounds in the column's own units (a strain column: stretch - 1)
    shift = 1.0 if strain else 0.0
    cols = ((i_s, head[i_s] if named else "stretch", MIN_STRETCH - shift, MAX_STRETCH - shift, ""),
            (i_p, head[i_p] if named else "stress", -MAX_STRESS_MPA, MAX_STRESS_MPA, "MPa"))
    for n, (r, line) in enumerate(zip(body, lines[1:] if named else lines), start=2 if named else 1):
        try:
            lam.append(float(r[i_s]))
            P.append(float(r[i_p]))
        except (ValueError, IndexError):
            raise FitDataError("data", f"{path.name} row {n}: {','.join(r)}", "two numbers (stretch, stress)") from None
        for i, name, lo, hi, unit in cols:
            x = float(r[i])
            if not lo <= x <= hi:  # NaN too
                hint = ("" if not math.isfinite(x) else "a stress in kPa or Pa? give MPa" if unit
                        else "a strain in percent? give it as a fraction (0.5 for 50 %)" if x > hi
                        else "" if named else "a strain without its 'strain' header (stretch = 1 + strain), "
                                              "or are the columns swapped (stretch first)?")
                raise FitDataError(name, f"{r[i].strip()} on line {line} of {path.name}",
                                   range_text(lo, hi, unit=unit), hint)
    lam, P = np.array(lam), np.array(P)
    if strain and lam.size and np.all(np.isfinite(lam)) and np.all(np.isfinite(P)):
        # the unloaded state of a strain column is strain 0; at strain 1 it is a stretch column
        rest = float(lam[int(np.argmin(np.abs(P)))])
        if abs(rest - 1.0) < 0.05 and float(lam.min()) > 0.5:
            raise FitDataError("strain", f"{path.name}: the least stressed row at strain {rest:g}",
                               "engineering strain (0 unloaded, 0.5 for 50 %)",
                               "the column holds stretches: name it 'stretch'")
    return (1.0 + lam if strain else lam), P


def _csv_numbered_rows(path: Path, what: str) -> list[tuple[int, list[str]]]:
    """The non-empty, non-comment rows of a UTF-8 CSV of at most MAX_CSV_BYTES, each with its
    line number in the file (where it ends), for messages."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_CSV_BYTES + 1)
    except FileNotFoundError:
        raise FitDataError("data", str(path), "an existing CSV file") from None
    except OSError as e:
        raise FitDataError("data", str(path), "a readable CSV file", e.strerror or str(e)) from None
    if len(raw) > MAX_CSV_BYTES:
        raise FitDataError("data", str(path), f"a CSV of at most {MAX_CSV_BYTES >> 20} MiB")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise FitDataError("data", str(path), "a UTF-8 text CSV") from None
    reader = csv.reader(io.StringIO(text))
    rows = [(reader.line_num, r) for r in reader if r and any(c.strip() for c in r)]
    rows = [(n, r) for n, r in rows if not r[0].lstrip().startswith("#")]
    if not rows:
        raise FitDataError("data", str(path), f"a CSV with rows of {what}")
    return rows


def _is_number(s) -> bool:
    try:
        float(s)
        return True
    except ValueError:
        return False
