"""PARDISO's fill-reducing ordering for the 2D tangents (issue 13 T10): METIS nested dissection
against minimum degree (AMD), on the matrices the solver factorises and in whole solves.

--matrices: every free-block tangent a Newton solve factorises for a few 2D cases (captured
from the solver), timed with each ordering in one process, the orderings alternating per
round: analysis (phase 11) CPU ms, factorisation + solve CPU ms per matrix (medians of
--repeat rounds), factor nonzeros and MFlops as PARDISO reports them, and the largest relative
difference of the two orderings' solutions.

--src OLD/src NEW/src: the 18 paper 2D cases at --quality, each run a fresh process per source
tree (e.g. a `git worktree` of the old revision), trees alternating per round (old, new; new,
old; ...). A run builds the meshes first (not timed), warms numba's cache with one solve, then
solves the cases; it reports the CPU seconds of the solves (process time) and the PARDISO
phases' CPU, and writes every case's results (peak, reaction, Newton count, pressure profile,
contact pressure, displacements) to an .npz; the trees' results are compared case by case
(Newton counts equal, largest relative difference of each array to its largest magnitude).

    .venv/bin/python benchmarks/pardiso_ordering.py --matrices [--repeat 5]
    .venv/bin/python benchmarks/pardiso_ordering.py --src OLD/src NEW/src [--repeat 3] [--quality preview]
    .venv/bin/python benchmarks/pardiso_ordering.py --src OLD/src NEW/src --repeat 1 --quality default \\
        --cases t1-silicone-flat,t1-silicone-braille,t5-silicone-flat,t5-silicone-braille
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter

import numpy as np

ALL = [f"t{t:g}-{m}-{i}" for t, m, i in itertools.product((1, 3, 5), ("silicone", "polyurethane"),
                                                            ("flat", "curved", "braille"))]
MATRIX_CASES = [("t1-silicone-flat", "preview"), ("t3-polyurethane-curved", "preview"),
                ("t5-silicone-braille", "preview"), ("t1-silicone-flat", "default"),
                ("t5-silicone-braille", "default")]
ARRAYS = ("pressure", "contact_pressure", "displacement_mm")


def _scene(label: str, quality: str):
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    t, m, i = label.split("-")
    return with_quality(Scene(thickness=float(t[1:]), material=m, indenter=i), quality)


def _captured(label: str, quality: str) -> list:
    """The free-block matrices the solver factorises in the solve of one case."""
    from tactileskin.fe import linsolve, solve
    from tactileskin.mesh import build_mesh

    mats, real = [], linsolve.SymmetricSolver._factor

    def spy(self, A):
        mats.append(A.copy())
        return real(self, A)

    sc = _scene(label, quality)
    linsolve.SymmetricSolver._factor = spy
    try:
        solve(sc, build_mesh(sc))
    finally:
        linsolve.SymmetricSolver._factor = real
    return mats


def matrices(repeat: int) -> None:
    os.environ.setdefault("MKL_NUM_THREADS", "1")
    from tactileskin.fe import linsolve

    print(f"load average {os.getloadavg()[0]:.2f}; CPU ms, medians of {repeat} rounds, orderings alternating\n")
    print("| case | quality | free dofs | matrices | ordering | analysis ms | factor + solve ms per matrix "
          "| factor nnz | MFlops | max rel. difference of solutions |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, quality in MATRIX_CASES:
        mats = _captured(label, quality)
        n = mats[0].shape[0]
        b = np.random.default_rng(0).standard_normal(n)
        ana, fs, info, xs = {o: [] for o in linsolve.ORDERINGS}, {o: [] for o in linsolve.ORDERINGS}, {}, {}
        for r in range(repeat):
            for o in (list(linsolve.ORDERINGS) if r % 2 == 0 else list(linsolve.ORDERINGS)[::-1]):
                c0 = time.process_time()
                s = linsolve.SymmetricSolver(mats[0], "pardiso", ordering=o)
                c1 = time.process_time()
                xs[o] = [s.factor(A).solve(b) for A in mats]
                c2 = time.process_time()
                ana[o].append(1e3 * (c1 - c0))
                fs[o].append(1e3 * (c2 - c1) / len(mats))
                info[o] = (s._pardiso.factor_nnz, s._pardiso.factor_mflops)
                s.close()
        diff = max(float(np.max(np.abs(x - y)) / np.max(np.abs(x))) for x, y in zip(xs["metis"], xs["amd"]))
        for o in linsolve.ORDERINGS:
            print(f"| {label} | {quality} | {n} | {len(mats)} | {o} | {np.median(ana[o]):.2f} | "
                  f"{np.median(fs[o]):.3f} | {info[o][0]} | {info[o][1]:g} | {diff:.1e} |", flush=True)


def one(quality: str, cases: list, out: str) -> dict:
    os.environ.setdefault("MKL_NUM_THREADS", "1")
    from tactileskin.fe import linsolve, solve
    from tactileskin.mesh import build_mesh

    scenes = [_scene(c, quality) for c in cases]
    meshes = [build_mesh(sc) for sc in scenes]
    solve(scenes[0], meshes[0])   # numba's cache loaded, first-call costs paid
    phase_cpu, real = Counter(), linsolve._Pardiso._pardiso

    def timed(self, phase, *a):
        c = time.process_time()
        real(self, phase, *a)
        phase_cpu[phase] += time.process_time() - c

    linsolve._Pardiso._pardiso = timed
    arrays = {}
    c0, w0 = time.process_time(), time.perf_counter()
    for label, sc, sm in zip(cases, scenes, meshes):
        r = solve(sc, sm)
        pd = (r.fields or {}).get("point_data") or {}
        got = {"pressure": r.pressure, "contact_pressure": r.contact_pressure,
               "displacement_mm": pd.get("displacement_mm"),
               "scalars": np.array([r.peak, r.reaction, r.stats["newton_iterations"]], float)}
        for k, x in got.items():
            if x is not None:
                arrays[f"{label}/{k}"] = np.asarray(x, float)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    np.savez(out, **arrays)
    return dict(cpu=cpu, wall=wall, pardiso={str(k): v for k, v in phase_cpu.items()})


def run(src: str, quality: str, cases: list, out: str) -> dict:
    env = dict(os.environ, PYTHONPATH=os.path.abspath(src), MKL_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    p = subprocess.run([sys.executable, __file__, "--one", quality, "--cases", ",".join(cases), "--out", out],
                       env=env, check=True, capture_output=True, text=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def compare(a: str, b: str, cases: list) -> tuple[list, float, dict]:
    """Cases whose Newton counts differ, the largest relative difference of a peak, and per
    array kind the largest relative difference (to that array's largest magnitude; the
    reaction as a scalar) with its case."""
    A, B = np.load(a), np.load(b)
    if set(A.files) != set(B.files):
        raise SystemExit(f"the runs wrote different arrays: {sorted(set(A.files) ^ set(B.files))}")
    newton, peak, worst = [], 0.0, {}
    for c in cases:
        sa, sb = A[f"{c}/scalars"], B[f"{c}/scalars"]
        if sa[2] != sb[2]:
            newton.append(f"{c}: {sa[2]:g} / {sb[2]:g}")
        peak = max(peak, abs(sa[0] - sb[0]) / max(abs(sa[0]), 1e-300))
        d = {"reaction": abs(sa[1] - sb[1]) / max(abs(sa[1]), 1e-300)}
        for k in ARRAYS:
            if f"{c}/{k}" in A.files:
                x, y = A[f"{c}/{k}"], B[f"{c}/{k}"]
                d[k] = float(np.max(np.abs(x - y)) / max(np.max(np.abs(x)), 1e-300))
        for k, v in d.items():
            if v >= worst.get(k, (0.0, ""))[0]:
                worst[k] = (v, c)
    return newton, peak, worst


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--matrices", action="store_true")
    ap.add_argument("--src", nargs="+", default=["src"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quality", default="preview")
    ap.add_argument("--cases", default=",".join(ALL))
    ap.add_argument("--one", help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    cases = a.cases.split(",")
    if a.matrices:
        matrices(a.repeat)
        return 0
    if a.one is not None:
        print(json.dumps(one(a.one, cases, a.out)))
        return 0
    load0 = os.getloadavg()
    res = {s: [] for s in a.src}
    with tempfile.TemporaryDirectory() as tmp:
        files = {s: [] for s in a.src}
        for i in range(a.repeat):
            for j, s in enumerate(a.src if i % 2 == 0 else a.src[::-1]):
                out = os.path.join(tmp, f"{a.src.index(s)}_{i}.npz")
                res[s].append(r := run(s, a.quality, cases, out))
                files[s].append(out)
                print(f"# round {i + 1}, {s}: CPU {r['cpu']:.2f} s, wall {r['wall']:.2f} s", flush=True)
        load1 = os.getloadavg()
        print(f"\n{len(cases)} 2D cases at {a.quality}; {a.repeat} rounds, trees alternating; "
              f"load average at start {load0[0]:.2f}, at end {load1[0]:.2f}\n")
        print("| tree | CPU s (median) | CPU s (runs) | wall s (median) | PARDISO analysis | factor | solve |")
        print("|---|---|---|---|---|---|---|")
        for s, rs in res.items():
            ph = " | ".join(f"{np.median([r['pardiso'].get(k, 0.0) for r in rs]):.3f}" for k in ("11", "22", "33"))
            print(f"| {s} | {np.median([r['cpu'] for r in rs]):.2f} | "
                  f"{', '.join(format(r['cpu'], '.2f') for r in rs)} | {np.median([r['wall'] for r in rs]):.2f} | {ph} |")
        print("\nPARDISO phases: median CPU s summed over the solves (analysis 11, factorisation 22, solve 33)")
        first = files[a.src[0]][0]
        for s in a.src:
            for f in files[s]:
                if f == first:
                    continue
                newton, peak, worst = compare(first, f, cases)
                same = peak == 0.0 and all(v == 0.0 for v, _ in worst.values())
                print(f"results of {s} ({os.path.basename(f)}) against {a.src[0]} (first run): Newton counts "
                      f"{'the same' if not newton else 'DIFFER: ' + '; '.join(newton)}, "
                      + ("bit for bit the same" if same else f"peaks differ by at most {peak:.1e} (relative), "
                         + ", ".join(f"{k} {v:.1e} ({c})" for k, (v, c) in worst.items())))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
