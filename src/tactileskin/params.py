"""Locate and read the geometry parameter files (fingertip, indenters, Braille, molds).

The TOML files are the single source of truth for every dimension. They ship inside the
package (tactileskin/data/geometry/*.toml, read through importlib.resources, as the material
presets are), so an installed wheel finds them; TACTILESKIN_GEOMETRY overrides the folder.
"""

from __future__ import annotations

import atexit
import contextlib
import datetime
import functools
import hashlib
import json
import math
import os
import tomllib
from importlib import resources
from pathlib import Path

from tactileskin import validate
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


# Parameter files are a few kB; a cap keeps a wrong path (a log, an image, /dev/zero) from
# being read whole. 1 MiB is ~100x the largest file the toolkit writes or ships.
MAX_TOML_BYTES = 1 << 20


def _read_capped(path, what: str) -> bytes:
    """The bytes of a TOML file, at most MAX_TOML_BYTES; a ParameterError naming `what` else."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_TOML_BYTES + 1)
    except FileNotFoundError:
        raise ParameterError(what, str(path), "an existing TOML file") from None
    except OSError as e:
        raise ParameterError(what, str(path), "a readable TOML file", e.strerror or str(e)) from None
    if len(raw) > MAX_TOML_BYTES:
        raise ParameterError(what, str(path), f"a TOML file of at most {MAX_TOML_BYTES // 1024} KiB")
    return raw


def _parse(raw: bytes, path, what: str) -> dict:
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ParameterError(what, str(path), "a UTF-8 text file",
                             f"byte {e.start} is not UTF-8") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ParameterError(what, str(path), f"valid TOML ({e})") from None
    except ValueError as e:  # an integer past Python's int() digit limit (4300)
        raise ParameterError(what, str(path), "valid TOML", str(e)) from None
    except RecursionError:
        raise ParameterError(what, str(path), "valid TOML", "nested too deeply") from None


def read_toml(path: str | Path, what: str) -> dict:
    """Parse a user's TOML file; a missing, unreadable, oversized (> MAX_TOML_BYTES), non-UTF-8
    or malformed file is a ParameterError naming `what`."""
    validate.path(path, what, "a file path (str or os.PathLike)")
    return _parse(_read_capped(path, what), path, what)


# parsed files by content: a file edited during a process is read again, never served stale
_PARSED: dict[tuple[str, bytes], dict] = {}


def load(name: str) -> dict:
    """Parsed <geometry_dir>/<name>.toml (memoised by content; treat as read-only)."""
    path = geometry_dir() / f"{name}.toml"
    return _parsed(name, _read_capped(path, "parameter file"), path)


def _parsed(name: str, data: bytes, path) -> dict:
    """`data` (the bytes of `name`.toml) parsed, memoised by content."""
    hit = _PARSED.get((name, data))
    if hit is None:
        hit = _parse(data, path, "parameter file")
        if f"{name}.toml" not in NOT_SOLVED:  # the mold's reader (geometry.molds) names its own values
            _check_numbers(hit, _shipped(name), f"{name}.toml: ")  # first: a date there is told a number
        _refuse_dates(hit, f"{name}.toml: ")
        hit = _Table.of(hit, f"{name}.toml: ")
        if len(_PARSED) > 64:  # only edits add entries; keep the memo small
            _PARSED.clear()
        _PARSED[(name, data)] = hit
    return hit


class _Table(dict):
    """A parsed table whose missing key, read as table[key] (a reader's required value), is a
    ParameterError naming the file and key (a user's file without `radius` ended in a KeyError
    traceback); .get() of an optional key is unchanged."""

    where = ""

    @classmethod
    def of(cls, value, where: str, key: str = ""):
        if isinstance(value, dict):
            t = cls({k: cls.of(v, where, f"{key}.{k}" if key else str(k)) for k, v in value.items()})
            t.where = where + (key + "." if key else "")
            return t
        if isinstance(value, list):
            return [cls.of(v, where, key) for v in value]
        return value

    def __missing__(self, key):
        raise ParameterError(self.where + str(key), None, "a value (the file lacks the key)",
                             "copy it from the shipped file in tactileskin/data/geometry")


def _refuse_dates(value, where: str, key: str = "") -> None:
    """No geometry parameter is a date or time: tomllib reads `radius = 2024-01-01` as one, which
    a reader's float() met as a TypeError traceback and the cache key could not tell from the
    text "2024-01-01"; a ParameterError names the file and the key."""
    if isinstance(value, dict):
        for k, v in value.items():
            _refuse_dates(v, where, f"{key}.{k}" if key else str(k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _refuse_dates(v, where, f"{key}[{i}]")
    elif isinstance(value, (datetime.date, datetime.time)):  # datetime is a date
        raise ParameterError(where + key, value.isoformat(), "a number or text, not a TOML date or time",
                             "quote it if it is text")


@functools.cache
def _shipped(name: str) -> dict:
    """The shipped `name`.toml parsed ({} for a file the package does not ship)."""
    try:
        return tomllib.loads((_packaged_dir() / f"{name}.toml").read_text("utf-8"))
    except (OSError, tomllib.TOMLDecodeError):
        return {}


def _is_number(v) -> bool:
    """A finite int or float (an int too large for a float is not: math.isfinite overflows)."""
    if not isinstance(v, (int, float)) or isinstance(v, bool):
        return False
    try:
        return math.isfinite(v)
    except OverflowError:
        return False


def _check_numbers(value: dict, shipped: dict, where: str, key: str = "") -> None:
    """Where the shipped file has a number (or a list of numbers), a user's file must have a
    finite one (or a list of them): its readers take float() of it, which met text as a
    ValueError traceback, a nan as a nan geometry. Keys the shipped file lacks (a user's own
    Braille standard) and missing keys are the readers' to judge."""
    for k, ref in shipped.items():
        if k not in value:
            continue
        v, name = value[k], f"{key}.{k}" if key else str(k)
        if isinstance(ref, dict):
            if not isinstance(v, dict):
                raise ParameterError(where + name, v, "a table, as the shipped file has")
            _check_numbers(v, ref, where, name)
        elif isinstance(ref, list) and all(_is_number(r) for r in ref):
            if not (isinstance(v, list) and v and all(_is_number(x) for x in v)):
                raise ParameterError(where + name, v, "a list of finite numbers, as the shipped file has")
        elif _is_number(ref) and not _is_number(v):
            raise ParameterError(where + name, v, "a finite number, as the shipped file has")


def geometry_changes() -> list[str] | None:
    """None when the geometry parameter files are the shipped ones (no TACTILESKIN_GEOMETRY, or
    it names the shipped folder); else the names of the .toml files whose bytes differ from the
    shipped ones (missing or added included): what a report must state, since its numbers come
    from them."""
    folder, shipped = geometry_dir(), _packaged_dir()
    with contextlib.suppress(OSError):
        if folder.resolve() == shipped.resolve():
            return None

    def files(d: Path) -> dict:
        try:
            return {p.name: p.read_bytes() for p in d.iterdir() if p.name.endswith(".toml") and p.is_file()}
        except OSError:
            return {}

    a, b = files(folder), files(shipped)
    return sorted(n for n in set(a) | set(b) if a.get(n) != b.get(n))


# geometry files no solve reads: the casting mold is CAD for `build` alone (geometry/molds.py),
# so editing its wall or pins must not re-solve every cached case
NOT_SOLVED = ("molds.toml",)


def geometry_digest() -> str:
    """SHA-256 of every geometry parameter file but NOT_SOLVED (names and parsed values, sorted
    by name): part of the result cache's key, so that editing a dimension invalidates the cached
    results, and a comment or re-spacing (the same values) does not re-solve them. A file that
    is not valid TOML enters by its bytes (its solve names the error)."""
    folder = geometry_dir()
    try:
        paths = sorted((p for p in folder.iterdir() if p.name.endswith(".toml") and p.is_file()
                        and p.name not in NOT_SOLVED), key=lambda p: p.name)
    except OSError as e:
        raise ParameterError("geometry folder", str(folder), "a readable folder of TOML files",
                             e.strerror or type(e).__name__) from None
    h = hashlib.sha256()
    for p in paths:
        data = _read_capped(p, "parameter file")
        try:
            parsed = _parsed(p.stem, data, p)
            # floats as repr (exact), 1 and 1.0 apart as TOML has them (dates and times are refused)
            data = b"toml\0" + json.dumps(parsed, sort_keys=True).encode()
        except ParameterError:
            pass
        h.update(p.name.encode() + b"\0" + str(len(data)).encode() + b"\0" + data)
    return h.hexdigest()
