"""tactileskin's 3D solver against CalculiX on the same tetrahedral mesh.

Writes each scene as the 3D CalculiX deck (tactileskin.mesh.deck3d: C3D10 skin, the indenter
face meshed on its exact surface as prescribed C3D6 wedges, penalty surface-to-surface
contact, instantaneous hyperfoam since ccx has no Prony series), runs `ccx` (Debian package
calculix-ccx; not a project dependency: without it this script stops with a message), and
solves the same scene on the same mesh with tactileskin (elastic; mixed and displacement
formulations). Compared, on four levels that separate the solution from its post-processing:
- the indenter force (whole indenter: the modelled quarter's times 4);
- the nodal displacements of the whole skin (same nodes: no recovery involved);
- the mean pressure of each element touching the bone, averaged over its 4 integration
  points (both codes use the same 4-point rule on C3D10; ccx's from *EL PRINT);
- the bone pressure profile P = -(trace sigma)/3 on the section plane z = 0: ccx's nodal
  stresses (extrapolated from the integration points and averaged at the nodes, .frd)
  against tactileskin's profile (fe.recovery.PointFit) and its L2-projected nodal field.
Plus the largest penetration ccx's penalty allowed.

    PYTHONPATH=src python benchmarks/calculix_compare3d.py [--case braille:1 flat:1]
        [--penalty-factor 10 40] [--quality preview] [--out benchmarks/results/calculix_compare3d.md]

A finished case's numbers are kept in benchmarks/results/raw_calculix3d/ (one JSON per case
and penalty), so a rerun only solves what is missing (--fresh: solve everything again).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from calculix_compare import plot_panels, read_dat_totals, read_frd_last  # noqa: E402

from tactileskin import fileio  # noqa: E402
from tactileskin.fe.recovery import PointFit  # noqa: E402
from tactileskin.materials import get_material  # noqa: E402
from tactileskin.mesh import build_mesh  # noqa: E402
from tactileskin.mesh.deck3d import deck_text_3d  # noqa: E402
from tactileskin.mesh.skinmesh import facet_nodes  # noqa: E402
from tactileskin.planner import with_quality  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402

HERE = Path(__file__).parent
OUT = HERE / "results" / "calculix_compare3d.md"
RAW = HERE / "results" / "raw_calculix3d"
CCX_ENV = {"OMP_NUM_THREADS": "1", "CCX_NPROC_STIFFNESS": "1", "CCX_NPROC_EQUATION_SOLVER": "1"}


def read_dat_elstress(path: Path) -> dict[int, np.ndarray]:
    """The last block of integration-point stresses of a .dat file (*EL PRINT S): element id ->
    (points, 6) rows sxx syy szz sxy sxz syz."""
    out, cur = {}, None
    with open(path) as fh:
        for line in fh:
            if line.strip().startswith("stresses (elem, integ.pnt."):
                cur = {}
                out = cur
                continue
            if cur is None:
                continue
            v = line.split()
            if len(v) == 8:
                try:
                    cur.setdefault(int(v[0]), []).append([float(x) for x in v[2:]])
                    continue
                except ValueError:
                    pass
            if v:
                cur = None
    return {k: np.array(v) for k, v in out.items()}


def start_ccx(text: str, work: Path) -> tuple[subprocess.Popen, float]:
    (work / "job.inp").write_text(text)
    proc = subprocess.Popen(["ccx", "-i", "job"], cwd=work, env=dict(os.environ, **CCX_ENV),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return proc, time.perf_counter()


def finish_ccx(proc: subprocess.Popen, t0: float, work: Path, timeout: float) -> dict:
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    out, _ = proc.communicate(timeout=timeout)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    sta = (work / "job.sta").read_text() if (work / "job.sta").exists() else ""
    if proc.returncode != 0 or "*ERROR" in out:
        raise RuntimeError(f"ccx failed ({proc.returncode}):\n{out[-3000:]}")
    rows = [r.split() for r in sta.splitlines()[2:] if len(r.split()) > 3]
    return {"cpu_s": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
            "wall_s": time.perf_counter() - t0, "increments": len(rows),
            "iterations": sum(int(r[3]) for r in rows)}


def ts_solve(scene, sm):
    """tactileskin on the given mesh: (Result, quadrature Cauchy stress (E, Q, 3, 3), CPU s, Model)."""
    from tactileskin.fe import blas_threads, model_for_scene, run
    from tactileskin.fe.output import make_result

    c0 = time.process_time()
    model, _ = model_for_scene(scene, sm)
    with blas_threads():
        ev, stats = run(model, scene.duration)
    res = make_result(model, ev, stats, s_of_point=scene.section().s_of_point, scene=scene.to_dict())
    sig = model.stress(ev)
    return res, sig, time.process_time() - c0, model


def even_fit_peak(s: np.ndarray, p: np.ndarray, window: float) -> float:
    """a of the even quadratic a + b s^2 fitted to the samples with s < window (the profile is
    even about s = 0): a peak estimate that the corner / mid-node scatter does not bias."""
    near = s < window
    A = np.column_stack([np.ones(near.sum()), s[near] ** 2])
    return float(np.linalg.lstsq(A, p[near], rcond=None)[0][0])


def make_scene(kind: str, thickness: float, quality: str, mesh: str | None = None, skin: str | None = None):
    """kind: an indenter kind, "sphere-R2.5" / "cylinder-R3" with its radius; skin: default the Scene's."""
    kind, _, radius = kind.partition("-R")
    extra = {"indenter_radius": float(radius)} if radius else {}
    if skin:
        extra["skin"] = skin
    scene = with_quality(Scene(thickness=thickness, material="polyurethane", indenter=kind, dim=3,
                               viscoelastic=False, **extra), quality)
    if mesh:
        size, _, ref = mesh.partition("/")
        scene = scene.replace(mesh_size=float(size), refinement=float(ref or scene.refinement))
    return scene


