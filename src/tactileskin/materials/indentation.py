"""Fit a law's small-strain shear modulus to a spherical indentation test on a bonded layer.

A rigid sphere of radius R indents by d a layer of thickness t bonded to a rigid base. For an
incompressible layer, Dimitriadis et al. 2002 (Biophys. J. 82:2798, eq. 13, bonded sample,
nu = 0.5) give the Hertz force with a finite-thickness correction:

    F = 16 E / 9 * R^(1/2) d^(3/2) * (1 + 1.133 chi + 1.283 chi^2 + 0.769 chi^3 + 0.0975 chi^4),
    chi = sqrt(R d) / t,   E = 3 mu (incompressible).

Validity (refused outside, `FitDataError` naming the row): chi <= 1 (the series was derived
for a contact radius sqrt(R d) below the thickness), and d / R <= 0.1 (Hertz: a small
contact radius against R, a/R <= 0.32, where the neo-Hookean force stays within a few % of
the linear one), so d / t = chi^2 t / R as well. F is linear in E, so the fit is the closed
least-squares E = sum(F g) / sum(g^2) (g = F / E above); it minimises the RMSE it reports.
Only the small-strain modulus is identifiable in this range: the fitted law is neo-Hookean
(mu = E / 3) with the bulk modulus of fit.NU_INCOMPRESSIBLE; laws with more parameters are
refused. Pure numpy.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tactileskin.errors import ParameterError, check_range
from tactileskin.materials.fit import REL_FLOOR, NU_INCOMPRESSIBLE, FitDataError

__all__ = ["IndentationFit", "bonded_sphere_force", "fit_indentation", "read_indentation_csv",
           "CHI_MAX", "DEPTH_OVER_RADIUS_MAX"]

CHI_MAX = 1.0                 # sqrt(R d) / t: contact radius below the thickness
DEPTH_OVER_RADIUS_MAX = 0.1   # Hertz: small contact radius against R
COEFFS = (1.0, 1.133, 1.283, 0.769, 0.0975)  # Dimitriadis 2002, bonded, nu = 0.5
LAWS = ("neo_hookean",)


def bonded_sphere_force(E, depth, radius, thickness):
    """Force (N) of the corrected Hertz law above (E in MPa, lengths in mm)."""
    d = np.asarray(depth, float)
    chi = np.sqrt(radius * d) / thickness
    poly = np.polynomial.polynomial.polyval(chi, COEFFS)
    return 16.0 * E / 9.0 * np.sqrt(radius) * d ** 1.5 * poly


@dataclass
class IndentationFit:
    law: object
    E: float
    depth: np.ndarray
    force: np.ndarray
    predicted: np.ndarray
    radius: float
    thickness: float
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
        return (f"{self.law.law}: {self.law.to_dict()} (E = 3 mu = {self.E:.5g} MPa, the incompressible "
                f"formula's; the file's bulk modulus makes nu = {NU_INCOMPRESSIBLE:g}); R^2 = {q['r2']:.5f}, "
                f"RMSE = {q['rmse_n']:.3g} N, max relative error {100 * q['max_rel_err']:.2f} % "
                f"({q['n_points']} points, sphere R = {self.radius:g} mm on a bonded layer t = "
                f"{self.thickness:g} mm, chi <= {q['chi_max']:.3g})"
                + "".join(f"\n  suspect fit: {w}" for w in self.warnings))


def check_indentation(depth, force, radius, thickness):
    R = check_range("radius", radius, 0.0, 1e4, lo_open=True, unit="mm")
    t = check_range("thickness", thickness, 0.0, 1e4, lo_open=True, unit="mm")
    try:
        d = np.asarray(depth, float).ravel()
        F = np.asarray(force, float).ravel()
    except (TypeError, ValueError):
        raise FitDataError("data", "non-numeric values", "numbers (depth mm, force N)") from None
    if d.shape != F.shape:
        raise FitDataError("force", f"{F.size} values", f"{d.size} values (one per depth)")
    if d.size < 3:
        raise FitDataError("data", f"{d.size} points", ">= 3 points")
    for name, x in (("depth", d), ("force", F)):
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            raise FitDataError(name, f"non-finite value at row {bad[0] + 1}", "finite numbers")
    # the contact point (0, 0) that most recordings start with carries no information: a
    # leading one is dropped (rows keep their numbers in the messages below)
    row = np.arange(1, d.size + 1)
    if d[0] == 0.0 and F[0] == 0.0:
        d, F, row = d[1:], F[1:], row[1:]
    if d.size < 3:
        raise FitDataError("data", f"{d.size} points past first contact", ">= 3 points with depth > 0")
    if np.any(d <= 0.0):
        i = int(np.flatnonzero(d <= 0.0)[0])
        raise FitDataError("depth", f"{d[i]:g} at row {row[i]}", "> 0 mm (depth from first contact)")
    dmax = min(DEPTH_OVER_RADIUS_MAX * R, CHI_MAX ** 2 * t * t / R)
    over = np.flatnonzero(d > dmax)
    if over.size:
        i = int(over[0])
        chi = np.sqrt(R * d[i]) / t
        raise FitDataError("depth", f"{d[i]:g} mm at row {row[i]} (d/R = {d[i] / R:.3g}, chi = sqrt(R d)/t = {chi:.3g})",
                           f"<= {dmax:.4g} mm for R = {R:g} mm, t = {t:g} mm (d/R <= {DEPTH_OVER_RADIUS_MAX:g}, "
                           f"chi <= {CHI_MAX:g})",
                           "outside the range of the bonded-layer Hertz correction; drop the deeper points")
    return d, F, R, t


def fit_indentation(law: str, depth, force, *, radius: float, thickness: float) -> IndentationFit:
    """Fit `law` (neo_hookean) to (depth mm, force N) of a sphere of `radius` on a bonded
    layer of `thickness` (see the module docstring for the formula and its range)."""
    from tactileskin.materials.fit import _quality
    from tactileskin.materials.laws import get_law

    if law not in LAWS:
        get_law(law)  # an unknown name gets the registry's error
        raise ParameterError("law", law, " or ".join(LAWS) + " for an indentation fit",
                             "indentation in the Hertz range identifies the small-strain modulus only")
    d, F, R, t = check_indentation(depth, force, radius, thickness)
    g = bonded_sphere_force(1.0, d, R, t)
    E = float(np.dot(F, g) / np.dot(g, g))
    if not E > 0.0:
        raise FitDataError("force", f"fitted E = {E:g} MPa", "forces that give a positive modulus",
                           "force in N, positive in compression")
    from tactileskin.materials.neo_hookean import NeoHookean

    mat = NeoHookean.from_fit(np.array([E / 3.0]), NU_INCOMPRESSIBLE)
    pred = E * g
    q = _quality(F, pred, 1)
    if not q["r2"] > 0.0:  # worse than the data's mean (a force falling with depth, swapped columns)
        order = np.argsort(d)
        falls = bool(np.any(np.diff(F[order]) < 0.0))
        raise FitDataError("force", f"a fit with R^2 = {q['r2']:.3g}",
                           "forces that rise with depth as a sphere on a layer gives (F ~ d^1.5)",
                           ("the force falls with depth at some rows; " if falls else "")
                           + "check the columns (depth_mm, force_n) and their units")
    from tactileskin.materials.fit import SOFT_MU_MAX, _check_loadable, misfit_warning

    _check_loadable(law, mat, None)
    # the uniaxial fit's rules: a point missed past MAX_REL_ERR, and a modulus past any skin
    # elastomer's (most often a unit slip)
    miss = misfit_warning(F, pred, d, "depth", "mm",
                          "the bonded-layer Hertz force (F ~ d^1.5) does not describe this test; check the "
                          "radius, the thickness and that depth is measured from first contact")
    q["warnings"] = [miss] if miss else []
    if mat.mu0 > SOFT_MU_MAX:
        q["warnings"].append(f"shear modulus {mat.mu0:.4g} MPa: stiffer than the soft elastomers of skins (up to "
                             f"about {SOFT_MU_MAX:g} MPa); is the force column in mN? N is expected (and depth in mm)")
    q["rmse_n"] = q.pop("rmse_mpa")
    q["chi_max"] = float(np.sqrt(R * d.max()) / t)
    q["rel_floor"] = REL_FLOOR
    return IndentationFit(law=mat, E=E, depth=d, force=F, predicted=pred, radius=R, thickness=t, quality=q)


_DEPTH = ("depth_mm", "depth", "indentation_mm", "indentation")
_FORCE = ("force_n", "force")


# What no indentation test of a skin layer gives, so that a value outside is a slip (a typo, a
# unit), refused naming it as the CSV is read (as fit.read_uniaxial_csv does). Depth in
# [0, 1000] mm: the fit takes d/R <= 0.1 at R <= 1e4 mm, so a deeper point cannot be fitted,
# and 1 m is past any instrument's travel on a layer (0: the contact row). Force within +-1e4 N:
# 10 kN is past the load cells of tabletop testing machines (loading.MAX_FORCE, the solver's
# target, is the same bound); a small negative reading is a load cell's noise near contact
# (compression positive), left to the fit as before.
MAX_DEPTH_MM = 1e3
MAX_FORCE_N = 1e4


def read_indentation_csv(path) -> tuple[np.ndarray, np.ndarray]:
    """(depth mm, force N) from a CSV with a header naming a depth column (depth_mm | depth |
    indentation_mm | indentation) and a force column (force_n | force), or two unnamed
    numeric columns (depth, force). A value outside [0, MAX_DEPTH_MM] mm or [0, MAX_FORCE_N]
    N (NaN, inf too) raises FitDataError naming the column, the value and its line."""
    import math
    from pathlib import Path

    from tactileskin.errors import range_text
    from tactileskin.materials.fit import _csv_numbered_rows, _is_number

    path = Path(path)
    lines, rows = zip(*_csv_numbered_rows(path, "depth and force"))
    head = [c.strip().lower() for c in rows[0]]
    named = not _is_number(rows[0][0])
    if named:
        i_d = next((head.index(n) for n in _DEPTH if n in head), None)
        i_f = next((head.index(n) for n in _FORCE if n in head), None)
        if i_d is None or i_f is None:
            raise FitDataError("data header", ",".join(head), f"a depth column ({' | '.join(_DEPTH)}) and a "
                                                             f"force column ({' | '.join(_FORCE)})")
        body, where = rows[1:], lines[1:]
    else:
        i_d, i_f, body, where = 0, 1, rows, lines
    # the column as the header spells it
    cols = ((i_d, rows[0][i_d].strip() if named else "depth", 0.0, MAX_DEPTH_MM, "mm", "a depth in um? give mm"),
            (i_f, rows[0][i_f].strip() if named else "force", -MAX_FORCE_N, MAX_FORCE_N, "N", "a force in mN? give N"))
    out = ([], [])
    for r, line in zip(body, where):
        for k, (i, name, lo, hi, unit, hint) in enumerate(cols):
            try:
                x = float(r[i])
            except (ValueError, IndexError):
                raise FitDataError("data", f"line {line} of {path.name}: {','.join(r)}",
                                   "two numbers (depth mm, force N)") from None
            if not lo <= x <= hi:  # NaN too
                raise FitDataError(name, f"{r[i].strip()} on line {line} of {path.name}", range_text(lo, hi, unit=unit),
                                   hint if math.isfinite(x) and abs(x) > hi else
                                   "" if not math.isfinite(x) else "a depth is measured from first contact")
            out[k].append(x)
    return np.array(out[0]), np.array(out[1])
