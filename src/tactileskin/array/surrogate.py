"""Braille characters' sensor maps by superposing single-dot responses.

In the linear limit the map of a character is the sum of the single-dot response
P1(s - s_k, z - z_k) over its raised dots k. On the flat pad (skins.pad) the translation is
exact in x and z away from the pad's edges (s = x). On the fingertip the slab is uniform
along z; across the finger the dot at face coordinate x_k is placed at the bone arc length
s_k of the bone point on the skin's inward normal under x_k (the surface is curved, so the
translation in s is approximate: an off-centre dot meets a skin that has dropped away).
What remains is the contact nonlinearity and, under depth control, the dots' interaction
(a neighbour's load lowers the skin under a dot, or on a thin layer heaves it up):
`interaction_weights` gives each dot its load from the lone dot's surface deflection and
its load-approach law (`load_exponent`, from a second lone-dot solve at SHALLOW x the
depth); `validate` measures the models against full solves, and `fit_scale` is the
one-number correction fitted on them.

Past the dot height the Braille plate presses the skin too, and a lone dot's map holds the
plate's load: summed per dot it would count the plate once per dot. The plate-aware model
splits it: kernel = (lone dot with its plate) - (blank plate alone, at the plate's own depth,
depth - dot height), and a character = blank plate + sum of kernels (`plate_kernel`, the
`base` of `superpose`).
"""

from __future__ import annotations

import numpy as np

from tactileskin.array.maps import cropped, interpolator, mirrored, relative_error, resampled, taxel_averaged
from tactileskin.errors import ParameterError
from tactileskin.geometry import braille
from tactileskin.results import BoneMap

FULL_CELL = 0x3F        # all six dots (U+283F)
TOLERANCE = 0.05        # the bound: max |surrogate - full| <= 5 % of the full map's peak


def bone_s_under(x, section) -> np.ndarray:
    """Bone arc length s of the interface point on the inward normal through the skin's outer
    point at lateral position x (signed like x)."""
    x = np.asarray(x, float)
    ft = getattr(section, "fingertip", None)
    if ft is None:  # a flat skin: s is x
        return x.copy()
    u = np.arcsin(np.clip(np.abs(x) / ft.half_width, 0.0, 1.0))
    s = section.s_of_point(section.interface(u))
    return np.sign(x) * s.reshape(x.shape)


def cell_centres(mask: int, standard="standard_american") -> np.ndarray:
    """(k, 2) face coordinates (x, z) of the raised dots of cell `mask`, in the frame of the
    full cell centred on the origin (as a reader's finger sits on a cell, whatever its dots;
    braille.dot_centres instead centres each pattern on its own dots)."""
    return cells_centres([mask], standard)


def cells_centres(masks, standard="standard_american") -> np.ndarray:
    """(k, 2) face coordinates of the raised dots of a row of cells, in the frame of as many
    full cells centred on the origin."""
    masks = list(masks)
    for mask in masks:
        if not (isinstance(mask, (int, np.integer)) and 0 <= mask <= FULL_CELL):
            raise ParameterError("cell mask", mask, "an integer in [0, 63]")
    if not masks or not any(masks):
        raise ParameterError("cell masks", masks, "at least one raised dot")
    full = braille.dot_centres(chr(0x2800 + FULL_CELL) * len(masks), standard)  # cell by cell, dots 1..6
    return full[[6 * i + k for i, mask in enumerate(masks) for k in range(6) if mask >> k & 1]]


def char_centres(ch: str, standard="standard_american") -> np.ndarray:
    """The raised dots of a chart character in the frame of its full cells: a letter a-z one
    cell; a digit 0-9 two, the number sign and the digit's cell (a-j's), as the standard
    writes a digit standing alone."""
    if not (isinstance(ch, str) and len(ch) == 1 and (ch in braille.LETTERS or ch in braille.DIGITS)):
        raise ParameterError("character", ch, "one letter a-z or digit 0-9")
    return cells_centres(braille.check_text(ch)[0], standard)


def superpose(kernel: BoneMap, centres, section, s=None, z=None, weights=None, base: BoneMap | None = None) -> BoneMap:
    """Map of the dots at face coordinates `centres` (k, 2) = (x, z): sum of the single-dot
    response `kernel` (a full map centred on the dot, see maps.mirrored) translated to each
    (s_k, z_k), times `weights` (k,) (default 1: each dot as a lone dot), plus `base` (a full
    map not translated: the blank plate's, see plate_kernel). Evaluated on the grid s x z
    (default: the kernel's grid)."""
    centres = np.atleast_2d(np.asarray(centres, float))
    if centres.shape[1] != 2 or centres.shape[0] < 1:
        raise ParameterError("dot centres", centres.shape, "(k, 2) face coordinates (x, z)")
    s = kernel.s if s is None else np.asarray(s, float)
    z = kernel.z if z is None else np.asarray(z, float)
    f = interpolator(kernel)
    S, Z = np.meshgrid(s, z)
    sk = bone_s_under(centres[:, 0], section)
    w = np.ones(len(centres)) if weights is None else np.asarray(weights, float)
    P = sum(wk * f(S - a, Z - b) for wk, a, b in zip(w, sk, centres[:, 1]))
    if base is not None:
        P = P + resampled(base, s, z)
    return BoneMap(s, z, P, kernel.section_z)


