"""build123d solids: fingertip skin and rigid base, indenters with their mounting stems.

This module (with molds.py, parts.py and export.py) is the only place that imports
build123d; the solver never does. Every dimension comes from the analytic geometry
(fingertip.Section, indenters.Indenter), which in turn reads data/geometry/*.toml.

Frame (mm): x lateral, y towards the pulp, z along the finger. The fingertip prism spans
z in [-L/2, L/2] (L = Fingertip.sample_length) so that it lines up with the indenters,
whose face patterns are centred on z = 0. Indenters sit in their scene position: lowest
point at `Indenter.y0` (the skin top), working face towards -y, stem along +y.

Faces are built from the analytic curves: the outer contour is an exact ellipse arc, the
bone interface (an offset of the ellipse, not a conic) an interpolating B-spline through
points of Section.interface with its own parameter u as knots (deviation < 1e-6 mm, see
tests/test_cad.py).
"""

from __future__ import annotations

import contextlib
import logging
import math

import numpy as np

from tactileskin import params
from tactileskin.errors import CadError, ParameterError, TactileSkinError, check_range
from tactileskin.geometry.fingertip import Section
from tactileskin.geometry.indenters.sphere import CAP
from tactileskin.geometry.indenters import (BrailleIndenter, CylinderIndenter, FlatIndenter, Indenter,
                                            SphereIndenter)
from tactileskin.geometry.occ import bd

log = logging.getLogger(__name__)

# Interface spline samples per half-width. With u as the spline parameter, 80 intervals
# keep the spline within 3e-7 mm of the analytic offset curve even at the largest valid
# thickness (interface radius of curvature ~0.6 mm).
_SPLINE_INTERVALS = 80


@contextlib.contextmanager
def occ_guard(what: str, **parameters):
    """Turn any CAD-kernel exception into a CadError naming the operation and its parameters."""
    try:
        yield
    except TactileSkinError:
        raise
    except Exception as e:  # OCC raises StdFail_NotDone, RuntimeError, ValueError, ...
        raise CadError(f"{what} failed for {format_params(parameters)}: {type(e).__name__}: {e}") from e


def format_params(parameters: dict) -> str:
    """Every digit of a float (repr): a failure reported at 'thickness=3.35547' did not recur
    there, only at the 3.355469 that failed."""
    return ", ".join(f"{k}={v!r}" for k, v in parameters.items()) or "defaults"


def check_solid(shape, what: str, **parameters) -> bd.Solid:
    """One valid solid of positive volume, else CadError."""
    with occ_guard(f"checking {what}", **parameters):
        solids = shape.solids() if not isinstance(shape, bd.Solid) else [shape]
        if len(solids) != 1:
            raise CadError(f"{what}: expected one solid, got {len(solids)} for {format_params(parameters)}")
        s = solids[0]
        ok, vol = s.is_valid, s.volume
    if not ok or not (vol > 0.0 and math.isfinite(vol)):
        raise CadError(f"{what}: invalid solid (valid={ok}, volume={vol:g} mm^3) for {format_params(parameters)}")
    return s


# --- fingertip ---------------------------------------------------------------------------

def _pts3(xy: np.ndarray, z: float) -> list[tuple[float, float, float]]:
    return [(float(x), float(y), z) for x, y in xy]


def _ellipse_arc(sec: Section, u_from: float, u_to: float, z: float) -> bd.Edge:
    """Exact arc of the outer contour P(u) = (a sin u, b cos u) for u_from < u_to, in plane z.

    build123d's ellipse angle phi (x = a cos phi, y = b sin phi) is phi = 90 deg - u; the arc
    runs counter-clockwise from phi(u_to) to phi(u_from).
    """
    ft = sec.fingertip
    return bd.Edge.make_ellipse(ft.half_width, ft.height, plane=bd.Plane.XY.offset(z),
                                start_angle=90.0 - math.degrees(u_to),
                                end_angle=90.0 - math.degrees(u_from))


