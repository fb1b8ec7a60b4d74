"""3D slab of the skin: the 2D half section extruded along the finger axis z.

Symmetry: the slab is always the half x >= 0 (boundary `symmetry` is the plane x = 0). If
the indenter is mirror-symmetric about z = 0 (flat plate, cylinder, Braille dots symmetric in
z) only the half z in [0, L/2] is meshed and `end_back` is the mid-plane z = 0 (a symmetry
plane, u_z = 0; SkinMesh.z_symmetric = True); otherwise z in [-L/2, L/2] and `end_back` is
the free end z = -L/2. `end_front` is always the free end z = +L/2. L = sample length
(data/geometry/fingertip.toml).
"""

from __future__ import annotations

import dataclasses
import logging
import time

import numpy as np

from tactileskin.geometry.indenters import indenter_symmetry
from tactileskin.mesh import _gmsh, sizing
from tactileskin.mesh.section2d import add_section_curves
from tactileskin.mesh.skinmesh import (MIN_SCALED_JACOBIAN, SkinMesh, cell_jacobian_ratios, check_quality,
                                       jacobian_ratio)
from tactileskin.mesh.snap import snap_boundary_nodes

logger = logging.getLogger(__name__)


def z_symmetric(scene) -> bool:
    """True if the indenter is mirror-symmetric about the plane z = 0."""
    return indenter_symmetry(scene)[1]


def x_symmetric(scene) -> bool:
    """True if the indenter is mirror-symmetric about the plane x = 0 (assumed by the half slab)."""
    return indenter_symmetry(scene)[0]


def _unfold(mesh):
    """The mesh with the curved edges of its folded cells straight again: a cell whose
    snapped mid-nodes fold it (scaled Jacobian below skinmesh.MIN_SCALED_JACOBIAN; one cell in
    tens of thousands, where a thin sliver lies on the curved bone or outer surface: the t = 5
    sphere at 1.6 / 8 had one at -0.16) gets its mid-nodes back on the straight edges, a
    boundary that deviates from the true curve by the chord's sagitta there (~h^2 / 8R), instead of a
    refused mesh. Returns (mesh, edges straightened)."""
    ratio = cell_jacobian_ratios(mesh)
    bad = np.flatnonzero(ratio < MIN_SCALED_JACOBIAN)
    if bad.size == 0:
        return mesh, 0
    edges = np.unique(mesh.t2e[:, bad])
    p = mesh.doflocs.copy()
    p[:, mesh.dofs.edge_dofs[0, edges]] = p[:, mesh.edges[:, edges]].mean(axis=1)
    logger.info("%d folded curved cells (min scaled Jacobian %.3g): %d of their edges made straight",
                bad.size, float(ratio.min()), edges.size)
    return dataclasses.replace(mesh, doflocs=p), int(edges.size)


def slab_plan(scene, section=None, *, mesh_size: float | None = None, refinement: float | None = None,
              order: int | None = None, length: float | None = None, use_z_symmetry: bool = True,
              local: bool = True):
    """(sizing plan, slab length, z-symmetric) of build_slab_mesh's mesh, without meshing:
    ParameterError if it exceeds the dofs cap (sizing.plan)."""
    section = scene.section() if section is None else section
    length = section.fingertip.sample_length if length is None else length
    zsym = use_z_symmetry and z_symmetric(scene)
    plan = sizing.plan(scene, section, mesh_size=mesh_size, refinement=refinement, dim=3, length=length,
                       z_symmetric=zsym, order=scene.order if order is None else order, local=local)
    return plan, length, zsym


