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

import functools
import importlib

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
    against MU0_RANGE and MAX_BULK_OVER_SHEAR."""
    from tactileskin.errors import check_range

    cls = get_law(validate.string(name, f"{what} law", "a law name"))
    law = cls.from_dict(table, f"{what} {name}")
    check_range(f"{what} {name}: small-strain shear modulus mu0", law.mu0, *MU0_RANGE, unit="MPa")
    check_range(f"{what} {name}: bulk / shear modulus K0 / mu0 (nu0 = {nu0(law):.6g})", law.K0 / law.mu0,
                None, MAX_BULK_OVER_SHEAR)
    return law


def nu0(law) -> float:
    """A law's small-strain Poisson ratio, from its mu0 and K0."""
    return (3 * law.K0 - 2 * law.mu0) / (2 * (3 * law.K0 + law.mu0))
