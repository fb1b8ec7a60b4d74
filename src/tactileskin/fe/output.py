"""Post-processing of a converged state into a Result (pressure along a path, contact, reaction)."""

from __future__ import annotations

import logging

import numpy as np

from tactileskin.errors import ConvergenceError, ParameterError
from tactileskin.fe import kernels
from tactileskin.fe.model import Evaluation, Model
from tactileskin.fe.recovery import PointFit, Projector
from tactileskin.results import BoneMap, Result

logger = logging.getLogger(__name__)

_VTK_CELL = {(2, 6): "triangle6", (2, 3): "triangle", (3, 10): "tetra10", (3, 4): "tetra",
             (2, 9): "quad9", (2, 4): "quad"}
# nodal Cauchy stress components of the result fields (plane strain: no syz, sxz)
STRESS_COMPONENTS = {"sxx": (0, 0), "syy": (1, 1), "szz": (2, 2), "sxy": (0, 1), "syz": (1, 2), "sxz": (0, 2)}


def reaction(model: Model, ev: Evaluation, names=None) -> np.ndarray:
    """Resultant force (m,) that the Dirichlet boundaries (all, or those named) exert on the body."""
    dofs = model.fixed
    if names is not None:
        dofs = np.unique(np.concatenate([d for bc, d, _ in model._bc_groups if bc.boundary in names]))
    comp = dofs % model.m
    return np.bincount(comp, weights=ev.fint[dofs], minlength=model.m)


def indenter_force(model: Model, ev: Evaluation) -> float:
    """The indenter's vertical force on the skin (N in 3D: on the whole indenter, the modelled
    part's reaction times its mirror copies, `Model.force_factor`; N/mm of the half section
    x >= 0 in 2D)."""
    return float(reaction(model, ev)[1]) * float(getattr(model, "force_factor", 1.0))


def nodal_fields(model: Model, ev: Evaluation, projector: Projector | None = None,
                 sig: np.ndarray | None = None) -> dict:
    """Nodal (projected) mean pressure and Cauchy stress components; displacement. `sig`:
    the Cauchy stress at the quadrature points when the caller has it already."""
    pj = projector or Projector(model)
    sig = model.stress(ev) if sig is None else sig
    P = kernels.mean_pressure(sig)
    out = {"pressure": pj.project(P)}
    for n, (i, j) in STRESS_COMPONENTS.items():
        if model.m == 2 and n in ("syz", "sxz"):
            continue
        out[n] = pj.project(sig[..., i, j])
    out["displacement"] = model.u.reshape(-1, model.m)
    return out


def path_nodes(model: Model, boundary: str, s_of_point) -> tuple[np.ndarray, np.ndarray]:
    """(scalar dofs, s) of a named boundary's nodes, sorted by s = s_of_point(reference xy)."""
    sd = model.facet_scalar_dofs(boundary)
    s = np.asarray(s_of_point(model.basis.doflocs[:, sd].T), float)
    order = np.argsort(s, kind="stable")
    return sd[order], s[order]


def _facet_nodes(model: Model, boundary: str) -> np.ndarray:
    """(F, 3) or (F, 6) scalar dofs of the facets of a named 3D boundary: vertices v0 v1 v2,
    then (P2) the mid-side nodes of edges v0v1, v1v2, v2v0 (the node order of `_tri_shape`)."""
    mesh, b = model.mesh, model.basis
    f = np.asarray(model.boundaries[boundary])
    v = mesh.facets[:, f].T                                     # (F, 3) vertex indices
    nodes = [b.dofs.nodal_dofs[0, v[:, k]] for k in range(3)]
    if b.dofs.edge_dofs.size:
        # the edge of each facet joining vertices (a, b): match on the sorted vertex pair
        key = lambda a, c: np.minimum(a, c) * mesh.nvertices + np.maximum(a, c)  # noqa: E731
        ev = mesh.edges
        ekey = key(ev[0], ev[1])
        order = np.argsort(ekey)
        for a, c in ((0, 1), (1, 2), (2, 0)):
            e = order[np.searchsorted(ekey[order], key(v[:, a], v[:, c]))]
            nodes.append(b.dofs.edge_dofs[0, e])
    return np.stack(nodes, axis=1)


