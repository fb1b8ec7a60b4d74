"""Reading scans: any Pillow image -> float grayscale on the 0-255 scale, size-capped.

Pixel scale, by the stored type (the rule is explicit because an integer image does not
say which range its values use):
- 8-bit (L, P, RGB, ...): as is.
- 16-bit integer (I;16*): scaled by 255/65535, unless its largest value is <= 255, which
  means an 8-bit scan stored in a 16-bit container: then as is (logged).
- 32-bit integer (I): as is if within 0-255, scaled by 255/65535 if within 0-65535
  (logged), else refused.
- float (F): within [0, 1] -> x255; within [0, 255] -> as is; else refused. (A float scan
  in 0-255 whose values are all <= 1 would be a black image; it is read as a 0-1 image.)
Colour is BT.601 luma (Y = 0.299 R + 0.587 G + 0.114 B, float). An alpha channel must be
opaque: a transparent pixel's colour is undefined (often black, which the film would read as
its highest pressure), so an image with any alpha < full is refused (flatten it first).

Scale: `file_px_per_mm` gives the pixels per mm the file records (PNG pHYs in metres, TIFF
resolution in inches (also without a unit tag, the TIFF default) or cm; None when the
file records none or no absolute unit), which
`film.scan.analyze_scan` checks against the scale it is given.

Size: the header's width x height is checked against MAX_PIXELS before any pixel is
decoded; a compressed image can claim far more pixels than its file size suggests.
"""

from __future__ import annotations

import logging
import warnings
from pathlib import Path

import numpy as np

from tactileskin.errors import ParameterError

log = logging.getLogger(__name__)

LUMA_BT601 = (0.299, 0.587, 0.114)
LUMINANCE_NOTE = "ITU-R BT.601 luma Y = 0.299 R + 0.587 G + 0.114 B (float; alpha must be opaque)"
# 40 megapixels: a film strip of 300 x 300 mm at the paper's 8 px/mm is 5.8 Mpx, and a
# whole A4 flatbed scan at 600 dpi (23.6 px/mm) is 34.8 Mpx. The analysis holds a few
# float64 copies of the image (grayscale, pressure, masks): about 1.5 GB at the cap.
MAX_PIXELS = 40_000_000
VALID = "a readable, non-empty PNG or TIFF image"


def luminance(rgb: np.ndarray) -> np.ndarray:
    """BT.601 luma of an (..., 3) RGB array, in the array's own scale."""
    return np.asarray(rgb, float)[..., :3] @ np.asarray(LUMA_BT601)


def _too_big(path, w, h) -> ParameterError:
    return ParameterError("scan", str(path), f"an image of at most {MAX_PIXELS / 1e6:g} "
                          "megapixels", hint=f"the image header says {w} x {h} px = "
                          f"{w * h / 1e6:.1f} Mpx; crop or downsample the scan")


def _to_0_255(path, mode: str, a: np.ndarray) -> tuple[np.ndarray, str]:
    """Apply the pixel-scale rule of the module docstring to a single-channel array."""
    if a.size == 0:
        raise ParameterError("scan", str(path), VALID, hint="empty image")
    top = float(a.max())
    if mode.startswith("I;16"):
        if top <= 255:
            log.info("%s: 16-bit image with values <= 255: read as 8-bit values", path)
            return a.astype(float), "16-bit integer holding 0-255: read as is"
        return a.astype(float) * (255.0 / 65535.0), "16-bit integer: scaled by 255/65535"
    if mode == "I":
        lo = float(a.min())
        if lo >= 0 and top <= 255:
            return a.astype(float), "32-bit integer holding 0-255: read as is"
        if lo >= 0 and top <= 65535:
            log.info("%s: 32-bit integer image with values up to %g: scaled from 0-65535",
                     path, top)
            return a.astype(float) * (255.0 / 65535.0), "32-bit integer holding 0-65535: scaled by 255/65535"
        raise ParameterError("scan", str(path), "integer pixel values in 0-255 or 0-65535",
                             hint=f"values span {lo:g}-{top:g}")
    if mode == "F":
        a = a.astype(float)
        if not np.all(np.isfinite(a)):
            raise ParameterError("scan", str(path), "finite float pixel values",
                                 hint="the image holds NaN or infinity")
        lo = float(a.min())
        if lo >= 0 and top <= 1:
            return a * 255.0, "float in [0, 1]: scaled by 255"
        if lo >= 0 and top <= 255:
            return a, "float in [0, 255]: read as is"
        raise ParameterError("scan", str(path), "float pixel values in [0, 1] or [0, 255]",
                             hint=f"values span {lo:g}-{top:g}")
    return a.astype(float), "8-bit: read as is"


