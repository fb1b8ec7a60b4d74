"""The flat pad (skins.pad), meshed by gmsh: 2D half section x in [0, W/2], y in [0, t]
(plane strain), or the 3D block over z in [0, L/2] (z-symmetric indenter: `end_back` is the
mid-plane) or [-L/2, L/2] (free ends). An indenter not mirror-symmetric about x = 0 (e.g. a
Braille text with dots on one side only) gets the full width x in [-W/2, W/2] (no
`symmetry` boundary, both sides `side`): a half model would solve its mirror image too. The same size plan and fields as the fingertip
(mesh.sizing: fine under the contact, fine along the bonded surface for s <= ROI_S, graded;
3D Braille: fine only in balls at each dot's contact point and on the bonded surface under it,
sizing.local_plan).

Boundaries: `bone_interface` (y = 0, bonded to the board), `outer_surface` (y = t), `symmetry`
(x = 0), `side` (x = W/2, free), and in 3D `end_front` (z = L/2), `end_back`. All faces are
planar, so straight P2 mid-nodes are exact (no snapping).
"""

from __future__ import annotations

import dataclasses
import logging
import time

import numpy as np

from tactileskin.errors import MeshError, ParameterError
from tactileskin.mesh import _gmsh, sizing
from tactileskin.mesh.skinmesh import SkinMesh, check_quality, jacobian_ratio

logger = logging.getLogger(__name__)

NAMES_2D = ("bone_interface", "outer_surface", "symmetry", "side")
NAMES_3D = NAMES_2D + ("end_front", "end_back")


def _add_rectangle(gmsh, w2: float, t: float, roi_s: float, full: bool = False) -> dict[str, list[int]]:
    """The section's curves: the half x in [0, w2] (left edge `symmetry`), or with `full` the
    whole width [-w2, w2] (both edges `side`); the bottom split at |x| = roi_s when shorter
    than the pad."""
    occ = gmsh.model.occ
    x0 = -w2 if full else 0.0
    p00, p10 = occ.addPoint(x0, 0, 0), occ.addPoint(w2, 0, 0)
    p11, p01 = occ.addPoint(w2, t, 0), occ.addPoint(x0, t, 0)
    cuts = [x for x in ((-roi_s,) if full else ()) + (roi_s,) if x0 + 1e-9 < x < w2 - 1e-9]
    pts = [p00, *(occ.addPoint(x, 0, 0) for x in cuts), p10]
    bottom = [occ.addLine(a, b) for a, b in zip(pts[:-1], pts[1:])]
    # the ROI pieces: those between the cuts around x = 0 (all of it when nothing is cut)
    xs = [x0, *cuts, w2]
    roi = [c for c, a, b in zip(bottom, xs[:-1], xs[1:]) if a >= -roi_s - 1e-9 and b <= roi_s + 1e-9] or bottom
    side, top, left = occ.addLine(p10, p11), occ.addLine(p11, p01), occ.addLine(p01, p00)
    loop = occ.addCurveLoop([*bottom, side, top, left])
    surf = occ.addPlaneSurface([loop])
    edges = {"symmetry": [], "side": [side, left]} if full else {"symmetry": [left], "side": [side]}
    return {"bone_interface": bottom, "outer_surface": [top], **edges, "interface_roi": roi, "surface": [surf]}


def pad_plan(scene, section=None, *, mesh_size: float | None = None, refinement: float | None = None,
             order: int | None = None, use_z_symmetry: bool = True, local: bool = True):
    """(sizing plan, z-symmetric) of build_pad_mesh's mesh, without meshing: ParameterError if
    it exceeds the dofs cap (sizing.plan)."""
    from tactileskin.geometry.indenters import indenter_symmetry

    section = scene.section() if section is None else section
    dim = scene.dim
    zsym = indenter_symmetry(scene)[1] and use_z_symmetry and dim == 3
    plan = sizing.plan(scene, section, mesh_size=mesh_size, refinement=refinement, dim=dim,
                       length=section.length if dim == 3 else None, z_symmetric=zsym,
                       order=scene.order if order is None else order, local=local)
    return plan, zsym


