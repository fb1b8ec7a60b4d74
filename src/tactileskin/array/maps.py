"""Pressure maps on tensor grids: the common currency of the array package.

A map is a `results.BoneMap` (s, z grids in mm, pressure[j, i] at (s_i, z_j)). A *map source*
is any function returning one: today the bone-pressure map of a 3D solve (the sensor film on
the bone, Result.bone_map), or at ChartConfig.sensor_depth below the contact surface the
pressure read from the cached solve's result.vtu (chart.map_of); nothing downstream (sampler,
classify, chart) changes.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from tactileskin.errors import ParameterError
from tactileskin.results import BoneMap

MapSource = Callable[..., BoneMap]


def mirrored(m: BoneMap, tol: float = 1e-9) -> BoneMap:
    """The full map of a symmetric half or quarter model: a grid starting at s = 0 (z = 0) is
    mirrored to negative s (z), the symmetry planes of the solver's reduced models."""
    s, z, P = m.s, m.z, m.pressure
    if abs(s[0]) <= tol:
        s = np.concatenate([-s[:0:-1], s])
        P = np.concatenate([P[:, :0:-1], P], axis=1)
    if abs(z[0]) <= tol:
        z = np.concatenate([-z[:0:-1], z])
        P = np.concatenate([P[:0:-1], P], axis=0)
    return BoneMap(s, z, P, m.section_z)


def interpolator(m: BoneMap) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """f(s, z) -> P, bilinear on the map's grid and zero outside it (no load beyond the
    modelled surface). A one-point axis is constant along it."""
    axes, vals = [], m.pressure
    for ax, v in ((0, m.z), (1, m.s)):
        if v.size == 1:  # RegularGridInterpolator needs two points per axis
            v = np.array([v[0] - 1e9, v[0] + 1e9])
            vals = np.repeat(vals, 2, axis=ax)
        axes.append(v)
    f = RegularGridInterpolator(tuple(axes), vals, method="linear", bounds_error=False, fill_value=0.0)

    def at(s, z):
        s, z = np.broadcast_arrays(np.asarray(s, float), np.asarray(z, float))
        return f(np.column_stack([z.ravel(), s.ravel()])).reshape(s.shape)

    return at


def on_grid(f: Callable, s, z, section_z: float = 0.0) -> BoneMap:
    """A BoneMap of the function f(s, z) on the grid s x z."""
    s, z = np.asarray(s, float), np.asarray(z, float)
    S, Z = np.meshgrid(s, z)
    return BoneMap(s, z, f(S, Z), section_z)


def cropped(m: BoneMap, s_range, z_range) -> BoneMap:
    """The part of m on its grid points with s in s_range and z in z_range (closed intervals)."""
    ks = (m.s >= s_range[0] - 1e-9) & (m.s <= s_range[1] + 1e-9)
    kz = (m.z >= z_range[0] - 1e-9) & (m.z <= z_range[1] + 1e-9)
    if not ks.any() or not kz.any():
        raise ParameterError("map region", (tuple(s_range), tuple(z_range)), "a region holding grid points of the map")
    return BoneMap(m.s[ks], m.z[kz], m.pressure[np.ix_(kz, ks)], m.section_z)


def resampled(m: BoneMap, s, z) -> np.ndarray:
    """m's pressure on the grid s x z (rows z, columns s; bilinear, zero outside m)."""
    return interpolator(m)(*np.meshgrid(np.asarray(s, float), np.asarray(z, float)))


def relative_error(approx: BoneMap, ref: BoneMap) -> dict:
    """Errors of `approx` against `ref` on ref's grid: rel_l2 = ||a - r|| / ||r|| and
    max_abs_over_peak = max |a - r| / max r, peak_rel = (max a - max r) / max r."""
    a = resampled(approx, ref.s, ref.z)
    r = ref.pressure
    top = float(r.max())
    if top <= 0:
        raise ParameterError("reference map", f"peak {top:g}", "a map with a positive peak")
    return {"rel_l2": float(np.linalg.norm(a - r) / np.linalg.norm(r)),
            "max_abs_over_peak": float(np.abs(a - r).max() / top),
            "peak_rel": float((a.max() - top) / top)}


def taxel_averaged(m: BoneMap, side: float, h: float | None = None) -> BoneMap:
    """The map as read by square taxels of `side` (mm) centred at every point: the box average
    of m over side x side, on an even grid of step h (default side / 8) over m's extent
    (zero beyond it, as `interpolator`). Pointwise noise finer than a taxel (the mesh's
    ripple in a recovered bone pressure) is what an array never reads."""
    from scipy.ndimage import convolve1d

    if not (np.isfinite(side) and side > 0):
        raise ParameterError("taxel side", side, "> 0 mm")
    n = max(1, int(round(side / (side / 8.0 if h is None else h))))
    h = side / n
    s = np.arange(m.s[0], m.s[-1] + 0.5 * h, h) if m.s.size > 1 else m.s.copy()
    z = np.arange(m.z[0], m.z[-1] + 0.5 * h, h) if m.z.size > 1 else m.z.copy()
    P = resampled(m, s, z)
    # trapezoid weights over n + 1 samples: the box [-side/2, side/2] of the sampled map
    w = np.ones(n + 1)
    w[[0, -1]] = 0.5
    w /= w.sum()
    for ax, size in ((1, s.size), (0, z.size)):
        if size > 1:
            P = convolve1d(P, w, axis=ax, mode="constant", cval=0.0)
    return BoneMap(s, z, P, m.section_z)
