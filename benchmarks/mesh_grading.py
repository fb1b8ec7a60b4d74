"""Graded against box-refined 2D meshes: cells, solve time and accuracy of the bone pressure.

Issue #7. For each case, three meshes at the scene's default sizes are solved with
tactileskin.fe.solve:

- legacy: the former default fields (fine box through the whole skin under the contact
  zone, plus the threshold band along the bone ROI), reproduced here by `legacy_fields`;
- graded: the current fields of tactileskin.mesh.sizing (fine at the contact surface and
  along the ROI, growing by sizing.GROWTH per mm in between);
- reference: the graded fields with the fine size halved (refinement doubled).

Errors: peak |P - P_ref| / P_ref; profile = RMS over s <= 6 mm of P(s) - P_ref(s) on a common
s grid, divided by the reference peak (helpers from benchmarks/speed_vs_error.py); and the
same two between graded and legacy (the acceptance criterion: <= 0.3 %). One solve per mesh
(t = 5 solves take minutes; the machine is shared): the times are single measurements.

Rows are kept in benchmarks/results/mesh_grading.json (one per case, mesh and grading
parameters), so cases can be run one process at a time; every run rewrites
benchmarks/results/mesh_grading.md from all stored rows. Usage:

    .venv/bin/python benchmarks/mesh_grading.py --cases t1-silicone-flat t1-silicone-curved
    .venv/bin/python benchmarks/mesh_grading.py --cases t3-silicone-flat --growth 0.3
    .venv/bin/python benchmarks/mesh_grading.py --table     # rewrite the .md only
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from tactileskin.fe import solve
from tactileskin.mesh import build_mesh, sizing
from tactileskin.scene import Scene

sys.path.insert(0, str(Path(__file__).parent))
from speed_vs_error import WINDOW_S  # noqa: E402

RESULTS = Path(__file__).parent / "results"
STORE = RESULTS / "mesh_grading.json"
TABLE = RESULTS / "mesh_grading.md"
ACCEPT = 0.003  # graded vs legacy, peak and profile (issue #7)


def legacy_fields(ymin: float):
    """The fields of the former default (2D only), as an apply_fields replacement:
    Min(box through the skin under the contact zone, y >= ymin, threshold on the ROI
    distance with DistMin = fine, DistMax = fine + 4 coarse)."""
    def apply(gmsh, p, outer, interface_roi, dim):
        f = gmsh.model.mesh.field
        trans = 4.0 * p.coarse
        box = f.add("Box")
        for k, v in (("VIn", p.fine), ("VOut", p.coarse), ("XMin", -1.0), ("XMax", p.contact_x),
                     ("YMin", ymin), ("YMax", 1e3), ("ZMin", -1.0), ("ZMax", 1.0), ("Thickness", trans)):
            f.setNumber(box, k, v)
        dist = f.add("Distance")
        f.setNumbers(dist, "CurvesList", interface_roi)
        f.setNumber(dist, "Sampling", 400)
        thr = f.add("Threshold")
        for k, v in (("InField", dist), ("SizeMin", p.fine), ("SizeMax", p.coarse), ("DistMin", p.fine),
                     ("DistMax", p.fine + trans)):
            f.setNumber(thr, k, v)
        mn = f.add("Min")
        f.setNumbers(mn, "FieldsList", [box, thr])
        f.setAsBackgroundMesh(mn)
        for k, v in (("MeshSizeExtendFromBoundary", 0), ("MeshSizeFromPoints", 0),
                     ("MeshSizeFromCurvature", 0), ("MeshSizeMax", p.coarse), ("MeshSizeMin", p.fine)):
            gmsh.option.setNumber(f"Mesh.{k}", v)
    return apply


@contextlib.contextmanager
def patched(**attrs):
    """Temporarily set attributes of tactileskin.mesh.sizing (fields or grading constants)."""
    old = {k: getattr(sizing, k) for k in attrs}
    try:
        for k, v in attrs.items():
            setattr(sizing, k, v)
        yield
    finally:
        for k, v in old.items():
            setattr(sizing, k, v)


def legacy_mesh(scene: Scene):
    """The former default mesh: its box reached from the contact zone's end through the skin."""
    sec = scene.section()
    ft = sec.fingertip
    w = sizing.contact_halfwidth(scene, sec)
    ymin = float(ft.outer(np.arcsin(min(w / ft.half_width, 1.0)))[1]) - sec.thickness
    with patched(apply_fields=legacy_fields(ymin)):
        return build_mesh(scene)


def profile_diff(s, p, s_ref, p_ref, peak_ref: float) -> float:
    """RMS over s <= WINDOW_S of P - P_ref on a common grid, relative to the reference peak
    (as speed_vs_error.profile_error, on plain arrays)."""
    hi = min(WINDOW_S, s_ref[-1], s[-1])
    x = np.linspace(0.0, hi, 400)
    e = np.interp(x, s, p) - np.interp(x, s_ref, p_ref)
    return float(np.sqrt(np.trapezoid(e * e, x) / hi) / peak_ref)


