"""Printable parts of the flat pad (skins.pad): the pad itself and its two-part casting mold.

Frame as the solver's: the pad is x in [-W/2, W/2], y in [0, t] (y = 0 the board side),
z in [-L/2, L/2]. The mold casts the pad face down:
- lower part: a block whose pocket is exactly the pad, open at the split plane y = 0 (its
  floor is the pad's outer surface, so that face comes out as smooth as the print);
  four alignment pins stand on the split face;
- upper part (lid): a plate over y < 0 with the pin holes, a sprue at the pad's centre and an
  air vent near each end. The sensor board, if it is to be bonded while curing, replaces the
  lid (same footprint). Wall, pin and sprue sizes from data/geometry/molds.toml.
"""

from __future__ import annotations

from tactileskin.errors import ParameterError
from tactileskin.geometry.molds import MoldParams, vertical_cylinder
from tactileskin.geometry.occ import bd
from tactileskin.geometry.parts import Part
from tactileskin.geometry.solids import box, check_solid, occ_guard


def pad_solid(width: float, length: float, thickness: float) -> bd.Solid:
    w, z = 0.5 * width, 0.5 * length
    return box(-w, w, 0.0, thickness, -z, z)


def pad_mold(width: float, length: float, thickness: float, mp: MoldParams | None = None):
    """(lower part with the pocket and pins, lid with sprue and vents)."""
    mp = mp or MoldParams.from_params()
    w, z = 0.5 * width, 0.5 * length
    # the sizes the user chose are what stops the mold: name them (and the way out), not the
    # molds.toml entries they collide with
    no_molds = "or build without molds (--no-molds)"
    for name, size in (("pad_width", width), ("pad_length", length)):
        if mp.pour_diameter >= size:
            raise ParameterError(name, size, f"> {mp.pour_diameter:g} mm for the mold's sprue "
                                 "(molds.toml [pour] pour_diameter)", no_molds)
    if not 0.5 * mp.vent_diameter <= mp.vent_inset <= z:
        if mp.vent_inset > z:
            raise ParameterError("pad_length", length, f">= {2 * mp.vent_inset:g} mm for the mold's vents "
                                 "(molds.toml [pour] vent_inset)", no_molds)
        raise ParameterError("molds.pour.vent_inset", mp.vent_inset, f"[{0.5 * mp.vent_diameter:g}, {z:g}] mm")
    # as the dome's mold: the vents 1 mm of mold apart from the sprue, or they open into it
    # and the air at the pocket's ends has no way out (an 8 mm pad had one hole, a 5 mm one none)
    need = mp.vent_inset + 0.5 * (mp.pour_diameter + mp.vent_diameter) + 1.0
    if z < need:
        raise ParameterError("pad_length", length, f">= {2 * need:g} mm for the mold's sprue and two vents "
                             "(molds.toml [pour])", no_molds)
    p = dict(width=width, length=length, thickness=thickness, wall=mp.wall)
    with occ_guard("building the pad mold", **p):
        cavity = pad_solid(width, length, thickness)
    zv = z - mp.vent_inset
    return face_down_mold(cavity, (-w, w, thickness, -z, z), 0.0, mp, "pad mold", p,
                          holes=lambda: ((0.0, 0.0), [(0.0, -zv), (0.0, zv)]))


def face_down_mold(skin, extent, y_b: float, mp: MoldParams, what: str, p: dict, *, holes, check=None):
    """(lower part with the pocket and pins, lid with sprue and vents) of a skin cast face down:
    the pocket is a block `wall` around the skin minus the skin, open at its bonded plane y = y_b,
    which the lid closes; a pin at each corner of the skin's footprint, in a flange beside the
    pocket. extent: (x0, x1, y_top, z0, z1) of the skin; holes(): ((x, z) of the sprue, [(x, z)
    of the vents]), asked once the pocket is made and `check`ed (check(lower): raises for a
    pocket the mold cannot cast)."""
    x0, x1, y_top, z0, z1 = extent
    hole = mp.pin_diameter + mp.pin_clearance
    xp = (x0 - mp.wall - 0.5 * hole, x1 + mp.wall + 0.5 * hole)  # `wall` from the pocket
    bx0, bx1 = xp[0] - 0.5 * hole - mp.pin_flange, xp[1] + 0.5 * hole + mp.pin_flange
    bz0, bz1 = z0 - mp.wall, z1 + mp.wall
    lid = max(mp.wall, mp.pin_height + mp.pin_depth_clearance + 1.0)  # the pin holes stay blind
    pins = [(x, z) for x in xp for z in (z0, z1)]
    with occ_guard(f"building the {what}", **p):
        pin_solids = [vertical_cylinder(x, z, y_b - mp.pin_height, y_b, mp.pin_diameter) for x, z in pins]
        lower = box(bx0, bx1, y_b, y_top + mp.wall, bz0, bz1).cut(skin)
    if check is not None:
        check(lower)
    sprue, vents = holes()
    with occ_guard(f"building the {what}", **p):
        lower = lower.fuse(*pin_solids).clean()
        drill = [vertical_cylinder(x, z, y_b - (mp.pin_height + mp.pin_depth_clearance), y_b, hole) for x, z in pins]
        drill += [vertical_cylinder(*sprue, y_b - lid - 1.0, y_b, mp.pour_diameter)]
        drill += [vertical_cylinder(x, z, y_b - lid - 1.0, y_b, mp.vent_diameter) for x, z in vents]
        upper = box(bx0, bx1, y_b - lid, y_b, bz0, bz1).cut(*drill).clean()
    return check_solid(lower, f"{what} lower part", **p), check_solid(upper, f"{what} lid", **p)


def build_pad_parts(thickness: float, width: float, length: float, *, molds: bool = True) -> list[Part]:
    """The pad and (molds=True) its mold parts; the sizes are validated like a Scene's."""
    from tactileskin.skins.pad import SIZE, THICKNESS
    from tactileskin.errors import check_range

    t = check_range("thickness", thickness, *THICKNESS, unit="mm")
    width = check_range("pad_width", width, *SIZE, unit="mm")
    length = check_range("pad_length", length, *SIZE, unit="mm")
    fp = dict(skin="pad", thickness=t, pad_width=width, pad_length=length)
    with occ_guard("building the pad", **fp):
        pad = check_solid(pad_solid(width, length, t), "pad", **fp)
    parts = [Part("skin", f"flat pad {width:g} x {length:g} x {t:g} mm (cast in the mold)", pad, fp)]
    if molds:
        mp = MoldParams.from_params()
        lower, upper = pad_mold(width, length, t, mp)
        parts.append(Part("mold_lower", "pad mold, lower part (pocket = the pad, pins)", lower, fp))
        parts.append(Part("mold_upper", "pad mold, lid (sprue, vents; or the sensor board)", upper, fp))
    return parts
