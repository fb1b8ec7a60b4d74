"""A registry of named classes filled from the modules of one package (indenter kinds, skins).

Every module of the package that defines such a class registers it with `@register`; the
package's modules are imported on first use, so a new kind is one new file (plus its test).
"""

from __future__ import annotations

import importlib
import pkgutil

from tactileskin import validate
from tactileskin.errors import ParameterError


class Registry:
    def __init__(self, package: str, what: str, parameter: str, skip=("base", "registry")):
        self.package, self.what, self.parameter, self.skip = package, what, parameter, set(skip)
        self._classes: dict[str, type] = {}
        self._loaded = False

    def register(self, cls):
        """Class decorator: make `cls` (with a `name` and an `order`) one of the registered."""
        if not cls.name or cls.name in self._classes and self._classes[cls.name] is not cls:
            raise ValueError(f"{self.what} {cls.name!r} is empty or registered twice")
        self._classes[cls.name] = cls
        return cls

    def _load(self) -> None:
        if self._loaded:
            return
        pkg = importlib.import_module(self.package)
        for info in pkgutil.iter_modules(pkg.__path__):
            if info.name not in self.skip and not info.name.startswith("_"):
                importlib.import_module(f"{self.package}.{info.name}")
        self._loaded = True

    def names(self) -> tuple[str, ...]:
        """The registered names (the paper's first: by `order`, then name)."""
        self._load()
        return tuple(sorted(self._classes, key=lambda n: (self._classes[n].order, n)))

    def get(self, name):
        """The class registered as `name`; ParameterError listing the valid names."""
        self._load()
        name = getattr(name, "value", name)
        if not isinstance(name, str) or name not in self._classes:
            raise ParameterError(self.parameter, name, "one of " + ", ".join(self.names()),
                                 validate.did_you_mean(name, self._classes) if isinstance(name, str) else "")
        return self._classes[name]