def _ref_path(scene) -> Path:
    return RAW / f"ref_{scene.label()}_{scene.mesh_size:g}-{scene.refinement:g}.json"


def reference(scene, fresh: bool) -> dict:
    """tactileskin (mixed) alone on the scene's own mesh: the finer levels a ccx run is judged
    against (a mesh-converged peak tells which recovery reads the coarse mesh better)."""
    path = _ref_path(scene)
    if path.exists() and not fresh:
        return json.loads(path.read_text())
    sm = build_mesh(scene)
    res, _, cpu, _ = ts_solve(scene, sm)
    row = {"scene": scene.label(), "mesh": f"{scene.mesh_size:g}/{scene.refinement:g}", "cells": int(sm.mesh.nelements),
           "dofs": 3 * int(sm.mesh.doflocs.shape[1]), "peak": float(res.peak), "force": float(res.reaction),
           "cpu_s": cpu, "newton": int(res.stats["newton_iterations"])}
    RAW.mkdir(parents=True, exist_ok=True)
    fileio.atomic_write_text(path, json.dumps(row, indent=1))
    return row


def compare(scene, penalty_factors: list[float], fresh: bool, timeout: float, cached: bool = False,
            cap_size: float | None = None) -> list[dict]:
    raw = lambda f: _raw(scene, f, cap_size)  # noqa: E731
    if cached:  # every cap size held for each penalty
        stem = lambda f: _raw(scene, f).stem  # noqa: E731
        return [json.loads(q.read_text()) for f in penalty_factors
                for q in sorted(RAW.glob(stem(f) + "*.json")) if q.stem == stem(f) or q.stem.startswith(stem(f) + "_cap")]
    todo = [f for f in penalty_factors if fresh or not raw(f).exists()]
    if not todo:
        return [json.loads(raw(f).read_text()) for f in penalty_factors]
    sm = build_mesh(scene)
    hf = get_material(scene.material).hyperfoam
    h = float(sm.sizes["fine"])
    # bone nodes on the section plane z = 0 (the profile's plane), sorted by s
    bone = np.unique(facet_nodes(sm.mesh, sm.boundaries["bone_interface"], 3, sm.order))
    X = sm.mesh.doflocs.T
    plane = bone[np.abs(X[bone, 2]) < 1e-9]
    s_nodes = scene.section().s_of_point(X[plane, :2])
    o = np.argsort(s_nodes)
    plane, s_nodes = plane[o], s_nodes[o]
    # elements with a face on the bone
    bone_cells = np.unique(sm.mesh.f2t[0, sm.boundaries["bone_interface"]])

    ts, rows = {}, []
    for f in todo:
        deck = deck_text_3d(scene, sm, penalty=f * max(hf.K0, hf.mu0) / h, cap_size=cap_size)
        text = deck.text.replace("*END STEP\n", "*EL PRINT, ELSET=skin\nS\n*END STEP\n")
        work = Path(tempfile.mkdtemp(prefix="tsk_ccx3d_"))
        proc = None
        try:
            proc, t0 = start_ccx(text, work)
            if not ts:  # tactileskin solves while the first ccx job runs (CPU times are per process)
                for form in ("mixed", "displacement"):
                    ts[form] = ts_solve(scene.replace(formulation=form), sm)
            ccx = finish_ccx(proc, t0, work, timeout)
            row = _row(scene, sm, deck, work, ccx, f, ts, plane, s_nodes, bone_cells)
            row["cap_size_mm"] = cap_size
        finally:
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.wait()
            shutil.rmtree(work, ignore_errors=True)
        RAW.mkdir(parents=True, exist_ok=True)
        fileio.atomic_write_text(raw(f), json.dumps(row, indent=1))
        rows.append(row)
    done = {r["penalty_factor"]: r for r in rows}
    return [done[f] if f in done else json.loads(raw(f).read_text()) for f in penalty_factors]


