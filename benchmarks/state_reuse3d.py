"""The 3D law computed once per Newton iterate (fe.Model's state reuse), before/after: the
silicone single Braille dot at the `default` 3D preset (issue 13's T3 case is t = 5 mm).

Whole solves (default): each run a fresh process, the source trees given by --src (e.g. a
`git worktree` of the old revision) alternating per thickness, --repeat rounds; prints per
tree and thickness the CPU s (process time of the solve, all threads) and wall s of each run
and their medians, increments / Newton, the peak, and the counts of one run: material law
calls with the eigenproblem (S only, S + D), D from kept spectral data, residual
evaluations, evaluations that reused their state, tangents assembled. The counts are taken
by wrapping Model methods (the same wrappers in both trees; their cost is a counter).

--law: the isolated CPU ms of one law call at the t = 5 dot's size (its quadrature points at
0.1 x kernels.trial_state), median of --repeat calls: S only, S + D, S keeping the spectral
data, D from it; 1 and 2 numba threads.

    .venv/bin/python benchmarks/state_reuse3d.py --src OLD/src NEW/src [--thickness 5 1] [--repeat 3]
    .venv/bin/python benchmarks/state_reuse3d.py --law [--repeat 15]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections import Counter

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def one(t: float, warm: bool = False) -> dict:
    from tactileskin.fe import kernels, model as fem, solve
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    counts, models = Counter(), []
    init, law, evaluate, tangent = fem.Model.__init__, fem.Model._law, fem.Model.evaluate, fem.Model.tangent
    ktangent = kernels.tangent

    def w_init(self, *a, **k):
        init(self, *a, **k)
        models.append(self)

    def w_law(self, C, tangent, *a, **k):
        counts["law S+D" if tangent else "law S"] += 1
        return law(self, C, tangent, *a, **k)

    def w_evaluate(self, *a, **k):
        counts["residuals"] += 1
        return evaluate(self, *a, **k)

    def w_ktangent(*a, **k):
        counts["tangents"] += 1
        return ktangent(*a, **k)

    fem.Model.__init__, fem.Model._law, fem.Model.evaluate = w_init, w_law, w_evaluate
    kernels.tangent = w_ktangent
    sc = Scene(dim=3, indenter="braille", thickness=t, material="silicone", braille_text="")
    if warm:  # the same compiled loops on the coarse preview mesh: fills numba's cache
        sc = with_quality(sc, "preview")
    w0, c0 = time.perf_counter(), time.process_time()
    r = solve(sc)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    mc = getattr(models[-1], "counts", {})
    counts["D kept"] = mc.get("tangent_kept", 0)
    counts["state reused"] = mc.get("state_reused", 0)
    return dict(wall=wall, cpu=cpu, incr=r.stats["increments"], newton=r.stats["newton_iterations"],
                peak=float(r.peak), counts=dict(counts), phases=r.stats["phases_s"])


def run(src: str, t: float, warm: bool = False) -> dict:
    env = dict(os.environ, PYTHONPATH=os.path.abspath(src))
    out = subprocess.run([sys.executable, __file__, "--one", str(t)] + (["--warm"] if warm else []), env=env, check=True, capture_output=True,
                         text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def law_times(repeat: int) -> None:
    sys.path.insert(0, HERE)
    from assembly_speed import dot_state, timed

    from tactileskin.materials import get_material
    from tactileskin.materials.hyperfoam import pk2_kept_solid, pk2_tangent_solid, tangent_kept_solid
    from tactileskin.threads import numba_threads

    _, model, ev = dot_state(__doc__, ["--thickness", "5"])
    hf = get_material("silicone").hyperfoam
    C = ev.kin.C
    kept = pk2_kept_solid(hf, C)[2]
    print(f"t = 5 mm dot: {C.shape[0] * C.shape[1]} points; CPU ms (wall ms), medians of {repeat}; "
          f"load average {os.getloadavg()[0]:.2f}")
    for th in (1, 2):
        with numba_threads(th):
            res = timed({"S only": lambda: pk2_tangent_solid(hf, C, tangent=False),
                         "S + D": lambda: pk2_tangent_solid(hf, C),
                         "S, keeping": lambda: pk2_kept_solid(hf, C),
                         "D from kept": lambda: tangent_kept_solid(hf, kept)}, repeat)
        print(f"{th} thread(s): " + "; ".join(f"{k} {c:.1f} ({w:.1f})" for k, (c, w) in res.items()))
    same = np.array_equal(tangent_kept_solid(hf, kept), pk2_tangent_solid(hf, C)[1])
    print(f"D from kept == D of S + D bit for bit: {same}")
    # the model's units: a residual evaluation afresh against one at the same u (only the
    # contact part computed), a tangent with D from the law against D from the kept data
    u = ev._u
    for th in (1, 2):
        model.threads = th

        def fresh_tangent():
            model.reuse_state = False
            model.tangent(model.evaluate(u, 0.0, 1.0, tangent=False))
            model.reuse_state = True

        def kept_tangent():
            model._last = None
            model.tangent(model.evaluate(u, 0.0, 1.0, tangent=False))

        def fresh_residual():
            model._last = None
            model.evaluate(u, 0.0, 1.0, tangent=False)

        model.evaluate(u, 0.0, 1.0, tangent=False)
        res = timed({"residual afresh": fresh_residual,
                     "residual, state reused": lambda: model.evaluate(u, 0.0, 1.0, tangent=False),
                     "residual + tangent, D from the law": fresh_tangent,
                     "residual + tangent, D from kept": kept_tangent}, repeat)
        print(f"Model, {th} thread(s): " + "; ".join(f"{k} {c:.1f} ({w:.1f})" for k, (c, w) in res.items()))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", nargs="+", default=["src"])
    ap.add_argument("--thickness", type=float, nargs="+", default=[5.0, 1.0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--law", action="store_true")
    ap.add_argument("--one", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--warm", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one is not None:
        print(json.dumps(one(a.one, a.warm)))
        return 0
    if a.law:
        law_times(a.repeat)
        return 0
    for s in a.src:  # numba's caches of each tree (a first 3D run compiles)
        run(s, a.thickness[0], warm=True)
    load0 = os.getloadavg()
    res = {(s, t): [] for t in a.thickness for s in a.src}
    for i in range(a.repeat):
        for t in a.thickness:
            for s in (a.src if i % 2 == 0 else a.src[::-1]):   # alternate which tree goes first
                res[s, t].append(r := run(s, t))
                print(f"# round {i + 1}, t = {t:g}, {s}: CPU {r['cpu']:.1f} s, wall {r['wall']:.1f} s", flush=True)
    load1 = os.getloadavg()
    print(f"silicone dot, default 3D preset; {a.repeat} rounds, trees alternating; "
          f"load average at start {load0[0]:.2f}, at end {load1[0]:.2f}")
    for (s, t), rs in res.items():
        r0 = rs[0]
        same = {(r["incr"], r["newton"], r["peak"]) for r in rs}
        cpus = ", ".join(f"{r['cpu']:.1f}" for r in rs)
        walls = ", ".join(f"{r['wall']:.1f}" for r in rs)
        print(f"t = {t:g} {s}: CPU {np.median([r['cpu'] for r in rs]):.1f} s ({cpus}), "
              f"wall {np.median([r['wall'] for r in rs]):.1f} s ({walls}), {r0['incr']} / {r0['newton']}, "
              f"peak {r0['peak']!r}"
              + ("" if len(same) == 1 else f" (runs differ: {sorted(same)})"))
        print("   counts:", json.dumps(r0["counts"], sort_keys=True), " phases (median wall s):",
              json.dumps({k: round(float(np.median([r["phases"].get(k, 0.0) for r in rs])), 2)
                          for k in ("residual", "tangent", "contact", "factor", "solve")}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
