"""Skin geometries: each skin an object that answers for itself (see `base.Skin`).

`get(name)` / `names()`; `skin_for_scene(scene)`. Kinds: `fingertip` (the paper's elliptical
section and its extrusion), `pad` (a flat pad bonded to a rigid board). See
docs/architecture.md, "skins".
"""

from __future__ import annotations

from tactileskin.skins.base import Skin  # noqa: F401
from tactileskin.skins.registry import get, names  # noqa: F401


def skin_for_scene(scene):
    """The skin class of a scene (its `skin` field)."""
    return get(scene.skin)
