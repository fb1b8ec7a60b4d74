"""The one registry of skin geometries: name -> class (tactileskin.registry.Registry).

Every module of this package that defines a skin registers it with `@register`; the package
imports its modules on first use, so a new skin is one new file here (plus its test). Skin
modules import only numpy, scipy and the standard library at module level; meshing (gmsh) and
CAD (build123d) are imported inside the methods that need them.
"""

from __future__ import annotations

from tactileskin.registry import Registry

_REGISTRY = Registry("tactileskin.skins", "skin", "skin")
register, names, get = _REGISTRY.register, _REGISTRY.names, _REGISTRY.get
