"""Time the 18 paper cases (t = 1, 3, 5 mm x silicone, polyurethane x flat, curved, Braille)
at a quality preset, one case after the other in one process, one thread.

Prints, per case: dofs, increments, Newton iterations, peak, CPU seconds for meshing and
for the solve, and the sum; the sum halved is the ideal wall time on two workers (the CLI
sweep's own wall time is measured separately with `tactileskin sweep`).

    .venv/bin/python benchmarks/paper_sweep.py [--quality default] [--cases t1-silicone-flat,...]
"""

from __future__ import annotations

import os

os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

from tactileskin import fe  # noqa: E402
from tactileskin.mesh import build_mesh  # noqa: E402
from tactileskin.planner import with_quality  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402
from tactileskin.sweep import PAPER_INDENTERS, PAPER_MATERIALS, PAPER_THICKNESSES  # noqa: E402

ALL = [f"t{t:g}-{m}-{i}" for t in PAPER_THICKNESSES for m in PAPER_MATERIALS for i in PAPER_INDENTERS]


def scene_of(label: str, quality: str) -> Scene:
    t, mat, ind = label.split("-")
    return with_quality(Scene(thickness=float(t[1:]), material=mat, indenter=ind), quality)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quality", default="default")
    ap.add_argument("--cases", default=",".join(ALL))
    ap.add_argument("--repeat", type=int, default=1, help="runs per case; the median CPU time is quoted")
    a = ap.parse_args()
    print(f"quality {a.quality}\n")
    print("| case | dofs | increments | Newton | peak MPa | mesh CPU s | solve CPU s | total CPU s |")
    print("|---|---|---|---|---|---|---|---|")
    tot_mesh = tot_solve = 0.0
    for label in a.cases.split(","):
        sc = scene_of(label, a.quality)
        meshes, solves = [], []
        for _ in range(a.repeat):
            c0 = time.process_time()
            mesh = build_mesh(sc)
            c1 = time.process_time()
            r = fe.solve(sc, mesh)
            c2 = time.process_time()
            meshes.append(c1 - c0)
            solves.append(c2 - c1)
        m, s = statistics.median(meshes), statistics.median(solves)
        tot_mesh += m
        tot_solve += s
        st = r.stats
        print(f"| {label} | {st['dofs']} | {st['increments']} | {st['newton_iterations']} | {r.peak:.5f} "
              f"| {m:.2f} | {s:.2f} | {m + s:.2f} |", flush=True)
    print(f"\nsum: meshing {tot_mesh:.1f} s + solving {tot_solve:.1f} s = {tot_mesh + tot_solve:.1f} s CPU; "
          f"ideal wall on 2 workers {(tot_mesh + tot_solve) / 2:.1f} s")


if __name__ == "__main__":
    main()
