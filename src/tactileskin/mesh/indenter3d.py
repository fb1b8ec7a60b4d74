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
The footprint may extend past the printed face (the solver's contact is against the kind's
unbounded analytic surface, `Indenter.gap`): outside the face box the face is continued as
its base plane (surface_y at the clipped point, which is the base plane there because every
dot lies `margin` inside the face).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError

KINDS = ("flat", "braille")


@dataclass(frozen=True)
class IndenterFace:
    """points (n, 3) on the face at zero travel; tris (m, 3) 0-based, ordered so that the
    right-hand normal points down (-y, towards the skin)."""

    points: np.ndarray
    tris: np.ndarray
    kind: str


def _lift(indenter, xz: np.ndarray) -> np.ndarray:
    x0, x1, z0, z1 = indenter.face_box()
    x = np.clip(xz[:, 0], x0, x1)
    z = np.clip(xz[:, 1], z0, z1)
    return np.column_stack([xz[:, 0], indenter.surface_y(x, z), xz[:, 1]])


def _dots_in(indenter, box) -> list[tuple[float, float, float]]:
    """(cx, cz, a) of the Braille dots whose base disk overlaps the footprint box."""
    if indenter.kind != "braille":
        return []
    a = 0.5 * float(indenter.standard.base_diameter)
    x0, x1, z0, z1 = box
    return [(float(cx), float(cz), a) for cx, cz in indenter.dots
            if cx + a > x0 and cx - a < x1 and cz + a > z0 and cz - a < z1]


def indenter_face(indenter, box: tuple[float, float, float, float], h: float,
                  h_dot: float | None = None) -> IndenterFace:
    """Triangulate the face of `indenter` over the footprint box (xmin, xmax, zmin, zmax) at
    size h, the Braille caps at h_dot (default min(h / 2, base radius / 16))."""
    from tactileskin.mesh import _gmsh

    if indenter.kind not in KINDS:
        raise ParameterError("indenter", indenter.kind, "flat or braille for a 3D deck",
                             "other kinds are not meshed as rigid 3D surfaces yet")
    x0, x1, z0, z1 = (float(v) for v in box)
    if not (x1 > x0 and z1 > z0):
        raise ParameterError("box", box, "xmin < xmax and zmin < zmax (mm)")
    if not h > 0.0:
        raise ParameterError("h", h, "a positive element size (mm)")
    dots = _dots_in(indenter, (x0, x1, z0, z1))
    if h_dot is None:
        h_dot = min(0.5 * h, dots[0][2] / 16.0) if dots else h
    params = {"kind": indenter.kind, "box": (x0, x1, z0, z1), "h": h, "h_dot": h_dot, "dots": len(dots)}
    with _gmsh.session("indenter_face", params) as gmsh:
        occ = gmsh.model.occ
        rect = occ.addRectangle(x0, z0, 0.0, x1 - x0, z1 - z0)
        disks = [occ.addDisk(cx, cz, 0.0, a, a) for cx, cz, a in dots]
        if disks:  # the base circles become edges of the face's triangulation (the kink)
            occ.fragment([(2, rect)], [(2, d) for d in disks])
            # a disk crossing the box edge leaves a piece outside it: not part of the face
            outside = [(2, t) for _, t in occ.getEntities(2)
                       if not (x0 <= occ.getCenterOfMass(2, t)[0] <= x1 and z0 <= occ.getCenterOfMass(2, t)[1] <= z1)]
            if outside:
                occ.remove(outside, recursive=True)
        occ.synchronize()
        fields = []
        fld = gmsh.model.mesh.field
        for cx, cz, a in dots:
            f = fld.add("Ball")
            for k, v in (("XCenter", cx), ("YCenter", cz), ("ZCenter", 0.0), ("Radius", a + h_dot),
                         ("Thickness", 4.0 * h), ("VIn", h_dot), ("VOut", h)):
                fld.setNumber(f, k, v)
            fields.append(f)
        rims = [c for _, c in gmsh.model.getEntities(1) if gmsh.model.getType(1, c) != "Line"]  # the base circles
        if rims:
            # the cap steepens towards its rim (slope rho / sqrt(R^2 - rho^2), 2.4 at a Standard
            # American dot's rim): a facet's plan size there must shrink by the cosine of the
            # slope, sqrt(R^2 - rho^2) / R, for the same chord on the sphere
            R = float(indenter.standard.sphere_radius)
            a = dots[0][2]
            cos_rim = math.sqrt(max(R * R - a * a, 0.0)) / R
            dist = fld.add("Distance")
            fld.setNumbers(dist, "CurvesList", rims)
            fld.setNumber(dist, "Sampling", 200)
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
    pts = _lift(indenter, xz)
    # orient: right-hand normal along -y (the lifted face is a graph over (x, z))
    n_y = np.cross(pts[tris[:, 1]] - pts[tris[:, 0]], pts[tris[:, 2]] - pts[tris[:, 0]])[:, 1]
    tris[n_y > 0] = tris[n_y > 0][:, [0, 2, 1]]
    return IndenterFace(points=pts, tris=tris, kind=indenter.kind)


def max_chord_error(face: IndenterFace, indenter, samples: int = 3) -> float:
    """Largest |y_facet - y_true| (mm) at interior points of the facets (barycentric grid):
    how far the faceted face departs from the kind's surface (tests, deck info)."""
    w = [(i, j, samples - i - j) for i in range(1, samples) for j in range(1, samples - i)]
    if not w:
        return 0.0
    W = np.array(w, float) / samples
    P = np.einsum("wk,tkd->twd", W, face.points[face.tris]).reshape(-1, 3)
    xz = P[:, [0, 2]]
    return float(np.max(np.abs(P[:, 1] - _lift(indenter, xz)[:, 1])))


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
