"""A 3D fingertip with a rounded tip (skins.dome): solids and printable parts (build123d).

The outer surface is the paper's elliptical section (semi-axes a along x, b along y) extruded
along the finger for z in [-L, 0] and closed for z > 0 by a half ellipsoid (semi-axis c along
z); the rigid bone is the same shape with every semi-axis reduced by the skin thickness t
(a - t, b - t, c - t), so the skin is t thick at the pulp (x = 0, y = b), the sides and the tip.
`half=True` keeps x >= 0 (the half model the solver meshes, symmetry plane x = 0).

Parts: the skin (cast), the bone core (printed, the mold's insert) and a two-part mold split at
y = 0 (a block minus the outer body, with alignment pins, a sprue and two vents), every part checked closed (solids.check_solid; the STLs
by trimesh in export.py).
"""

from __future__ import annotations

import math

from tactileskin.errors import ParameterError
from tactileskin.geometry.occ import bd
from tactileskin.geometry.solids import box, check_solid, occ_guard

BONE_STEM = 5.0  # mm of bone core beyond the skin's end z = -L (held by the mold)


def _one(shape) -> bd.Solid:
    """The single solid of a boolean's result (build123d returns a Shape or a ShapeList)."""
    solids = shape.solids()
    return solids[0] if len(solids) == 1 else shape


def body(a: float, b: float, c: float, length: float, *, extra: float = 0.0) -> bd.Solid:
    """The elliptic cylinder z in [-length - extra, 0] closed by a half ellipsoid for z > 0."""
    ell = bd.Face(bd.Wire([bd.Edge.make_ellipse(a, b, plane=bd.Plane.XY.offset(-length - extra))]))
    cyl = bd.Solid.extrude(ell, bd.Vector(0, 0, length + extra))
    cap = bd.scale(bd.Solid.make_sphere(1.0), by=(a, b, c))
    cap = _one(cap.intersect(box(-a - 1, a + 1, -b - 1, b + 1, 0.0, c + 1)))
    return _one(cyl.fuse(cap).clean())


def skin_solid(a, b, c, length, t, *, half: bool = False) -> bd.Solid:
    """The skin: the outer body minus the bone (x >= 0 only if `half`)."""
    p = dict(a=a, b=b, c=c, length=length, thickness=t)
    with occ_guard("building the dome skin", **p):
        s = _one(body(a, b, c, length).cut(body(a - t, b - t, c - t, length, extra=1.0)))
        if half:
            s = _one(s.intersect(box(0.0, a + 1, -b - 1, b + 1, -length - 1, c + 1)))
        return check_solid(_one(s.clean()), "dome skin", **p)


def bone_solid(a, b, c, length, t) -> bd.Solid:
    p = dict(a=a, b=b, c=c, length=length, thickness=t)
    with occ_guard("building the dome bone core", **p):
        return check_solid(body(a - t, b - t, c - t, length, extra=BONE_STEM), "dome bone core", **p)


def skin_volume(a, b, c, length, t, *, half: bool = False) -> float:
    """Analytic skin volume (mm^3): the elliptic annulus times L plus the two half ellipsoids."""
    ai, bi, ci = a - t, b - t, c - t
    v = math.pi * (a * b - ai * bi) * length + 2.0 / 3.0 * math.pi * (a * b * c - ai * bi * ci)
    return 0.5 * v if half else v


