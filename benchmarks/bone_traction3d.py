"""Reference study of the 3D bone pressure: the recovered stress against the consistent traction.

The bone map and peak (Result.bone_map, Result.peak) are the mean pressure P = -tr(sigma)/3
(Abaqus PRESS) at the bone nodes, from the one-sided local fit to element averages
(fe.recovery.PointFit, fe.output._fit_on_path); the stress components there come from the
same fit. A probe found the fitted normal stress -sigma_nn under-integrating the indenter's
force by 4-5 % and reading high (+3-5 %) at the contact spot. This script measures, per mesh
level, the fitted normal stress against the variationally consistent traction of the bone:
the bone nodes' reaction forces R (the internal force at the fixed dofs) turned into a
traction field t_h on the bone's P2 surface by its mass matrix, M_s t = R (int t_h . v dA =
R . v for every P2 surface field v: the boundary flux consistent with the discrete
equilibrium), and -t_n = -n . t_h. Pointwise that P2 field oscillates from vertex to mid-side
node, so it is compared as its L2 projection onto P1 (`p1_smoothed`, same integral) on the map,
and exactly in kernel averages over the contact spot (`kernel_averages`: -R . v for v = phi n).

Table A per level: dofs, the reported peaks (P: the section profile's and the map's, >= t
from the edges), the peaks of -sigma_nn (fit) and of -t_n (consistent: P2 nodal, smoothed
map), the force balance int (sigma n)_y dA / F - 1 of the fit, the L2 projection, a fit to
quadrature points and the consistent traction (F the modelled part's indenter force; the
consistent one differs from 0 by the nail edge's share only), the relative L2 between the
fit's -sigma_nn map and the smoothed consistent map (near: where -t_n >= 10 % of its peak;
away: the rest) and the map integrals within 1.5 mm of the peak and beyond. Table B: the
spot averages (radius 0.3 mm) of the three recoveries against the consistent traction, their
P, and their P less their own -sigma_nn error.

Levels are the quality presets' (planner.with_quality: preview, default, fine) and finer
ones by mesh_size / refinement as in benchmarks/convergence3d.py (local plan), each solved
alone in its own subprocess, one at a time; raw numbers and maps go to --raw (JSON, reused).

    PYTHONPATH=src .venv/bin/python benchmarks/bone_traction3d.py --thickness 1 \
        --levels preview,default,fine,0.4/8    (results: benchmarks/results/bone_traction3d.md)
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BONE = "bone_interface"
NEAR_FRACTION = 0.10   # "near": where the consistent -t_n is at least this fraction of its peak
FAR_DISTANCE = 1.5     # mm from the map's peak: the far field of the probe

# Dunavant's degree-5 rule on the reference triangle (0,0) (1,0) (0,1): P2 x P2 x area
_A, _B = 0.470142064105115, 0.101286507323456
_QP = np.array([[1 / 3, 1 / 3], [_A, _A], [1 - 2 * _A, _A], [_A, 1 - 2 * _A],
                [_B, _B], [1 - 2 * _B, _B], [_B, 1 - 2 * _B]])
_QW = 0.5 * np.array([0.225, *[0.132394152788506] * 3, *[0.125939180544827] * 3])


def _tri_grad(xi, eta, n):
    """(k, n, 2) derivatives of fe.output._tri_shape's functions."""
    l0 = 1.0 - xi - eta
    if n == 3:
        g = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
        return np.broadcast_to(g, (len(xi), 3, 2)).copy()
    z = np.zeros_like(xi)
    dxi = [-(4 * l0 - 1), 4 * xi - 1, z, 4 * (l0 - xi), 4 * eta, -4 * eta]
    deta = [-(4 * l0 - 1), z, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (l0 - eta)]
    return np.stack([np.stack(dxi, -1), np.stack(deta, -1)], -1)


