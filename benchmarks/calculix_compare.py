"""tactileskin against CalculiX on the same mesh: bone pressure and reaction of a 2D case.

Exports the scene as a CalculiX-flavoured deck (tactileskin.mesh.deck, dialect "calculix":
instantaneous hyperfoam, no Prony since ccx has none, the indenter a strip of elements moved
as one, penalty contact), runs `ccx` (Debian package calculix-ccx; not a project dependency),
reads the last increment's nodal stresses from the .frd file and the force totals from the
.dat file, solves the same scene on the same mesh with tactileskin (elastic; mixed and
displacement formulations) and writes benchmarks/results/calculix_compare.md.

    PYTHONPATH=src python benchmarks/calculix_compare.py [--thickness 3] [--quality preview]
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tactileskin import fileio
from tactileskin.fe import solve
from tactileskin.materials import get_material
from tactileskin.mesh import build_mesh
from tactileskin.mesh.deck import deck_text
from tactileskin.planner import with_quality
from tactileskin.scene import Scene

OUT = Path(__file__).parent / "results" / "calculix_compare.md"


def read_frd_last(path: Path, name: str) -> dict[int, np.ndarray]:
    """Nodal values of the last result block `name` (e.g. STRESS, DISP, CONTACT) of an ASCII
    .frd file: node id -> values. Records: ' -1' + I10 node id + E12.5 fields."""
    blocks, cur = [], None
    with open(path) as fh:
        for line in fh:
            if line.startswith(" -4"):
                cur = {} if line.split()[1] == name else None
                if cur is not None:
                    blocks.append(cur)
            elif cur is not None and line.startswith(" -1"):
                body = line[13:].rstrip("\n")
                cur[int(line[3:13])] = np.array([float(body[i:i + 12]) for i in range(0, len(body) - 11, 12)])
            elif line.startswith(" -3"):
                cur = None
    if not blocks:
        raise RuntimeError(f"no {name} block in {path}")
    return blocks[-1]


def read_dat_totals(path: Path) -> dict[str, np.ndarray]:
    """Last 'total force (fx,fy,fz) for set NAME' of a .dat file, per set."""
    out, lines = {}, Path(path).read_text().splitlines()
    for i, line in enumerate(lines):
        if line.strip().startswith("total force") and " for set " in line:
            name = line.split(" for set ")[1].split()[0]
            vals = next(v for v in lines[i + 1:] if v.strip())
            out[name] = np.array([float(v) for v in vals.split()])
    return out


def run_ccx(deck: str, workdir: Path, timeout: float = 1800.0) -> dict:
    (workdir / "job.inp").write_text(deck)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_STIFFNESS="1", CCX_NPROC_EQUATION_SOLVER="1")
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(["ccx", "-i", "job"], cwd=workdir, env=env, capture_output=True, text=True,
                          timeout=timeout)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    sta = (workdir / "job.sta").read_text() if (workdir / "job.sta").exists() else ""
    if proc.returncode != 0 or "ERROR" in proc.stdout:
        raise RuntimeError(f"ccx failed ({proc.returncode}):\n{proc.stdout[-3000:]}")
    return {"cpu_s": (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime),
            "wall_s": time.perf_counter() - t0, "increments": max(0, len(sta.splitlines()) - 2),
            "iterations": sum(int(r.split()[3]) for r in sta.splitlines()[2:] if len(r.split()) > 3)}


def compare(thickness: float, quality: str, penalty_factor: float = 10.0, material: str = "polyurethane") -> dict:
    scene = with_quality(Scene(thickness=thickness, material=material, indenter="flat",
                               viscoelastic=False), quality)
    sm = build_mesh(scene)
    hf = get_material(material).hyperfoam
    penalty = penalty_factor * max(hf.K0, hf.mu0) / sm.sizes["fine"]  # the deck's default is factor 10
    deck = deck_text(scene, sm, "calculix", penalty=penalty)
    with tempfile.TemporaryDirectory(prefix="tsk_ccx_") as tmp:
        work = Path(tmp)
        ccx = run_ccx(deck.text, work)
        stress = read_frd_last(work / "job.frd", "STRESS")
        contact = read_frd_last(work / "job.frd", "CONTACT")
        totals = read_dat_totals(work / "job.dat")
    from tactileskin.mesh.skinmesh import facet_nodes

    bone = np.unique(facet_nodes(sm.mesh, sm.boundaries["bone_interface"], 2, sm.order))
    X = sm.mesh.doflocs.T[bone]
    S = np.array([stress[int(i) + 1] for i in bone])  # sxx syy szz sxy syz szx
    P_ccx = -(S[:, 0] + S[:, 1] + S[:, 2]) / 3.0
    s_ccx = scene.section().s_of_point(X)
    order = np.argsort(s_ccx)
    s_ccx, P_ccx = s_ccx[order], P_ccx[order]
    # ccx's nodal values alternate between corner and mid-side nodes near the peak (extrapolated
    # integration-point stresses): its peak also as an even quadratic a + b s^2 fitted to the
    # nodes within 0.5 mm of the symmetry line (the profile is even in s about s = 0)
    near = s_ccx < 0.5
    fit_peak = float(np.linalg.lstsq(np.column_stack([np.ones(near.sum()), s_ccx[near] ** 2]), P_ccx[near],
                                     rcond=None)[0][0])
    copen = np.array([v[0] for v in contact.values()])
    cpress = np.array([v[3] for v in contact.values()])
    row = {"scene": scene.label(), "depth": scene.indentation, "mesh": f"{scene.mesh_size:g}/{scene.refinement:g} ({quality})",
           "cells": deck.n_skin_cells, "nodes": deck.n_skin_nodes, "ccx": ccx,
           "ccx_peak": float(P_ccx.max()), "ccx_fit_peak": fit_peak, "ccx_peak_s": float(s_ccx[np.argmax(P_ccx)]),
           "ccx_force": float(-totals["INDENTER_NODES"][1]), "ccx_bone_fy": float(totals["BONE_INTERFACE"][1]),
           "ccx_penetration": float(max(0.0, -copen.min())), "ccx_cpress_max": float(cpress.max()),
           "penalty": deck.info["penalty_mpa_per_mm"], "penalty_factor": penalty_factor,
           "profile_ccx": (s_ccx, P_ccx), "ts": {}}
    for form in ("mixed", "displacement"):
        c0 = time.process_time()
        res = solve(scene.replace(formulation=form), mesh=sm)
        cpu = time.process_time() - c0
        p_at = np.interp(res.s, s_ccx, P_ccx)
        k = int(np.argmax(np.abs(res.pressure - p_at)))
        row["ts"][form] = {"max_diff_s": float(res.s[k]), "profile": (res.s, res.pressure),"peak": float(res.peak), "peak_s": float(res.s[np.argmax(res.pressure)]),
                           "force": float(res.reaction), "cpu_s": cpu,
                           "max_diff": float(np.max(np.abs(res.pressure - p_at))),
                           "rms_diff": float(np.sqrt(np.mean((res.pressure - p_at) ** 2))),
                           "newton": int(res.stats["newton_iterations"])}
    return row


def markdown(rows: list[dict]) -> str:
    L = ["# tactileskin vs CalculiX (ccx 2.20) on the same mesh", "",
         "Command: `PYTHONPATH=src python benchmarks/calculix_compare.py` (one ccx run and two tactileskin "
         "solves per case; CPU seconds of each process).", "",
         "Polyurethane, flat plate, 20 % nominal strain at 1 mm/s, elastic (instantaneous hyperfoam; CalculiX "
         "has no Prony viscoelasticity), plane strain per mm of depth. Same P2 triangle mesh: tactileskin "
         "solves it as is; the deck gives it to ccx as CPE6, which ccx expands to 15-node wedges (C3D15, "
         "9 integration points, displacement formulation). Bone pressure P = -(sxx+syy+szz)/3: ccx's nodal "
         "stresses (extrapolated from the integration points and averaged over the elements at each node, "
         ".frd; 'fit': an even quadratic fitted to ccx's nodes with s < 0.5 mm, at s = 0) against tactileskin's bone profile (fe.recovery.PointFit); differences are max / rms over the "
         "bone samples of |P_ts - P_ccx| with ccx interpolated linearly in s.", "",
         "| case | mesh | code | peak P (MPa) | at s (mm) | indenter force (N/mm) | max diff (MPa) at s (mm) / rms | CPU (s) |",
         "|---|---|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        c = r["ccx"]
        L.append(f"| {r['scene']} | {r['mesh']}, {r['cells']} cells | CalculiX, penalty {r['penalty']:.0f} MPa/mm "
                 f"({r['penalty_factor']:g} K0/h), penetration {r['ccx_penetration'] * 1e3:.2f} um = "
                 f"{100 * r['ccx_penetration'] / r['depth']:.2f} % of the travel | {r['ccx_peak']:.4f} "
                 f"(fit {r['ccx_fit_peak']:.4f}) | "
                 f"{r['ccx_peak_s']:.2f} | {r['ccx_force']:.4f} | - | {c['cpu_s']:.1f} "
                 f"({c['increments']} incr., {c['iterations']} it.) |")
        for form, t in r["ts"].items():
            dpk = 100.0 * (t["peak"] / r["ccx_peak"] - 1.0)
            dfit = 100.0 * (t["peak"] / r["ccx_fit_peak"] - 1.0)
            dF = 100.0 * (t["force"] / r["ccx_force"] - 1.0)
            L.append(f"| | | tactileskin {form} | {t['peak']:.4f} ({dpk:+.1f} %; fit {dfit:+.1f} %) | {t['peak_s']:.2f} | "
                     f"{t['force']:.4f} ({dF:+.1f} %) | {t['max_diff']:.4f} at {t['max_diff_s']:.2f} / {t['rms_diff']:.4f} | "
                     f"{t['cpu_s']:.1f} ({t['newton']} Newton) |")
    return "\n".join(L) + "\n"


def plot_panels(panels: list[dict], path: Path) -> None:
    """One panel per dict: the CalculiX profile(s) as markers and tactileskin's per formulation
    as lines; keys title, xlim, ccx [(s, p, label, marker, colour)], ts {form: (s, p)}.
    Shared by the 2D and 3D comparisons."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.4), squeeze=False)
    for ax, pn in zip(axes[0], panels):
        for s, p, label, marker, colour in pn["ccx"]:
            ax.plot(s, p, marker, ms=3 if marker == "o" else 4, color=colour, label=label)
        for (form, prof), c in zip(pn["ts"].items(), ("#D55E00", "#009E73")):
            ax.plot(*prof, "-", color=c, lw=1.2, label=f"tactileskin {form}")
        ax.set(title=pn["title"], xlabel="s along the bone (mm)", ylabel="bone pressure P (MPa)", xlim=pn["xlim"])
        ax.title.set_fontsize(8)
        ax.legend(fontsize=7)
    fig.tight_layout()
    with fileio.atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def plot(rows: list[dict], path: Path) -> None:
    plot_panels([{"title": f"{r['scene']} {r['mesh']}, {r['penalty_factor']:g} K0/h", "xlim": (0, 8),
                  "ccx": [(*r["profile_ccx"], "CalculiX (nodal)", "o", "#0072B2")],
                  "ts": {form: t["profile"] for form, t in r["ts"].items()}} for r in rows], path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", type=float, nargs="+", default=[3.0])
    ap.add_argument("--quality", nargs="+", default=["preview"])
    ap.add_argument("--penalty-factor", type=float, nargs="+", default=[10.0],
                    help="CalculiX contact slope in units of K0 / h_fine")
    ap.add_argument("--out", type=Path, default=OUT)
    a = ap.parse_args(argv)
    if shutil.which("ccx") is None:
        print("ccx not found: apt-get install calculix-ccx", file=sys.stderr)
        return 2
    rows = [compare(t, q, f) for q in a.quality for t in a.thickness for f in a.penalty_factor]
    plot(rows, a.out.with_suffix(".png"))
    text = markdown(rows)
    print(text)
    if a.out.exists() and "\n## Findings" in a.out.read_text():  # keep the hand-written analysis
        text += "\n## Findings" + a.out.read_text().split("\n## Findings", 1)[1]
    fileio.atomic_write_text(a.out, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
