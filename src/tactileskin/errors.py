"""Typed exceptions. Library code raises these; only the CLI prints and exits."""

from __future__ import annotations


class TactileSkinError(Exception):
    """Base class for every error the toolkit raises on purpose."""


class ParameterError(TactileSkinError, ValueError):
    """A user-supplied parameter is outside its valid range.

    The message always names the parameter, the value given and the valid range.
    """

    def __init__(self, name: str, value, valid: str, hint: str = ""):
        self.name, self.value, self.valid = name, value, valid
        msg = f"{name}={value!r} is invalid; valid: {valid}"
        if hint:
            msg += f" ({hint})"
        super().__init__(msg)


class CadError(TactileSkinError):
    """The CAD kernel could not build a solid; the message names the parameters."""


class MeshError(TactileSkinError):
    """gmsh could not make the requested mesh, or the request is unreasonable."""


class ConvergenceError(TactileSkinError):
    """A nonlinear solve stopped without converging; carries a diagnosis."""

    def __init__(self, message: str, diagnosis: dict | None = None):
        self.diagnosis = diagnosis or {}
        super().__init__(message)


def check_range(name: str, value: float, lo: float | None = None, hi: float | None = None,
                *, lo_open: bool = False, hi_open: bool = False, unit: str = "") -> float:
    """Return float(value) if lo <= value <= hi (open ends as flagged), else raise ParameterError."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, _range_text(lo, hi, lo_open, hi_open, unit)) from None
    ok = v == v  # rejects NaN
    if lo is not None:
        ok &= v > lo if lo_open else v >= lo
    if hi is not None:
        ok &= v < hi if hi_open else v <= hi
    if not ok:
        raise ParameterError(name, value, _range_text(lo, hi, lo_open, hi_open, unit))
    return v


def _range_text(lo, hi, lo_open, hi_open, unit):
    u = f" {unit}" if unit else ""
    if lo is not None and hi is not None:
        return f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}{u}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo:g}{u}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {hi:g}{u}"
    return "a finite number"
