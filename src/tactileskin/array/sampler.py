"""A map read by a sensor array: taxel lattice, area averaging, noise and quantisation.

The array is a square lattice of square taxels of side `taxel` (0: point sensors) at
`pitch`, `n` x `n` taxels centred on the origin of the map's (s, z) plane, rotated by
`rotation_deg`, shifted by a sub-pitch `offset` (the stimulus' unknown position relative to
the array). A taxel reads the mean of the map over its area, computed with an
`quad` x `quad` Gauss-Legendre rule on the bilinear interpolant of the map (exact for a
linear field). The default `quad` is one point per TAXEL_SPACING (0.25 mm, as the sensors'
taxels: tactileskin.sensors) of the side, at least 4, at most MAX_QUAD: a fixed 4 x 4 rule
read a 3.2 mm taxel (the chart's 4 mm pitch) over a t = 1 mm single dot up to 16 % off its
area mean, depending on where the dot fell between the points (a 4.8 mm taxel 61 %).
The readout adds Gaussian noise (MPa, plus a fraction of full scale) and rounds to `bits`
over [0, full_scale].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tactileskin.array.maps import interpolator
from tactileskin.errors import ParameterError
from tactileskin.results import BoneMap
from tactileskin.sensors import TAXEL_SPACING  # mm between Gauss points of the default rule

MIN_QUAD, MAX_QUAD = 4, 64
MAX_TAXELS = 200  # taxels a side of an array's lattice


def default_quad(taxel: float) -> int:
    """Gauss points per direction of a taxel of side `taxel` (mm) when none are given."""
    import math

    return int(min(MAX_QUAD, max(MIN_QUAD, math.ceil(float(taxel) / TAXEL_SPACING - 1e-9))))


def _positive(name, v, allow_zero=False):
    v = float(v)
    ok = np.isfinite(v) and (v >= 0 if allow_zero else v > 0)
    if not ok:
        raise ParameterError(name, v, ">= 0" if allow_zero else "> 0 (mm)")
    return v


@dataclass(frozen=True)
class ArraySpec:
    """Taxel lattice: pitch (mm), taxel side (mm, 0 = point), n x n taxels, rotation (deg)."""

    pitch: float
    taxel: float = 0.0
    n: int = 9
    rotation_deg: float = 0.0
    quad: int | None = None   # None: default_quad(taxel)

    def __post_init__(self):
        _positive("pitch", self.pitch)
        _positive("taxel", self.taxel, allow_zero=True)
        if self.quad is None:
            object.__setattr__(self, "quad", default_quad(self.taxel))
        if self.taxel > self.pitch:
            raise ParameterError("taxel", self.taxel, f"<= pitch = {self.pitch:g} mm (taxels must not overlap)")
        if not (isinstance(self.n, (int, np.integer)) and 1 <= self.n <= MAX_TAXELS):
            raise ParameterError("n", self.n, f"an integer in [1, {MAX_TAXELS}] taxels per side")
        if not (isinstance(self.quad, (int, np.integer)) and 1 <= self.quad <= MAX_QUAD):
            raise ParameterError("quad", self.quad, f"an integer in [1, {MAX_QUAD}]")
        if not np.isfinite(self.rotation_deg):
            raise ParameterError("rotation_deg", self.rotation_deg, "a finite angle")

    def centres(self, offset=(0.0, 0.0)) -> np.ndarray:
        """(n*n, 2) taxel centres (s, z), row-major in z then s."""
        k = (np.arange(self.n) - 0.5 * (self.n - 1)) * self.pitch
        S, Z = np.meshgrid(k, k)
        c, s_ = np.cos(np.radians(self.rotation_deg)), np.sin(np.radians(self.rotation_deg))
        pts = np.column_stack([S.ravel(), Z.ravel()]) @ np.array([[c, s_], [-s_, c]])
        return pts + np.asarray(offset, float)

    def _quadrature(self) -> tuple[np.ndarray, np.ndarray]:
        """Points (q, 2) relative to a taxel centre (rotated with the array) and weights (sum 1)."""
        if self.taxel == 0.0:
            return np.zeros((1, 2)), np.ones(1)
        x, w = np.polynomial.legendre.leggauss(self.quad)
        x = 0.5 * self.taxel * x
        X, Y = np.meshgrid(x, x)
        W = np.outer(w, w).ravel() / 4.0
        c, s_ = np.cos(np.radians(self.rotation_deg)), np.sin(np.radians(self.rotation_deg))
        return np.column_stack([X.ravel(), Y.ravel()]) @ np.array([[c, s_], [-s_, c]]), W


def sample(m: BoneMap, spec: ArraySpec, offset=(0.0, 0.0), f=None) -> np.ndarray:
    """Noise-free taxel readings (n*n,) of map m (f: its interpolator, to reuse)."""
    f = f or interpolator(m)
    centres = spec.centres(offset)
    q, w = spec._quadrature()
    pts = centres[:, None, :] + q[None, :, :]
    return f(pts[..., 0], pts[..., 1]) @ w


@dataclass(frozen=True)
class Readout:
    """Electronics: Gaussian noise `noise_mpa` + `noise_fs` x full_scale (std, MPa), and
    `bits`-bit quantisation over [0, full_scale] (None: no quantisation)."""

    full_scale: float = 1.0
    noise_mpa: float = 0.0
    noise_fs: float = 0.0
    bits: int | None = None

    def __post_init__(self):
        _positive("full_scale", self.full_scale)
        _positive("noise_mpa", self.noise_mpa, allow_zero=True)
        _positive("noise_fs", self.noise_fs, allow_zero=True)
        if self.bits is not None and not (isinstance(self.bits, (int, np.integer)) and 1 <= self.bits <= 32):
            raise ParameterError("bits", self.bits, "an integer in [1, 32] (None from Python: no quantisation)")

    @property
    def sigma(self) -> float:
        return self.noise_mpa + self.noise_fs * self.full_scale

    @property
    def lsb(self) -> float:
        """Quantisation step: full scale over 2^bits - 1 steps (0 and full scale are codes)."""
        return 0.0 if self.bits is None else self.full_scale / (2**self.bits - 1)

    def __call__(self, values: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        v = np.asarray(values, float)
        if self.sigma > 0:
            v = v + rng.normal(0.0, self.sigma, size=v.shape)
        return quantise(v, self.bits, self.full_scale) if self.bits is not None else v


def quantise(values, bits: int, full_scale: float) -> np.ndarray:
    """Round to the nearest of 2^bits levels over [0, full_scale], clipping outside."""
    lsb = full_scale / (2**bits - 1)
    return np.clip(np.round(np.asarray(values, float) / lsb), 0, 2**bits - 1) * lsb