def plate_kernel(dot: BoneMap, blank: BoneMap) -> BoneMap:
    """The plate-aware kernel: the lone dot's map with its plate (`dot`, full) minus the blank
    plate's (`blank`, full; interpolated on the dot's grid), i.e. what one dot adds to the plate."""
    return BoneMap(dot.s, dot.z, dot.pressure - resampled(blank, dot.s, dot.z), dot.section_z)


# the second lone-dot solve of the interaction model is indented to this fraction of the depth
# (load_exponent: the lone dot's load over the +-10 % approach changes its neighbours make)
SHALLOW = 0.9


def interaction_weights(centres, deflection, exponent: float = 1.0) -> np.ndarray:
    """Loads of the dots of one character, in units of a lone dot's, under depth control: a
    dot carrying load f_j deflects the surface by f_j w(dx, dz) (w: the lone dot's surface
    deflection, downward positive; on a thin bonded layer the surface heaves up around a dot,
    w < 0), so dot k meets a surface already moved by sum_(j != k) f_j W_kj, W_kj = w(c_k - c_j),
    and indents it by a_k = w0 - sum_(j != k) W_kj f_j, w0 = w(0, 0) the lone dot's own.
    Its load follows the lone dot's load-approach law f = (a / w0)^exponent (`load_exponent`;
    exponent 1, the linear limit: sum_j W_kj f_j = w0). A dot whose approach vanishes carries
    nothing. `deflection(dx, dz)` takes arrays."""
    c = np.atleast_2d(np.asarray(centres, float))
    d = c[:, None, :] - c[None, :, :]
    W = np.asarray(deflection(d[..., 0], d[..., 1]), float)
    w0 = float(np.mean(np.diag(W)))
    if not (np.all(np.isfinite(W)) and w0 > 0):
        raise ParameterError("deflection", f"w(0, 0) = {w0:g}", "a finite surface deflection, > 0 under the dot")
    if not (np.isfinite(exponent) and 0.5 <= exponent <= 5.0):
        raise ParameterError("load exponent", exponent, "[0.5, 5] (a lone dot's load ~ approach^exponent)")
    if exponent == 1.0:
        try:
            return np.linalg.solve(W, np.full(len(c), w0))
        except np.linalg.LinAlgError:
            raise ParameterError("deflection", "singular dot-to-dot matrix", "distinct dot centres") from None
    off = W / w0
    np.fill_diagonal(off, 0.0)

    def residual(f):
        a = np.maximum(1.0 - off @ f, 0.0)
        return f - a ** exponent, a

    # damped Newton on r(f) = f - max(1 - off f, 0)^p over f >= 0, from the lone dots' loads
    f = np.ones(len(c))
    r, a = residual(f)
    for _ in range(100):
        norm = float(np.max(np.abs(r)))
        if norm <= 1e-13:
            return f
        slope = np.where(a > 0, exponent * np.where(a > 0, a, 1.0) ** (exponent - 1.0), 0.0)
        try:
            step = np.linalg.solve(np.eye(len(c)) + slope[:, None] * off, r)
        except np.linalg.LinAlgError:
            break
        lam = 1.0
        while True:
            fn = np.maximum(f - lam * step, 0.0)
            rn, an = residual(fn)
            if np.max(np.abs(rn)) < norm or lam < 1e-6:
                break
            lam *= 0.5
        f, r, a = fn, rn, an
    raise ParameterError("interaction weights", np.round(f, 3).tolist(), "a converged load of every dot")


def load_exponent(load: float, load_shallow: float, fraction: float = SHALLOW) -> float:
    """p of the lone dot's load ~ approach^p from its loads at the full depth and at `fraction`
    of it (a power law through the two: Hertz 1.5, a flat punch 1)."""
    ok = np.isfinite(load) and np.isfinite(load_shallow) and 0 < load_shallow < load
    p = float(np.log(load / load_shallow) / -np.log(fraction)) if ok else float("nan")
    if not (np.isfinite(p) and 0.5 <= p <= 5.0):
        raise ParameterError("lone-dot loads", (load, load_shallow),
                             f"0 < load at {fraction:g} x depth < load at depth, a power law p in [0.5, 5]")
    return p


