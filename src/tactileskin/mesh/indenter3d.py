"""The working face of a 3D indenter as a triangulated rigid surface (for the 3D input deck).

CalculiX has no analytical rigid surfaces, so a 3D deck needs the indenter meshed. The face
is triangulated in its (x, z) footprint by gmsh and lifted onto the kind's own surface,
y = indenter.surface_y(x, z): every node lies on the true face. Kinds:
- flat: the plane y = y0 (two-level sizes are pointless: one size h);
- braille: the base plane plus the spherical caps. Each dot's base circle is an embedded
  curve (the face has a kink there, so no triangle may straddle it) and the caps are meshed
  at h_dot, finer towards the steep rim. The chords lie inside the sphere, so a faceted dot is
  slightly smaller: at the former default h_dot = a/8 (3 um off vertically) ccx's force on
  a t = 1 mm dot read 0.9 % below tactileskin's on the same mesh, at a/16 (1 um) 0.2 %
  (benchmarks/results/calculix_compare3d.md); a/16 is the default.
- sphere, cylinder (axis z or x), curved: the exact surface where it rises less than
  CAP_RISE x the travel above its lowest point (the only part the skin can reach: its top
  would have to rise by the travel above where it started to touch more), then a flat
  flange at that height (a kink: the cap's rim is a line of nodes, as a dot's base circle;
  for a cylinder never past its printed chord; the pole or lowest line is a node or a line
  of nodes, where it first touches). Facet sizes from a stated tolerance: the
  faceted cap within CHORD_TOL x the travel (vertically) of the exact surface, the size
  the Braille caps use measured against their travel (1.0 um at 0.2 mm: ccx's force 0.2 %
  below tactileskin's; 3 um, 1.5 %, read 0.9 % below). A Hertzian force goes as travel^1.5
  and the facets' mean offset is about half their largest, so this costs ~0.4 % of force.
A file indenter (file_face) is not remeshed: its own triangles that can touch are the face,
exactly the surface the solver's gap measures.
The footprint may extend past the printed face (the solver's contact is against the kind's
unbounded analytic surface, `Indenter.gap`): outside the face box the face is continued as
its base plane (surface_y at the clipped point, which is the base plane there because every
dot lies `margin` inside the face), outside a sphere's or cylinder's cap as its flange.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError

KINDS = ("flat", "braille", "sphere", "cylinder", "curved")
CURVED = ("sphere", "cylinder", "curved")  # meshed up to CAP_RISE x the travel (module docstring)
CAP_RISE = 2.0
CHORD_TOL = 0.005  # facets within this fraction of the travel of a curved face (vertically)


@dataclass(frozen=True)
class Cap:
    """A curved part of the face, bounded by a kink: a spherical cap (a Braille dot, a
    sphere's working cap) of sphere radius R and base radius a about (cx, cz), axis None; or a
    cylinder's strip |x| <= a (axis "z") or |z| <= a (axis "x") of radius R."""

    cx: float
    cz: float
    a: float
    R: float
    axis: str | None = None


@dataclass(frozen=True)
class IndenterFace:
    """points (n, 3) on the face at zero travel; tris (m, 3) 0-based, ordered so that the
    right-hand normal points down (-y, towards the skin)."""

    points: np.ndarray
    tris: np.ndarray
    kind: str
    caps: tuple = ()  # a sphere's or cylinder's Cap: where its flange starts (_lift)


def _lift(indenter, xz: np.ndarray, caps=()) -> np.ndarray:
    x0, x1, z0, z1 = indenter.face_box()
    x = np.clip(xz[:, 0], x0, x1)
    z = np.clip(xz[:, 1], z0, z1)
    if indenter.kind in CURVED and caps:  # past the cap's rim: its flange, at the rim's height
        c = caps[0]
        if c.axis is None:
            scale = c.a / np.maximum(np.hypot(x, z), c.a)
            x, z = x * scale, z * scale
        elif c.axis == "z":
            x = np.clip(x, -c.a, c.a)
        else:
            z = np.clip(z, -c.a, c.a)
    return np.column_stack([xz[:, 0], indenter.surface_y(x, z), xz[:, 1]])


def cap_rise(indenter, reach: float) -> float:
    """Height (mm) above its lowest point to which a sphere's or cylinder's face is meshed
    exactly: CAP_RISE x the travel, at most the printed ball's cap or the cylinder's sagitta."""
    if indenter.kind == "sphere":
        return min(CAP_RISE * reach, indenter.working_depth)
    return min(CAP_RISE * reach, indenter.sagitta)


def curved_cap(indenter, reach: float) -> Cap:
    """The exactly meshed cap of a sphere (about x = z = 0) or of a cylinder (the strip about its
    lowest line), up to cap_rise; past it the flange."""
    R, rise = float(indenter.radius), cap_rise(indenter, reach)
    a = math.sqrt(max(2.0 * R * rise - rise * rise, 0.0))
    if indenter.kind == "sphere":
        return Cap(0.0, 0.0, a, R)
    return Cap(0.0, 0.0, min(a, 0.5 * indenter.chord), R, indenter.axis)


def _caps_in(indenter, box, reach: float | None) -> list[Cap]:
    """The curved parts of the face that overlap the footprint box."""
    x0, x1, z0, z1 = box
    if indenter.kind == "braille":
        a = 0.5 * float(indenter.standard.base_diameter)
        R = float(indenter.standard.sphere_radius)
        return [Cap(float(cx), float(cz), a, R) for cx, cz in indenter.dots
                if cx + a > x0 and cx - a < x1 and cz + a > z0 and cz - a < z1]
    if indenter.kind not in CURVED:
        return []
    c = curved_cap(indenter, reach)
    ax, az = (c.a, c.a) if c.axis is None else (c.a, math.inf) if c.axis == "z" else (math.inf, c.a)
    return [c] if ax > x0 and -ax < x1 and az > z0 and -az < z1 else []


def curved_cap_size(cap: Cap, reach: float) -> float:
    """Facet size (mm, in plan) on a sphere's or cylinder's cap for facets within CHORD_TOL x
    reach of the surface (vertically). A facet of plan size s on a graph of curvature k sags
    ~ k s^2 / 8 below it; here k = 1 / (R cos^3) at the rim, where the slope's cosine is
    cos = sqrt(R^2 - a^2) / R and the size is cos x the cap's (the rim refinement of
    indenter_face), with a safety factor 2 for gmsh's irregular triangles: the cap's size
    is sqrt(4 tol R cos^3) / cos. Towards the pole the error falls (to tol x cos)."""
    tol = CHORD_TOL * reach
    cos = max(math.sqrt(max(cap.R * cap.R - cap.a * cap.a, 0.0)) / cap.R, 0.2)
    return math.sqrt(4.0 * tol * cap.R * cos ** 3) / cos


def indenter_face(indenter, box: tuple[float, float, float, float], h: float,
                  h_dot: float | None = None, reach: float | None = None) -> IndenterFace:
    """Triangulate the face of `indenter` over the footprint box (xmin, xmax, zmin, zmax) at
    size h, the Braille caps at h_dot (default min(h / 2, base radius / 16)), a sphere's or
    cylinder's cap at h_dot (default curved_cap_size: within CHORD_TOL x reach). reach: the
    travel (mm) the face must cover (needed for a sphere or cylinder: how far up it is meshed)."""
    from tactileskin.mesh import _gmsh

    if indenter.kind not in KINDS:
        raise ParameterError("indenter", indenter.kind, ", ".join(KINDS) + " for a 3D deck",
                             "a file indenter's face is its own triangles (file_face)")
    x0, x1, z0, z1 = (float(v) for v in box)
    if not (x1 > x0 and z1 > z0):
        raise ParameterError("box", box, "xmin < xmax and zmin < zmax (mm)")
    if not h > 0.0:
        raise ParameterError("h", h, "a positive element size (mm)")
    if indenter.kind in CURVED and not (reach is not None and math.isfinite(reach) and reach > 0.0):
        raise ParameterError("reach", reach, f"a positive travel (mm) for the {indenter.kind} indenter's face")
    caps = _caps_in(indenter, (x0, x1, z0, z1), reach)
    dots = [c for c in caps if c.axis is None]
    strips = [c for c in caps if c.axis is not None]
    if h_dot is None:
        if indenter.kind == "braille":
            h_dot = min(0.5 * h, dots[0].a / 16.0) if dots else h
        else:
            h_dot = min(h, curved_cap_size(caps[0], reach)) if caps else h
    params = {"kind": indenter.kind, "box": (x0, x1, z0, z1), "h": h, "h_dot": h_dot, "caps": len(caps)}
    with _gmsh.session("indenter_face", params) as gmsh:
        occ = gmsh.model.occ
        rect = occ.addRectangle(x0, z0, 0.0, x1 - x0, z1 - z0)
        disks = [occ.addDisk(c.cx, c.cz, 0.0, c.a, c.a) for c in dots]
        # a cylinder's strip, clipped to the box: its long sides are the kink lines
        sbox = [(max(x0, -c.a), min(x1, c.a), z0, z1) if c.axis == "z" else (x0, x1, max(z0, -c.a), min(z1, c.a))
                for c in strips]
        disks += [occ.addRectangle(b[0], b[2], 0.0, b[1] - b[0], b[3] - b[2]) for b in sbox]
        # a sphere's pole, a cylinder's lowest line: nodes where it first touches the skin
        low = []
        if indenter.kind in CURVED and caps:
            if strips and strips[0].axis == "z" and x0 < 0.0 < x1:
                low = [(1, occ.addLine(occ.addPoint(0.0, z0, 0.0), occ.addPoint(0.0, z1, 0.0)))]
            elif strips and strips[0].axis == "x" and z0 < 0.0 < z1:
                low = [(1, occ.addLine(occ.addPoint(x0, 0.0, 0.0), occ.addPoint(x1, 0.0, 0.0)))]
            elif not strips and x0 < 0.0 < x1 and z0 < 0.0 < z1:
                low = [(0, occ.addPoint(0.0, 0.0, 0.0))]
        if disks:  # the base circles become edges of the face's triangulation (the kink)
            occ.fragment([(2, rect)], [(2, d) for d in disks] + low)
            # a disk crossing the box edge leaves a piece outside it: not part of the face
            outside = [(2, t) for _, t in occ.getEntities(2)
                       if not (x0 <= occ.getCenterOfMass(2, t)[0] <= x1 and z0 <= occ.getCenterOfMass(2, t)[1] <= z1)]
            if outside:
                occ.remove(outside, recursive=True)
        occ.synchronize()
        fields = []
        fld = gmsh.model.mesh.field
        for c in dots:
            f = fld.add("Ball")
            for k, v in (("XCenter", c.cx), ("YCenter", c.cz), ("ZCenter", 0.0), ("Radius", c.a + h_dot),
                         ("Thickness", 4.0 * h), ("VIn", h_dot), ("VOut", h)):
                fld.setNumber(f, k, v)
            fields.append(f)
        for b in sbox:
            f = fld.add("Box")
            for k, v in (("XMin", b[0] - h_dot), ("XMax", b[1] + h_dot), ("YMin", b[2] - h_dot),
                         ("YMax", b[3] + h_dot), ("ZMin", -1.0), ("ZMax", 1.0), ("Thickness", 4.0 * h),
                         ("VIn", h_dot), ("VOut", h)):
                fld.setNumber(f, k, v)
            fields.append(f)
        rims = [c for _, c in gmsh.model.getEntities(1) if gmsh.model.getType(1, c) != "Line"]  # the base circles
        for cap in strips:  # the strip's kink lines (inside the box: not its edges)
            ax = 0 if cap.axis == "z" else 1
            for _, t in gmsh.model.getEntities(1):
                bb = gmsh.model.getBoundingBox(1, t)
                lo, hi = bb[ax], bb[ax + 3]
                edge = (x0, x1) if ax == 0 else (z0, z1)
                if abs(hi - lo) < 1e-6 and abs(abs(0.5 * (lo + hi)) - cap.a) < 1e-6 and min(abs(lo - e) for e in edge) > 1e-6:
                    rims.append(t)
        if rims:
            # the cap steepens towards its rim (slope rho / sqrt(R^2 - rho^2), 2.4 at a Standard
            # American dot's rim): a facet's plan size there must shrink by the cosine of the
            # slope, sqrt(R^2 - rho^2) / R, for the same chord on the sphere
            R, a = caps[0].R, caps[0].a
            cos_rim = math.sqrt(max(R * R - a * a, 0.0)) / R
            dist = fld.add("Distance")
            fld.setNumbers(dist, "CurvesList", rims)
            # a cylinder's rim line (the slab's length): samples at most half its facet size apart
            longest = max([z1 - z0 if c.axis == "z" else x1 - x0 for c in strips], default=0.0)
            fld.setNumber(dist, "Sampling", max(200, math.ceil(2.0 * longest / (max(cos_rim, 0.2) * h_dot))))
            thr = fld.add("Threshold")
            for k, v in (("InField", dist), ("SizeMin", max(cos_rim, 0.2) * h_dot), ("SizeMax", h_dot),
                         ("DistMin", 0.0), ("DistMax", 0.5 * a), ("StopAtDistMax", 1)):
                fld.setNumber(thr, k, v)
            fields.append(thr)
        if fields:
            fmin = gmsh.model.mesh.field.add("Min")
            gmsh.model.mesh.field.setNumbers(fmin, "FieldsList", fields)
            gmsh.model.mesh.field.setAsBackgroundMesh(fmin)
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.2 * h_dot)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0 if fields else 1)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        etypes, _, enodes = gmsh.model.mesh.getElements(2)
    xyz = np.asarray(coords, float).reshape(-1, 3)
    index = {int(t): i for i, t in enumerate(tags)}
    tri = [np.asarray(n, np.int64).reshape(-1, 3) for t, n in zip(etypes, enodes) if t == _gmsh.TRI3]
    tris = np.vectorize(index.__getitem__)(np.concatenate(tri))
    used = np.unique(tris)  # gmsh keeps geometry points that no triangle uses only rarely
    remap = np.full(len(xyz), -1, np.int64)
    remap[used] = np.arange(len(used))
    xz = xyz[used][:, :2]
    tris = remap[tris]
    flange = (curved_cap(indenter, reach),) if indenter.kind in CURVED else ()
    pts = _lift(indenter, xz, flange)
    # orient: right-hand normal along -y (the lifted face is a graph over (x, z))
    n_y = np.cross(pts[tris[:, 1]] - pts[tris[:, 0]], pts[tris[:, 2]] - pts[tris[:, 0]])[:, 1]
    tris[n_y > 0] = tris[n_y > 0][:, [0, 2, 1]]
    return IndenterFace(points=pts, tris=tris, kind=indenter.kind, caps=flange)


