"""Pressure profiles along the bone path and their metrics (peak, span, AUC).

The same definitions serve the simulation and the pressure-film measurements, so that the
two compare like for like. Pure numpy.
"""

from __future__ import annotations

import numpy as np

from tactileskin.errors import ParameterError


def _check(s, p):
    s = np.asarray(s, float)
    p = np.asarray(p, float)
    if s.ndim != 1 or s.shape != p.shape or s.size < 2:
        raise ParameterError("profile", f"s {s.shape}, p {p.shape}", "1-D arrays of equal length >= 2")
    if not (np.all(np.isfinite(s)) and np.all(np.isfinite(p))):
        raise ParameterError("profile", "non-finite values", "finite s and P")
    if np.any(np.diff(s) <= 0):
        raise ParameterError("profile s", "not increasing", "strictly increasing positions")
    return s, p


def peak(s, p) -> float:
    """Largest pressure of the profile."""
    s, p = _check(s, p)
    return float(np.max(p))


def span(s, p, fraction: float = 0.1) -> float:
    """Extent of s where P >= fraction * peak (mm).

    From the first to the last sample at or above the threshold, each end moved to the
    linearly interpolated crossing with its outer neighbour (so the value does not jump
    with the sampling); an end that never drops below the threshold stays at the profile's
    end. Zero if the peak is not positive.
    """
    s, p = _check(s, p)
    if not 0 < fraction <= 1:
        raise ParameterError("fraction", fraction, "(0, 1]")
    top = float(np.max(p))
    if top <= 0:
        return 0.0
    thr = fraction * top
    idx = np.flatnonzero(p >= thr)
    a, b = idx[0], idx[-1]
    sa = s[a] if a == 0 else float(np.interp(thr, [p[a - 1], p[a]], [s[a - 1], s[a]]))
    sb = s[b] if b == s.size - 1 else float(np.interp(thr, [p[b + 1], p[b]], [s[b + 1], s[b]]))
    return float(sb - sa)


def auc(s, p) -> float:
    """Area under P(s), trapezoid rule (MPa mm for a pressure profile)."""
    s, p = _check(s, p)
    return float(np.trapezoid(p, s))