def surface_quadrature(model, boundary: str = BONE):
    """(fn (F, n) scalar dofs, N (Q, n), w (F, Q) area weights, nq (F, Q, 3) unit normals out of
    the body) of the boundary's (curved P2) facets."""
    from tactileskin.fe.output import _facet_nodes, _tri_shape

    fn = _facet_nodes(model, boundary)
    n = fn.shape[1]
    X = model.basis.doflocs[:, fn]                                  # (3, F, n)
    N = _tri_shape(_QP[:, 0], _QP[:, 1], n)                         # (Q, n)
    dN = _tri_grad(_QP[:, 0], _QP[:, 1], n)                         # (Q, n, 2)
    J = np.einsum("dfn,qnk->fqdk", X, dN)                           # (F, Q, 3, 2)
    c = np.cross(J[..., 0], J[..., 1])                              # (F, Q, 3)
    area = np.linalg.norm(c, axis=-1)
    nq = c / area[..., None]
    # out of the body: away from the centroid of the element behind the facet
    mesh = model.mesh
    f = np.asarray(model.boundaries[boundary])
    elem = mesh.f2t[0, f]
    xe = mesh.p[:, mesh.t[:, elem]].mean(axis=1)                    # (3, F)
    xf = mesh.p[:, mesh.facets[:, f]].mean(axis=1)
    sign = np.sign(np.einsum("df,fd->f", xf - xe, nq[:, 0]))
    nq = nq * sign[:, None, None]
    return fn, N, area * _QW[None, :], nq


def consistent_traction(model, ev, boundary: str = BONE):
    """(nodes, t (nb, 3), n (nb, 3)): the consistent traction of the boundary (M_s t = R, R
    the nodes' reaction forces on the body) and unit nodal normals out of the body."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from tactileskin.fe.assembly import vector_dofs

    fn, N, w, nq = surface_quadrature(model, boundary)
    nodes, loc = np.unique(fn, return_inverse=True)
    loc = loc.reshape(fn.shape)
    Me = np.einsum("fq,qa,qb->fab", w, N, N)
    A = fn.shape[1]
    M = sp.coo_matrix((Me.ravel(), (np.repeat(loc, A, axis=1).ravel(), np.tile(loc, (1, A)).ravel())),
                      shape=(len(nodes), len(nodes))).tocsc()
    R = np.asarray(ev.fint, float)[vector_dofs(nodes, model.m)]    # (nb, 3)
    t = spla.splu(M).solve(R)
    # nodal normals: the quadrature normals, weighted by area and shape function
    nn = np.zeros((len(nodes), 3))
    for d in range(3):
        nn[:, d] = np.bincount(loc.ravel(), weights=np.einsum("fq,qa,fq->fa", w, np.abs(N), nq[..., d]).ravel(),
                               minlength=len(nodes))
    nn /= np.linalg.norm(nn, axis=1, keepdims=True)
    return nodes, t, nn


def p1_smoothed(model, nodes: np.ndarray, t: np.ndarray, boundary: str = BONE) -> np.ndarray:
    """(nb, 3) the L2 projection of a P2 surface field (nodal values t at `nodes`) onto the
    P1 field of the facets' vertices, as P2 nodal values (mid-sides: the mean of their edge's
    ends). Why: the P2 consistent traction oscillates from vertex to mid-side node (the P2
    vertex functions integrate to zero over a triangle); the projection keeps int t dA."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    fn, N2, w, _ = surface_quadrature(model, boundary)
    N1 = np.stack([1.0 - _QP[:, 0] - _QP[:, 1], _QP[:, 0], _QP[:, 1]], -1)   # (Q, 3)
    verts, vloc = np.unique(fn[:, :3], return_inverse=True)
    vloc = vloc.reshape(-1, 3)
    loc = np.searchsorted(nodes, fn)
    M1e = np.einsum("fq,qa,qb->fab", w, N1, N1)
    M1 = sp.coo_matrix((M1e.ravel(), (np.repeat(vloc, 3, axis=1).ravel(), np.tile(vloc, (1, 3)).ravel())),
                       shape=(len(verts), len(verts))).tocsc()
    rhs = np.zeros((len(verts), 3))
    tq = np.einsum("qa,fad->fqd", N2, t[loc])                       # the P2 field at the points
    for d in range(3):
        rhs[:, d] = np.bincount(vloc.ravel(), weights=np.einsum("fq,qa,fq->fa", w, N1, tq[..., d]).ravel(),
                                minlength=len(verts))
    t1 = spla.splu(M1).solve(rhs)
    out = np.zeros_like(t)
    vat = np.searchsorted(verts, fn[:, :3])
    nv = t1[vat]                                                    # (F, 3, 3)
    out[loc[:, :3].ravel()] = nv.reshape(-1, 3)
    if fn.shape[1] == 6:
        for k, (a, b) in enumerate(((0, 1), (1, 2), (2, 0))):
            out[loc[:, 3 + k]] = 0.5 * (nv[:, a] + nv[:, b])
    return out


