"""The elastic half-space as a spatial filter (Fearing and Hollerbach 1985).

A normal surface load on a linear elastic half-space gives, at depth d, a vertical stress
that is the load convolved with a kernel; the kernel's spectrum is a low-pass filter.

- Point load P (Boussinesq): sigma_zz(r, d) = 3 P d^3 / (2 pi R^5), R = sqrt(r^2 + d^2).
- Line load q per length (Flamant): sigma_zz(x, d) = 2 q d^3 / (pi R^4), R = sqrt(x^2 + d^2).

Both kernels integrate to the load (vertical equilibrium of the layer above depth d) and both
have the same normalised spectrum, independent of Poisson's ratio,

    H(k d) = (1 + |k| d) exp(-|k| d)       (k: angular wavenumber, rad/mm),

(Flamant: 1D Fourier transform; Boussinesq: 2D transform, a Hankel transform of order 0).
A pattern of wavenumber k reaches the sensor plane attenuated by H. The cut-off k_c is where
H falls to `level`; a pattern passing the filter is sampled without aliasing at a pitch of
at most pi / k_c (two samples per period 2 pi / k_c): the Nyquist pitch. Stresses in MPa
for loads in N (point) or N/mm (line), lengths in mm.
"""

from __future__ import annotations

import numpy as np
from scipy.special import lambertw

from tactileskin.errors import ParameterError

DEFAULT_LEVEL = 0.1   # cut-off where the filter passes 10 % of a pattern (-20 dB)


def _depth(d) -> float:
    d = float(d)
    if not (np.isfinite(d) and d > 0):
        raise ParameterError("depth", d, "a finite depth > 0 mm")
    return d


def boussinesq_szz(r, d: float, load: float = 1.0) -> np.ndarray:
    """Vertical stress at depth d and radial distance r under a point load (compression > 0)."""
    d = _depth(d)
    r = np.asarray(r, float)
    return 3.0 * load * d**3 / (2.0 * np.pi * (r * r + d * d) ** 2.5)


def flamant_szz(x, d: float, load: float = 1.0) -> np.ndarray:
    """Vertical stress at depth d and lateral distance x under a line load per length."""
    d = _depth(d)
    x = np.asarray(x, float)
    return 2.0 * load * d**3 / (np.pi * (x * x + d * d) ** 2)


def spectrum(k, d: float) -> np.ndarray:
    """H(k) = (1 + |k| d) exp(-|k| d): the normalised spectrum of both kernels at depth d."""
    d = _depth(d)
    kd = np.abs(np.asarray(k, float)) * d
    return (1.0 + kd) * np.exp(-kd)


def _level(level: float) -> float:
    level = float(level)
    if not 0 < level < 1:
        raise ParameterError("level", level, "(0, 1): the fraction of a pattern the filter passes")
    return level


def cutoff(d: float, level: float = DEFAULT_LEVEL) -> float:
    """Angular wavenumber k_c (rad/mm) where H(k_c d) = level.

    (1 + x) e^-x = level with x = k d has the solution x = -1 - W_-1(-level / e) (Lambert W,
    lower branch: the root with x > 0)."""
    d, level = _depth(d), _level(level)
    x = -1.0 - float(np.real(lambertw(-level / np.e, -1)))
    return x / d


def nyquist_pitch(d: float, level: float = DEFAULT_LEVEL) -> float:
    """Largest array pitch (mm) that samples every pattern the filter passes above `level`:
    pi / k_c."""
    return float(np.pi / cutoff(d, level))


def measured_cutoff(x, p, level: float = DEFAULT_LEVEL) -> tuple[float, np.ndarray, np.ndarray]:
    """Cut-off of a measured narrow response p(x) (e.g. a single-dot row of a bone map) on an
    equally spaced grid: (k_c, k, |P(k)| / P(0)) with k_c the first wavenumber where the
    normalised amplitude spectrum falls to `level` (linear interpolation; inf if it never
    does). The response includes the stimulus' own width, so this is an upper bound on
    the filter's attenuation, not the filter alone."""
    level = _level(level)
    x, p = np.asarray(x, float), np.asarray(p, float)
    if x.ndim != 1 or x.shape != p.shape or x.size < 4:
        raise ParameterError("response", f"x {x.shape}, p {p.shape}", "1-D arrays of equal length >= 4")
    h = np.diff(x)
    if np.any(h <= 0) or np.ptp(h) > 1e-6 * h.mean():
        raise ParameterError("response x", "not equally spaced", "an equally spaced increasing grid")
    amp = np.abs(np.fft.rfft(p))
    if amp[0] <= 0:
        raise ParameterError("response", "zero mean", "a response with a positive integral")
    amp = amp / amp[0]
    k = 2.0 * np.pi * np.fft.rfftfreq(x.size, d=h.mean())
    below = np.flatnonzero(amp <= level)
    if below.size == 0:
        return float("inf"), k, amp
    i = below[0]
    kc = float(np.interp(level, [amp[i], amp[i - 1]], [k[i], k[i - 1]]))
    return kc, k, amp
