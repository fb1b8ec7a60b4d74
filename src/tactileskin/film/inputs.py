"""Checks shared by the film readers: bounded text reads and finite numbers.

Text inputs (calibration JSON and CSV, profile CSV, summary JSON) are read with a size cap
so that a wrong file (a scan, a log, /dev/zero) is refused before it is read into memory.
"""

from __future__ import annotations

import math
from pathlib import Path

from tactileskin.errors import ParameterError

# A calibration is tens of presses and a profile a few thousand rows (both well under
# 1 MB); 16 MB leaves room for long reports while bounding what a wrong file costs.
MAX_TEXT_BYTES = 16 * 2**20


def read_text(path, what: str, valid: str, *, limit: int | None = None) -> str:
    """UTF-8 text of `path` (at most `limit` bytes, default MAX_TEXT_BYTES), or
    ParameterError(what) naming the file and the problem."""
    limit = MAX_TEXT_BYTES if limit is None else limit
    path = Path(path)
    try:
        with path.open("rb") as fh:
            data = fh.read(limit + 1)
    except FileNotFoundError:
        raise ParameterError(what, str(path), valid, hint="file not found") from None
    except OSError as e:
        raise ParameterError(what, str(path), valid, hint=f"unreadable: {e.strerror or e}") from None
    if len(data) > limit:
        raise ParameterError(what, str(path), valid,
                             hint=f"larger than {limit // 2**20} MB; not a {what} file?")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise ParameterError(what, str(path), valid, hint=f"not UTF-8 text ({e.reason} at "
                             f"byte {e.start})") from None


def finite(name: str, value, lo: float | None = None, *, lo_open: bool = False,
           unit: str = "") -> float:
    """float(value) if finite (and > / >= lo), else ParameterError naming `name`."""
    u = f" {unit}" if unit else ""
    valid = "a finite number" if lo is None else f"a finite number {'>' if lo_open else '>='} {lo:g}{u}"
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, valid) from None
    if not math.isfinite(v) or (lo is not None and (v <= lo if lo_open else v < lo)):
        raise ParameterError(name, value, valid)
    return v
