"""The one registry of indenter kinds: name -> class.

Every module of this package that defines a kind registers it with `@register`; the
package imports its modules on first use (`pkgutil`), so a new kind is one new file here
(plus its test). Kind modules import only numpy, scipy and the standard library at module
level (tests/test_import_rules.py); a kind that needs a heavier library imports it lazily.
"""

from __future__ import annotations

import importlib
import pkgutil

from tactileskin import validate
from tactileskin.errors import ParameterError

_KINDS: dict[str, type] = {}
_NOT_KINDS = {"base", "registry"}
_loaded = False


def register(cls):
    """Class decorator: make `cls` (an Indenter subclass with a `name`) a kind."""
    if not cls.name or cls.name in _KINDS and _KINDS[cls.name] is not cls:
        raise ValueError(f"indenter kind {cls.name!r} is empty or registered twice")
    _KINDS[cls.name] = cls
    return cls


def _load() -> None:
    global _loaded
    if _loaded:
        return
    import tactileskin.geometry.indenters as pkg

    for info in pkgutil.iter_modules(pkg.__path__):
        if info.name not in _NOT_KINDS and not info.name.startswith("_"):
            importlib.import_module(f"{pkg.__name__}.{info.name}")
    _loaded = True


def names() -> tuple[str, ...]:
    """The registered kind names (the paper's first)."""
    _load()
    return tuple(sorted(_KINDS, key=lambda n: (_KINDS[n].order, n)))


def get(name):
    """The kind class registered as `name`; ParameterError listing the valid names."""
    _load()
    name = getattr(name, "value", name)
    if not isinstance(name, str) or name not in _KINDS:
        raise ParameterError("indenter", name, "one of " + ", ".join(names()),
                             validate.did_you_mean(name, _KINDS) if isinstance(name, str) else "")
    return _KINDS[name]
