"""The rounded fingertip (skins.dome) meshed by gmsh from its build123d/OCC half solid (x >= 0):
P2 tetrahedra curved onto the CAD, `mesh_size` globally and `mesh_size / refinement` in a ball
around the pulp point (0, b, 0) where indenters start. Faces are named by where their mesh
vertices lie: x = 0 `symmetry`, z = -L `end_back`, on the outer body's implicit surface
`outer_surface`, else the bone's: `bone_interface` for z <= 0 (the profile and bone-map surface)
and `bone_tip` under the dome (fixed as well).
"""

from __future__ import annotations

import logging
import tempfile
import time
from pathlib import Path

import numpy as np

from tactileskin.errors import MeshError
from tactileskin.mesh import _gmsh
from tactileskin.mesh.skinfile import mesh_occ
from tactileskin.mesh.skinmesh import SkinMesh, check_quality

logger = logging.getLogger(__name__)


def outer_level(p: np.ndarray, a: float, b: float, c: float) -> np.ndarray:
    """Implicit function of the outer body: 0 on its lateral surface and dome."""
    x, y, z = p
    return (x / a) ** 2 + (y / b) ** 2 + (np.maximum(z, 0.0) / c) ** 2 - 1.0


def build_dome_mesh(scene, *, mesh_size=None, refinement=None, order=None) -> SkinMesh:
    from tactileskin.geometry.dome_parts import skin_solid

    from tactileskin.geometry.occ import bd

    sec = scene.section()
    a, b, c, length, t = sec.a, sec.b, sec.c, sec.length, sec.thickness
    h = scene.mesh_size if mesh_size is None else mesh_size
    r = scene.refinement if refinement is None else refinement
    order = scene.order if order is None else order
    params = {"skin": "dome", "a": a, "b": b, "dome_tip": c, "dome_length": length, "thickness": t,
              "mesh_size": h, "refinement": r, "order": order}
    t0 = time.perf_counter()
    solid = skin_solid(a, b, c, length, t, half=True)
    # the solid crosses from build123d's OCC to gmsh's own OCC as a BREP file (no shared pointers)
    with tempfile.TemporaryDirectory(prefix="tactileskin-dome-") as tmp:
        brep = Path(tmp) / "skin.brep"
        bd.export_brep(solid, str(brep))
        with _gmsh.session("dome", params) as gmsh:
            gmsh.model.occ.importShapes(str(brep))
            gmsh.model.occ.synchronize()
            tol = 1e-4 * max(a, b, c, length)

            def classify(mesh, faces):
                names = {"bone_interface": [], "bone_tip": [], "outer_surface": [], "symmetry": [], "end_back": []}
                for tag, f in faces.items():
                    v = mesh.p[:, np.unique(mesh.facets[:, f])]
                    if np.all(np.abs(v[0]) < tol):
                        names["symmetry"].append(tag)
                    elif np.all(np.abs(v[2] + length) < tol):
                        names["end_back"].append(tag)
                    elif np.all(np.abs(outer_level(v, a, b, c)) < 1e-3):
                        names["outer_surface"].append(tag)
                    elif np.all(np.abs(outer_level(v, a - t, b - t, c - t)) < 1e-3):
                        # the bone under the dome is fixed too, but kept out of the bone map,
                        # whose (s, z) parametrisation degenerates at the tip
                        names["bone_tip" if np.min(v[2]) > -tol else "bone_interface"].append(tag)
                    else:
                        raise MeshError(f"dome face {tag} is on no known surface ({params})")
                return names

            mesh, boundaries, quality = mesh_occ(gmsh, "dome skin", mesh_size=h, fine=h / r,
                                                 centre=(0.0, b, 0.0), radius=max(3.0 * t, 3.0 * h / r),
                                                 order=order, classify=classify)
    quality["wall_s"] = time.perf_counter() - t0
    check_quality(quality, {"coarse": h})
    return SkinMesh(mesh=mesh, boundaries=boundaries, dim=3, quality=quality, section=sec,
                    z_symmetric=False, length=length + c, sizes={"coarse": h, "fine": h / r})
