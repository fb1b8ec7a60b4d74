"""Locate and read the geometry parameter files (fingertip, indenters, Braille, molds).

The TOML files are the single source of truth for every dimension. They ship inside the
package (tactileskin/data/geometry/*.toml, read through importlib.resources, as the material
presets are), so an installed wheel finds them; TACTILESKIN_GEOMETRY overrides the folder.
"""

from __future__ import annotations

import atexit
import contextlib
import functools
import os
import tomllib
from importlib import resources
from pathlib import Path

from tactileskin.errors import ParameterError

_PACKAGE_DIR = ("data", "geometry")


@functools.cache
def _packaged_dir() -> Path:
    res = resources.files("tactileskin").joinpath(*_PACKAGE_DIR)
    if isinstance(res, Path):
        return res
    # a zipped install: extract once for the life of the process (callers want a real folder)
    stack = contextlib.ExitStack()
    atexit.register(stack.close)
    return Path(stack.enter_context(resources.as_file(res)))


def geometry_dir() -> Path:
    """The folder holding fingertip.toml, indenters.toml, braille.toml and molds.toml."""
    env = os.environ.get("TACTILESKIN_GEOMETRY")
    if env:
        return Path(env)
    return _packaged_dir()


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
    """Parsed <geometry_dir>/<name>.toml (cached; treat as read-only)."""
    return read_toml(geometry_dir() / f"{name}.toml", "parameter file")
