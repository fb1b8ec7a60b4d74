"""The one registry of skin geometries: name -> class.

Every module of this package that defines a skin registers it with `@register`; the package
imports its modules on first use, so a new skin is one new file here (plus its test). Skin
modules import only numpy, scipy and the standard library at module level; meshing (gmsh) and
CAD (build123d) are imported inside the methods that need them.
"""

from __future__ import annotations

import importlib
import pkgutil

from tactileskin import validate
from tactileskin.errors import ParameterError

_SKINS: dict[str, type] = {}
_NOT_SKINS = {"base", "registry"}
_loaded = False


def register(cls):
    """Class decorator: make `cls` (a Skin subclass with a `name`) a skin."""
    if not cls.name or cls.name in _SKINS and _SKINS[cls.name] is not cls:
        raise ValueError(f"skin {cls.name!r} is empty or registered twice")
    _SKINS[cls.name] = cls
    return cls


def _load() -> None:
    global _loaded
    if _loaded:
        return
    import tactileskin.skins as pkg

    for info in pkgutil.iter_modules(pkg.__path__):
        if info.name not in _NOT_SKINS and not info.name.startswith("_"):
            importlib.import_module(f"{pkg.__name__}.{info.name}")
    _loaded = True


def names() -> tuple[str, ...]:
    """The registered skin names (the paper's fingertip first)."""
    _load()
    return tuple(sorted(_SKINS, key=lambda n: (_SKINS[n].order, n)))


def get(name):
    """The skin class registered as `name`; ParameterError listing the valid names."""
    _load()
    name = getattr(name, "value", name)
    if not isinstance(name, str) or name not in _SKINS:
        raise ParameterError("skin", name, "one of " + ", ".join(names()),
                             validate.did_you_mean(name, _SKINS) if isinstance(name, str) else "")
    return _SKINS[name]