def file_face(indenter, box: tuple[float, float, float, float], reach: float) -> IndenterFace:
    """A file indenter's own triangles (the surface the solver's gap measures, so no chord
    error) that reach below y0 + CAP_RISE x reach (what the skin can touch, as a sphere's cap)
    and overlap the footprint box. They are thickened upwards into wedges (wedge_cells), so each
    must face the skin (outward normal's y < 0): walls or overhangs there are refused."""
    if not (reach is not None and math.isfinite(reach) and reach > 0.0):
        raise ParameterError("reach", reach, "a positive travel (mm) for the file indenter's face")
    x0, x1, z0, z1 = (float(v) for v in box)
    tri = indenter.vertices[indenter.faces]
    keep = ((tri[:, :, 1].min(axis=1) <= indenter.y0 + CAP_RISE * reach)
            & (tri[:, :, 0].max(axis=1) >= x0) & (tri[:, :, 0].min(axis=1) <= x1)
            & (tri[:, :, 2].max(axis=1) >= z0) & (tri[:, :, 2].min(axis=1) <= z1))
    faces = indenter.faces[keep]
    n = np.cross(tri[keep, 1] - tri[keep, 0], tri[keep, 2] - tri[keep, 0])  # outward (file._read)
    up = n[:, 1] >= -1e-3 * np.linalg.norm(n, axis=1)  # vertical within 0.06 degrees, or facing up
    if up.any() or not len(faces):
        at = tri[keep][up].mean(axis=1)[0] if up.any() else None
        raise ParameterError("indenter_file", indenter.file,
                             "a surface facing the skin (down) everywhere within "
                             f"{CAP_RISE * reach:g} mm above its lowest point, for a deck",
                             f"{int(up.sum())} of its triangles there face sideways or up (walls, overhangs), "
                             f"the first near ({at[0]:.3g}, {at[1]:.3g}, {at[2]:.3g}) mm; such faces are not "
                             "written to decks yet" if up.any() else "no triangle of it lies over the skin")
    used, tris = np.unique(faces, return_inverse=True)
    tris = tris.reshape(-1, 3)  # the outward normal points down: already right-hand along -y
    return IndenterFace(points=indenter.vertices[used].copy(), tris=tris, kind=indenter.kind)


