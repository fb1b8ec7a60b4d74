"""Meshes of the skin (gmsh at the edge) handed to scikit-fem with named boundaries.

`build_mesh(scene) -> SkinMesh`: the 2D plane-strain half section (scene.dim == 2) or the
3D slab (scene.dim == 3), P2 curved cells by default (scene.order). Boundaries by name:
`bone_interface`, `outer_surface`, `symmetry`, `nail_edge` (+ `end_front`, `end_back` in 3D).
"""

from __future__ import annotations

from tactileskin.errors import ParameterError
from tactileskin.mesh.skinmesh import BOUNDARIES_2D, BOUNDARIES_3D, FORMATS, SkinMesh

__all__ = ["build_mesh", "SkinMesh", "BOUNDARIES_2D", "BOUNDARIES_3D", "FORMATS"]


def build_mesh(scene, *, cell: str = "tri", **overrides) -> SkinMesh:
    """Mesh the skin of `scene`. Keyword overrides (mesh_size, refinement, order) take
    precedence over the scene's fields without changing it. cell="quad" gives a 2D
    all-quadrilateral mesh (MeshQuad2, 9-node) instead of triangles."""
    if cell not in ("tri", "quad") or (cell == "quad" and scene.dim == 3):
        raise ParameterError("cell", cell, "'tri' in 3D (tetrahedra); 'quad' is 2D only")
    if scene.dim == 3:
        from tactileskin.mesh import _gmsh

        if _gmsh.forked_after_3d_mesh():  # gmsh would wait for the parent's threads (see _gmsh)
            return _gmsh.in_fresh_process(build_mesh, scene, cell=cell, **overrides)
    return scene.skin_kind.build_mesh(scene, cell=cell, **overrides)
