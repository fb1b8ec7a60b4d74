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

__all__ = ["get_law", "list_laws", "law_from_dict"]

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


def law_from_dict(name: str, table, what: str):
    """An instance of law `name` from its parameter table."""
    cls = get_law(validate.string(name, f"{what} law", "a law name"))
    return cls.from_dict(table, f"{what} {name}")