def _interface_spline(sec: Section, u_from: float, u_to: float, z: float) -> bd.Edge:
    n = max(8, int(round(_SPLINE_INTERVALS * (u_to - u_from) / sec.u_interface_end)))
    u = np.linspace(u_from, u_to, n + 1)
    return bd.Edge.make_spline(_pts3(sec.interface(u), z), parameters=[float(v) for v in u])


def _line(p, q, z: float) -> bd.Edge:
    return bd.Edge.make_line((float(p[0]), float(p[1]), z), (float(q[0]), float(q[1]), z))


def _mirror_x(p) -> np.ndarray:
    return np.array([-p[0], p[1]])


def skin_face(sec: Section, *, full: bool = True, z: float = 0.0) -> bd.Face:
    """Skin cross-section in the plane z: the shell between the outer contour and the interface.

    full=True: both sides of the symmetry line (nail edge to nail edge); False: x >= 0 only.
    """
    uo, ui = sec.u_outer_end, sec.u_interface_end
    oe, ie = sec.outer_end, sec.interface_end
    if full:
        edges = [_ellipse_arc(sec, -uo, uo, z), _line(oe, ie, z), _interface_spline(sec, -ui, ui, z),
                 _line(_mirror_x(ie), _mirror_x(oe), z)]
    else:
        top_o, top_i = sec.fingertip.outer(0.0), sec.interface(0.0)
        edges = [_ellipse_arc(sec, 0.0, uo, z), _line(oe, ie, z), _interface_spline(sec, 0.0, ui, z),
                 _line(top_i, top_o, z)]
    return bd.Face(bd.Wire(edges))


def base_face(sec: Section, *, full: bool = True, z: float = 0.0) -> bd.Face:
    """Rigid bone/nail/stiff-tissue cross-section: the contour's region minus the skin."""
    ft = sec.fingertip
    uo, ui = sec.u_outer_end, sec.u_interface_end
    oe, ie = sec.outer_end, sec.interface_end
    if full:
        # the contour below the nail edges runs from u = uo through the bottom (u = pi) to 2 pi - uo
        edges = [_interface_spline(sec, -ui, ui, z), _line(ie, oe, z),
                 _ellipse_arc(sec, uo, 2.0 * math.pi - uo, z), _line(_mirror_x(oe), _mirror_x(ie), z)]
    else:
        bottom, top_i = ft.outer(math.pi), sec.interface(0.0)
        edges = [_interface_spline(sec, 0.0, ui, z), _line(ie, oe, z), _ellipse_arc(sec, uo, math.pi, z),
                 _line(bottom, top_i, z)]
    return bd.Face(bd.Wire(edges))


def _prism(face_fn, sec: Section, full: bool, what: str) -> bd.Solid:
    L = sec.fingertip.sample_length
    p = dict(thickness=sec.thickness, full=full, sample_length=L)
    with occ_guard(f"building the {what}", **p):
        solid = bd.Solid.extrude(face_fn(sec, full=full, z=-0.5 * L), (0.0, 0.0, L))
    return check_solid(solid, what, **p)


def skin_solid(sec: Section, *, full: bool = True) -> bd.Solid:
    """The skin: the section's shell extruded over z in [-L/2, L/2]."""
    return _prism(skin_face, sec, full, "skin")


def base_solid(sec: Section, *, full: bool = True) -> bd.Solid:
    """The rigid base (bone, stiff tissue, nail): the contour's prism minus the skin."""
    return _prism(base_face, sec, full, "rigid base")


def contour_solid(sec: Section, *, extra_length: float = 0.0) -> bd.Solid:
    """The full outer contour (ellipse) extruded over z in [-L/2 - e, L/2 + e] (mold cavity tool)."""
    ft = sec.fingertip
    L = ft.sample_length + 2.0 * extra_length
    with occ_guard("building the contour prism", sample_length=L):
        e = bd.Edge.make_ellipse(ft.half_width, ft.height, plane=bd.Plane.XY.offset(-0.5 * L))
        return bd.Solid.extrude(bd.Face(bd.Wire([e])), (0.0, 0.0, L))


# --- indenters ---------------------------------------------------------------------------

