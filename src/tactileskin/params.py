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


# Parameter files are a few kB; a cap keeps a wrong path (a log, an image, /dev/zero) from
# being read whole. 1 MiB is ~100x the largest file the toolkit writes or ships.
MAX_TOML_BYTES = 1 << 20


def read_toml(path: str | Path, what: str) -> dict:
    """Parse a user's TOML file; a missing, unreadable, oversized (> MAX_TOML_BYTES), non-UTF-8
    or malformed file is a ParameterError naming `what`."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_TOML_BYTES + 1)
    except FileNotFoundError:
        raise ParameterError(what, str(path), "an existing TOML file") from None
    except OSError as e:
        raise ParameterError(what, str(path), "a readable TOML file", e.strerror or str(e)) from None
    if len(raw) > MAX_TOML_BYTES:
        raise ParameterError(what, str(path), f"a TOML file of at most {MAX_TOML_BYTES // 1024} KiB")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ParameterError(what, str(path), "a UTF-8 text file",
                             f"byte {e.start} is not UTF-8") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ParameterError(what, str(path), f"valid TOML ({e})") from None
    except RecursionError:
        raise ParameterError(what, str(path), "valid TOML", "nested too deeply") from None


@functools.cache
def load(name: str) -> dict:
    """Parsed geometry/<name>.toml (cached; treat as read-only)."""
    return read_toml(geometry_dir() / f"{name}.toml", "parameter file")
