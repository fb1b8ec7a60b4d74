"""The one registry of indenter kinds: name -> class (tactileskin.registry.Registry).

Every module of this package that defines a kind registers it with `@register`; the package
imports its modules on first use, so a new kind is one new file here (plus its test). Kind
modules import only numpy, scipy and the standard library at module level
(tests/test_import_rules.py); a kind that needs a heavier library imports it lazily.
"""

from __future__ import annotations

from tactileskin.registry import Registry

_REGISTRY = Registry("tactileskin.geometry.indenters", "indenter kind", "indenter")
register, names, get = _REGISTRY.register, _REGISTRY.names, _REGISTRY.get
