"""The registry of material laws, keyed by the name a material file gives in `law = "..."`.

Each law is one module of this package defining a frozen dataclass with
- `law` (its registry name), `mu0`, `K0` (small-strain shear and bulk moduli, MPa);
- `from_dict(table, what)` (validates its TOML table, ParameterError naming the parameter
  and its range), `to_dict()` (the numbers that enter the cache key);
- `energy(C)`, `pk2(C, detF=None) -> (S, ok)`,
  `pk2_tangent(C, detF=None, tangent=True) -> (S, D, ok)` (C (..., 3, 3)),
  `pk2_tangent_plane(C2, detF=None, out_of_plane=False, tangent=True)` (plane strain);
- for `materials.fit`: `fit_start(mu0) -> (x0, bounds)` and `from_fit(x, nu)`.
A new law is its module plus one line in `_MODULES`.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import math

from tactileskin import validate
from tactileskin.errors import ParameterError

__all__ = ["get_law", "list_laws", "law_from_dict", "nu0"]

# registry name -> (module, class)
_MODULES = {
    "hyperfoam": ("hyperfoam", "Hyperfoam"),
    "neo_hookean": ("neo_hookean", "NeoHookean"),
    "mooney_rivlin": ("mooney_rivlin", "MooneyRivlin"),
    "yeoh": ("yeoh", "Yeoh"),
    "ogden": ("ogden", "Ogden"),
}


def list_laws() -> list[str]:
    return sorted(_MODULES)


@functools.cache
def get_law(name: str):
    """The law class registered as `name`."""
    if name not in _MODULES:
        raise ParameterError("law", name, "one of " + ", ".join(list_laws()), validate.did_you_mean(name, _MODULES))
    mod, cls = _MODULES[name]
    return getattr(importlib.import_module(f"tactileskin.materials.{mod}"), cls)


# Plausible small-strain moduli of a skin material (MPa): 1 Pa (the softest gels) to 10 GPa
# (past any elastomer), and the bulk-to-shear ratio of nu = 0.4999. Beyond them a file's numbers
# are a units slip or a typo: mu = 1e300 and 1e-300, nu = 0.499999 were accepted and failed
# only inside the solver with a message naming no parameter.
MU0_RANGE = (1e-6, 1e4)
MAX_BULK_OVER_SHEAR = 5000.0  # nu0 = 0.4999


def law_from_dict(name: str, table, what: str):
    """An instance of law `name` from its parameter table, its small-strain moduli checked
    against MU0_RANGE and MAX_BULK_OVER_SHEAR (a ParameterError naming the bulk parameter,
    kappa or nu, and its range)."""
    from tactileskin.errors import check_range

    cls = get_law(validate.string(name, f"{what} law", "a law name"))
    law = cls.from_dict(table, f"{what} {name}")
    check_range(f"{what} {name}: small-strain shear modulus mu0", law.mu0, *MU0_RANGE, unit="MPa")
    if not law.K0 / law.mu0 <= MAX_BULK_OVER_SHEAR:
        raise bulk_error(law, f"{what} {name}", f"K0 / mu0 = {law.K0 / law.mu0:.6g} is over "
                         f"{MAX_BULK_OVER_SHEAR:g} (nu0 = {nu0(law):.6g} over {_nu_of(MAX_BULK_OVER_SHEAR):.6g})")
    return law


# the parameter that sets each law's small-strain bulk modulus: nu for the hyperfoam, kappa (MPa)
# for the others; its valid range depends on the law's other parameters (mu0 and stability)
def _bulk_name(law) -> str:
    return "nu" if law.law == "hyperfoam" else "kappa"


def _nu_of(ratio: float) -> float:
    """The Poisson ratio of a bulk / shear modulus ratio."""
    return (3 * ratio - 2) / (2 * (3 * ratio + 1))


def _bulk_value(law, ratio: float) -> float:
    """`law`'s bulk parameter (nu, or kappa MPa) at K0 / mu0 = ratio."""
    return _nu_of(ratio) if _bulk_name(law) == "nu" else ratio * law.mu0


def _with_ratio(law, ratio: float):
    """`law` with its bulk parameter set so that K0 / mu0 = ratio."""
    return dataclasses.replace(law, **{_bulk_name(law): _bulk_value(law, ratio)})


def _sig(x: float, up: bool, digits: int) -> float:
    """x to `digits` significant digits, rounded up or down (a printed bound that is itself valid)."""
    e = 10.0 ** (math.floor(math.log10(abs(x))) - digits + 1)
    v = (math.ceil if up else math.floor)(x / e) * e
    return float(f"{v:.{digits}g}")


def bulk_range(law, stretch: tuple[float, float] | None = None) -> tuple[float | None, float]:
    """The valid range of `law`'s bulk parameter (kappa MPa, or nu) with its other parameters:
    from the smallest at which its uniaxial stress rises with stretch (over `stretch`, default
    materials.fit.STABLE_RANGE; None: no value up to the largest is stable; _OPEN_END: stable
    down to the parameter's own open bound, kappa > 0 or nu > -1) to the largest,
    K0 / mu0 = MAX_BULK_OVER_SHEAR.
    A bisection in log(K0 / mu0), stability assumed to grow with the bulk modulus: for error
    messages only (~50 stability checks)."""
    from tactileskin.materials.fit import STABLE_RANGE, unstable_stretch

    stretch = STABLE_RANGE if stretch is None else stretch

    def stable(r):
        try:
            trial = _with_ratio(law, r)
        except ParameterError:  # nu rounds to -1
            return False
        return unstable_stretch(trial, nu0(trial), *stretch) is None

    value = functools.partial(_bulk_value, law)
    hi = MAX_BULK_OVER_SHEAR
    if not stable(hi):
        return None, _sig(value(hi), False, 4)
    lo = min(law.K0 / law.mu0, 1.0)
    while stable(lo) and lo > 1e-30:
        lo /= 1e3
    a, b = math.log(lo), math.log(hi)        # unstable at a, stable at b
    for _ in range(50):
        m = 0.5 * (a + b)
        a, b = (a, m) if stable(math.exp(m)) else (m, b)
    # stable down to K0 / mu0 = 1e-9 (nu = -1 + 4.5e-9): the law's own bound, the rest is float
    # noise (a hyperfoam failed its check at nu = -1 + 5e-15 and was told 'valid: [-0.999, ...]')
    if math.exp(b) < 1e-9:
        return _OPEN_END[_bulk_name(law)], _sig(value(hi), False, 4)
    return _sig(value(math.exp(b)), True, 3), _sig(value(hi), False, 4)


# the bulk parameter's own (open) lower bound: kappa > 0 MPa, nu > -1
_OPEN_END = {"kappa": 0.0, "nu": -1.0}


def bulk_error(law, where: str, why: str) -> ParameterError:
    """A ParameterError naming `where`.kappa (or .nu) and its valid range (bulk_range)."""
    lo, hi = bulk_range(law)
    name = _bulk_name(law)
    unit = " MPa" if name == "kappa" else ""
    valid = (f"{'(' if lo == _OPEN_END[name] else '['}{lo:g}, {hi:g}]{unit}" if lo is not None else
             f"<= {hi:g}{unit}, and the law's other parameters stable (none of its values is)")
    return ParameterError(f"{where}.{name}", getattr(law, name), valid + f" with mu0 = {law.mu0:g} MPa", why)


def nu0(law) -> float:
    """A law's small-strain Poisson ratio, from its mu0 and K0."""
    return (3 * law.K0 - 2 * law.mu0) / (2 * (3 * law.K0 + law.mu0))