def build_slab_mesh(scene, section=None, *, mesh_size: float | None = None,
                    refinement: float | None = None, order: int | None = None,
                    length: float | None = None, use_z_symmetry: bool = True,
                    local: bool = True) -> SkinMesh:
    """Mesh the 3D slab of `scene` (P2 tetrahedra with curved faces by default). Braille:
    local refinement at the dots (sizing.local_plan); local=False refines the whole contact
    strip and bone ROI instead (the former plan, kept for comparisons)."""
    section = scene.section() if section is None else section
    order = scene.order if order is None else order
    if not x_symmetric(scene):
        logger.warning("the indenter (%s) is not symmetric about x = 0, but the slab is the half "
                       "x >= 0 with a symmetry plane there", scene.indenter_label())
    plan, length, zsym = slab_plan(scene, section, mesh_size=mesh_size, refinement=refinement, order=order,
                                   length=length, use_z_symmetry=use_z_symmetry, local=local)
    z0, z1 = (0.0, 0.5 * length) if zsym else (-0.5 * length, 0.5 * length)
    params = {"thickness": section.thickness, "order": order, "length": length, "z_symmetric": zsym,
              **plan.as_dict()}
    logger.info("meshing 3D slab: %s", params)
    t0 = time.perf_counter()
    with _gmsh.session("slab3d", params) as gmsh:
        occ = gmsh.model.occ
        tags = add_section_curves(gmsh, section, plan.roi_s)
        occ.synchronize()
        com = {c: np.array(occ.getCenterOfMass(1, c)[:2])
               for name in ("outer_surface", "nail_edge", "bone_interface", "symmetry") for c in tags[name]}
        out = occ.extrude([(2, tags["surface"][0])], 0.0, 0.0, z1 - z0)
        vol = [t for d, t in out if d == 3]
        if z0 != 0.0:
            occ.translate([(3, v) for v in vol], 0.0, 0.0, z0)
        occ.synchronize()
        faces = {k: [] for k in ("outer_surface", "nail_edge", "bone_interface", "symmetry",
                                 "end_front", "end_back", "interface_roi")}
        curve_name = {c: n for n in ("outer_surface", "nail_edge", "bone_interface", "symmetry")
                      for c in tags[n]}
        for _, s in gmsh.model.getBoundary([(3, v) for v in vol], oriented=False):
            c = np.array(occ.getCenterOfMass(2, s))
            if abs(c[2] - z0) < 1e-9:
                faces["end_back"].append(s)
            elif abs(c[2] - z1) < 1e-9:
                faces["end_front"].append(s)
            else:  # a lateral face: swept from the curve with the same (x, y) centre of mass
                src = min(com, key=lambda k: np.linalg.norm(com[k] - c[:2]))
                if np.linalg.norm(com[src] - c[:2]) > 1e-6:
                    raise _gmsh.MeshError(f"cannot identify slab face {s} (centre {c}) with {params}")
                faces[curve_name[src]].append(s)
                if src in tags["interface_roi"]:
                    faces["interface_roi"].append(s)
        names = ("bone_interface", "outer_surface", "symmetry", "nail_edge", "end_front", "end_back")
        for name in names:
            gmsh.model.addPhysicalGroup(2, faces[name], name=name)
        gmsh.model.addPhysicalGroup(3, vol, name="skin")
        sizing.apply_fields(gmsh, plan, faces["outer_surface"], faces["interface_roi"], dim=3)
        gmsh.option.setNumber("Mesh.Algorithm", 6)
        gmsh.option.setNumber("Mesh.Algorithm3D", 10)  # HXT: fastest here, best min SICN
        gmsh.model.mesh.generate(3)
        quality = _gmsh.shape_quality(gmsh, 3)
        if order == 2:
            # straight mid-nodes here (fast); snap.py puts the boundary ones on the true surfaces
            gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)
            gmsh.model.mesh.setOrder(2)
        mesh, boundaries = _gmsh.to_skfem(gmsh, 3, order, {n: faces[n] for n in names})
    # one rebuild of the skfem mesh: snapped nodes and the named boundaries together
    doflocs = snap_boundary_nodes(mesh, boundaries, section) if order == 2 else mesh.doflocs
    mesh = dataclasses.replace(mesh, doflocs=doflocs, _boundaries=boundaries)
    mesh, straightened = _unfold(mesh) if order == 2 else (mesh, 0)
    quality.update(elements=int(mesh.nelements), nodes=int(mesh.doflocs.shape[1]),
                   vertices=int(mesh.nvertices), min_scaled_jacobian=jacobian_ratio(mesh),
                   straightened_edges=straightened, wall_s=time.perf_counter() - t0)
    logger.info("3D mesh: %(elements)d cells, %(nodes)d nodes, min SICN %(min_sicn).3f, "
                "min scaled Jacobian %(min_scaled_jacobian).3f", quality)
    check_quality(quality, plan.as_dict())
    return SkinMesh(mesh=mesh, boundaries=boundaries, dim=3, quality=quality, section=section,
                    z_symmetric=zsym, length=length, sizes=plan.as_dict())