def mold(a, b, c, length, t, mp=None):
    """(lower, upper) mold halves split at y = 0: a block around the outer body minus it; the
    bone core rests in the half-round seats its stem leaves at z < -L, pushed home against the
    end wall behind them (molds.toml [block] wall thick), which fixes it along the finger and closes the cavity. As the fingertip's mold
    (molds.toml): four alignment pins on the lower half beside the cavity, in holes of the
    upper one; an air vent near each end of the pulp line (the straight part's end, half way up
    the tip) and a sprue onto the pulp half way between (moved off the straight part's seam with the
    tip where its rim would touch it: SEAM_GAP), so the skin can be poured and the air leave (a dome
    too short to hold the three apart is refused)."""
    from tactileskin.geometry.molds import MoldParams, vertical_cylinder

    mp = mp or MoldParams.from_params()
    p = dict(a=a, b=b, c=c, length=length, thickness=t)
    hole = mp.pin_diameter + mp.pin_clearance
    xp = a + mp.wall + 0.5 * hole            # the wall between the cavity and a pin hole
    A, B = xp + 0.5 * hole + mp.pin_flange, b + mp.wall
    # an end wall behind the stem: the core's stop along the finger (the skin's tip thickness
    # depends on it) and the cavity's end (the stem's seat ran out through the block's end face,
    # leaving the core free to slide and the silicone a way out along it)
    z0, z1 = -length - BONE_STEM - mp.wall, c + mp.wall
    if mp.pin_height + mp.pin_depth_clearance >= B:
        raise ParameterError("molds.pins.height", mp.pin_height, f"< {B - mp.pin_depth_clearance:g} mm (the dome "
                             f"mold's upper half is {B:g} mm thick)")
    zp = (z0 + 0.5 * hole + mp.pin_flange, z1 - 0.5 * hole - mp.pin_flange)
    # a vent near each end of the pulp line, the sprue half way between, 1 mm of mold apart
    zv = (-length + mp.vent_inset, 0.5 * c)
    zs = 0.5 * (zv[0] + zv[1])
    need = mp.pour_diameter + mp.vent_diameter + 2.0
    if zv[1] - zv[0] < need:
        raise ParameterError("dome_length", length, f">= {need - 0.5 * c + mp.vent_inset:g} mm with dome_tip "
                             f"{c:g} mm for the mold's sprue and two vents", "or build without molds (--no-molds)")
    zs = _off_the_seam(zs, 0.5 * mp.pour_diameter, zv, 0.5 * mp.vent_diameter)
    pins = [(sx * xp, z) for sx in (-1, 1) for z in zp]
    with occ_guard("building the dome mold", **p):
        cavity = _one(body(a, b, c, length).fuse(body(a - t, b - t, c - t, length, extra=BONE_STEM)))
        lower = box(-A, A, -B, 0.0, z0, z1).cut(cavity).fuse(
            *[vertical_cylinder(x, z, 0.0, mp.pin_height, mp.pin_diameter) for x, z in pins])
        holes = [vertical_cylinder(x, z, 0.0, mp.pin_height + mp.pin_depth_clearance, hole) for x, z in pins]
        holes += [vertical_cylinder(0.0, zs, 0.0, B + 1.0, mp.pour_diameter)]
        holes += [vertical_cylinder(0.0, z, 0.0, B + 1.0, mp.vent_diameter) for z in zv]
        lower = _one(lower.clean())
        upper = _one(box(-A, A, 0.0, B, z0, z1).cut(cavity, *holes).clean())
    return check_solid(lower, "dome mold lower half", **p), check_solid(upper, "dome mold upper half", **p)


# the sprue's rim kept this far from the seam z = 0 of the straight part and the tip: a rim
# tangent to it (the default dome: sprue z in [-4, 0]) left mold_upper.step invalid on re-reading
# (volume -3.7 mm3 off; the STL and the CAD solid were fine)
SEAM_GAP = 0.25  # mm


def _off_the_seam(zs: float, r: float, vents, rv: float) -> float:
    """The sprue's centre z moved along the pulp line so its rim clears z = 0 by SEAM_GAP, if it
    touched it, keeping 1 mm of mold to the vents; else zs."""
    if min(abs(zs - r), abs(zs + r)) >= SEAM_GAP:
        return zs
    for z in (-(r + SEAM_GAP), r + SEAM_GAP):
        if all(abs(z - v) >= r + rv + 1.0 for v in vents):
            return z
    return zs


def build_dome_parts(thickness: float, a: float, b: float, c: float, length: float, *, molds: bool = True):
    from tactileskin.geometry.parts import Part

    fp = dict(skin="dome", thickness=thickness, half_width=a, height=b, dome_tip=c, dome_length=length)
    parts = [Part("skin", f"rounded fingertip skin, t = {thickness:g} mm (cast)",
                  skin_solid(a, b, c, length, thickness), fp),
             Part("bone_core", "rigid bone core (printed; the mold's insert)",
                  bone_solid(a, b, c, length, thickness), fp)]
    if molds:
        lower, upper = mold(a, b, c, length, thickness)
        parts += [Part("mold_lower", "dome mold, lower half (y < 0)", lower, fp),
                  Part("mold_upper", "dome mold, upper half (y > 0, the pulp)", upper, fp)]
    return parts