def integrate_traction(model, nodal_t: np.ndarray, nodes: np.ndarray, boundary: str = BONE) -> np.ndarray:
    """int t_h dA (3,) of a nodal traction field (nb, 3) on the boundary."""
    fn, N, w, _ = surface_quadrature(model, boundary)
    loc = np.searchsorted(nodes, fn)
    tq = np.einsum("qa,fad->fqd", N, nodal_t[loc])
    return np.einsum("fq,fqd->d", w, tq)


def integrate_stress(model, sig_nodal: np.ndarray, boundary: str = BONE) -> np.ndarray:
    """int sigma_h n dA (3,) of a nodal stress field (nsdof, 3, 3), interpolated on each facet."""
    fn, N, w, nq = surface_quadrature(model, boundary)
    sq = np.einsum("qa,faij->fqij", N, sig_nodal[fn])
    return np.einsum("fq,fqij,fqj->i", w, sq, nq)


KERNEL_RADII = (0.2, 0.3, 0.5)   # mm: the contact spot's averages (P falls to half at ~0.45 mm)


def kernel_averages(model, nodes, R, nn, sig_nodal, P_nodal, radii=KERNEL_RADII, boundary: str = BONE) -> dict:
    """Averages of the normal stress over the bone under the dot, weighted by the kernel
    phi = (1 - (r / rho)^2)^2 (r from the bone point nearest x = z = 0; its P2 interpolant
    phi_I): the fit's -int (sigma n) . v dA / int phi_I dA and the consistent traction's
    -R . v / int phi_I dA with v = phi_I n (nodal normals), which equals the consistent
    traction's average by construction, no mass matrix, no smoothing; also the fit's P.
    Why: the consistent traction is exact in such weak averages, not pointwise."""
    fn, N, w, nq = surface_quadrature(model, boundary)
    X = model.basis.doflocs
    loc = np.searchsorted(nodes, fn)
    xb = X[:, nodes]
    centre = xb[:, int(np.argmin(np.hypot(xb[0], xb[2])))]
    sq = np.einsum("qa,faij->fqij", N, sig_nodal[fn])
    tq = np.einsum("fqij,fqj->fqi", sq, nq)                         # the fit's sigma n at the points
    Pq = np.einsum("qa,fa->fq", N, P_nodal[fn])
    out = {}
    for rho in radii:
        r = np.linalg.norm(xb - centre[:, None], axis=0) / rho
        phi = np.where(r < 1.0, (1.0 - r ** 2) ** 2, 0.0)          # (nb,) nodal kernel
        phq = np.einsum("qa,fa->fq", N, phi[loc])                    # phi_I at the points
        vq = np.einsum("qa,fad->fqd", N, phi[loc][..., None] * nn[loc])
        area = float(np.sum(w * phq))
        out[f"{rho:g}"] = {"fit_nn": -float(np.einsum("fq,fqd,fqd->", w, tq, vq)) / area,
                           "cons_tn": -float(np.einsum("kd,kd,k->", R, nn, phi)) / area,
                           "fit_P": float(np.sum(w * phq * Pq)) / area}
    return out


def qpoint_fit(model, points: np.ndarray, k: int = 120):
    """q (E, Q) -> values at `points`: PointFit's weighted linear fit, to the k nearest
    quadrature points instead of the element averages (the probe's alternative)."""
    from scipy.spatial import cKDTree

    w = np.asarray(model.w).ravel()
    xq = np.moveaxis(np.asarray(model.basis.mapping.F(model.basis.X)), 0, -1).reshape(-1, model.m)
    dist, idx = cKDTree(xq).query(points, k=k)
    r = dist.max(axis=1, keepdims=True) * 1.01
    wt = w[idx] * (1.0 - (dist / r) ** 2) ** 2
    A = np.concatenate([np.ones((len(points), k, 1)), (xq[idx] - points[:, None, :]) / r[..., None]], axis=2)
    M = np.einsum("nk,nki,nkj->nij", wt, A, A)
    e0 = np.zeros((len(points), model.m + 1))
    e0[:, 0] = 1.0
    coef = np.einsum("ni,nki,nk->nk", (np.linalg.pinv(M) @ e0[..., None])[..., 0], A, wt)
    return lambda q: np.einsum("nk,nk->n", coef, np.asarray(q).ravel()[idx])