def max_chord_error(face: IndenterFace, indenter, samples: int = 3) -> float:
    """Largest |y_facet - y_true| (mm) at interior points of the facets (barycentric grid):
    how far the faceted face departs from the kind's surface, its flange past a sphere's or
    cylinder's cap included (tests, deck info)."""
    w = [(i, j, samples - i - j) for i in range(1, samples) for j in range(1, samples - i)]
    if not w:
        return 0.0
    W = np.array(w, float) / samples
    P = np.einsum("wk,tkd->twd", W, face.points[face.tris]).reshape(-1, 3)
    xz = P[:, [0, 2]]
    return float(np.max(np.abs(P[:, 1] - _lift(indenter, xz, face.caps)[:, 1])))


def wedge_cells(face: IndenterFace, height: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """The face thickened upwards into 6-node wedges (C3D6): points (2n, 3) (face nodes, then
    the same shifted +height in y) and cells (m, 6) with positive volume, so that the wedge's
    face S1 (nodes 1-2-3) is the working face with its outward normal towards the skin."""
    if not height > 0.0 or not math.isfinite(height):
        raise ParameterError("height", height, "a positive wedge height (mm)")
    n = len(face.points)
    top = face.points + np.array([0.0, height, 0.0])
    # positive volume wants 1-2-3 counter-clockwise seen from 4-5-6 (right-hand normal +y):
    # the face triangles reversed; face S1's outward normal is then -y, towards the skin
    t = face.tris[:, [0, 2, 1]]
    cells = np.column_stack([t, t + n])
    return np.concatenate([face.points, top]), cells