def _single(result):
    """build123d booleans may return a ShapeList; a single shape is unwrapped."""
    if isinstance(result, (list, bd.ShapeList)):
        return result[0] if len(result) == 1 else bd.Compound(list(result))
    return result


def box(x0, x1, y0, y1, z0, z1) -> bd.Solid:
    return bd.Solid.make_box(x1 - x0, y1 - y0, z1 - z0, plane=bd.Plane((x0, y0, z0), x_dir=(1, 0, 0), z_dir=(0, 0, 1)))


def _add_stem(body: bd.Solid, ind: Indenter, y_back: float, what: str, p: dict) -> bd.Solid:
    """Fuse the mounting stem (axis y, from the back face y_back upwards) and fillet its root."""
    q = params.load("indenters")["stem"]
    fillet = float(q["fillet"])
    r, h = 0.5 * ind.stem_diameter, ind.stem_length
    # a back face too small for the stem and its whole fillet (a small ball's plate, half-width
    # 1.2 R; a small cylinder's chord) gets a mount block, the stem's width plus the fillet's
    # room each side: the stem is the same for every indenter (the load cell's adapter); it
    # used to shrink with the body instead, to 0.48 mm across and 20 mm long for R = 0.3
    bb = body.bounding_box()
    room = min(-bb.min.X, bb.max.X, -bb.min.Z, bb.max.Z) - r
    with occ_guard(f"adding the stem to the {what}", stem_diameter=ind.stem_diameter,
                   stem_length=h, stem_fillet=fillet, **p):
        if room < 2.0 * fillet:
            mount = _mount_thickness(q)
            m = r + 2.0 * fillet
            body = _single(body.fuse(box(-m, m, y_back, y_back + mount, -m, m)).clean())
            y_back += mount
            room = 2.0 * fillet
        stem = bd.Solid.make_cylinder(r, h, plane=bd.Plane((0.0, y_back, 0.0), x_dir=(1, 0, 0), z_dir=(0, 1, 0)))
        solid = body.fuse(stem).clean()
        if fillet > 0.0:
            root = [e for e in solid.edges()
                    if e.geom_type == bd.GeomType.CIRCLE and abs(e.radius - r) < 1e-6
                    and abs(e.center().Y - y_back) < 1e-6]
            if len(root) != 1:
                raise CadError(f"{what}: found {len(root)} stem root edges, expected 1 for {format_params(p)}")
            solid = solid.fillet(fillet, root)
    return check_solid(solid, what, **p)


def _mount_thickness(stem: dict) -> float:
    """indenters.toml [stem] mount_thickness, checked: a geometry folder written before the
    mount block (TACTILESKIN_GEOMETRY) lacks it, and only the indenters that need a block read it."""
    name = "indenters.stem.mount_thickness"
    if "mount_thickness" not in stem:
        raise ParameterError(name, None, "> 0 mm in indenters.toml",
                             "add `mount_thickness = 3.0` under [stem] (the block under the stem of a "
                             "ball or cylinder narrower than the stem)")
    return check_range(name, stem["mount_thickness"], 0.0, None, lo_open=True, unit="mm")


def indenter_solid(ind: Indenter) -> bd.Solid:
    """The printable indenter in its scene position (lowest point y0), with its mounting stem:
    the kind's answer (`Indenter.solid()`, which calls its builder here)."""
    return ind.solid()


def flat_indenter(ind: FlatIndenter) -> bd.Solid:
    w, L, y0 = ind.width, ind.length, ind.y0
    p = dict(kind="flat", width=w, length=L, thickness=ind.thickness)
    with occ_guard("building the flat indenter plate", **p):
        plate = box(-w / 2, w / 2, y0, y0 + ind.thickness, -L / 2, L / 2)
    return _add_stem(plate, ind, y0 + ind.thickness, "flat indenter", p)


