"""A quarter block graded towards one corner of its top face (3D contact verification).

The block is x in [0, L], y in [-L, 0], z in [0, L]; the point load sits at the origin, a
corner of the top face y = 0 where the two symmetry planes x = 0 and z = 0 meet. Tetrahedra
of size `h` within the distance `r_fine` of the origin, growing linearly with the distance
(slope `grade`, ~ the ratio of neighbouring sizes minus one) up to `h_max`.

Boundaries: `top` (y = 0), `bottom` (y = -L), `sym_x` (x = 0), `sym_z` (z = 0), `side_x`
(x = L), `side_z` (z = L).
"""

from __future__ import annotations

import logging

import numpy as np

from tactileskin.errors import ParameterError
from tactileskin.mesh import _gmsh

logger = logging.getLogger(__name__)

FACES = ("top", "bottom", "sym_x", "sym_z", "side_x", "side_z")


def _check(name, value, lo, hint):
    if not (np.isfinite(value) and value > lo):
        raise ParameterError(name, value, f"> {lo:g}", hint)


def build_quarter_block(size: float, h: float, r_fine: float, *, grade: float = 0.3,
                        h_max: float | None = None, order: int = 2):
    """(mesh, boundaries) of the graded quarter block (scikit-fem MeshTet1/MeshTet2)."""
    _check("size", size, 0.0, "the block edge in mm")
    _check("h", h, 0.0, "the element size at the load point in mm")
    if not (np.isfinite(r_fine) and r_fine >= 0.0):
        raise ParameterError("r_fine", r_fine, ">= 0", "the radius of the uniformly fine zone in mm")
    _check("grade", grade, 0.0, "the growth of the element size per unit distance, e.g. 0.3")
    if h >= size:
        raise ParameterError("h", h, f"< size ({size:g} mm)", "the fine size must be below the block size")
    if order not in (1, 2):
        raise ParameterError("order", order, "1 or 2")
    h_max = 0.25 * size if h_max is None else h_max
    params = {"size": size, "h": h, "r_fine": r_fine, "grade": grade, "h_max": h_max, "order": order}
    with _gmsh.session("quarter_block", params) as gmsh:
        occ = gmsh.model.occ
        vol = occ.addBox(0.0, -size, 0.0, size, size, size)
        occ.synchronize()
        faces = {k: [] for k in FACES}
        where = {"top": (1, 0.0), "bottom": (1, -size), "sym_x": (0, 0.0), "sym_z": (2, 0.0),
                 "side_x": (0, size), "side_z": (2, size)}
        for _, s in gmsh.model.getBoundary([(3, vol)], oriented=False):
            c = occ.getCenterOfMass(2, s)
            # a face's centre lies on its own plane and mid-way along the other two axes
            name = next(k for k, (axis, v) in where.items() if abs(c[axis] - v) < 1e-9 * size)
            faces[name].append(s)
        for name in FACES:
            gmsh.model.addPhysicalGroup(2, faces[name], name=name)
        gmsh.model.addPhysicalGroup(3, [vol], name="block")
        corner = [t for _, t in gmsh.model.getEntities(0)
                  if np.allclose(gmsh.model.getValue(0, t, []), 0.0, atol=1e-9 * size)]
        f = gmsh.model.mesh.field
        dist = f.add("Distance")
        f.setNumbers(dist, "PointsList", corner)
        thr = f.add("Threshold")
        f.setNumber(thr, "InField", dist)
        f.setNumber(thr, "SizeMin", h)
        f.setNumber(thr, "SizeMax", h_max)
        f.setNumber(thr, "DistMin", r_fine)
        f.setNumber(thr, "DistMax", r_fine + (h_max - h) / grade)
        f.setAsBackgroundMesh(thr)
        for opt in ("MeshSizeExtendFromBoundary", "MeshSizeFromPoints", "MeshSizeFromCurvature"):
            gmsh.option.setNumber(f"Mesh.{opt}", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.option.setNumber("Mesh.Algorithm3D", 10)
        gmsh.model.mesh.generate(3)
        if order == 2:
            gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)  # flat faces: straight mid-nodes
            gmsh.model.mesh.setOrder(2)
        mesh, boundaries = _gmsh.to_skfem(gmsh, 3, order, faces)
    logger.info("quarter block: %d tetrahedra, %d nodes (%s)", mesh.nelements, mesh.doflocs.shape[1], params)
    return mesh, boundaries