def recoveries(model, ev, nodes, sig_fit, P_fit):
    """{name: (sigma (nsdof, 3, 3), P (nsdof,))} at the bone nodes by the tool's fit, the plain
    L2 projection onto P1 (fe.recovery.Projector) and the quadrature-point fit."""
    from tactileskin.fe import kernels
    from tactileskin.fe.output import STRESS_COMPONENTS
    from tactileskin.fe.recovery import Projector

    sig_q = model.stress(ev)
    out = {"fit": (sig_fit, P_fit)}
    pj = Projector(model)
    qf = qpoint_fit(model, model.basis.doflocs[:, nodes].T)
    for name, rec in (("projection", pj.project), ("qpoint_fit", qf)):
        sig = np.zeros((model.nsdof, 3, 3))
        P = np.zeros(model.nsdof)
        for (i, j) in STRESS_COMPONENTS.values():
            v = rec(sig_q[..., i, j])
            sig[nodes, i, j] = sig[nodes, j, i] = v if len(v) == len(nodes) else v[nodes]
        v = rec(kernels.mean_pressure(sig_q))
        P[nodes] = v if len(v) == len(nodes) else v[nodes]
        out[name] = (sig, P)
    return out


def nodal_stress(fields: dict, nsdof: int) -> np.ndarray:
    from tactileskin.fe.output import STRESS_COMPONENTS

    pd = fields["point_data"]
    sig = np.zeros((nsdof, 3, 3))
    for name, (i, j) in STRESS_COMPONENTS.items():
        sig[:, i, j] = sig[:, j, i] = np.asarray(pd[f"{name}_MPa"], float)
    return sig


# --- one level, in a child process ---------------------------------------------------------

def scene_for(t: float, level: str):
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    scene = Scene(dim=3, indenter="braille", thickness=t, material="silicone", braille_text="")
    if "/" in level:
        h, r = (float(x) for x in level.split("/"))
        return scene.replace(mesh_size=h, refinement=r)
    return with_quality(scene, level)


def solve_level(t: float, level: str, out: Path) -> None:
    import tactileskin.fe as fe
    from tactileskin.fe.assembly import vector_dofs
    from tactileskin.fe.output import _facet_nodes, reaction, surface_grid
    from tactileskin.fileio import atomic_write_json
    from tactileskin.results import BoneMap, skin_says

    scene = scene_for(t, level)
    seen = {}
    make_result = fe.make_result

    def capture(model, ev, *a, **k):  # the converged state the Result is made of
        seen.update(model=model, ev=ev)
        return make_result(model, ev, *a, **k)

    fe.make_result = capture
    c0, w0 = time.process_time(), time.perf_counter()
    res = fe.solve(scene)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    model, ev = seen["model"], seen["ev"]
    F = float(reaction(model, ev)[1])                              # modelled part, on the body
    nodes, t_c, nn = consistent_traction(model, ev)
    sig = nodal_stress(res.fields, model.nsdof)
    t_s = p1_smoothed(model, nodes, t_c)
    tn_c = -np.einsum("kd,kd->k", t_c, nn)                          # -t_n, positive in compression
    tn_s = -np.einsum("kd,kd->k", t_s, nn)
    tn_f = -np.einsum("ki,kij,kj->k", nn, sig[nodes], nn)           # the fit's -sigma_nn
    R = np.asarray(ev.fint, float)[vector_dofs(nodes, 3)]
    P_fit = np.asarray(res.fields["point_data"]["pressure_MPa"], float)
    recs = recoveries(model, ev, nodes, sig, P_fit)
    kavg = {name: kernel_averages(model, nodes, R, nn, sg, Pn) for name, (sg, Pn) in recs.items()}
    other = {name: {"balance_y": float(integrate_stress(model, sg)[1] / F - 1),
                    "P_max": float(Pn[nodes].max()),
                    "nn_max": float((-np.einsum("ki,kij,kj->k", nn, sg[nodes], nn)).max())}
             for name, (sg, Pn) in recs.items()}
    bm = res.bone_map
    sp = scene.section().s_of_point

    def grid(vals):
        full = np.zeros(model.nsdof)
        full[nodes] = vals
        return surface_grid(model, full, BONE, sp, bm.s, bm.z)

    g_c, g_f, g_s = grid(tn_c), grid(tn_f), grid(tn_s)
    flags = (skin_says(scene.to_dict(), "map_z_end_free"), skin_says(scene.to_dict(), "profile_ends_free"))

    def ipeak(P):
        return BoneMap(bm.s, bm.z, P, bm.section_z).interior_peak(t, *flags)

    # vertex / mid-side nodes: the consistent traction's node-to-node oscillation, if any
    fn = _facet_nodes(model, BONE)
    vert = np.isin(nodes, fn[:, :3])
    atomic_write_json(out, {
        "thickness": t, "level": level, "mesh_size": scene.mesh_size, "refinement": scene.refinement,
        "dofs": int(res.stats["dofs"]), "cpu_s": cpu, "wall_s": wall,
        "maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "force_modelled": F, "bone_force_consistent": integrate_traction(model, t_c, nodes).tolist(),
        "bone_force_fit": integrate_stress(model, sig).tolist(),
        "bone_reaction_sum": float(R[:, 1].sum()),
        "peak_section_P": float(res.peak), "peak_map_P": ipeak(bm.pressure),
        "kernel": kavg, "recoveries": other,
        "bone_force_smoothed": integrate_traction(model, t_s, nodes).tolist(),
        "peak_map_fit_nn": ipeak(g_f), "peak_map_cons_tn": ipeak(g_c), "peak_map_smooth_tn": ipeak(g_s),
        "node_max_fit_nn": float(tn_f.max()), "node_max_cons_tn": float(tn_c.max()),
        "vertex_max_cons_tn": float(tn_c[vert].max()), "midside_max_cons_tn": float(tn_c[~vert].max()),
        "map": {"s": bm.s.tolist(), "z": bm.z.tolist(), "section_z": bm.section_z, "P": bm.pressure.tolist(),
                "fit_nn": g_f.tolist(), "cons_tn": g_c.tolist(), "smooth_tn": g_s.tolist()},
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    })