def build_pad_mesh(scene, section=None, *, mesh_size: float | None = None, refinement: float | None = None,
                   order: int | None = None, cell: str = "tri", use_z_symmetry: bool = True,
                   local: bool = True) -> SkinMesh:
    """Mesh the pad of `scene` (2D or 3D by scene.dim). 3D Braille: fine only at the dots
    (sizing.local_plan); local=False refines the whole contact strip and bonded ROI instead."""
    from tactileskin.geometry.indenters import indenter_symmetry

    section = scene.section() if section is None else section
    order = scene.order if order is None else order
    dim = scene.dim
    if cell not in ("tri", "quad") or (cell == "quad" and dim == 3):
        raise ParameterError("cell", cell, "'tri' or 'quad' in 2D, 'tri' in 3D")
    w2, t = section.half_width, section.thickness
    length = section.length
    xsym, _ = indenter_symmetry(scene)
    full = not xsym  # a half model with a symmetry plane would solve the mirrored indenter too
    plan, zsym = pad_plan(scene, section, mesh_size=mesh_size, refinement=refinement, order=order,
                          use_z_symmetry=use_z_symmetry, local=local)
    z0, z1 = (0.0, 0.5 * length) if zsym else (-0.5 * length, 0.5 * length)
    params = {"skin": "pad", "width": section.width, "thickness": t, "order": order, "cell": cell,
              "full_width": full,
              **({"length": length, "z_symmetric": zsym} if dim == 3 else {}), **plan.as_dict()}
    logger.info("meshing the %dD pad: %s", dim, params)
    t0 = time.perf_counter()
    with _gmsh.session(f"pad{dim}d", params) as gmsh:
        occ = gmsh.model.occ
        tags = _add_rectangle(gmsh, w2, t, plan.roi_s, full)
        if dim == 2:
            occ.synchronize()
            groups = {n: tags[n] for n in NAMES_2D if tags[n]}
            for name, ents in groups.items():
                gmsh.model.addPhysicalGroup(1, ents, name=name)
            gmsh.model.addPhysicalGroup(2, tags["surface"], name="skin")
            sizing.apply_fields(gmsh, plan, tags["outer_surface"], tags["interface_roi"], dim=2, full_width=full)
            if cell == "quad":
                gmsh.option.setNumber("Mesh.Algorithm", 8)
                gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 2)
                gmsh.model.mesh.setRecombine(2, tags["surface"][0])
            else:
                gmsh.option.setNumber("Mesh.Algorithm", 6)
        else:
            out = occ.extrude([(2, tags["surface"][0])], 0.0, 0.0, z1 - z0)
            vol = [v for d, v in out if d == 3]
            if z0 != 0.0:
                occ.translate([(3, v) for v in vol], 0.0, 0.0, z0)
            occ.synchronize()
            groups = {k: [] for k in NAMES_3D}
            roi_faces = []
            for _, f in gmsh.model.getBoundary([(3, v) for v in vol], oriented=False):
                c = np.array(occ.getCenterOfMass(2, f))
                tol = 1e-9 * max(w2, t, length)
                name = ("end_back" if abs(c[2] - z0) < tol else "end_front" if abs(c[2] - z1) < tol
                        else "bone_interface" if abs(c[1]) < tol else "outer_surface" if abs(c[1] - t) < tol
                        else "side" if abs(abs(c[0]) - w2) < tol else "symmetry" if abs(c[0]) < tol and not full
                        else None)
                if name is None:
                    raise MeshError(f"cannot identify pad face {f} (centre {c}) with {params}")
                groups[name].append(f)
                if name == "bone_interface" and abs(c[0]) < plan.roi_s:
                    roi_faces.append(f)
            groups = {k: v for k, v in groups.items() if v}
            for name, ents in groups.items():
                gmsh.model.addPhysicalGroup(2, ents, name=name)
            gmsh.model.addPhysicalGroup(3, vol, name="skin")
            sizing.apply_fields(gmsh, plan, groups["outer_surface"], roi_faces, dim=3, full_width=full)
            gmsh.option.setNumber("Mesh.Algorithm", 6)
            gmsh.option.setNumber("Mesh.Algorithm3D", 10)
        gmsh.model.mesh.generate(dim)
        quality = _gmsh.shape_quality(gmsh, dim)
        if order == 2:
            gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)  # planar faces: straight mid-nodes are exact
            gmsh.model.mesh.setOrder(2)
        mesh, boundaries = _gmsh.to_skfem(gmsh, dim, order, groups, cell=cell)
    mesh = dataclasses.replace(mesh, _boundaries=boundaries) if dim == 3 else mesh.with_boundaries(boundaries)
    quality.update(elements=int(mesh.nelements), nodes=int(mesh.doflocs.shape[1]),
                   vertices=int(mesh.nvertices), min_scaled_jacobian=jacobian_ratio(mesh),
                   wall_s=time.perf_counter() - t0)
    logger.info("pad mesh: %(elements)d cells, %(nodes)d nodes, min SICN %(min_sicn).3f", quality)
    check_quality(quality, plan.as_dict())
    return SkinMesh(mesh=mesh, boundaries=boundaries, dim=dim, quality=quality, section=section,
                    z_symmetric=zsym, length=length if dim == 3 else None, sizes=plan.as_dict())
