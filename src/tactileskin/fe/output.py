"""Post-processing of a converged state into a Result (pressure along a path, contact, reaction)."""

from __future__ import annotations

import numpy as np

from tactileskin.errors import ConvergenceError
from tactileskin.fe import kernels
from tactileskin.fe.model import Evaluation, Model
from tactileskin.fe.recovery import Projector
from tactileskin.results import Result

_VTK_CELL = {(2, 6): "triangle6", (2, 3): "triangle", (3, 10): "tetra10", (3, 4): "tetra",
             (2, 9): "quad9", (2, 4): "quad"}


def reaction(model: Model, ev: Evaluation, names=None) -> np.ndarray:
    """Resultant force (m,) that the Dirichlet boundaries (all, or those named) exert on the body."""
    dofs = model.fixed
    if names is not None:
        dofs = np.unique(np.concatenate([d for bc, d, _ in model._bc_groups if bc.boundary in names]))
    comp = dofs % model.m
    return np.bincount(comp, weights=ev.fint[dofs], minlength=model.m)


def nodal_fields(model: Model, ev: Evaluation, projector: Projector | None = None) -> dict:
    """Nodal (projected) mean pressure and Cauchy stress components; displacement."""
    pj = projector or Projector(model)
    sig = model.stress(ev)
    P = kernels.mean_pressure(sig)
    out = {"pressure": pj.project(P)}
    names = ["sxx", "syy", "szz", "sxy", "syz", "sxz"]
    idx = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]
    for n, (i, j) in zip(names, idx):
        if model.m == 2 and n in ("syz", "sxz"):
            continue
        out[n] = pj.project(sig[..., i, j])
    out["displacement"] = model.u.reshape(-1, model.m)
    return out


def path_profile(model: Model, nodal: np.ndarray, boundary: str, s_of_point) -> tuple[np.ndarray, np.ndarray]:
    """(s, values) at the scalar dofs of a named boundary, sorted by s = s_of_point(reference xy)."""
    sd = model.facet_scalar_dofs(boundary)
    X = model.basis.doflocs[:, sd].T
    s = np.asarray(s_of_point(X), float)
    order = np.argsort(s, kind="stable")
    return s[order], nodal[sd][order]


def arc_length(points: np.ndarray) -> np.ndarray:
    """A fallback s for generic meshes: distance from the point nearest x = 0, along a
    nearest-neighbour chain ordered by x (fine for open, x-monotone boundaries)."""
    order = np.argsort(points[:, 0])
    seg = np.linalg.norm(np.diff(points[order], axis=0), axis=1)
    s = np.empty(len(points))
    s[order] = np.concatenate([[0.0], np.cumsum(seg)])
    return s


def make_result(model: Model, ev: Evaluation, stats, *, s_of_point=None, path: str = "bone_interface",
                vertical: int = 1, scene: dict | None = None) -> Result:
    pj = Projector(model)
    fields = nodal_fields(model, ev, pj)
    if s_of_point is None:
        s_of_point = arc_length
    s, p = path_profile(model, fields["pressure"], path, s_of_point)
    if model.surface is not None and ev.contact is not None:
        g, lamN, x, n = ev.contact
        pc = model.surface.current_pressure(model.u, lamN)
        xs, ps = x[..., 0].ravel(), pc.ravel()
        keep = ps > 0
        order = np.argsort(xs[keep])
        cx, cp = xs[keep][order], ps[keep][order]
    else:
        cx, cp = np.zeros(0), np.zeros(0)
    r = reaction(model, ev)
    for name, v in fields.items():
        if not np.all(np.isfinite(v)):
            raise ConvergenceError(f"non-finite nodal field {name!r}", {"field": name})
    cells = model.sdofs
    X = model.basis.doflocs.T
    u = model.u.reshape(-1, model.m)
    vtk = {
        "points": X + u,
        "cells": cells,
        "cell_type": _VTK_CELL[(model.m, cells.shape[1])],
        "point_data": {k: v for k, v in fields.items()},
    }
    st = {"dofs": int(model.ndof), "free_dofs": int(len(model.free)), "elements": int(len(cells)),
          "increments": stats.increments, "newton_iterations": stats.newton_iterations,
          "cutbacks": stats.cutbacks, "uzawa_iterations": stats.uzawa_iterations,
          "wall_s": stats.wall_s, "formulation": model.formulation,
          "reaction_vector": r.tolist()}
    return Result(s=s, pressure=p, contact_x=cx, contact_pressure=cp, reaction=float(r[vertical]),
                  stats=st, fields=vtk, history=list(stats.history), scene=scene)
