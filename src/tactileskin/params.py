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


def read_toml(path: str | Path, what: str) -> dict:
    """Parse a user's TOML file; a missing or malformed file is a ParameterError naming `what`."""
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ParameterError(what, str(path), "an existing TOML file") from None
    except tomllib.TOMLDecodeError as e:
        raise ParameterError(what, str(path), f"valid TOML ({e})") from None


@functools.cache
def load(name: str) -> dict:
    """Parsed geometry/<name>.toml (cached; treat as read-only)."""
    return read_toml(geometry_dir() / f"{name}.toml", "parameter file")