def kernel_from(bone_map: BoneMap) -> BoneMap:
    """The full single-dot response from a (possibly quarter) solved map."""
    return mirrored(bone_map)


def validate(kernel: BoneMap, full: BoneMap, text: str, section, standard="standard_american",
             deflection=None, scale: float = 1.0, base: BoneMap | None = None, taxel: float | None = None,
             extent: float | None = None, exponent: float = 1.0) -> dict:
    """Errors of the superposition against the full solve of `text` (its map `full`, possibly a
    quarter: mirrored here), dots placed as the solver placed them (braille.dot_centres);
    with `deflection` the dots' loads from `interaction_weights` (with `exponent`); the dots' sum times
    `scale`, plus `base` (the blank plate's map of the plate-aware model). With `taxel` (mm)
    also the errors of both maps as read by taxels of that side (keys *_taxel): what the
    finest array of a chart sees, blind to sub-taxel ripple. With `extent` (mm) the errors
    count only the square |s|, |z| <= extent of the chart's frame (`cells_centres`: where
    a chart's arrays read the character, ChartConfig.read_extent), not the skin's far edges."""
    ref = mirrored(full)
    c = braille.dot_centres(text, standard)
    w = None if deflection is None else interaction_weights(c, deflection, exponent)
    approx = superpose(kernel, c, section, ref.s, ref.z, weights=w)
    P = scale * approx.pressure
    if base is not None:
        P = P + resampled(base, ref.s, ref.z)
    approx = BoneMap(approx.s, approx.z, P, approx.section_z)   # on ref's grid
    ds, dz = chart_shift(text, section, standard) if extent is not None else (0.0, 0.0)

    def read(m):  # the part of a map (on ref's grid) the chart reads
        if extent is None:
            return m
        return cropped(m, (-extent - ds, extent - ds), (-extent - dz, extent - dz))

    err = relative_error(read(approx), read(ref))
    err["within_tolerance"] = err["max_abs_over_peak"] <= TOLERANCE
    if taxel:
        et = relative_error(read(taxel_averaged(approx, taxel)), read(taxel_averaged(ref, taxel)))
        err.update({f"{k}_taxel": v for k, v in et.items()})
        err["within_tolerance_taxel"] = et["max_abs_over_peak"] <= TOLERANCE
    if extent is not None:
        err["extent_mm"] = float(extent)
    return err


def fit_scale(kernel: BoneMap, fulls: dict, section, standard="standard_american",
              base: BoneMap | None = None) -> float:
    """The one factor a minimising sum ||a S + B - P||^2 over the full solves `fulls`
    ({text: map}) of the plain superpositions S (B: `base`, the blank plate's map, or 0): the
    cheapest correction of the sum."""
    num = den = 0.0
    for text, full in fulls.items():
        ref = mirrored(full)
        approx = superpose(kernel, braille.dot_centres(text, standard), section, ref.s, ref.z)
        b = 0.0 if base is None else resampled(base, ref.s, ref.z)
        num += float(np.sum(approx.pressure * (ref.pressure - b)))
        den += float(np.sum(approx.pressure ** 2))
    if not den > 0:
        raise ParameterError("surrogate", "zero superposition", "a kernel with a positive response")
    return num / den


def placed(full: BoneMap, text: str, section, standard="standard_american") -> BoneMap:
    """The full solve's map of a one-line `text` (braille.dot_centres: the pattern centred on
    its own dots; a half or quarter map is mirrored) moved to the full-cell frame of
    `cells_centres`, where the chart reads every character: a translation (s through
    `bone_s_under`: exact on the flat pad, approximate across the curved fingertip)."""
    ds, dz = chart_shift(text, section, standard)
    ref = mirrored(full)
    return BoneMap(ref.s + ds, ref.z + dz, ref.pressure, ref.section_z)


def chart_shift(text: str, section, standard="standard_american") -> tuple[float, float]:
    """(ds, dz) (mm) that move a one-cell `text` from the solver's frame (braille.dot_centres:
    the pattern centred on its own dots) to the chart's (`cells_centres`): s through
    `bone_s_under`."""
    cells = braille.check_text(text)
    if len(cells) != 1 or not cells[0]:
        raise ParameterError("text", text, "one line of Braille cells")
    solver = braille.dot_centres(text, standard)
    cell = cells_centres(cells[0], standard)
    a, b = cell.mean(axis=0), solver.mean(axis=0)  # the same pattern, translated
    ds = float(np.diff(bone_s_under(np.array([b[0], a[0]]), section))[0])
    return ds, float(a[1] - b[1])