def _tri_shape(xi: np.ndarray, eta: np.ndarray, n: int) -> np.ndarray:
    """(k, n) shape functions of the linear (n = 3) or quadratic (n = 6) triangle at
    reference points (xi, eta); nodes (0,0) (1,0) (0,1) [(.5,0) (.5,.5) (0,.5)]."""
    l0, l1, l2 = 1.0 - xi - eta, xi, eta
    if n == 3:
        return np.stack([l0, l1, l2], axis=-1)
    return np.stack([l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1),
                     4 * l0 * l1, 4 * l1 * l2, 4 * l2 * l0], axis=-1)


MAX_MAP_PLANES = 400  # bounds the bone map's size (rows x section samples)

_REF_TRI = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


def _plane_trace(zf: np.ndarray, zc: float, tol: float) -> list:
    """Reference points (xi, eta) where the affine interpolant of the vertex values zf (3,)
    equals zc on the triangle: [] (no cut), [p] (touches a vertex), [p, q] (a segment)."""
    f = zf - zc
    pts = []
    for i, j in ((0, 1), (1, 2), (2, 0)):
        if abs(f[i]) <= tol:
            pts.append(_REF_TRI[i])
        elif abs(f[j]) > tol and f[i] * f[j] < 0:
            t = f[i] / (f[i] - f[j])
            pts.append((1 - t) * _REF_TRI[i] + t * _REF_TRI[j])
    uniq = []
    for p in pts:
        if not any(np.allclose(p, q, atol=1e-12) for q in uniq):
            uniq.append(p)
    return uniq


