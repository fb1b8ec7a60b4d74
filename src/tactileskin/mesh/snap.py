"""Place boundary nodes of the slab exactly on the analytic outer contour and bone interface.

gmsh's own second-order projection onto the extruded spline surfaces costs seconds per
10^4 tetrahedra, so the 3D slab is made with straight second-order edges and its boundary
nodes are moved here: vertices to their closest point on the curve (a ~1e-9 mm correction,
they already lie on gmsh's spline), edge mid-nodes to the curve point at the mean curve
parameter of the edge's end vertices (z: the mean z). Both lateral surfaces are cylinders
over a planar curve, so this is a point of the true surface.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def curve_parameter(curve, p: np.ndarray, u_max: float) -> np.ndarray:
    """Parameter u in [0, u_max] of the closest curve point to each p (n, 2): a dense-table
    guess refined by Newton on (C(u) - p) . C'(u) = 0 with central differences."""
    u_tab = np.linspace(0.0, u_max, 4001)
    _, k = cKDTree(curve(u_tab)).query(p)
    u = u_tab[k]
    h = 1e-5
    for _ in range(6):
        c, cp, cm = curve(u), curve(u + h), curve(u - h)
        d1 = (cp - cm) / (2 * h)
        d2 = (cp - 2 * c + cm) / h ** 2
        g = np.einsum("ij,ij->i", c - p, d1)
        dg = np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", c - p, d2)
        u = np.clip(u - g / dg, 0.0, u_max)
    return u


def snap_boundary_nodes(mesh, boundaries: dict, section) -> np.ndarray:
    """Node coordinates (doflocs) of the (3D, P2) skfem mesh with the outer-surface and
    bone-interface nodes moved onto the analytic curves."""
    ft = section.fingertip
    p = mesh.doflocs.copy()
    curves = {"outer_surface": (ft.outer, section.u_outer_end),
              "bone_interface": (section.interface, section.u_interface_end)}
    u_v = {}
    for name, (curve, u_max) in curves.items():
        verts = np.unique(mesh.facets[:, boundaries[name]])
        u_v[name] = np.zeros(p.shape[1])
        u_v[name][verts] = curve_parameter(curve, p[:2, verts].T, u_max)
        p[:2, verts] = curve(u_v[name][verts]).T
    if mesh.dofs.edge_dofs.shape[0]:
        # every other edge stays straight: mid-node = midpoint of the (moved) end vertices
        p[:, mesh.dofs.edge_dofs[0]] = p[:, mesh.edges].mean(axis=1)
        for name, (curve, _) in curves.items():
            edges = np.unique(mesh.f2e[:, boundaries[name]])
            ends = mesh.edges[:, edges]
            mid = mesh.dofs.edge_dofs[0, edges]
            p[:2, mid] = curve(u_v[name][ends].mean(axis=0)).T
            p[2, mid] = p[2, ends].mean(axis=0)
    return p
