"""Typed exceptions. Library code raises these; only the CLI prints and exits."""

from __future__ import annotations

import math
import sys


class TactileSkinError(Exception):
    """Base class for every error the toolkit raises on purpose."""


class ParameterError(TactileSkinError, ValueError):
    """A user-supplied parameter is outside its valid range.

    The message always names the parameter, the value given and the valid range.
    """

    def __init__(self, name: str, value, valid: str, hint: str = ""):
        self.name, self.value, self.valid, self.hint = name, value, valid, hint
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
    """Return float(value) if it is a finite number with lo <= value <= hi (open ends as
    flagged), else raise ParameterError. Booleans and strings are not numbers here (a TOML
    `thickness = true` or `"3"` is a mistake, not 1.0 or 3.0).

    A closed bound is met within a few ulps: bounds are often computed (0.6 * t) and a value
    typed as the printed bound (1.8 for 0.6 * 3 = 1.7999999999999998) must pass."""
    valid = range_text(lo, hi, lo_open=lo_open, hi_open=hi_open, unit=unit)
    if isinstance(value, (bool, str, bytes)):
        raise ParameterError(name, value, valid, "a number")
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(name, value, valid) from None
    ok = math.isfinite(v)
    if lo is not None:
        ok &= v > lo if lo_open else v >= lo - _slack(lo)
    if hi is not None:
        ok &= v < hi if hi_open else v <= hi + _slack(hi)
    if not ok:
        raise ParameterError(name, value, valid)
    return v


def _slack(bound: float) -> float:
    return 4.0 * sys.float_info.epsilon * abs(bound)


def fmt_bound(x: float) -> str:
    """Shortest text of x that reads back as x to within a few ulps (`:g` drops digits:
    a bound 0.74074068 would print as 0.740741, which is above it)."""
    for digits in (6, 10, 15, 17):
        text = f"{x:.{digits}g}"
        if abs(float(text) - x) <= _slack(x):
            return text
    return repr(x)


def range_text(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False,
               hi_open: bool = False, unit: str = "") -> str:
    """The valid range as check_range states it, e.g. "[0.05, 20] mm" or "> 0 mm" (for help
    texts and list checks that quote the same bounds)."""
    u = f" {unit}" if unit else ""
    if lo is not None and hi is not None:
        return f"{'(' if lo_open else '['}{fmt_bound(lo)}, {fmt_bound(hi)}{')' if hi_open else ']'}{u}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {fmt_bound(lo)}{u}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {fmt_bound(hi)}{u}"
    return "a finite number" + (f" ({unit})" if unit else "")


class MissingDependency(TactileSkinError, ImportError):
    """An optional package is not installed; the message names it and the extra to install."""

    def __init__(self, package: str, needed_for: str, extra: str = "render"):
        self.package, self.extra = package, extra
        super().__init__(f"{package} is not installed; {needed_for} needs it: "
                         f"pip install 'tactileskin[{extra}]'")


def require_pyvista(needed_for: str):
    """The pyvista module, or MissingDependency naming the extra that installs it."""
    try:
        import pyvista
    except ImportError:
        raise MissingDependency("pyvista", needed_for) from None
    return pyvista