def read_scan(path) -> tuple[np.ndarray, str]:
    """Read a PNG/TIFF (any Pillow mode) as (float (H, W) array on 0-255, scale note)."""
    from PIL import Image, UnidentifiedImageError

    path = Path(path)
    try:
        with warnings.catch_warnings():
            # Pillow warns above its own limit; ours is lower and checked below
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as im:
                w, h = im.size
                if w * h > MAX_PIXELS:
                    raise _too_big(path, w, h)
                im.load()
                if getattr(im, "n_frames", 1) > 1:
                    log.warning("%s has %d frames; using the first", path, im.n_frames)
                mode = im.mode
                _check_opaque(path, im)
                if mode in ("L", "F", "I") or mode.startswith("I;16"):
                    arr, note = _to_0_255(path, mode, np.asarray(im))
                elif mode in ("LA", "La"):
                    arr, note = _to_0_255(path, "L", np.asarray(im.getchannel(0)))
                else:                                # 1, P, RGB, RGBA, CMYK, YCbCr, ...
                    arr = luminance(np.asarray(im.convert("RGB"), float))
                    note = f"{mode} converted to RGB, then {LUMINANCE_NOTE}"
    except FileNotFoundError:
        raise ParameterError("scan", str(path), VALID, hint="file not found") from None
    except Image.DecompressionBombError as e:
        raise ParameterError("scan", str(path), f"an image of at most {MAX_PIXELS / 1e6:g} "
                             "megapixels", hint=f"too large: {e}") from None
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError, EOFError) as e:
        if isinstance(e, ParameterError):
            raise
        raise ParameterError("scan", str(path), VALID, hint=f"unreadable: {e}") from None
    except MemoryError:
        raise ParameterError("scan", str(path), VALID, hint="not enough memory to decode it") from None
    if arr.ndim != 2 or arr.size == 0:
        raise ParameterError("scan", str(path), VALID, hint=f"image shape {arr.shape}")
    if not np.all(np.isfinite(arr)) or arr.min() < 0 or arr.max() > 255:
        raise ParameterError("scan", str(path), VALID,
                             hint=f"values must be finite on 0-255, got [{arr.min()}, {arr.max()}]")
    return arr, note


def _check_opaque(path, im) -> None:
    """Refuse an image with transparent pixels (their colour is not the film's)."""
    if im.mode in ("RGBA", "LA", "La", "RGBa", "PA") or (im.mode == "P" and "transparency" in im.info):
        alpha = np.asarray(im.convert("RGBA").getchannel("A") if im.mode in ("P", "PA")
                           else im.getchannel("A"))
        clear = float(np.mean(alpha < 255))
        if clear > 0:
            raise ParameterError("scan", str(path), "an opaque image (no transparent pixels)",
                                 hint=f"{100 * clear:.3g} % of its pixels are (partly) transparent, whose colour is "
                                      "not the film's (often black: the highest pressure); flatten the image "
                                      "onto white or crop to the film")


SCREEN_DPI = (72.0, 96.0)  # written by default, not measured: no scale


def file_px_per_mm(path) -> float | None:
    """Pixels per mm recorded in an image file's header (PNG pHYs, TIFF resolution), or None
    when it records none, no absolute unit (TIFF ResolutionUnit 1; a TIFF without
    XResolution, which Pillow reports as 1 x 1) or a screen default (SCREEN_DPI). A TIFF
    XResolution without a ResolutionUnit tag is in inches (the TIFF 6.0 default)."""
    from PIL import Image, UnidentifiedImageError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as im:
                info = dict(im.info)
                tags = getattr(im, "tag_v2", None)
                # TIFF 6.0: ResolutionUnit defaults to 2 (inch), so an XResolution without a
                # unit tag is dots per inch; without XResolution Pillow reports its 1 x 1
                tiff_inch = tags is not None and 282 in tags and 296 not in tags
    except (OSError, UnidentifiedImageError, ValueError, SyntaxError, EOFError):
        return None
    dpi = info.get("dpi")
    # Pillow sets "resolution" too when the unit is 1 (none) or absent (inch by the spec)
    if not dpi or ("resolution" in info and not tiff_inch):
        return None
    try:
        x = float(dpi[0])
    except (TypeError, ValueError, IndexError):
        return None
    # 72 and 96 dpi are the screen defaults editors and screenshot tools stamp on any image;
    # read as a scale they flagged every such file and advised a wrong --px-per-mm
    # (PNG's pHYs keeps whole pixels per metre: 72 dpi reads back as 72.009)
    return x / 25.4 if x > 1.0 and all(abs(x - s) > 0.05 for s in SCREEN_DPI) else None


def load_grayscale(path) -> np.ndarray:
    """Read a PNG/TIFF as a float (H, W) array on the 0-255 scale (see ``read_scan``)."""
    return read_scan(path)[0]