def raw_name(t: float, level: str) -> str:
    return f"t{t:g}_{level.replace('/', '_')}.json"


def run_level(args, level: str) -> dict:
    path = args.raw / raw_name(args.thickness, level)
    if not path.exists() or args.force:
        cmd = [sys.executable, __file__, "--one", level, "--thickness", str(args.thickness), "--raw", str(args.raw)]
        print(f"[{time.strftime('%H:%M:%S')}] solving t = {args.thickness:g}, {level} ...", flush=True)
        subprocess.run(cmd, check=True, env=dict(os.environ, PYTHONPATH=str(ROOT / "src")))
    return json.loads(path.read_text(encoding="utf-8"))


# --- analysis --------------------------------------------------------------------------------

def _trapz_weights(x):
    w = np.zeros_like(x)
    if x.size > 1:
        d = np.diff(x)
        w[:-1] += d / 2
        w[1:] += d / 2
    return w


def compare(d: dict, ref: str = "smooth_tn") -> dict:
    """The fit's -sigma_nn map against a consistent -t_n map of one level: relative L2 over the
    map (less one thickness at the slab's free end, as convergence3d.map_l2), near the contact
    spot (where -t_n >= NEAR_FRACTION of its peak) and away from it, and the map integrals
    int -sigma_nn ds dz within FAR_DISTANCE of the peak and beyond (trapezoid weights)."""
    m = d["map"]
    s, z = np.asarray(m["s"]), np.asarray(m["z"])
    f, c = np.asarray(m["fit_nn"]), np.asarray(m[ref])
    keep_z = z <= z[-1] - d["thickness"]
    W = np.outer(_trapz_weights(z) * keep_z, _trapz_weights(s))
    near = c >= NEAR_FRACTION * c[keep_z].max()
    _, ps, pz = d["peak_map_cons_tn"]
    close = np.hypot(*np.meshgrid(s - ps, z - pz)) <= FAR_DISTANCE

    def rel(mask):
        wm = W * mask
        return math.sqrt(float(np.sum(wm * (f - c) ** 2)) / float(np.sum(wm * c ** 2)))

    Wa = np.outer(_trapz_weights(z), _trapz_weights(s))
    return {"l2": rel(np.ones_like(near)), "l2_near": rel(near), "l2_far": rel(~near),
            "int_close": (float(np.sum(Wa * f * close)), float(np.sum(Wa * c * close))),
            "int_far": (float(np.sum(Wa * f * ~close)), float(np.sum(Wa * c * ~close)))}


