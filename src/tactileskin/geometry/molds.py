"""Two-part casting mold for the skin; the printed rigid base is its core.

Layout (dimensions in data/geometry/molds.toml, frame as in solids.py):
- The cavity is the full-width outer contour (the ellipse) extruded over the sample length,
  z in [-L/2, L/2]; the end walls close it.
- The rigid base (the printed core) sits in the lower half, in a seat below the nail edges,
  with `core_clearance` (molds.toml [core] clearance) around it where mold faces would hold it
  from opposite sides: a printer cannot make an exact fit (a core printed a little oversize
  would jam between the end walls and ride on the seat's rim, lifting it and thinning the
  skin). The seat is the contour offset outwards by the clearance and raised by it, so it
  touches the contour at the bottom, where the core rests under gravity and keeps the
  position that makes the skin t thick, and leaves a normal gap c (1 + n_y) elsewhere (about
  0.54 c at the nail edges, and it reaches c past them for the core's corners): a core
  printed up to c oversize all round still rests on the bottom (its top then stands about
  twice its oversize higher: the skin over the pulp is that much thinner). The end walls have a slot as
  deep as the clearance: the core's section offset by it.
  What is left of the cavity is exactly the skin plus that gap (tests/test_cad.py checks both
  within 0.5 % of the skin); silicone that runs into the gap is a thin flash along the nail
  edges and over the core's ends, trimmed after demolding. 0 gives the exact, unprintable fit.
- Split plane y = 0, the contour's widest section: neither half has an undercut, and the
  lower half releases the cast skin together with its base.
- Four alignment pins on the lower half's split face, in clearance holes in the upper half.
- A sprue on the skin's ridge (x = 0) near the z < 0 end (`pour_inset` from it) and an air
  vent near the other end, both through the upper half's roof: the skin fills from one end
  and its air leaves at the other, and the gate's mark stays off the middle of the sample,
  where the indenters press (a sprue at z = 0 left it under the Braille dot and the sphere).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from tactileskin import params
from tactileskin.errors import CadError, ParameterError
from tactileskin.geometry.fingertip import Section
from tactileskin.geometry.occ import bd
from tactileskin.geometry.solids import _single, base_face, box, check_solid, contour_solid, occ_guard

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class MoldParams:
    wall: float
    pin_diameter: float
    pin_height: float
    pin_clearance: float
    pin_depth_clearance: float
    pin_flange: float
    pour_diameter: float
    pour_inset: float
    vent_diameter: float
    vent_inset: float
    core_clearance: float

    @classmethod
    def from_params(cls, **overrides) -> "MoldParams":
        p = params.load("molds")
        kw = dict(wall=p["block"]["wall"], pin_diameter=p["pins"]["diameter"], pin_height=p["pins"]["height"],
                  pin_clearance=p["pins"]["clearance"], pin_depth_clearance=p["pins"]["depth_clearance"],
                  pin_flange=p["pins"]["flange"], pour_diameter=p["pour"]["pour_diameter"],
                  pour_inset=p["pour"].get("pour_inset"),
                  vent_diameter=p["pour"]["vent_diameter"], vent_inset=p["pour"]["vent_inset"])
        core = p.get("core", {})
        if "clearance" not in core and "core_clearance" not in overrides:
            raise ParameterError("molds.core.clearance", None, ">= 0 mm in molds.toml",
                                 "add `[core] clearance = 0.2` (the gap around the printed core)")
        kw["core_clearance"] = core.get("clearance")
        if kw["pour_inset"] is None and "pour_inset" not in overrides:  # a molds.toml from before it
            raise ParameterError("molds.pour.pour_inset", None, ">= 0 mm in molds.toml",
                                 "add `pour_inset = 3.0` under [pour] (the fingertip sprue's distance "
                                 "from the sample's z < 0 end)")
        kw.update(overrides)
        from tactileskin import validate

        for k, v in kw.items():  # a string in molds.toml was a ValueError traceback
            if not validate.is_number(v):
                raise ParameterError(f"molds.{k}", v, "a number (mm) in molds.toml")
        return cls(**{k: float(v) for k, v in kw.items()})

    def __post_init__(self):
        # every skin's mold (fingertip, pad, dome) is built from these: the pad's and the dome's
        # molds never ran `check`, and a negative pin clearance (holes narrower than the pins:
        # a mold that cannot close) was written as a good part
        import dataclasses
        import math

        for f in dataclasses.fields(self):
            if not math.isfinite(getattr(self, f.name)):
                raise ParameterError(f"molds.{f.name}", getattr(self, f.name), "a finite number (mm)")
        for name in ("wall", "pin_diameter", "pin_height", "pour_diameter", "vent_diameter", "pin_flange"):
            if not getattr(self, name) > 0.0:
                raise ParameterError(f"molds.{name}", getattr(self, name), "> 0 mm")
        for name in ("pin_clearance", "pin_depth_clearance", "vent_inset", "pour_inset"):
            if not getattr(self, name) >= 0.0:
                raise ParameterError(f"molds.{name}", getattr(self, name), ">= 0 mm")
        if not 0.0 <= self.core_clearance <= 0.5 * self.wall:
            raise ParameterError("molds.core.clearance", self.core_clearance,
                                 f"[0, {0.5 * self.wall:g}] mm (at most half the {self.wall:g} mm wall)")

    def check(self, sec: Section) -> None:
        """Raise ParameterError if the mold cannot be made for this fingertip (the values' own
        ranges are checked when a MoldParams is made)."""
        ft = sec.fingertip
        roof = ft.height + self.wall
        if self.pin_height + self.pin_depth_clearance >= roof:
            raise ParameterError("molds.pins.height", self.pin_height,
                                 f"< {roof - self.pin_depth_clearance:g} mm (the upper half is {roof:g} mm thick)")
        half_l = 0.5 * ft.sample_length
        if not 0.5 * self.vent_diameter <= self.vent_inset <= half_l:
            raise ParameterError("molds.pour.vent_inset", self.vent_inset,
                                 f"[{0.5 * self.vent_diameter:g}, {half_l:g}] mm")
        if self.pour_diameter >= 2.0 * ft.half_width:
            raise ParameterError("molds.pour.pour_diameter", self.pour_diameter, f"< {2 * ft.half_width:g} mm")
        # the sprue inside the sample, 1 mm of mold from the vent at the other end
        zv = half_l - self.vent_inset
        hi = zv - 0.5 * (self.pour_diameter + self.vent_diameter) - 1.0 + half_l
        if not 0.5 * self.pour_diameter <= self.pour_inset <= hi:
            raise ParameterError("molds.pour.pour_inset", self.pour_inset,
                                 f"[{0.5 * self.pour_diameter:g}, {hi:g}] mm (the sprue inside the "
                                 f"{ft.sample_length:g} mm sample, 1 mm of mold from the vent at z = {zv:g})")

    def sprue_z(self, sample_length: float) -> float:
        """z of the fingertip mold's sprue: `pour_inset` from the sample's z < 0 end."""
        return -0.5 * sample_length + self.pour_inset


@dataclass(frozen=True)
class MoldLayout:
    """Derived positions (mm) shared by the two halves."""

    half_width: float     # block x half-extent
    half_length: float    # block z half-extent
    floor: float          # y of the lower half's bottom (negative)
    roof: float           # y of the upper half's top
    pins: tuple[tuple[float, float], ...]   # (x, z) pin axes

    @classmethod
    def of(cls, sec: Section, mp: MoldParams) -> "MoldLayout":
        ft = sec.fingertip
        hole = mp.pin_diameter + mp.pin_clearance
        xp = ft.half_width + mp.wall + 0.5 * hole         # `wall` between the cavity and the hole
        half_l = 0.5 * ft.sample_length
        return cls(half_width=xp + 0.5 * hole + mp.pin_flange, half_length=half_l + mp.wall,
                   floor=-(ft.height + mp.wall), roof=ft.height + mp.wall,
                   pins=tuple((sx * xp, sz * half_l) for sx in (-1, 1) for sz in (-1, 1)))


def vertical_cylinder(x: float, z: float, y_from: float, y_to: float, diameter: float) -> bd.Solid:
    return bd.Solid.make_cylinder(0.5 * diameter, y_to - y_from,
                                  plane=bd.Plane((x, y_from, z), x_dir=(1, 0, 0), z_dir=(0, 1, 0)))


# offset edges shorter than this (mm) are artefacts of OCC's offset, far below a printer's
# resolution (t = 3.355469 mm: two of 2.6 and 3.5 um, whose offset curves ended 1e-6 mm from
# their neighbours; rebuilt, the wire was open, and with them forced shut the fused seat was
# an invalid solid): dropped, the neighbours meeting at the middle of the gap
SHORTEST_OFFSET_EDGE = 1e-5
# OCC's offset of the core section at t = 3.3554 mm returned 3 of its 19 edges (a 7 mm gap);
# 0.2 mm +- 2e-7 mm gives them all: the distance is retried with these factors (a clearance
# 1e-6 of itself off) until the edges meet
OFFSET_RETRIES = (1.0, 1.0 + 1e-6, 1.0 - 1e-6, 1.0 + 1e-5)


def _bspline_offset(wire: bd.Wire, distance: float) -> bd.Wire:
    """`wire` offset by `distance` (mm) in its plane, round at convex corners, with every
    offset curve replaced by a B-spline within 1e-7 mm of it: the STEP writer drops the faces
    swept from OCC's offset curves (the mold halves' STEP files lost 22 of 48 and 18 of 36
    faces and re-read as open shells), as solids.py builds the interface as a B-spline.
    Edges shorter than SHORTEST_OFFSET_EDGE are dropped (their neighbours' end poles moved to
    the middle of the gap) where the offset's edges come in wire order; an offset whose edges
    do not meet is made again at a distance 1e-6 of itself off (OFFSET_RETRIES)."""
    from OCP.Approx import Approx_Curve3d
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.gp import gp_Pnt

    for factor in OFFSET_RETRIES:
        edges = list(wire.offset_2d(distance * factor, kind=bd.Kind.ARC).edges())
        n = len(edges)
        in_order = all((edges[i] @ 1 - edges[(i + 1) % n] @ 0).length < 1e-4 for i in range(n))
        if in_order:
            break
    kept = [k for k in range(n) if not in_order or edges[k].length >= SHORTEST_OFFSET_EDGE] or list(range(n))
    # where kept edge k must end: beside a dropped edge, the middle of the gap it leaves (None:
    # its own end)
    ends = {}
    for j, k in enumerate(kept):
        nxt = kept[(j + 1) % len(kept)]
        ends[k] = (edges[k] @ 1 + edges[nxt] @ 0) * 0.5 if nxt != (k + 1) % n else None

    def pnt(v) -> gp_Pnt:
        return gp_Pnt(v.X, v.Y, v.Z)

    out = []
    for j, k in enumerate(kept):
        e = edges[k]
        first, last = ends[kept[j - 1]], ends[k]
        if e.geom_type == bd.GeomType.OFFSET or first is not None or last is not None:
            approx = Approx_Curve3d(BRepAdaptor_Curve(e.wrapped), 1e-7, GeomAbs_C2, 200, 9)
            if not (approx.IsDone() and approx.HasResult()):
                raise CadError(f"offsetting the mold seat by {distance:g} mm: no B-spline within 1e-7 mm "
                               f"(max error {approx.MaxError():g} mm)")
            curve = approx.Curve()  # clamped: its first and last poles are its ends
            if first is not None:
                curve.SetPole(1, pnt(first))
            if last is not None:
                curve.SetPole(curve.NbPoles(), pnt(last))
            e = bd.Edge(BRepBuilderAPI_MakeEdge(curve).Edge())
        out.append(e)
    return bd.Wire(out)


def core_seat(sec: Section, clearance: float) -> bd.Solid:
    """The room the mold leaves for the printed core (the rigid base) with `clearance` c (mm):
    over the sample length, the core's section widened below the nail rays, and an arc c
    beyond them for the core's corners there, to the seat (the contour offset outwards by c
    and raised by c: it touches the contour only at the bottom, x = 0, y = -b, and leaves a
    normal gap c (1 + n_y) elsewhere, so a core printed up to c oversize all round still rests
    on the bottom); beyond each end, a slot c deep in the end wall: the core's section offset
    by c all round."""
    ft = sec.fingertip
    c, L = clearance, ft.sample_length
    z0 = -0.5 * L
    with occ_guard("building the core seat", thickness=sec.thickness, core_clearance=c):
        contour = bd.Wire([bd.Edge.make_ellipse(ft.half_width, ft.height, plane=bd.Plane.XY.offset(z0))])
        grown = bd.Face(_bspline_offset(contour, c)).translate((0.0, c, 0.0))
        # below both nail rays (polar angle from +y beyond the nail angle): the core's side,
        # and c further along the contour, so that the core's corners at the nail edges fit too
        s = 4.0 * (ft.half_width + ft.height)
        angle = ft.nail_angle - c / float(np.hypot(*sec.outer_end))
        dx, dy = math.sin(angle), math.cos(angle)
        wedge = bd.Face(bd.Wire.make_polygon([(0.0, 0.0, z0), (s * dx, s * dy, z0), (s * dx, -s, z0),
                                              (-s * dx, -s, z0), (-s * dx, s * dy, z0)], close=True))
        seat = _single(bd.Solid.extrude(grown, (0.0, 0.0, L)).intersect(bd.Solid.extrude(wedge, (0.0, 0.0, L))))
        section = base_face(sec, full=True, z=z0)
        core = bd.Solid.extrude(section, (0.0, 0.0, L))
        slot = bd.Face(_bspline_offset(section.outer_wire(), c))
        ends = [bd.Solid.extrude(slot.translate((0.0, 0.0, z)), (0.0, 0.0, c)) for z in (-c, L)]
        return _single(core.fuse(seat, *ends).clean())


def skin_mold(sec: Section, mp: MoldParams | None = None) -> tuple[bd.Solid, bd.Solid]:
    """(lower half, upper half) of the skin's casting mold, in the fingertip's frame."""
    mp = mp or MoldParams.from_params()
    mp.check(sec)
    lay = MoldLayout.of(sec, mp)
    ft = sec.fingertip
    A, Z = lay.half_width, lay.half_length
    p = dict(thickness=sec.thickness, wall=mp.wall, pin_diameter=mp.pin_diameter,
             pour_diameter=mp.pour_diameter, vent_diameter=mp.vent_diameter, core_clearance=mp.core_clearance)
    with occ_guard("building the casting mold", **p):
        cavity = contour_solid(sec)
        if mp.core_clearance > 0.0:
            cavity = _single(cavity.fuse(core_seat(sec, mp.core_clearance)).clean())
        pins = [vertical_cylinder(x, z, 0.0, mp.pin_height, mp.pin_diameter) for x, z in lay.pins]
        lower = box(-A, A, lay.floor, 0.0, -Z, Z).cut(cavity).fuse(*pins).clean()
        # the upper half: pin holes, a sprue near one end of the ridge and a vent near the
        # other; the holes start at the split plane (inside the cavity) so they open into it
        holes = [vertical_cylinder(x, z, 0.0, mp.pin_height + mp.pin_depth_clearance,
                                    mp.pin_diameter + mp.pin_clearance) for x, z in lay.pins]
        zv = 0.5 * ft.sample_length - mp.vent_inset
        holes += [vertical_cylinder(0.0, mp.sprue_z(ft.sample_length), 0.0, lay.roof + 1.0, mp.pour_diameter)]
        holes += [vertical_cylinder(0.0, zv, 0.0, lay.roof + 1.0, mp.vent_diameter)]
        upper = box(-A, A, 0.0, lay.roof, -Z, Z).cut(cavity, *holes).clean()
    return check_solid(lower, "mold lower half", **p), check_solid(upper, "mold upper half", **p)