def _raw(scene, factor: float, cap_size: float | None = None) -> Path:
    cap = f"_cap{cap_size:g}" if cap_size else ""
    return RAW / f"{scene.label()}_{scene.mesh_size:g}-{scene.refinement:g}_p{factor:g}{cap}.json"


def _row(scene, sm, deck, work, ccx, factor, ts, plane, s_nodes, bone_cells) -> dict:
    stress = read_frd_last(work / "job.frd", "STRESS")
    disp = read_frd_last(work / "job.frd", "DISP")
    contact = read_frd_last(work / "job.frd", "CONTACT")
    totals = read_dat_totals(work / "job.dat")
    ip = read_dat_elstress(work / "job.dat")
    ff = deck.info["force_factor"]
    n = deck.n_skin_nodes
    U_ccx = np.array([disp[i + 1][:3] for i in range(n)])
    S = np.array([stress[int(i) + 1] for i in plane])
    P_ccx = -(S[:, 0] + S[:, 1] + S[:, 2]) / 3.0
    Pq_ccx = np.array([-ip[e + 1][:, :3].sum(axis=1) / 3.0 for e in range(deck.n_skin_cells)])  # (E, 4)
    Pe_ccx = Pq_ccx[bone_cells].mean(axis=1)
    # ccx's integration-point pressure through tactileskin's own bone recovery (PointFit: a
    # local linear fit to element averages; the 4-point rule's equal weights make the order of
    # the points irrelevant): the same post-processing on both solutions
    model = next(iter(ts.values()))[3]
    fit = PointFit(model, np.asarray(sm.mesh.doflocs, float)[:, plane].T)
    Pfit_ccx = fit.values(Pq_ccx)
    copen = np.array([v[0] for v in contact.values()])
    window = 0.5 if scene.indenter == "flat" else 0.25
    row = {"scene": scene.label(), "mesh": f"{scene.mesh_size:g}/{scene.refinement:g}",
           "cells": deck.n_skin_cells, "nodes": n, "dofs": 3 * n, "depth": scene.indentation,
           "penalty_factor": factor, "penalty": deck.info["penalty_mpa_per_mm"],
           "indenter_cells": deck.info["indenter_cells"], "face_chord_um": 1e3 * deck.info["face_chord_error_mm"],
           "fit_window_mm": window,
           "ccx": {**ccx, "peak": float(P_ccx.max()), "peak_s": float(s_nodes[np.argmax(P_ccx)]),
                   "fit_peak": even_fit_peak(s_nodes, P_ccx, window),
                   "pointfit_peak": float(Pfit_ccx.max()),
                   "pointfit_profile": [s_nodes.tolist(), Pfit_ccx.tolist()],
                   "force": float(-totals["INDENTER_NODES"][1] * ff),
                   "penetration_mm": float(max(0.0, -copen.min())),
                   "profile": [s_nodes.tolist(), P_ccx.tolist()]},
           "ts": {}}
    for form, (res, sig, cpu, _) in ts.items():
        pd = res.fields["point_data"]
        U = np.asarray(pd["displacement_mm"])
        du = np.linalg.norm(U - U_ccx, axis=1)
        umax = float(np.linalg.norm(U_ccx, axis=1).max())
        P_nodal = np.asarray(pd["pressure_MPa"])[plane]
        Pe = -np.trace(sig[bone_cells], axis1=-2, axis2=-1).mean(axis=1) / 3.0
        dPe = Pe - Pe_ccx
        p_at = np.interp(res.s, s_nodes, P_ccx)
        k = int(np.argmax(np.abs(res.pressure - p_at)))
        row["ts"][form] = {
            "peak": float(res.peak), "peak_s": float(res.s[np.argmax(res.pressure)]),
            "fit_peak": even_fit_peak(np.asarray(res.s), np.asarray(res.pressure), window),
            "force": float(res.reaction), "cpu_s": cpu, "newton": int(res.stats["newton_iterations"]),
            "increments": int(res.stats["increments"]),
            "profile_max_diff": float(np.abs(res.pressure - p_at)[k]), "profile_max_diff_s": float(res.s[k]),
            "profile_rms_diff": float(np.sqrt(np.mean((res.pressure - p_at) ** 2))),
            "nodal_peak": float(P_nodal.max()),
            "nodal_rms_diff": float(np.sqrt(np.mean((P_nodal - P_ccx) ** 2))),
            # like with like: tactileskin's bone nodes (PointFit) against ccx through PointFit
            "pointfit_max_diff": float(np.abs(P_nodal - Pfit_ccx).max()),
            "pointfit_rms_diff": float(np.sqrt(np.mean((P_nodal - Pfit_ccx) ** 2))),
            "u_max_mm": umax, "u_rms_diff_rel": float(np.sqrt(np.mean(du ** 2)) / umax),
            "u_max_diff_rel": float(du.max() / umax),
            "elem_P_max_ccx": float(Pe_ccx.max()), "elem_P_max_ts": float(Pe.max()),
            "elem_P_rms_diff": float(np.sqrt(np.mean(dPe ** 2))), "elem_P_max_diff": float(np.abs(dPe).max()),
            "elem_P_mean_diff": float(dPe.mean()),
            "profile": [np.asarray(res.s).tolist(), np.asarray(res.pressure).tolist()],
        }
    return row


