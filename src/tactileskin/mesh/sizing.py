"""Element-size plan: global and refined sizes, the contact zone, the count estimate.

Pure numpy (no gmsh): the plan is checked before gmsh is called, so an absurd request is a
ParameterError, not a hang. `apply_fields` turns a plan into gmsh size fields.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import math
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError, check_range

logger = logging.getLogger(__name__)

ROI_S = 6.0  # mm: the paper reports bone pressure within 6 mm of s = 0; refine the interface there
# Limits on the estimated displacement dofs of a request (the solver's memory and time grow
# with them; the mesh exists to be solved). A 2D cap of 2e6 cells (~8e6 P2 dofs) let
# through requests that crashed in scikit-fem after minutes and 4.5 GB, and a 3D request
# under a 5e6-cell cap meshed for over 5 minutes. 3D P2 element matrices are 30 x 30 (2D:
# 12 x 12) and the sparse factorisation fills in faster than in 2D: the default 3D slab
# (~74k dofs) solves in about 2 min, so 3D is capped at ~5x that. The estimate is 1-2x the
# actual count, so these caps refuse no mesh below about half of them.
MAX_DOFS = {2: 1_500_000, 3: 400_000}
# above this a request is allowed but logged as a warning: it takes many minutes (the 3D
# defaults estimate 0.04-0.2e6 dofs at t = 0.5-5 mm; a 6-character Braille text 0.32e6)
WARN_DOFS = {2: 300_000, 3: 250_000}
# mesh nodes per cell for large meshes (Euler: a triangle mesh has V ~ T/2, E ~ 3T/2; a
# tetrahedral one V ~ T/5.5, E ~ 1.2 T); P2 adds a node per edge
_NODES_PER_CELL = {(2, 1): 0.5, (2, 2): 2.0, (3, 1): 0.18, (3, 2): 1.38}


def estimate_dofs(cells: int, dim: int, order: int = 2) -> int:
    """Displacement dofs of a mesh of `cells` triangles/tetrahedra of this order."""
    return int(dim * _NODES_PER_CELL[(dim, order)] * cells)

# Grading (issue #7, benchmarks/results/mesh_grading.md): the size is `fine` within
# OUTER_LAYER fine cells of the contact surface and ROI_LAYER of the bone ROI, and grows by
# GROWTH mm per mm of distance (each cell ~GROWTH larger than its neighbour) up to coarse.
# The peak (at s = 0) is most sensitive to the ROI layer: t1 silicone flat, peak change
# from the former box mesh -0.37 / -0.28 / -0.11 / -0.03 % with 1 / 2 / 3 / 4 cells
# (GROWTH 0.1 with 1 cell: -0.11 %; OUTER_LAYER 6: -0.20 %).
GROWTH = 0.2
OUTER_LAYER = 2.0
ROI_LAYER = 3.0
# cells per (size^dim) of area/volume for gmsh's Frontal-Delaunay / HXT meshes (a uniform
# 2D mesh has ~2.5, an equilateral tiling 2.31); with the strip integrals below and sizes
# clipped at the skin thickness (a cell cannot be thicker than the skin) the estimate is
# 1-2x the actual count (tests/test_mesh2d.py, tests/test_mesh3d.py; in 3D with
# mesh_size > thickness it can be ~20 % low: gmsh then fills the thin slab more densely).
_CELLS_PER_UNIT = {2: 2.6, 3: 5.0}


@dataclass(frozen=True)
class SizePlan:
    coarse: float                      # global element size (mm)
    fine: float                        # refined size on the contact surface and along the ROI
    growth: float                      # size gradient dh/dd away from the refined curves
    contact_x: float                   # contact zone: outer surface with x <= contact_x (mm) ...
    contact_z: tuple[float, float]     # ... and z in this range (3D)
    outer_layer: float                 # depth below the contact surface kept at the fine size
    roi_s: float                       # interface refined for s <= roi_s (mm)
    roi_layer: float                   # distance from the ROI kept at the fine size
    transition: float                  # (coarse - fine) / growth: distance from fine to coarse
    estimate: int                      # estimated cell count (upper side)
    # 3D Braille (local plan, `local_plan`): balls (x, y, z, radius, size) around each dot's
    # contact point on the outer surface and around the bone point under it; inside a ball the
    # size is `size` within the surface layer, graded by `growth` to `coarse` outside. `fine`
    # and the contact strip / ROI above then hold the base plate's contact strip (size
    # `fine`, equal to `coarse` when the plate does not touch).
    patches: tuple = ()
    bone_patches: tuple = ()
    strip: float = 0.0                 # local plan: size on the plate strip (0: none) ...
    strip_roi: float = 0.0             # ... and on the bone ROI then

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def contact_halfwidth(scene, section) -> float:
    """Half-width (x, mm) of the skin that may touch the indenter at full depth, with margin:
    the indenter kind's answer (`Indenter.contact_halfwidth`; plates and cylinders: the
    Hertz-like estimate 1.5 sqrt(2 R d), R the contour's radius at the top, a^2/b), clipped
    to the skin."""
    from tactileskin.geometry.indenters import indenter_for_scene

    ind = indenter_for_scene(scene, warn=False)
    w = ind.contact_halfwidth(scene.indentation, section.contact_radius(ind))
    return min(w, section.half_width)


def contact_zrange(scene, length: float, z_symmetric: bool) -> tuple[float, float]:
    """z range of the contact zone in the 3D slab (the indenter kind's `contact_zrange`)."""
    from tactileskin.geometry.indenters import indenter_for_scene

    z0, z1 = (0.0, 0.5 * length) if z_symmetric else (-0.5 * length, 0.5 * length)
    zr = indenter_for_scene(scene, warn=False).contact_zrange(scene.indentation)
    if zr is None:
        return z0, z1  # e.g. plate and cylinder along z touch along the whole slab
    return max(z0, zr[0]), min(z1, zr[1])


def _size_at(d, p: "SizePlan", layer: float):
    """Size of a threshold field at distance d from its curve: fine up to `layer`, then
    growing by `p.growth` per mm up to coarse."""
    return np.minimum(p.coarse, p.fine + p.growth * np.maximum(np.asarray(d) - layer, 0.0))


def _strip(p: "SizePlan", layer: float, depth: float, dim: int, cap: bool = False,
           kappa: float = 0.0) -> float:
    """Integral of h^-dim - coarse^-dim over a one-sided strip along a curve, per mm of curve,
    to `depth` into the domain; with cap=True, over the half disc around a free end of the
    curve (whole, not per mm). (1 + d kappa) bounds the widening of a strip on the convex
    side of a curve of curvature <= kappa."""
    d = np.linspace(0.0, depth, 2001)
    h = _size_at(d, p, layer)
    excess = np.maximum(h ** -dim - p.coarse ** -dim, 0.0)
    w = np.pi * d if cap else 1.0 + d * kappa
    return float(np.trapezoid(excess * w, d))


def plan(scene, section, *, mesh_size: float | None = None, refinement: float | None = None,
         dim: int = 2, length: float | None = None, z_symmetric: bool = False,
         order: int | None = None, local: bool = True) -> SizePlan:
    """Sizes for `section`; raises ParameterError if a size is not positive or the estimated
    dofs (cells of `dim`, element `order`, default the scene's) exceed MAX_DOFS[dim].
    local=False: the strip plan for 3D Braille too (the former plan, for comparisons)."""
    coarse = scene.mesh_size if mesh_size is None else mesh_size
    ratio = scene.refinement if refinement is None else refinement
    coarse = check_range("mesh_size", coarse, 0.0, None, lo_open=True, unit="mm")
    ratio = check_range("refinement", ratio, 1.0, None)
    if dim == 3 and length is None:
        raise ParameterError("length", length, "> 0 mm (slab length along z)")
    order = scene.order if order is None else order
    layout = functools.partial(_layout, scene, section, dim=dim, length=length, z_symmetric=z_symmetric,
                               local=local)
    p = layout(coarse, ratio)
    dofs = estimate_dofs(p.estimate, dim, order)
    cap = MAX_DOFS[dim]
    if dofs > cap:
        hc = _smallest_size(lambda h: estimate_dofs(layout(h, ratio).estimate, dim, order) <= cap, coarse)
        hint = (f"keep mesh_size at or above {hc:.3g} mm at refinement {ratio:g}" if hc is not None
                else f"lower the refinement ({ratio:g})")
        raise ParameterError(
            "mesh_size", coarse,
            f"a mesh of at most {cap:.2g} dofs in {dim}D; mesh_size={coarse:g} mm with "
            f"refinement={ratio:g} (refined size {p.fine:.3g} mm) needs about {p.estimate:.2e} P{order} "
            f"cells, {dofs:.2e} dofs", hint=hint)
    if dofs > WARN_DOFS[dim]:
        logger.warning("a large mesh: about %.2g P%d cells (%.2g dofs) in %dD for mesh_size=%g mm, "
                       "refinement=%g; meshing and solving it can take many minutes and GBs",
                       p.estimate, order, dofs, dim, coarse, ratio)
    return p


def _smallest_size(fits, too_small: float, largest: float = 5.0) -> float | None:
    """The smallest mesh_size (to 1 %, rounded up) in (too_small, largest] for which fits(size)
    holds (the estimate falls as the size grows), or None if not even `largest` fits."""
    if not fits(largest):
        return None
    lo, hi = too_small, largest
    while hi / lo > 1.01:
        mid = math.sqrt(lo * hi)
        lo, hi = (lo, mid) if fits(mid) else (mid, hi)
    return float(f"{hi * 1.005:.3g}") if fits(float(f"{hi * 1.005:.3g}")) else hi


def _layout(scene, section, coarse: float, ratio: float, *, dim: int, length: float | None,
            z_symmetric: bool, local: bool = True) -> SizePlan:
    """The plan for sizes (coarse, coarse / ratio), with its estimated cell count."""
    # the local plan places its balls on the fingertip's contour or the pad's flat top; other
    # skins keep the strip plan
    if dim == 3 and local and scene.indenter_kind.local_3d and scene.skin_kind.local_plan:
        from tactileskin.geometry.indenters import indenter_for_scene

        spots = indenter_for_scene(scene, warn=False).contact_patches(scene.indentation)
        if spots is not None:
            p = local_plan(scene, section, coarse, ratio, length=length, z_symmetric=z_symmetric,
                           spots=spots)
            if p.patches or p.bone_patches or p.strip:  # else no spot reaches the meshed part
                return p
    fine = coarse / ratio
    t = section.thickness
    w = contact_halfwidth(scene, section)
    roi = min(ROI_S, section.interface_length)
    trans = (coarse - fine) / GROWTH
    p = SizePlan(coarse, fine, GROWTH, w, (0.0, 0.0), OUTER_LAYER * fine, roi, ROI_LAYER * fine,
                 trans, 0)

    # estimate: the coarse background plus, for each refined curve, the excess of h^-dim in
    # a one-sided strip as deep as the skin; the contact strip runs to the end of the box
    # transition, the ROI strip widens on the bone's convex side and spreads around its end.
    l_out = section.outer_length_to_x(w + trans)
    kappa = 1.0 / max(section.min_radius_of_curvature - t, 0.1 * t)
    lz = 1.0
    if dim == 3:
        lz = 0.5 * length if z_symmetric else length
        zr = contact_zrange(scene, length, z_symmetric)
        p = dataclasses.replace(p, contact_z=zr)
        lc = min(lz, zr[1] - zr[0] + (trans if zr[0] == 0.0 else 2.0 * trans))
    else:
        lc = 1.0
    pe = dataclasses.replace(p, coarse=min(coarse, t), fine=min(fine, t))
    excess = (l_out * lc * _strip(pe, p.outer_layer, t, dim)
              + lz * (roi * _strip(pe, p.roi_layer, t, dim, kappa=kappa)
                      + (_strip(pe, p.roi_layer, t, dim, cap=True) if roi < section.interface_length else 0.0)))
    n = int(_CELLS_PER_UNIT[dim] * (_area(section) * lz / pe.coarse ** dim + excess))
    return dataclasses.replace(p, estimate=n)


# 3D Braille, local plan (issue 13, benchmarks/results/convergence3d.md): refining the whole
# contact strip and bone ROI at mesh_size / refinement spent most dofs on skin far from the
# dots while the pressure fall-off under each dot stayed under-resolved. The local plan puts
# the refined size only in balls around each dot's contact point (radius PATCH_RADIUS dot
# base radii: the contact radius is at most the base radius) and around the bone point under
# it (radius base radius + thickness: the bone imprint spreads over ~t; the measured spans are
# 0.9 mm at t = 1, 2.2 mm at t = 3), graded by GROWTH_3D to the coarse size. On the bone the
# size is scaled by max(1, t / base diameter), at most BONE_SCALE_MAX: the bone field's length
# scale is the larger of the dot and the skin thickness, but at t = 5 mm the unbounded scale
# (3.47) left the full cell's bone map 7.5 % off on 1.6 / 8 (BONE_SCALE_MAX 2.3: 3.1 %;
# benchmarks/results/convergence3d.md). t <= 3.3 mm is not affected.
GROWTH_3D = 0.35
PATCH_RADIUS = 1.25
BONE_SCALE_MAX = 2.3


# Contact spot under a thick skin (issue 13, T3): the bone map cannot see the contact patch's
# detail through t >= 5 mm, and the spot's fine cells cost Newton iterations (the contact set
# cycles over them). From THICK_SPOT_T, a dot-sized spot (patch_scale 1) meshed at a fine size
# of at least THICK_SPOT_H gets THICK_SPOT_FACTOR times that size (at most half the far size).
# Measured at t = 5 mm, 1.6 / 8 (the `default` there) against 0.8 / 8: dot map 4.52 -> 4.07 %,
# cell map 3.18 -> 3.75 %, peaks within +0.4 to +0.9 %, the dot's CPU -31 %, the cell's -43 to
# -48 % (benchmarks/results/spot_scale_t5.md, spot_scale_t5_cell.md; stored in presets.json
# "cases3d" as levels with "spot_factor" 3). The size bound keeps finer levels (the study's
# 1.2 / 8 and its reference 0.8 / 8, the `fine` preset) on the plan they were measured with, so
# the factor vanishes as the mesh is refined; thinner skins were measured at 1 only. A scene
# with sensors inside the skin (above the bonded surface) keeps 1: near the contact they see
# the detail the bone does not (t = 5 dot, `default`, a line 0.4 mm deep: the reading under
# the dot +34 % at 3x).
THICK_SPOT_T = 5.0
THICK_SPOT_H = 0.2
THICK_SPOT_FACTOR = 3.0
# Overrides for benchmarks/spot_scale_t5.py: SPOT_FACTOR (None: the rule above) replaces every
# spot's factor; STRIP_FACTOR scales the plate strip's size (the bone balls and ROI keep theirs).
SPOT_FACTOR: float | None = None
STRIP_FACTOR = 1.0


def spot_factor(thickness: float, a: float, h: float, sensors_inside: bool = False) -> float:
    """Contact-spot size / the spot's fine size `h` (mm) of the local plan for a spot of radius
    bound `a` (mm) under a skin `thickness` mm thick; `sensors_inside`: the scene reads the
    skin above its bonded surface (sensors_inside)."""
    if SPOT_FACTOR is not None:
        return float(SPOT_FACTOR)
    if thickness >= THICK_SPOT_T - 1e-9 and patch_scale(a) == 1.0 and h >= THICK_SPOT_H - 1e-9 \
            and not sensors_inside:
        return THICK_SPOT_FACTOR
    return 1.0


def sensors_inside(scene) -> bool:
    """Whether a sensor layout of the scene lies above the skin's bonded surface."""
    t = float(scene.thickness)
    return any((t - lay.height if lay.depth is None else lay.depth) < t - 1e-9
               for lay in getattr(scene, "sensors", ()) or ())


def bone_scale(thickness: float, base_radius: float) -> float:
    """Bone patch size / dot patch size of the local plan at a skin thickness."""
    return min(max(1.0, thickness / (2.0 * max(base_radius, 1e-9))), BONE_SCALE_MAX)


def _dot_frame(section, x: float) -> tuple[np.ndarray, np.ndarray]:
    """(outer point, outward normal) in the (x, y) section plane of the skin point a dot at face
    coordinate x meets first: on the fingertip the outer curve at |x|, on the flat pad
    (no `fingertip`) the top y = t straight above x."""
    ft = getattr(section, "fingertip", None)
    if ft is None:
        return np.array([float(x), float(section.top)]), np.array([0.0, 1.0])
    u = math.asin(min(abs(x) / ft.half_width, 1.0)) * (1.0 if x >= 0 else -1.0)
    return np.asarray(ft.outer(u), float), np.asarray(ft.outer_normal(u), float)


def _plate_halfwidth(section, depth_past_dots: float) -> float:
    """Half-width of the base plate's contact when it presses `depth_past_dots` (> 0) into the
    skin: the fingertip's Hertz-like estimate on its top radius; the pad's whole flat top (the
    plate is at least as wide as the pad, indenters.toml min_width)."""
    ft = getattr(section, "fingertip", None)
    if ft is None:
        return float(section.half_width)
    r_top = ft.half_width ** 2 / ft.height
    return min(1.5 * math.sqrt(2.0 * r_top * depth_past_dots), ft.half_width)


def patch_scale(a: float) -> float:
    """Element size at a contact spot of radius bound a / the preset's fine size: 1 up to the
    spot the local presets were chosen on (the standard American dot's base radius), growing
    as the square root of the radius beyond (at most half the far size, local_plan). Measured
    on the t = 3 mm R 2.5 sphere (a = 1.62 mm) at 1.6 / 8: sizes in proportion to a (2.25x)
    read its bone map 7.1 % off the finest level, the square root (1.5x) 2.3 % at half the
    dofs of no growth (1.6 %); a flat file face (a = 14 mm) stays affordable."""
    from tactileskin.geometry import braille

    return math.sqrt(max(1.0, a / braille.get_standard("standard_american").base_radius))


def spot_fine(coarse: float, fine: float, a: float) -> float:
    """The fine size (mm) at a contact spot of radius bound `a` of a local plan with these far
    and fine sizes: a spot much wider than a dot (a flat file face) still gets ratio 2."""
    return max(fine, min(0.5 * coarse, fine * patch_scale(a)))


def local_plan(scene, section, coarse: float, ratio: float, *, length: float, z_symmetric: bool,
               spots=None) -> SizePlan:
    """Local size plan of a 3D slab (fingertip) or block (pad) pressed in compact spots (the
    indenter's `contact_patches`: Braille dots, a ball, a file's low pieces): fine = coarse /
    ratio (times `patch_scale` for spots wider than a dot) at each spot's contact patch and
    (scaled with t) on the bone under it (the pad's bonded bottom y = 0); if a plate of the
    indenter presses too (`plate_depth`: Braille past the dot height) it touches along the
    whole slab, and that strip and the bone ROI get the geometric mean of the fine and coarse
    sizes (`strip`)."""
    from tactileskin.geometry.indenters import indenter_for_scene, indenter_symmetry

    ind = indenter_for_scene(scene, warn=False)
    spots = ind.contact_patches(scene.indentation) if spots is None else spots
    fine = coarse / ratio
    t = section.thickness
    g = GROWTH_3D
    z0, z1 = (0.0, 0.5 * length) if z_symmetric else (-0.5 * length, 0.5 * length)
    lz = z1 - z0
    # the meshed x range starts at the symmetry plane x = 0, or at -W/2 on a full-width pad
    # (mesh.pad: an x-asymmetric text)
    full = getattr(section, "fingertip", None) is None and not indenter_symmetry(scene)[0]
    x0 = -section.half_width if full else 0.0
    box = (x0, float(section.half_width), z0, z1)
    patches, bones = [], []
    inside = sensors_inside(scene)
    for x, z, a in spots:
        h = spot_fine(coarse, fine, a)
        hb = min(coarse, h * bone_scale(t, a))
        hs = max(h, min(0.5 * coarse, h * spot_factor(t, a, h, inside)))
        po, n = _dot_frame(section, x)
        pb = po - t * n
        for balls, c, r, size in ((patches, po, PATCH_RADIUS * a, hs), (bones, pb, a + t, hb)):
            if c[0] < x0 - r or z < z0 - r or z > z1 + r:
                continue  # the ball misses the meshed part (x >= x0, z0 <= z <= z1)
            balls.append((float(c[0]), float(c[1]), float(z), float(r), float(size)))
    excess = sum(_balls_excess([(b[0], b[2], b[3], min(b[4], t)) for b in balls], min(coarse, t), layer, t, g, box)
                 for balls, layer in ((patches, OUTER_LAYER), (bones, ROI_LAYER)))
    strip = 0.0
    w = 0.0
    plate = ind.plate_depth(scene.indentation)
    strip_roi = 0.0
    if plate > 0.0:
        strip_roi = math.sqrt(fine * coarse)
        strip = min(coarse, strip_roi * STRIP_FACTOR)
        w = _plate_halfwidth(section, plate)
    s_fine = strip if strip else coarse
    r_fine = strip_roi if strip_roi else coarse
    roi = min(ROI_S, section.interface_length)
    p = SizePlan(coarse, fine, g, w, (z0, z1), OUTER_LAYER * s_fine, roi, ROI_LAYER * r_fine,
                 (coarse - s_fine) / g, 0, tuple(patches), tuple(bones), strip, strip_roi)
    sides = 2.0 if full else 1.0
    if strip:
        pe = dataclasses.replace(p, coarse=min(coarse, t), fine=min(strip, t))
        pr = dataclasses.replace(p, coarse=min(coarse, t), fine=min(strip_roi, t))
        kappa = 1.0 / max(section.min_radius_of_curvature - t, 0.1 * t)
        excess += sides * lz * (section.outer_length_to_x(w + p.transition) * _strip(pe, p.outer_layer, t, 3)
                                + roi * _strip(pr, p.roi_layer, t, 3, kappa=kappa)
                                + (_strip(pr, p.roi_layer, t, 3, cap=True) if roi < section.interface_length else 0.0))
    n = int(_CELLS_PER_UNIT[3] * (sides * _area(section) * lz / min(coarse, t) ** 3 + excess))
    return dataclasses.replace(p, estimate=n)


def _balls_excess(balls, coarse: float, layer_factor: float, depth: float, g: float,
                  box: tuple[float, float, float, float]) -> float:
    """Integral of size^-3 - coarse^-3 over the refined layer of balls (x, z, r, h) at lateral
    centres (x, z), inside box = (x_lo, x_hi, z_lo, z_hi): size = the larger of the surface
    threshold (h0 = the smallest h within layer_factor h0 of the surface, growing by g per mm of
    depth) and the balls' (the smallest over the balls of h within lateral distance r of the
    centre, growing by g beyond), to `depth`. Overlapping balls count once (summing them read a
    t = 5 mm full cell's bone patches 3x over; a ring's overlapping spots 4x)."""
    if not balls:
        return 0.0
    b = np.asarray(balls, float)
    c, r, h = b[:, :2], b[:, 2], np.minimum(b[:, 3], coarse)
    h0 = float(h.min())
    layer = layer_factor * h0
    ext = float(np.max(r + np.maximum(coarse - h, 0.0) / g))
    d = np.linspace(0.0, depth, 301)
    hd = np.minimum(coarse, h0 + g * np.maximum(d - layer, 0.0))
    h_tab = np.linspace(h0, coarse, 201)
    size = np.maximum(h_tab[:, None], hd[None, :])
    per_area = np.trapezoid(np.maximum(size ** -3.0 - coarse ** -3.0, 0.0), d, axis=1)
    xa, xb = max(box[0], c[:, 0].min() - ext), min(box[1], c[:, 0].max() + ext)
    za, zb = max(box[2], c[:, 1].min() - ext), min(box[3], c[:, 1].max() + ext)
    if xb <= xa or zb <= za:
        return 0.0
    xs, zs = np.linspace(xa, xb, 301), np.linspace(za, zb, 301)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    hr = np.full(X.shape, float(coarse))
    for (cx, cz), ri, hi in zip(c, r, h):  # running minimum: memory O(grid), not O(grid x balls)
        np.minimum(hr, hi + g * np.maximum(np.hypot(X - cx, Z - cz) - ri, 0.0), out=hr)
    return float(np.trapezoid(np.trapezoid(np.interp(hr, h_tab, per_area), zs, axis=1), xs))


def _area(section) -> float:
    a = section.__dict__.get("_sizing_area")
    if a is None:  # Section is frozen; cache the 4000-point shoelace area beside it
        a = section.area()
        object.__setattr__(section, "_sizing_area", a)
    return a


def apply_fields(gmsh, p: SizePlan, outer: list[int], interface_roi: list[int], dim: int,
                 full_width: bool = False) -> None:
    """Install the size fields: Min(contact-surface threshold limited to the contact zone,
    threshold on the distance to the bone ROI); `outer`, `interface_roi`: curve (2D) or
    surface (3D) tags. `full_width`: the model spans x < 0 too (the contact zone is
    |x| <= contact_x, not 0 <= x <= contact_x)."""
    f = gmsh.model.mesh.field
    key = "CurvesList" if dim == 2 else "SurfacesList"
    if p.patches or p.bone_patches:
        return _apply_local(gmsh, p, outer, interface_roi, full_width)

    def threshold(tags, layer, sampling):
        dist = f.add("Distance")
        f.setNumbers(dist, key, tags)
        f.setNumber(dist, "Sampling", sampling)
        thr = f.add("Threshold")
        f.setNumber(thr, "InField", dist)
        f.setNumber(thr, "SizeMin", p.fine)
        f.setNumber(thr, "SizeMax", p.coarse)
        f.setNumber(thr, "DistMin", layer)
        f.setNumber(thr, "DistMax", layer + p.transition)
        return thr

    # samples along a curve at most ~fine/2 apart, so the sampled distance is exact to ~fine/4
    # at the surface (3D: per direction of a surface, capped for time)
    n2d = int(min(4000, max(400, 2.0 * 16.0 / p.fine)))
    sampling = n2d if dim == 2 else int(min(150, max(60, 2.0 * 10.0 / p.fine)))
    near_outer = threshold(outer, p.outer_layer, sampling)
    # the contact zone: Max with a box that is fine inside and coarse beyond a transition
    box = f.add("Box")
    f.setNumber(box, "VIn", p.fine)
    f.setNumber(box, "VOut", p.coarse)
    f.setNumber(box, "XMin", -p.contact_x if full_width else -1.0)
    f.setNumber(box, "XMax", p.contact_x)
    f.setNumber(box, "YMin", -1e3)
    f.setNumber(box, "YMax", 1e3)
    zmin, zmax = p.contact_z if dim == 3 else (-1.0, 1.0)
    f.setNumber(box, "ZMin", zmin - (1.0 if dim == 3 and zmin == 0.0 else 0.0))
    f.setNumber(box, "ZMax", zmax)
    f.setNumber(box, "Thickness", p.transition)
    contact = f.add("Max")
    f.setNumbers(contact, "FieldsList", [near_outer, box])

    near_roi = threshold(interface_roi, p.roi_layer, sampling)
    mn = f.add("Min")
    f.setNumbers(mn, "FieldsList", [contact, near_roi])
    f.setAsBackgroundMesh(mn)
    # the fields alone decide the size
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", p.coarse)
    gmsh.option.setNumber("Mesh.MeshSizeMin", p.fine)


def _options(gmsh, p: SizePlan, smallest: float) -> None:
    # the fields alone decide the size
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", p.coarse)
    gmsh.option.setNumber("Mesh.MeshSizeMin", smallest)


def _apply_local(gmsh, p: SizePlan, outer: list[int], interface_roi: list[int], full_width: bool = False) -> None:
    """Fields of a local plan: per ball, Max(surface threshold, ball) (fine only near the
    surface and inside the ball, graded outside both); Min over the balls and, if the plate
    touches, the strip's box and the bone ROI at size `strip`."""
    f = gmsh.model.mesh.field
    smallest = min([b[4] for b in p.patches + p.bone_patches] + [p.strip or p.coarse, p.strip_roi or p.coarse])
    sampling = int(min(200, max(60, 2.0 * 10.0 / smallest)))
    dists = {}

    def distance(tags):
        key = tuple(tags)
        if key not in dists:
            dist = f.add("Distance")
            f.setNumbers(dist, "SurfacesList", list(tags))
            f.setNumber(dist, "Sampling", sampling)
            dists[key] = dist
        return dists[key]

    def threshold(tags, size, layer):
        thr = f.add("Threshold")
        f.setNumber(thr, "InField", distance(tags))
        f.setNumber(thr, "SizeMin", size)
        f.setNumber(thr, "SizeMax", p.coarse)
        f.setNumber(thr, "DistMin", layer)
        f.setNumber(thr, "DistMax", layer + (p.coarse - size) / p.growth)
        return thr

    parts = []
    for balls, tags, layers in ((p.patches, outer, OUTER_LAYER), (p.bone_patches, interface_roi, ROI_LAYER)):
        thr = {}
        for x, y, z, r, h in balls:
            if h not in thr:
                thr[h] = threshold(tags, h, layers * h)
            ball = f.add("Ball")
            for k, v in (("XCenter", x), ("YCenter", y), ("ZCenter", z), ("Radius", r), ("VIn", h),
                         ("VOut", p.coarse), ("Thickness", (p.coarse - h) / p.growth)):
                f.setNumber(ball, k, v)
            mx = f.add("Max")
            f.setNumbers(mx, "FieldsList", [thr[h], ball])
            parts.append(mx)
    if p.strip:
        near_outer = threshold(outer, p.strip, p.outer_layer)
        box = f.add("Box")
        for k, v in (("VIn", p.strip), ("VOut", p.coarse), ("XMin", -p.contact_x if full_width else -1.0), ("XMax", p.contact_x),
                     ("YMin", -1e3), ("YMax", 1e3), ("ZMin", p.contact_z[0] - 1.0),
                     ("ZMax", p.contact_z[1] + 1.0), ("Thickness", p.transition)):
            f.setNumber(box, k, v)
        contact = f.add("Max")
        f.setNumbers(contact, "FieldsList", [near_outer, box])
        parts += [contact, threshold(interface_roi, p.strip_roi or p.strip, p.roi_layer)]
    mn = f.add("Min")
    f.setNumbers(mn, "FieldsList", parts)
    f.setAsBackgroundMesh(mn)
    _options(gmsh, p, smallest)
