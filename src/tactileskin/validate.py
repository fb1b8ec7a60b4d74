"""Type and key checks for values read from user files (TOML tables, Python keyword input).

Each check raises ParameterError naming the parameter, the value and what is valid, so a
mistyped key or a value of the wrong type is one clear line, never a later traceback.
"""

from __future__ import annotations

import difflib
import math
from numbers import Integral, Real
from typing import Iterable

from tactileskin.errors import ParameterError


def did_you_mean(word, choices: Iterable[str]) -> str:
    close = difflib.get_close_matches(str(word), list(choices), n=1)
    return f"did you mean {close[0]!r}?" if close else ""


def table(value, name: str) -> dict:
    """`value` must be a table (dict)."""
    if not isinstance(value, dict):
        raise ParameterError(name, value, "a table")
    return value


def known_keys(d: dict, allowed: Iterable[str], name: str) -> None:
    """Every key of table `d` must be one of `allowed` (the first unknown one is named)."""
    allowed = sorted(allowed)
    unknown = sorted(str(k) for k in d if k not in allowed)
    if unknown:
        raise ParameterError(f"{name} key", unknown[0], "one of " + ", ".join(allowed),
                             did_you_mean(unknown[0], allowed))


def is_number(v) -> bool:
    return isinstance(v, Real) and not isinstance(v, bool)


def number(v, name: str) -> float:
    """A finite int or float (not a bool, not a string) as float."""
    if not is_number(v) or not math.isfinite(float(v)):
        raise ParameterError(name, v, "a finite number")
    return float(v)


def integer(v, name: str, valid: str) -> int:
    """An int (not a bool, not a float such as 2.0: a dimension or order is counted)."""
    if isinstance(v, bool) or not isinstance(v, Integral):
        raise ParameterError(name, v, valid, "an integer")
    return int(v)


def boolean(v, name: str) -> bool:
    """True or False (not "no", not 0)."""
    if type(v).__name__ == "bool_":  # numpy bool
        v = bool(v)
    if not isinstance(v, bool):
        raise ParameterError(name, v, "true or false")
    return v


def path(v, name: str, valid: str = "a path (str or os.PathLike)"):
    """A file or folder path: a str or os.PathLike (an int would be taken for an open file
    descriptor, a number or None for nothing at all)."""
    import os

    if not isinstance(v, (str, os.PathLike)):
        raise ParameterError(name, repr(v), valid)
    return v


def string(v, name: str, valid: str = "a string") -> str:
    if not isinstance(v, str):
        raise ParameterError(name, v, valid)
    return v


def sequence(v, name: str, kind: str, max_len: int) -> list:
    """A list or tuple (never a string, which would iterate as characters) of at most
    max_len items."""
    if isinstance(v, (str, bytes, dict)) or not isinstance(v, (list, tuple)):
        raise ParameterError(name, v, f"a list of {kind}")
    if len(v) > max_len:
        raise ParameterError(name, f"{len(v)} items", f"at most {max_len} {kind}")
    return list(v)


def number_list(v, name: str, max_len: int, *, min_len: int = 0) -> tuple[float, ...]:
    items = sequence(v, name, "numbers", max_len)
    if len(items) < min_len:
        raise ParameterError(name, v, f"a list of at least {min_len} number(s)")
    return tuple(number(x, f"{name}[{i}]") for i, x in enumerate(items))


def string_list(v, name: str, max_len: int, *, min_len: int = 0) -> tuple[str, ...]:
    items = sequence(v, name, "strings", max_len)
    if len(items) < min_len:
        raise ParameterError(name, v, f"a list of at least {min_len} string(s)")
    return tuple(string(x, f"{name}[{i}]") for i, x in enumerate(items))


def integer_list(v, name: str, max_len: int, valid: str, *, min_len: int = 0) -> tuple[int, ...]:
    """A list of ints (not bools, not floats such as 2.0), e.g. the dims of a sweep."""
    items = sequence(v, name, "integers", max_len)
    if len(items) < min_len:
        raise ParameterError(name, v, f"a list of at least {min_len} integer(s)")
    return tuple(integer(x, f"{name}[{i}]", valid) for i, x in enumerate(items))