def plane_profile(model: Model, nodal: np.ndarray, boundary: str, s_of_point, z: float, *,
                  per_segment: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """(s, values) of a nodal field on the trace of a 3D boundary on the plane z = const.

    Each facet of the boundary cut by the plane contributes its cut segment (between the
    points where its vertex-affine z equals `z`; exact when the facet's z is affine, as on the
    extruded slab), sampled at `per_segment` + 1 equally spaced reference points and
    evaluated with the facet's own (P1/P2) shape functions: the mesh's interpolation on that
    facet, no mixing of nodes from other z. The sampled z is corrected to the plane by
    Newton steps on the facet's geometry map. s = s_of_point((x, y)) of the mapped points.
    Points at the same s (segment ends shared by neighbouring facets) are merged (mean).
    Raises ParameterError if the plane does not cut the boundary.
    """
    if model.m != 3:
        raise ParameterError("plane_profile dimension", model.m, "3 (a 2D model has its profile on its boundary)")
    fn = _facet_nodes(model, boundary)
    X = model.basis.doflocs                                      # (3, N) node positions
    zv = X[2, fn[:, :3]]                                         # (F, 3) vertex z
    scale = float(np.ptp(X[2])) or 1.0
    tol = 1e-9 * scale
    cut = np.flatnonzero((zv.min(axis=1) <= z + tol) & (zv.max(axis=1) >= z - tol))
    n = fn.shape[1]
    refs, owners = [], []
    t = np.linspace(0.0, 1.0, per_segment + 1)
    for f in cut:
        pts = _plane_trace(zv[f], z, tol)
        if len(pts) == 2:
            refs.append(pts[0][None, :] * (1 - t)[:, None] + pts[1][None, :] * t[:, None])
            owners.append(np.full(len(t), f))
    if not refs:
        zr = (float(X[2].min()), float(X[2].max()))
        raise ParameterError("profile plane z", z, f"[{zr[0]:g}, {zr[1]:g}] mm (the slab's z range)")
    ref = np.concatenate(refs)
    own = np.concatenate(owners)
    nodes = fn[own]                                              # (k, n)
    P = X[:, nodes]                                              # (3, k, n)
    grad_z = np.stack([P[2, :, 1] - P[2, :, 0], P[2, :, 2] - P[2, :, 0]], axis=-1)  # affine part
    for _ in range(3):  # move along grad z (reference) until the P2 map's z is on the plane
        zq = np.einsum("kn,kn->k", _tri_shape(ref[:, 0], ref[:, 1], n), P[2])
        g2 = np.einsum("ki,ki->k", grad_z, grad_z)
        ref = ref - ((zq - z) / np.where(g2 > 0, g2, 1.0))[:, None] * grad_z
    N = _tri_shape(ref[:, 0], ref[:, 1], n)                      # (k, n)
    xyz = np.einsum("kn,dkn->kd", N, P)
    vals = np.einsum("kn,kn->k", N, nodal[nodes])
    s = np.asarray(s_of_point(xyz[:, :2]), float)
    # merge coincident samples (shared segment ends): group on s to 1e-9 of the path length
    order = np.argsort(s, kind="stable")
    s, vals = s[order], vals[order]
    L = max(float(s[-1] - s[0]), 1.0)
    new = np.concatenate([[True], np.diff(s) > 1e-9 * L])
    grp = np.cumsum(new) - 1
    cnt = np.bincount(grp)
    return np.bincount(grp, weights=s) / cnt, np.bincount(grp, weights=vals) / cnt


def map_planes(model: Model, boundary: str, section_z: float, dz: float | None = None,
               max_planes: int = MAX_MAP_PLANES) -> np.ndarray:
    """Sorted z of the bone map's rows: equally spaced over the boundary's z range at about
    `dz` (default: a quarter of the 5th percentile of its facets' edge lengths, i.e. of the
    fine mesh size where the surface is refined, robust to slivers; a quarter as along s,
    where `plane_profile` samples each facet cut 4 times), with at most `max_planes`
    intervals, plus the section plane `section_z` (so the section profile is a row)."""
    fn = _facet_nodes(model, boundary)
    V = model.basis.doflocs[:, fn[:, :3]]                        # (3, F, 3) vertex coordinates
    z0, z1 = float(V[2].min()), float(V[2].max())
    if dz is None:
        edges = np.linalg.norm(V - np.roll(V, 1, axis=2), axis=0)  # (F, 3)
        dz = 0.25 * float(np.percentile(edges, 5))
    if not dz > 0:
        raise ParameterError("bone map dz", dz, "> 0 mm")
    n = int(min(max(np.ceil((z1 - z0) / dz), 1), max_planes))
    tol = 1e-9 * max(z1 - z0, 1.0)
    z = np.linspace(z0, z1, n + 1)
    # linspace's rounding: on a whole slab (-5, 5) in 154 intervals the middle row is z = -8.9e-16,
    # and a peak there printed as such; the axis and the section plane are exact rows
    z[np.abs(z) <= tol] = 0.0
    near = np.abs(z - section_z) <= tol
    if near.any():
        z[near] = section_z
    else:
        z = np.sort(np.append(z, section_z))
    return z


def surface_grid(model: Model, nodal: np.ndarray, boundary: str, s_of_point, s: np.ndarray,
                 z: np.ndarray, *, iterations: int = 8) -> np.ndarray:
    """(len(z), len(s)) values of a nodal field at the points (s_i, z_j) of a 3D boundary that
    (s, z) parametrise (the bone interface of the extruded slab: s along the section, z along
    the finger).

    Each grid point is located in the facet whose vertices' (s, z) triangle holds it best
    (largest smallest barycentric coordinate), then its reference coordinates are corrected
    by chord iterations (the facet's affine (s, z) Jacobian) until the facet's own P2 geometry
    maps it to (s_i, z_j); the value is the facet's P1/P2 interpolant there, as in
    `plane_profile`. Raises ParameterError for a grid point outside the boundary.
    """
    if model.m != 3:
        raise ParameterError("bone map dimension", model.m, "3 (a 2D model has a profile, not a map)")
    s, z = np.asarray(s, float), np.asarray(z, float)
    for name, v in (("s", s), ("z", z)):
        if v.ndim != 1 or v.size < 1 or np.any(np.diff(v) <= 0):
            raise ParameterError(f"bone map {name}", f"shape {v.shape}", "a strictly increasing 1-D grid")
    fn = _facet_nodes(model, boundary)
    X = model.basis.doflocs
    F, n = fn.shape
    sv = np.asarray(s_of_point(X[:2, fn[:, :3]].reshape(2, -1).T), float).reshape(F, 3)
    zv = X[2, fn[:, :3]]
    tol_s = 1e-7 * max(float(np.ptp(sv)), 1.0)
    tol_z = 1e-7 * max(float(np.ptp(zv)), 1.0)
    # candidate (facet, grid point) pairs: the grid points inside each facet's (s, z) box
    lo_i = np.searchsorted(s, sv.min(axis=1) - tol_s, "left")
    hi_i = np.searchsorted(s, sv.max(axis=1) + tol_s, "right")
    lo_j = np.searchsorted(z, zv.min(axis=1) - tol_z, "left")
    hi_j = np.searchsorted(z, zv.max(axis=1) + tol_z, "right")
    cs, cz = hi_i - lo_i, hi_j - lo_j
    cnt = cs * cz
    fac = np.repeat(np.arange(F), cnt)
    local = np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    ii = lo_i[fac] + local % cs[fac]
    jj = lo_j[fac] + local // cs[fac]
    # affine (s, z) map of each facet: (s, z) = (s0, z0) + A (xi, eta)
    A = np.stack([np.stack([sv[:, 1] - sv[:, 0], sv[:, 2] - sv[:, 0]], -1),
                  np.stack([zv[:, 1] - zv[:, 0], zv[:, 2] - zv[:, 0]], -1)], axis=1)  # (F, 2, 2)
    det = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    ok = np.abs(det) > 1e-12 * max(float(np.ptp(sv)), float(np.ptp(zv)), 1.0) ** 2  # not degenerate
    det = np.where(ok, det, 1.0)
    Ainv = np.stack([np.stack([A[:, 1, 1], -A[:, 0, 1]], -1),
                     np.stack([-A[:, 1, 0], A[:, 0, 0]], -1)], axis=1) / det[:, None, None]
    r = np.stack([s[ii] - sv[fac, 0], z[jj] - zv[fac, 0]], -1)
    ref = np.einsum("kab,kb->ka", Ainv[fac], r)
    score = np.minimum(np.minimum(ref[:, 0], ref[:, 1]), 1.0 - ref[:, 0] - ref[:, 1])
    score = np.where(ok[fac], score, -np.inf)                    # degenerate (s, z) triangles last
    # the best facet of each grid point: sort by point, then score descending
    k = jj * len(s) + ii
    order = np.lexsort((-score, k))
    first = np.concatenate([[True], np.diff(k[order]) != 0])
    pick = order[first]
    missing = np.setdiff1d(np.arange(len(s) * len(z)), k[pick])
    if missing.size or np.any(score[pick] < -1e-3):
        bad = missing[0] if missing.size else k[pick][np.argmin(score[pick])]
        raise ParameterError("bone map point (s, z)", (float(s[bad % len(s)]), float(z[bad // len(s)])),
                             f"on the {boundary} surface: s in [{sv.min():.6g}, {sv.max():.6g}], "
                             f"z in [{zv.min():.6g}, {zv.max():.6g}] mm")
    fac, ref, ii, jj = fac[pick], ref[pick], ii[pick], jj[pick]
    nodes = fn[fac]
    P = X[:, nodes]                                              # (3, k, n)
    Ai = Ainv[fac]
    for _ in range(iterations):  # chord iterations on the curved (P2) facet
        N = _tri_shape(ref[:, 0], ref[:, 1], n)
        xyz = np.einsum("kn,dkn->kd", N, P)
        res = np.stack([np.asarray(s_of_point(xyz[:, :2]), float) - s[ii], xyz[:, 2] - z[jj]], -1)
        ref = ref - np.einsum("kab,kb->ka", Ai, res)
    N = _tri_shape(ref[:, 0], ref[:, 1], n)
    out = np.empty(len(s) * len(z))
    out[jj * len(s) + ii] = np.einsum("kn,kn->k", N, np.asarray(nodal, float)[nodes])
    return out.reshape(len(z), len(s))


def profile_plane_z(model: Model) -> float:
    """z of the section plane of a 3D model: the indenter's 2D section row
    (`BrailleIndenter.section_z`, the dot row nearest z = 0), else z = 0 (a kind with
    `profile_at_map_peak` moves it to the bone map's peak after the solve, make_result)."""
    ind = getattr(model.contact, "indenter", None)
    return float(getattr(ind, "section_z", 0.0))


def arc_length(points: np.ndarray) -> np.ndarray:
    """A fallback s for generic meshes: distance from the point nearest x = 0, along a
    nearest-neighbour chain ordered by x (fine for open, x-monotone boundaries)."""
    order = np.argsort(points[:, 0])
    seg = np.linalg.norm(np.diff(points[order], axis=0), axis=1)
    s = np.empty(len(points))
    s[order] = np.concatenate([[0.0], np.cumsum(seg)])
    return s


def bone_peak(model: Model, path: str = "bone_interface"):
    """ev -> the largest mean pressure (MPa) at the path's nodes, for a time history: by the
    profile's and the bone map's PointFit; set up once."""
    sd = model.facet_scalar_dofs(path)
    fit = PointFit(model, model.basis.doflocs[:, sd].T)
    return lambda ev: float(np.max(fit.values(kernels.mean_pressure(model.stress(ev)))))


def law_state(ev: Evaluation, sig: np.ndarray) -> dict:
    """Extremes of the state the material law saw, for tactileskin.quality: `min_J` (the
    smallest volume ratio at a quadrature point; the mixed formulation's law sees the
    element dilatation, so its J), `max_abs_stress_mpa` (largest |principal Cauchy
    stress|) and `max_pressure_mpa` (largest mean pressure, positive in compression)."""
    J = np.asarray(ev.kin.Jbar, float)
    principal = np.linalg.eigvalsh(0.5 * (sig + np.swapaxes(sig, -1, -2)))
    return {"min_J": float(np.min(J)), "max_abs_stress_mpa": float(np.max(np.abs(principal))),
            "max_pressure_mpa": float(np.max(kernels.mean_pressure(sig)))}


# units of the nodal fields, put into their names in result.vtu (ParaView shows the names)
FIELD_UNITS = {"pressure": "MPa", "displacement": "mm", "sxx": "MPa", "syy": "MPa", "szz": "MPa",
               "sxy": "MPa", "syz": "MPa", "sxz": "MPa"}
_VTK_FACET = {2: "line", 3: "triangle"}


def contact_facet_pressure(model: Model, ev: Evaluation) -> np.ndarray | None:
    """(F,) nominal contact pressure of each facet of the contact boundary (in the order of
    model.boundaries[contact.boundary]): the facet's mean of the multipliers lambda_N (force
    per reference area) over its quadrature points, int lambda_N dA0 / A0, so that the sum
    of value x reference area over the facets is the contact force's magnitude (ParaView's
    Integrate Variables on the outer_surface cells of result.vtu). None without contact."""
    if model.surface is None or ev.contact is None:
        return None
    lam = np.maximum(np.asarray(ev.contact[1], float), 0.0)  # no adhesion (as contact.csv)
    w = model.surface.w
    return (w * lam).sum(axis=1) / w.sum(axis=1)


def vtk_fields(model: Model, fields: dict, history=(), contact_pressure: np.ndarray | None = None) -> dict:
    """The result.vtu content: the reference (undeformed) node positions, the nodal fields
    named with their unit (displacement_mm, pressure_MPa, sxx_MPa, ...; ParaView's Warp By
    Vector on displacement_mm shows the deformed skin), the named boundaries as facet cells
    (linear, on the vertices) with their name in field data, and the displacement of every
    increment of `history` (entries with "t" and "displacement") for result.pvd.
    `contact_pressure` (`contact_facet_pressure`) becomes the facet field
    contact_pressure_MPa of the contact boundary's cells ("facet_data")."""
    cells = model.sdofs
    X = model.basis.doflocs.T
    mesh, b = model.mesh, model.basis
    boundaries = {}
    for name, facets in getattr(model, "boundaries", {}).items():
        v = mesh.facets[:, np.asarray(facets)].T
        boundaries[name] = (_VTK_FACET[model.m], b.dofs.nodal_dofs[0, v])
    steps = [(float(h["t"]), np.asarray(h["displacement"], float)) for h in history if "displacement" in h]
    return {
        "points": X,
        "cells": cells,
        "cell_type": _VTK_CELL[(model.m, cells.shape[1])],
        "point_data": {f"{k}_{FIELD_UNITS[k]}" if k in FIELD_UNITS else k: v for k, v in fields.items()},
        "boundaries": boundaries,
        "steps": steps,
        "reference": True,
        "facet_data": ({"contact_pressure_MPa": {model.contact.boundary: np.asarray(contact_pressure, float)}}
                       if contact_pressure is not None else {}),
    }


def _fit_on_path(model: Model, fields: dict, sig: np.ndarray, sd: np.ndarray) -> None:
    """The nodal fields at the path's nodes `sd` from the local fit (second order at the
    boundary; the projected field, first order there, stays elsewhere): recovery.PointFit.
    The stress components too (the fit is linear: their -trace/3 is the pressure), which
    sensors on the bone interpolate (fe.probe). In 3D the projection's bone pressure rippled
    at the element scale: on a plane-strain slab (t = 1 curved, h = 0.5, 0.35, 0.25 mm) its
    section peak read -2.1, -1.9, -0.65 % from the converged 2D section and its rows 2-3 %
    apart, the fit's -1.1, -0.4, +0.1 % and rows within 0.8 %."""
    fit = PointFit(model, model.basis.doflocs[:, sd].T)
    fields["pressure"][sd] = fit.values(kernels.mean_pressure(sig))
    for name, (i, j) in STRESS_COMPONENTS.items():
        if name in fields:
            fields[name][sd] = fit.values(sig[..., i, j])


def make_result(model: Model, ev: Evaluation, stats, *, s_of_point=None, path: str = "bone_interface",
                vertical: int = 1, scene: dict | None = None, plane_z: float | None = None) -> Result:
    """Result of a converged state. 2D: the profile at the path's nodes. 3D: the profile on
    the section plane z = plane_z (default `profile_plane_z(model)`), see `plane_profile`, and
    the bone map P(s, z) on the grid (profile's s) x `map_planes` (see `surface_grid`)."""
    pj = Projector(model)
    sig = model.stress(ev)
    plane_from_map = False
    fields = nodal_fields(model, ev, pj, sig)
    if s_of_point is None:
        s_of_point = arc_length
    _fit_on_path(model, fields, sig, model.facet_scalar_dofs(path))
    if model.m == 3:
        plane_z = profile_plane_z(model) if plane_z is None else float(plane_z)
        s, p = plane_profile(model, fields["pressure"], path, s_of_point, plane_z)
        zg = map_planes(model, path, plane_z)
        try:
            grid = surface_grid(model, fields["pressure"], path, s_of_point, s, zg)
        except ParameterError as e:
            if (scene or {}).get("skin") != "file":
                raise
            # a user's bonded surface that is no graph over x (s = x - x_top folds where it
            # curves back: the fingertip written as a file): the result without its map
            if not getattr(model, "_no_map_warned", False):  # once per solve, not per load segment
                # in the user's terms, not surface_grid's ParameterError on an internal grid point
                at = e.value if isinstance(e.value, tuple) and len(e.value) == 2 else None
                logger.warning("no bone map for this skin file: its bonded surface is not one sheet over x and z "
                               "(s = x - x_top folds where the surface curves back under itself, as the "
                               "fingertip's does, or the surface has a gap%s); the profile is on z = %g mm only",
                               "" if at is None else f": no point of it at s = {at[0]:.3g}, z = {at[1]:.3g} mm",
                               plane_z)
                model._no_map_warned = True
            grid = None
        if grid is not None:
            # the section row is the same interpolant as the profile (equal to rounding: checked
            # in tests/test_bone_map.py); take the profile's values so that they agree exactly
            grid[int(np.argmin(np.abs(zg - plane_z)))] = p
        bmap = BoneMap(s, zg, grid, plane_z) if grid is not None else None
        at_map_peak = getattr(getattr(model.contact, "indenter", None), "profile_at_map_peak", False)
        if at_map_peak and bmap is None:
            plane_from_map = None  # quality: the plane could not follow the load
        elif at_map_peak:
            # no plane is known before the solve (a file indenter off z = 0, two bumps, a
            # ring): the profile is the map's row through its peak (>= t from the slab's ends)
            from tactileskin.results import skin_says

            margin = float((scene or {}).get("thickness", 0.0))
            plane_z = bmap.interior_peak(margin, skin_says(scene or {}, "map_z_end_free"),
                                         skin_says(scene or {}, "profile_ends_free"))[2]
            p = bmap.row(plane_z).copy()
            bmap = BoneMap(s, zg, grid, plane_z)
            plane_from_map = True
    else:
        bmap = None
        sd, s = path_nodes(model, path, s_of_point)
        p = fields["pressure"][sd]
    if model.surface is not None and ev.contact is not None:
        g, lamN, x, n = ev.contact
        pc = model.surface.current_pressure(model.u, lamN)
        pos = np.asarray(x, float).reshape(-1, model.m)
        xs, ps = pos[:, 0], pc.ravel()
        keep = ps > 0
        order = np.argsort(xs[keep], kind="stable")
        cx, cp, cpos = xs[keep][order], ps[keep][order], pos[keep][order]
    else:
        cx, cp, cpos = np.zeros(0), np.zeros(0), np.zeros((0, model.m))
    r = reaction(model, ev)
    law = law_state(ev, sig)
    for name, v in fields.items():
        if not np.all(np.isfinite(v)):
            raise ConvergenceError(f"non-finite nodal field {name!r}", {"field": name})
    vtk = vtk_fields(model, fields, stats.history, contact_facet_pressure(model, ev))
    st = {"dofs": int(model.ndof), "free_dofs": int(len(model.free)), "elements": int(len(model.sdofs)),
          "increments": stats.increments, "newton_iterations": stats.newton_iterations,
          "cutbacks": stats.cutbacks, "uzawa_iterations": stats.uzawa_iterations,
          "wall_s": stats.wall_s, "formulation": model.formulation, **law,
          **({"profile_plane_z": plane_z} if model.m == 3 else {}),
          **({"profile_plane_from_map": True} if plane_from_map else {}),
          **({"bone_map_missing": True} if model.m == 3 and bmap is None else {}),
          **({"profile_plane_unknown": True} if plane_from_map is None else {}),
          **({"profile_sides": 2} if getattr(model, "profile_sides", 1) == 2 else {}),
          "reaction_vector_modelled_part": r.tolist()}
    return Result(s=s, pressure=p, contact_x=cx, contact_pressure=cp, contact_points=cpos,
                  reaction=float(r[vertical]) * (model.force_factor if vertical == 1 else 1.0),
                  stats=st, fields=vtk, history=[{k: v for k, v in h.items() if k != "displacement"}
                                                 for h in stats.history], scene=scene,
                  bone_map=bmap)
