"""Whole-solve time of the t = 5 mm single Braille dot at the `default` 3D preset (issue 13's
T3 target), before/after a change: each run in a fresh process, the source tree given by
--src (e.g. a `git archive` of the old revision), medians over --repeat runs, alternating
the trees so both see the same machine load.

    .venv/bin/python benchmarks/dot5_speed.py --src OLD/src NEW/src [--repeat 3]

Prints per tree: wall s, increments / Newton iterations, peak, and the phases of
r.stats["phases_s"] (wall s, medians), plus the load average at start and end.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np


def one(warm: bool = False) -> dict:
    from tactileskin.fe import solve
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    sc = Scene(dim=3, indenter="braille", thickness=5, material="silicone", braille_text="")
    if warm:  # the same compiled loops on the coarse preview mesh: fills numba's cache
        sc = with_quality(sc, "preview")
    w0, c0 = time.perf_counter(), time.process_time()
    r = solve(sc)
    return dict(wall=time.perf_counter() - w0, cpu=time.process_time() - c0, dofs=r.stats["dofs"],
                incr=r.stats["increments"], newton=r.stats["newton_iterations"], peak=float(r.peak),
                span=float(r.span), phases=r.stats["phases_s"])


def run(src: str, warm: bool = False) -> dict:
    env = dict(os.environ, PYTHONPATH=os.path.abspath(src))
    out = subprocess.run([sys.executable, __file__, "--warm" if warm else "--one"], env=env, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", nargs="+", default=["src"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--warm", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one or a.warm:
        print(json.dumps(one(a.warm)))
        return 0
    load0 = os.getloadavg()
    for s in a.src:  # warm numba's caches of each tree (a first 3D run compiles ~30 s)
        run(s, warm=True)
    res = {s: [] for s in a.src}
    for _ in range(a.repeat):
        for s in a.src:
            res[s].append(run(s))
    load1 = os.getloadavg()
    keys = ["mesh", "setup", "residual", "tangent", "contact", "factor", "solve", "recovery", "other"]
    print(f"t = 5 mm dot, default 3D preset; medians of {a.repeat} runs per tree, alternating; wall s")
    print(f"load average at start {load0[0]:.2f}, at end {load1[0]:.2f} (1 min)")
    print(f"{'tree':40s} {'wall':>6s} {'cpu':>6s} {'incr/newton':>11s} {'peak MPa':>12s} "
          + " ".join(f"{k:>8s}" for k in keys))
    for s, rs in res.items():
        med = lambda f: float(np.median([f(r) for r in rs]))  # noqa: E731
        same = {(r["incr"], r["newton"], r["peak"]) for r in rs}
        r0 = rs[0]
        print(f"{s[-40:]:40s} {med(lambda r: r['wall']):6.1f} {med(lambda r: r['cpu']):6.1f} "
              f"{r0['incr']:>5d}/{r0['newton']:<5d} {r0['peak']:12.8f} "
              + " ".join(f"{med(lambda r: r['phases'].get(k, 0.0)):8.2f}" for k in keys)
              + ("" if len(same) == 1 else f"  (runs differ: {sorted(same)})"))
        print("   walls:", ", ".join(f"{r['wall']:.1f}" for r in rs), " dofs", r0["dofs"])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
