"""Solver-speed A/B on paper cases: the 2026-11-22 changes switched off one at a time.

Variants (SolverOptions on the same code and mesh):
  before   SuperLU, no sticky contact, curvature tangent from the first iterate, grow
           increments after <= 5 iterations (the solver as of commit 0f4194a, except the
           3D contact rule and the kernels, which are not switchable)
  +pardiso before with PARDISO
  +sticky  ... and contact points stay active within a Newton solve
  now      the defaults (curvature term from the third iterate, growth after <= 7)

Prints increments, Newton iterations, peak, CPU time and the per-phase wall times of the
`now` run. One process, one thread (MKL_NUM_THREADS=1 is set before numpy loads).

    .venv/bin/python benchmarks/solver_speed.py [--cases t1-silicone-curved,t3-silicone-flat]
"""

from __future__ import annotations

import os

os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402

from tactileskin import fe  # noqa: E402
from tactileskin.fe.solver import SolverOptions  # noqa: E402
from tactileskin.mesh import build_mesh  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402

VARIANTS = {
    "before": dict(linear_solver="superlu", sticky_contact=False, curvature_after=0, easy_iterations=5),
    "+pardiso": dict(linear_solver="pardiso", sticky_contact=False, curvature_after=0, easy_iterations=5),
    "+sticky": dict(linear_solver="pardiso", sticky_contact=True, curvature_after=0, easy_iterations=5),
    "now": {},
}
CASES = "t1-silicone-curved,t3-silicone-flat,t3-silicone-braille,t5-polyurethane-curved"


def scene_of(label: str) -> Scene:
    t, mat, ind = label.split("-")
    return Scene(thickness=float(t[1:]), material=mat, indenter=ind)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=CASES)
    ap.add_argument("--variants", default=",".join(VARIANTS))
    a = ap.parse_args()
    print("| case | variant | dofs | increments | Newton | cutbacks | peak MPa | CPU s |")
    print("|---|---|---|---|---|---|---|---|")
    phases = {}
    for label in a.cases.split(","):
        sc = scene_of(label)
        mesh = build_mesh(sc)
        for v in a.variants.split(","):
            opts = SolverOptions(**VARIANTS[v])
            c0 = time.process_time()
            try:
                r = fe.solve(sc, mesh, options=opts)
            except Exception as e:  # a failed variant is a result too
                print(f"| {label} | {v} | | | | | {type(e).__name__} | {time.process_time() - c0:.1f} |")
                continue
            st = r.stats
            print(f"| {label} | {v} | {st['dofs']} | {st['increments']} | {st['newton_iterations']} "
                  f"| {st['cutbacks']} | {r.peak:.5f} | {time.process_time() - c0:.1f} |", flush=True)
            if v == "now":
                phases[label] = st["phases_s"]
    if phases:
        keys = ["mesh", "setup", "residual", "tangent", "contact", "factor", "solve", "recovery", "other", "total"]
        print("\nPer-phase wall time of the `now` runs (s; contact is part of residual and tangent; "
              "mesh is 0 when the mesh is given):\n")
        print("| case | " + " | ".join(keys) + " |")
        print("|---|" + "---|" * len(keys))
        for label, ph in phases.items():
            print(f"| {label} | " + " | ".join(f"{ph.get(k, 0):.2f}" for k in keys) + " |")


if __name__ == "__main__":
    main()
