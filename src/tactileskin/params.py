"""Locate and read the parameter files under the repository's geometry/ folder.

The TOML files are the single source of truth for every dimension. They live beside the
package in a checkout (src layout); TACTILESKIN_GEOMETRY overrides the folder.
"""

from __future__ import annotations

import functools
import os
import tomllib
from pathlib import Path

from tactileskin.errors import ParameterError


def geometry_dir() -> Path:
    env = os.environ.get("TACTILESKIN_GEOMETRY")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[2] / "geometry"


@functools.cache
def load(name: str) -> dict:
    """Parsed geometry/<name>.toml (cached; treat as read-only)."""
    path = geometry_dir() / f"{name}.toml"
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ParameterError("parameter file", str(path), "an existing TOML file under geometry/") from None
