"""A bonded silicone pad under the flat plate (a plane over the whole top) at the default 20 %
depth: which widths (over t) solve, where the wider ones fail, and what the failure costs with
the solver's stop at a hopeless cap (fe.solver.run: after a cutback the increments left cannot
reach the end) against the crawl to the natural failure (max_increments so large the stop
never fires: the former behaviour), interleaved.

    .venv/bin/python benchmarks/confined_pad.py [--repeat 3]

Writes benchmarks/results/confined_pad.md.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from tactileskin.errors import ConvergenceError
from tactileskin.fe import solve
from tactileskin.fe.solver import SolverOptions
from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene

OUT = Path(__file__).parent / "results" / "confined_pad.md"
WIDTHS = [(1.0, 5.0), (1.0, 8.0), (1.0, 10.0), (1.0, 15.0), (1.0, 60.0), (3.0, 24.0), (3.0, 28.0)]


def attempt(scene, mesh=None, options=None):
    seen = []
    c0 = time.process_time()
    try:
        r = solve(scene, mesh=mesh, options=options, progress=seen.append)
        what = f"solved, {r.status.split(':')[0]}, peak {r.peak:.3g} MPa"
    except ConvergenceError as e:
        what = f"failed at {e.diagnosis.get('time', float('nan')) * scene.rate:.3g} mm"
    return what, time.process_time() - c0, seen[-1].increment if seen else 0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    lines = ["# Confined pad under the flat plate (silicone, 20 % depth, default mesh)", "",
             "Produced by `benchmarks/confined_pad.py`. CPU seconds of this process (shared machine).", "",
             "| t mm | W mm | W / t | outcome | increments | CPU s |", "|---|---|---|---|---|---|"]
    for t, w in WIDTHS:
        what, cpu, inc = attempt(Scene(skin="pad", pad_width=w, thickness=t, indenter="flat"))
        lines.append(f"| {t:g} | {w:g} | {w / t:.3g} | {what} | {inc} | {cpu:.1f} |")
    sc = Scene(skin="pad", pad_width=60.0, thickness=1.0, indenter="flat")
    mesh = build_mesh(sc)
    runs = {"stop at a hopeless cap (default)": SolverOptions(),
            "crawl to the natural failure (max_increments 1e7)": SolverOptions(max_increments=10 ** 7)}
    got = {k: [] for k in runs}
    for _ in range(a.repeat):
        for k, opts in runs.items():
            got[k].append(attempt(sc, mesh, opts))
    lines += ["", f"W = 60 mm, t = 1 mm, the mesh built once; median of {a.repeat} interleaved:", "",
              "| solver | outcome | increments | CPU s (median) |", "|---|---|---|---|"]
    for k, v in got.items():
        lines.append(f"| {k} | {v[0][0]} | {v[0][2]} | {statistics.median(x[1] for x in v):.1f} |")
    OUT.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