def run_mesh(scene: Scene, kind: str) -> dict:
    t0 = time.perf_counter()
    if kind == "legacy":
        sm = legacy_mesh(scene)
    elif kind == "graded":
        sm = build_mesh(scene)
    else:  # reference: fine size halved, same coarse size and grading
        sm = build_mesh(scene, refinement=2.0 * scene.refinement)
    mesh_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = solve(scene, sm)
    solve_s = time.perf_counter() - t0
    s, p = res._profile()
    return {"mesh": kind, "cells": int(sm.mesh.nelements), "dofs": int(res.stats["dofs"]),
            "fine": sm.sizes["fine"], "mesh_s": mesh_s, "solve_s": solve_s, "peak": res.peak,
            "s": s.tolist(), "p": p.tolist(), "increments": int(res.stats["increments"])}


def parse_case(name: str) -> Scene:
    t, mat, ind = name.split("-")
    return Scene(thickness=float(t.lstrip("t")), material=mat, indenter=ind)


def load() -> dict:
    return json.loads(STORE.read_text()) if STORE.exists() else {}


def save(store: dict) -> None:
    RESULTS.mkdir(parents=True, exist_ok=True)
    tmp = STORE.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(store))
    os.replace(tmp, STORE)


def grading_key() -> str:
    return f"g{sizing.GROWTH:g}-o{sizing.OUTER_LAYER:g}-r{sizing.ROI_LAYER:g}"


def _vs(r: dict, o: dict | None) -> tuple[str, str]:
    if o is None or o is r:
        return "-", "-"
    return (f"{abs(r['peak'] - o['peak']) / o['peak']:.2%}",
            f"{profile_diff(np.array(r['s']), np.array(r['p']), np.array(o['s']), np.array(o['p']), o['peak']):.2%}")


def table(store: dict) -> str:
    lines = [f"# Graded 2D meshes against the box-refined default ({datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC)",
             "", "Script: benchmarks/mesh_grading.py (see its docstring). Scene defaults: mesh_size 0.25 mm,",
             "refinement 3 (fine 0.083 mm); reference: graded, fine 0.042 mm. Grading: g = size growth",
             "per mm of distance, o / r = fine layer at the contact surface / along the ROI in fine",
             "cells. One solve per mesh on a shared 2-core machine (load average 5-7 during these",
             "runs: times are single measurements, 2-4x an idle machine; compare within a case). The",
             "solver's element kernels were rewritten while these ran (same results to round-off).",
             "", "| case | mesh | grading | cells | dofs | mesh s | solve s | peak MPa | peak vs ref | "
             "profile vs ref | peak vs legacy | profile vs legacy |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for case, rows in sorted(store.items(), key=lambda kv: (float(kv[0].split("-")[0][1:]), kv[0])):
        ref, leg = rows.get("reference"), rows.get("legacy")
        out = [("legacy", leg)] + [("graded", r) for _, r in sorted(rows.get("graded", {}).items())]
        out.append(("reference", ref))
        for kind, r in out:
            if r is None:
                continue
            pr = _vs(r, ref)
            lr = _vs(r, leg) if kind == "graded" else ("-", "-")
            lines.append(f"| {case} | {kind} | {r.get('grading', '-')} | {r['cells']} | {r['dofs']} | "
                         f"{r['mesh_s']:.2f} | {r['solve_s']:.1f} | {r['peak']:.5g} | {pr[0]} | {pr[1]} | "
                         f"{lr[0]} | {lr[1]} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="*", default=[], help="e.g. t3-silicone-curved")
    ap.add_argument("--meshes", nargs="*", default=["legacy", "graded", "reference"])
    ap.add_argument("--growth", type=float, default=None, help="override sizing.GROWTH")
    ap.add_argument("--outer-layer", type=float, default=None, help="override sizing.OUTER_LAYER")
    ap.add_argument("--roi-layer", type=float, default=None, help="override sizing.ROI_LAYER")
    ap.add_argument("--table", action="store_true", help="only rewrite the .md from stored rows")
    a = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(asctime)s %(message)s")
    over = {k: v for k, v in (("GROWTH", a.growth), ("OUTER_LAYER", a.outer_layer),
                              ("ROI_LAYER", a.roi_layer)) if v is not None}
    store = load()
    with patched(**over):
        key = grading_key()
        for case in [] if a.table else a.cases:
            scene = parse_case(case)
            for kind in a.meshes:
                r = run_mesh(scene, kind)
                rows = store.setdefault(case, {})
                if kind == "graded":
                    r["grading"] = key
                    rows.setdefault("graded", {})[key] = r
                else:
                    r["grading"] = key if kind == "reference" else "box"
                    rows[kind] = r
                save(store)
                print(f"{case} {kind} {r['grading']}: {r['cells']} cells, {r['dofs']} dofs, mesh "
                      f"{r['mesh_s']:.2f} s, solve {r['solve_s']:.1f} s, peak {r['peak']:.5g} MPa", flush=True)
    tmp = TABLE.with_suffix(".md.tmp")
    tmp.write_text(table(store))
    os.replace(tmp, TABLE)
    print(TABLE.read_text())


if __name__ == "__main__":
    main()