def cylinder_indenter(ind: CylinderIndenter) -> bd.Solid:
    """The cylinder's lowest strip (chord `ind.chord` across the axis) under a flat back;
    built along z and turned about y for an axis along x."""
    along = ind.length if ind.axis == "z" else ind.width
    w, L, y0, R = ind.chord, along, ind.y0, ind.radius
    y_back = y0 + ind.sagitta + ind.back_thickness
    p = dict(kind=ind.kind, radius=R, chord_width=w, length=L, back_thickness=ind.back_thickness, axis=ind.axis)
    with occ_guard(f"building the {ind.kind} indenter", **p):
        block = box(-w / 2, w / 2, y0, y_back, -L / 2, L / 2)
        # the block top (y0 + sagitta + back) stays below the axis only if back < R - sagitta;
        # then block ∩ cylinder is exactly the arc face under a flat back
        if y_back >= y0 + R:
            raise CadError(f"{ind.kind} indenter: back_thickness={ind.back_thickness:g} reaches the cylinder "
                           f"axis; valid: < radius - sagitta = {R - ind.sagitta:g} mm")
        cyl = bd.Solid.make_cylinder(R, L, plane=bd.Plane((0.0, y0 + R, -L / 2), x_dir=(1, 0, 0), z_dir=(0, 0, 1)))
        body = _single(block.intersect(cyl)).clean()
        if ind.axis == "x":
            body = body.rotate(bd.Axis.Y, 90)
    body = check_solid(body, f"{ind.kind} indenter body", **p)
    return _add_stem(body, ind, y_back, f"{ind.kind} indenter", p)


def sphere_indenter(ind: SphereIndenter) -> bd.Solid:
    """The ball fused into a plate whose underside is 0.05 R below the ball's equator: the
    working face is the spherical cap of height CAP R = 0.95 R (the model's ball, for any
    depth a scene may ask), and the sphere's poles (axis along z, on the equator) lie inside the plate,
    where OCC's degenerate pole facets cannot break the STL (as for the Braille dots)."""
    R, y0 = ind.radius, ind.y0
    yc, yb = y0 + R, y0 + CAP * R
    half, y_back = 1.2 * R, y0 + 2.2 * R
    p = dict(kind="sphere", radius=R)
    with occ_guard("building the sphere indenter", **p):
        plate = box(-half, half, yb, y_back, -half, half)
        ball = bd.Solid.make_sphere(R, plane=bd.Plane((0.0, yc, 0.0), x_dir=(1, 0, 0), z_dir=(0, 0, 1)))
        body = plate.fuse(ball).clean()
    body = check_solid(body, "sphere indenter body", **p)
    return _add_stem(body, ind, y_back, "sphere indenter", p)


def braille_indenter(ind: BrailleIndenter) -> bd.Solid:
    std = ind.standard
    w, L = ind.width, ind.length
    R, yb = std.sphere_radius, ind.base_plane(0.0)
    yc = yb + std.centre_offset
    p = dict(kind="braille", text=ind.text, standard=std.name, base_diameter=std.base_diameter,
             height=std.height, plate_thickness=ind.plate_thickness)
    y_back = yb + ind.plate_thickness
    if yc + R > y_back:
        raise CadError(f"braille indenter: plate_thickness={ind.plate_thickness:g} mm is thinner than the "
                       f"dot sphere above the base plane ({yc + R - yb:g} mm) for {format_params(p)}")
    with occ_guard("building the Braille indenter", **p):
        plate = box(-w / 2, w / 2, yb, y_back, -L / 2, L / 2)
        # Whole spheres fused with the plate: the part above the base plane lies inside the
        # plate, so the union is the plate plus exact spherical caps. The sphere axis is along
        # z: its poles (degenerate points that OCC meshes into a zero-area facet, breaking the
        # STL's watertightness) then lie inside the plate, not on the cap.
        spheres = [bd.Solid.make_sphere(R, plane=bd.Plane((float(x), yc, float(z)), x_dir=(1, 0, 0), z_dir=(0, 0, 1)))
                   for x, z in ind.dots]
        body = plate.fuse(*spheres).clean()
    body = check_solid(body, "Braille indenter body", **p)
    return _add_stem(body, ind, y_back, "Braille indenter", p)