def _pct(a: float, b: float) -> str:
    return f"{100.0 * (a / b - 1.0):+.1f} %"


def markdown(rows: list[dict], cmd: str, refs: list[dict] = ()) -> str:
    L = ["# tactileskin 3D vs CalculiX (ccx 2.20) on the same tetrahedral mesh", "",
         f"Command: `{cmd}` (CPU seconds of each process; ccx with OMP_NUM_THREADS=1, spooles; "
         "tactileskin with its default threads, all counted).", "",
         "Polyurethane, 20 % nominal strain at 1 mm/s, elastic (instantaneous hyperfoam; ccx has no "
         "Prony series), quarter model (x >= 0, z >= 0; end z = 10 mm free). Same P2 tetrahedra: "
         "tactileskin solves them as is, ccx as C3D10 (4 integration points, displacement "
         "formulation). The indenter in ccx: its face triangulated on the exact surface, C3D6 wedges "
         "with every node prescribed; surface-to-surface penalty contact (slope in units of K0 / h, h "
         "the fine mesh size). Force: whole indenter (4 x the quarter). u: nodal displacements of "
         "the whole skin, rms and max of |u_ts - u_ccx| over max |u_ccx|. Element P: mean over the 4 "
         "integration points of each element touching the bone, max |P_ts - P_ccx| (and the max "
         "element P of each code). Profile on z = 0: ccx's nodal values against tactileskin's "
         "PointFit profile (ccx interpolated linearly in s), max and rms difference.", "",
         "| case | mesh | code | peak P (MPa) | force (N) | u diff rms / max | element P max; max diff (MPa) | profile diff max at s / rms (MPa) | CPU (s) |",
         "|---|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        c = r["ccx"]
        cap = (f" (cap facets {r['cap_size_mm']:g} mm, " if r.get("cap_size_mm") else " (") + \
            f"face <= {r['face_chord_um']:.1f} um off the dot)" if "braille" in r["scene"] else \
            f" (face <= {r['face_chord_um']:.1f} um off the surface)" if r["face_chord_um"] > 1e-6 else ""
        L.append(f"| {r['scene']} | {r['mesh']}, {r['cells']} cells, {r['dofs']} dofs | CalculiX{cap}, penalty "
                 f"{r['penalty']:.0f} MPa/mm ({r['penalty_factor']:g} K0/h), penetration "
                 f"{c['penetration_mm'] * 1e3:.2f} um = {100 * c['penetration_mm'] / r['depth']:.2f} % of the travel "
                 f"| {c['peak']:.4f} at s = {c['peak_s']:.2f} | {c['force']:.4f} | - | "
                 f"{next(iter(r['ts'].values()))['elem_P_max_ccx']:.4f} | - | {c['cpu_s']:.0f} "
                 f"({c['increments']} incr., {c['iterations']} it.) |")
        for form, t in r["ts"].items():
            L.append(f"| | | tactileskin {form} | {t['peak']:.4f} ({_pct(t['peak'], c['peak'])}) | "
                     f"{t['force']:.4f} ({_pct(t['force'], c['force'])}) | "
                     f"{100 * t['u_rms_diff_rel']:.2f} / {100 * t['u_max_diff_rel']:.2f} % | "
                     f"{t['elem_P_max_ts']:.4f}; {t['elem_P_max_diff']:.4f} | "
                     f"{t['profile_max_diff']:.4f} at {t['profile_max_diff_s']:.2f} / {t['profile_rms_diff']:.4f} | "
                     f"{t['cpu_s']:.0f} ({t['increments']} incr., {t['newton']} Newton) |")
    L += ["", "The bone profile with the same post-processing on both: ccx's integration-point pressure through "
          "tactileskin's own recovery (PointFit at the bone nodes of z = 0) against tactileskin's.", "",
          "| case | mesh | penalty (K0/h) | ccx nodal peak | ccx PointFit peak | tactileskin mixed / displacement peak | PointFit profile diff max / rms (MPa), mixed; displacement |",
          "|---|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        c, t = r["ccx"], r["ts"]
        m, d = t["mixed"], t["displacement"]
        L.append(f"| {r['scene']} | {r['mesh']} | {r['penalty_factor']:g} | {c['peak']:.4f} | {c['pointfit_peak']:.4f} | "
                 f"{m['peak']:.4f} ({_pct(m['peak'], c['pointfit_peak'])}) / {d['peak']:.4f} "
                 f"({_pct(d['peak'], c['pointfit_peak'])}) | {m['pointfit_max_diff']:.4f} / {m['pointfit_rms_diff']:.4f}; "
                 f"{d['pointfit_max_diff']:.4f} / {d['pointfit_rms_diff']:.4f} |")
    if refs:
        L += ["", "tactileskin alone (mixed) on finer meshes of the same scenes: the mesh-converged answer.", "",
              "| case | mesh | cells | dofs | peak P (MPa) | force (N) | CPU (s) |", "|---|---|---:|---:|---:|---:|---:|"]
        for r in refs:
            L.append(f"| {r['scene']} | {r['mesh']} | {r['cells']} | {r['dofs']} | {r['peak']:.4f} | {r['force']:.4f} | "
                     f"{r['cpu_s']:.0f} ({r['newton']} Newton) |")
    return "\n".join(L) + "\n"


def plot(rows: list[dict], path: Path) -> None:
    stiffest = {}
    for r in rows:  # one panel per case and mesh: its stiffest penalty
        k = (r["scene"], r["mesh"])
        if k not in stiffest or r["penalty_factor"] > stiffest[k]["penalty_factor"]:
            stiffest[k] = r
    panels = []
    for r in stiffest.values():
        ccx = [(*r["ccx"]["profile"], "CalculiX (nodal, extrapolated)", "o", "#0072B2")]
        if "pointfit_profile" in r["ccx"]:
            ccx.append((*r["ccx"]["pointfit_profile"], "CalculiX via PointFit", "x", "#56B4E9"))
        panels.append({"title": f"{r['scene']} {r['mesh']}, {r['penalty_factor']:g} K0/h",
                       "xlim": (0, 4 if "flat" in r["scene"] else 2), "ccx": ccx,
                       "ts": {form: t["profile"] for form, t in r["ts"].items()}})
    plot_panels(panels, path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", nargs="+", default=["braille:1", "flat:1"],
                    help="indenter:thickness[:SIZE/REFINEMENT]; indenter sphere-R2.5 etc. with its radius")
    ap.add_argument("--skin", default=None, help="skin kind (default the Scene's: fingertip)")
    ap.add_argument("--cached", action="store_true",
                    help="solve nothing: tabulate the cases and penalties raw_calculix3d/ holds")
    ap.add_argument("--quality", default="preview")
    ap.add_argument("--mesh", default=None, help="SIZE/REFINEMENT instead of the quality's (e.g. 0.8/8)")
    ap.add_argument("--reference", nargs="*", default=[], metavar="SIZE/REFINEMENT",
                    help="finer meshes solved by tactileskin alone (mixed): the converged peak and force")
    ap.add_argument("--penalty-factor", type=float, nargs="+", default=[10.0],
                    help="CalculiX contact slope in units of K0 / h_fine")
    ap.add_argument("--cap-size", type=float, default=None,
                    help="facet size (mm) on the Braille caps of the ccx indenter (default mesh.indenter3d's)")
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds per ccx run")
    ap.add_argument("--fresh", action="store_true", help="solve again what raw_calculix3d/ holds")
    ap.add_argument("--out", type=Path, default=OUT)
    a = ap.parse_args(argv)
    if shutil.which("ccx") is None:
        print("ccx not found: this benchmark needs CalculiX (apt-get install calculix-ccx); nothing was run",
              file=sys.stderr)
        return 2
    rows, refs = [], []
    for case in a.case:
        parts = case.split(":")
        kind, t, mesh = parts[0], (parts[1:2] or ["1"])[0], (parts[2:3] or [""])[0]
        rows += compare(make_scene(kind, float(t), a.quality, mesh or a.mesh, a.skin), a.penalty_factor, a.fresh,
                        a.timeout, a.cached, a.cap_size)
        for m in a.reference:  # KIND:SIZE/REF for one indenter, SIZE/REF for every case
            k, _, m = m.rpartition(":")
            if k in ("", kind) and not any(r["scene"] == make_scene(kind, float(t), a.quality, m, a.skin).label()
                                           and r["mesh"] == m for r in refs) and not (a.cached and not _ref_path(make_scene(kind, float(t), a.quality, m, a.skin)).exists()):
                refs.append(reference(make_scene(kind, float(t), a.quality, m, a.skin), a.fresh))
    if not rows:
        print("no results: nothing solved and nothing in raw_calculix3d/ for these cases", file=sys.stderr)
        return 1
    plot(rows, a.out.with_suffix(".png"))
    cmd = "PYTHONPATH=src python benchmarks/calculix_compare3d.py " + " ".join(argv if argv is not None else sys.argv[1:])
    text = markdown(rows, cmd.strip(), refs)
    print(text)
    if a.out.exists() and "\n## Findings" in a.out.read_text():  # keep the hand-written analysis
        text += "\n## Findings" + a.out.read_text().split("\n## Findings", 1)[1]
    fileio.atomic_write_text(a.out, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
