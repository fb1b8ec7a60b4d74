"""Arrow columns of the sweep's Parquet tables from Python lists, as `pa.array(values, type)`
builds them, without its import of pandas: pa.array asks pandas whether a list is a Series
(importing it, ~0.2 s CPU), and the sweep command's process has no other use for it. The
lists here (str, int, float, None) are laid into Arrow buffers directly; any other list goes
to pa.array itself, so types, values and errors are pa.array's."""

from __future__ import annotations

import numpy as np

_INTS = (int, np.int64)      # pa.array: int64
_FLOATS = (float, np.float64)  # pa.array: double (ints among them too)


def _validity(values, n: int):
    """(bitmap buffer or None, null count) of the values that are not None."""
    import pyarrow as pa

    valid = np.fromiter((v is not None for v in values), bool, n)
    nulls = n - int(valid.sum())
    return (pa.py_buffer(np.packbits(valid, bitorder="little").tobytes()) if nulls else None), nulls


def _numbers(values, n: int, arrow_type, dtype):
    import pyarrow as pa

    data = np.array([0 if v is None else v for v in values], dtype=dtype)
    bitmap, nulls = _validity(values, n)
    return pa.Array.from_buffers(arrow_type, n, [bitmap, pa.py_buffer(data.tobytes())], null_count=nulls)


def _strings(values, n: int):
    import pyarrow as pa

    enc = [b"" if v is None else v.encode("utf-8") for v in values]  # a lone surrogate: UnicodeEncodeError
    offsets = np.zeros(n + 1, np.int64)
    np.cumsum(np.fromiter(map(len, enc), np.int64, n), out=offsets[1:])
    if offsets[-1] >= 2 ** 31:  # pa.string's int32 offsets (pa.array: a chunked array)
        raise OverflowError("strings too long for one array")
    bitmap, nulls = _validity(values, n)
    return pa.Array.from_buffers(pa.string(), n, [bitmap, pa.py_buffer(offsets.astype(np.int32).tobytes()),
                                                  pa.py_buffer(b"".join(enc))], null_count=nulls)


def column(values: list, type=None):  # noqa: A002 - pa.array's name
    """pa.array(values, type=type) for type None, pa.float64() or pa.string()."""
    import pyarrow as pa

    n = len(values)
    kinds = set(map(_kind, values)) - {None}
    if "float" in kinds or type == pa.float64():  # pa.array refuses an int a double does not hold exactly
        kinds |= {"other" for v in values if _kind(v) == "int" and abs(int(v)) > 2 ** 53}
    try:
        if type is None and not kinds:
            return pa.nulls(n)
        if (type is None or type == pa.string()) and kinds == {"str"}:
            return _strings(values, n)
        if type is None and kinds == {"int"}:
            return _numbers(values, n, pa.int64(), np.int64)
        if (type is None or type == pa.float64()) and kinds and kinds <= {"int", "float"}:
            return _numbers(values, n, pa.float64(), np.float64)
        if type == pa.float64() and not kinds:
            return pa.nulls(n, pa.float64())
        if type == pa.string() and not kinds:
            return pa.nulls(n, pa.string())
    except (OverflowError, UnicodeEncodeError):  # pa.array's own error (or its wider type)
        pass
    return pa.array(values, type=type)


def _kind(v) -> str | None:
    t = v.__class__
    if v is None:
        return None
    if t is str:
        return "str"
    if t in _INTS:
        return "int"
    if t in _FLOATS:
        return "float"
    return "other"