def table(levels: list[dict]) -> str:
    """Table A: peaks, force balance and maps of one series of levels."""
    rows = ["| t mm | level (mesh_size / ref.) | dofs | peak P section / map (reported) | peak -sigma_nn fit | "
            "peak -t_n consistent: P2 nodal / P1-smoothed map | balance fit / projection / q-point fit / "
            "consistent | map L2 vs smoothed consistent: fit -sigma_nn (near / away), reported P | "
            "int -sigma_nn ds dz within 1.5 mm / beyond, fit vs smoothed (1e-3 N) |",
            "|---|---|---|---|---|---|---|---|---|"]
    for d in levels:
        F = d["force_modelled"]
        c = compare(d)
        cP = compare(dict(d, map=dict(d["map"], fit_nn=d["map"]["P"])))
        bal = " / ".join(f"{d['recoveries'][k]['balance_y']:+.1%}" for k in ("fit", "projection", "qpoint_fit"))
        rows.append(
            f"| {d['thickness']:g} | {d['level']} ({d['mesh_size']:g} / {d['refinement']:g}) | {d['dofs']:,} | "
            f"{d['peak_section_P']:.5f} / {d['peak_map_P'][0]:.5f} | {d['peak_map_fit_nn'][0]:.5f} | "
            f"{d['node_max_cons_tn']:.5f} / {d['peak_map_smooth_tn'][0]:.5f} | "
            f"{bal} / {d['bone_force_consistent'][1] / F - 1:+.1%} | "
            f"{c['l2']:.1%} ({c['l2_near']:.1%} / {c['l2_far']:.0%}), {cP['l2']:.1%} | "
            f"{c['int_close'][0] * 1e3:.2f} / {c['int_far'][0] * 1e3:.2f} vs "
            f"{c['int_close'][1] * 1e3:.2f} / {c['int_far'][1] * 1e3:.2f} |")
    return "\n".join(rows) + "\n"


SPOT_RHO = "0.3"


def spot_table(levels: list[dict]) -> str:
    """Table B: kernel averages over the contact spot (radius 0.3 mm) of each recovery against
    the consistent traction, and the P they imply if their -sigma_nn error is volumetric
    (P - (-sigma_nn - (-t_n)): the same error in P as in -sigma_nn)."""
    rows = ["| t mm | level | dofs | -t_n consistent | -sigma_nn: fit / projection / q-point fit (vs consistent) | "
            "P: fit (reported recovery) / projection / q-point fit | P less the -sigma_nn error: fit / projection / "
            "q-point fit |", "|---|---|---|---|---|---|---|"]
    for d in levels:
        k = {n: d["kernel"][n][SPOT_RHO] for n in ("fit", "projection", "qpoint_fit")}
        c = k["fit"]["cons_tn"]
        nn = " / ".join(f"{v['fit_nn'] * 1e3:.2f} ({v['fit_nn'] / c - 1:+.1%})" for v in k.values())
        P = " / ".join(f"{v['fit_P'] * 1e3:.2f}" for v in k.values())
        Pc = " / ".join(f"{(v['fit_P'] - v['fit_nn'] + c) * 1e3:.2f}" for v in k.values())
        rows.append(f"| {d['thickness']:g} | {d['level']} | {d['dofs']:,} | {c * 1e3:.2f} | {nn} | {P} | {Pc} |")
    return "\n".join(rows) + "\n\n(kPa; averages weighted by (1 - (r / 0.3 mm)^2)^2 about the bone point under the dot)\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", type=float, default=1.0)
    ap.add_argument("--levels", default="preview,default,fine", help="quality presets or mesh_size/refinement")
    ap.add_argument("--raw", type=Path, default=HERE / "results" / "bone_traction3d_levels")
    ap.add_argument("--force", action="store_true", help="solve levels already in --raw again")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    args.raw.mkdir(parents=True, exist_ok=True)
    if args.one:
        solve_level(args.thickness, args.one, args.raw / raw_name(args.thickness, args.one))
        return 0
    levels = [run_level(args, lv.strip()) for lv in args.levels.split(",")]
    print(table(levels))
    print(spot_table(levels))
    return 0


if __name__ == "__main__":
    sys.exit(main())
