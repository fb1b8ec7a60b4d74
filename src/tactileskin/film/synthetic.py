"""Synthetic film scans rendered from a pressure profile, for round-trip checks.

The profile P(s) is laid along image x, uniform across a strip of given width, zero in
margins above and below. Each pixel's pressure goes through the calibration's inverse to a
grayscale (pressures beyond the activation range render at the saturation / threshold
grayscale, i.e. the film saturates), then optionally: Gaussian blur of the grayscale
(scanner optics), additive Gaussian noise, rounding to 8 bits and clipping to 0-255.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np
from scipy import ndimage

from tactileskin.errors import ParameterError, check_range
from tactileskin.film.calibration import Calibration, paper_eq8
from tactileskin.film.image import MAX_PIXELS
from tactileskin.film.inputs import finite


def gaussian_profile(peak: float, width_mm: float) -> Callable[[np.ndarray], np.ndarray]:
    """P(s) = peak * exp(-s^2 / (2 w^2)) (a closed-form stand-in for a subsurface profile)."""
    return lambda s: peak * np.exp(-0.5 * (np.asarray(s, float) / width_mm) ** 2)


def blurred_gaussian_profile(peak: float, width_mm: float, blur_mm: float):
    """The Gaussian profile convolved with a Gaussian blur of sd blur_mm (closed form)."""
    w = np.hypot(width_mm, blur_mm)
    return gaussian_profile(peak * width_mm / w, w)


def mirrored(s_half, p_half) -> Callable[[np.ndarray], np.ndarray]:
    """Two-sided profile from a half-model profile over s >= 0 (symmetric about s = 0)."""
    s_half = np.asarray(s_half, float)
    p_half = np.asarray(p_half, float)
    return lambda s: np.interp(np.abs(np.asarray(s, float)), s_half, p_half, right=0.0)


def render_scan(profile: Callable[[np.ndarray], np.ndarray], calibration: Calibration | None = None,
                *, length_mm: float = 20.0, width_mm: float = 5.0, margin_mm: float = 2.0,
                centre_mm: float | None = None, px_per_mm: float = 8.0, blur_px: float = 0.0,
                noise_gs: float = 0.0, background_gs: float | None = None,
                seed: int = 0) -> np.ndarray:
    """Render a uint8 grayscale scan (rows = across the strip, columns = along it).

    profile(s) gives the pressure at distance s (mm) from ``centre_mm`` (default: the
    middle of the strip), evaluated at pixel centres. ``background_gs`` (e.g. 245, white
    film) replaces every pixel that would read less than half a gray level above the
    activation threshold: unactivated film is lighter than the threshold, as on real scans;
    default None keeps the threshold grayscale there.
    """
    cal = calibration or paper_eq8()
    for name, v in (("length_mm", length_mm), ("width_mm", width_mm)):
        finite(name, v, 0, lo_open=True, unit="mm")
    finite("margin_mm", margin_mm, 0, unit="mm")
    finite("px_per_mm", px_per_mm, 0, lo_open=True, unit="px/mm")
    finite("blur_px", blur_px, 0, unit="px")
    finite("noise_gs", noise_gs, 0, unit="gray levels")
    nx = length_mm * px_per_mm
    nw = width_mm * px_per_mm
    nm = margin_mm * px_per_mm
    if not nx * (nw + 2 * nm) <= MAX_PIXELS:
        raise ParameterError("length_mm/width_mm/margin_mm", (length_mm, width_mm, margin_mm),
                             f"at most {MAX_PIXELS / 1e6:g} Mpx at {px_per_mm:g} px/mm")
    nx, nw, nm = int(round(nx)), int(round(nw)), int(round(nm))
    if nx < 3 or nw < 1:
        raise ParameterError("length_mm/width_mm", (length_mm, width_mm),
                             f">= 3 px long and 1 px wide at {px_per_mm:g} px/mm")
    c = 0.5 * length_mm if centre_mm is None else float(centre_mm)
    s = (np.arange(nx) + 0.5) / px_per_mm - c
    p = np.asarray(profile(s), float)
    if p.shape != s.shape or not np.all(np.isfinite(p)):
        raise ParameterError("profile", "callable", "finite P(s) with the shape of s")
    pimg = np.zeros((nw + 2 * nm, nx))
    pimg[nm:nm + nw] = p
    gs = cal.grayscale(pimg)
    if background_gs is not None:
        check_range("background_gs", background_gs, 0, 255)
        thr = cal.threshold_gs
        inactive = np.abs(gs - thr) < 0.5
        gs = np.where(inactive, background_gs, gs)
    if blur_px > 0:
        gs = ndimage.gaussian_filter(gs, blur_px, mode="nearest")
    if noise_gs > 0:
        gs = gs + np.random.default_rng(seed).normal(0.0, noise_gs, gs.shape)
    return np.clip(np.rint(gs), 0, 255).astype(np.uint8)


def save_scan(img: np.ndarray, path) -> Path:
    """Write a uint8 array as PNG/TIFF (by suffix), atomically."""
    from PIL import Image

    from tactileskin import fileio

    path = Path(path)
    fmt = {".png": "PNG", ".tif": "TIFF", ".tiff": "TIFF"}.get(path.suffix.lower())
    if fmt is None:
        raise ParameterError("scan path", str(path), "a .png, .tif or .tiff file name")
    with fileio.atomic_path(path, suffix=path.suffix) as tmp, fileio.os_errors(path):
        Image.fromarray(np.asarray(img)).save(tmp, format=fmt)
    return path
