"""PARDISO iparm options on the 3D Newton systems (issue 13 T3: the t = 5 default dot in <= 20 s).

--matrices: the free-block tangents the solver factorises in the default 3D silicone Braille
dot at --thickness (captured from a solve in a subprocess, kept in --store), a few of them
(--pick) timed per option in one process, options alternating per round (forward, then
reversed): analysis (phase 11), numerical factorisation (22) and one forward/backward
substitution (33), wall and CPU ms (process time: all of PARDISO's threads), medians of
--repeat rounds; factor nonzeros; the largest relative difference of the solution from the
base option's and the relative residual |A x - b| / |b| (in double). Precision, threads and
ordering as the solver uses them (single precision, --threads). --2d adds the 2D default
t = 5 silicone Braille tangents at one thread (the 2D solver's setting).

--src OLD/src NEW/src: whole solves of the default dot (t from --thickness), each a fresh
process per tree, trees alternating per round; CPU s, wall s, Newton and GMRES counts,
factorisations, the PARDISO phases' CPU, and the peak and bone pressure map compared with
the first run of the first tree.

    .venv/bin/python benchmarks/pardiso_options3d.py --matrices [--thickness 5] [--repeat 5]
    .venv/bin/python benchmarks/pardiso_options3d.py --src OLD/src NEW/src --thickness 5 1 [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter

import numpy as np

# name -> iparm components set on top of the solver's own (0-based indices)
OPTIONS = {
    "base": {},
    "iparm[24]=1": {24: 1},
    "iparm[24]=2": {24: 2},
    "iparm[23]=1 (two-level factor)": {23: 1},
    "iparm[1]=3 (parallel METIS)": {1: 3},
    "iparm[1]=0 (AMD)": {1: 0},
}


def _capture(t: float, dim: int, out: str) -> None:
    """Run in a subprocess: solve the default dot, save every factorised matrix."""
    from tactileskin.fe import linsolve, solve
    from tactileskin.scene import Scene

    mats, real = [], linsolve.SymmetricSolver._factor

    def spy(self, A):
        mats.append((A.indptr.copy(), A.indices.copy(), A.data.copy()))
        return real(self, A)

    linsolve.SymmetricSolver._factor = spy
    try:
        solve(Scene(dim=dim, indenter="braille", thickness=t, material="silicone"))
    finally:
        linsolve.SymmetricSolver._factor = real
    ip, ix = mats[0][0], mats[0][1]
    if not all(np.array_equal(m[0], ip) and np.array_equal(m[1], ix) for m in mats):
        raise SystemExit("the factorised matrices do not share one sparsity")
    np.savez(out, indptr=ip, indices=ix, data=np.array([m[2] for m in mats]))


def _load(t: float, dim: int, store: str):
    import scipy.sparse as sp

    path = os.path.join(store, f"t{t:g}_{dim}d.npz")
    if not os.path.exists(path):
        os.makedirs(store, exist_ok=True)
        subprocess.run([sys.executable, __file__, "--capture", f"{t:g}", str(dim), path], check=True)
    z = np.load(path)
    n = len(z["indptr"]) - 1
    return [sp.csr_matrix((d, z["indices"], z["indptr"]), shape=(n, n)) for d in z["data"]]


def _timed(f):
    """f(), and its wall, process CPU and calling-thread CPU ms."""
    c, w, m = time.process_time(), time.perf_counter(), time.thread_time()
    out = f()
    return out, (1e3 * (time.perf_counter() - w), 1e3 * (time.process_time() - c), 1e3 * (time.thread_time() - m))


SOLVES = 10


def time_options(mats: list, threads: int, single: bool, ordering: str, repeat: int, options: dict) -> dict:
    """Per option: median wall / CPU ms of analysis, factorisation and one substitution
    (averaged over the matrices), factor nonzeros, solution difference and residual."""
    from tactileskin.fe import linsolve

    A0 = mats[0]
    rows = np.repeat(np.arange(A0.shape[0]), np.diff(A0.indptr))
    upper = np.flatnonzero(A0.indices >= rows)
    ip = np.concatenate([[0], np.cumsum(np.bincount(rows[upper], minlength=A0.shape[0]))])
    ix = A0.indices[upper]
    b = np.random.default_rng(0).standard_normal(A0.shape[0])
    names = list(options)
    res = {o: dict(ana=[], fac=[], sol=[], nnz=0, x=None, res=0.0) for o in names}
    for r in range(repeat):
        for o in (names if r % 2 == 0 else names[::-1]):
            kw = dict(options[o])
            order = ordering
            p, ta = _timed(lambda: linsolve._Pardiso(A0.shape[0], ip, ix, threads, single=single,
                                                     ordering=order, iparm=kw))
            tf, ts = np.zeros(3), np.zeros(3)
            xs = []
            for A in mats:
                tf += _timed(lambda: p.factor(A.data[upper]))[1]
                for _ in range(SOLVES):   # the GMRES solves: many substitutions per factorisation
                    x, t = _timed(lambda: p.solve(b))
                    ts += np.array(t) / SOLVES
                xs.append(x)
            m = len(mats)
            res[o]["ana"].append(ta)
            res[o]["fac"].append(tf / m)
            res[o]["sol"].append(ts / m)
            res[o]["nnz"] = p.factor_nnz
            res[o]["x"] = xs
            res[o]["res"] = max(float(np.linalg.norm(A @ x - b) / np.linalg.norm(b)) for A, x in zip(mats, xs))
            p.close()
    base = res[names[0]]["x"]
    for o in names:
        res[o]["diff"] = max(float(np.max(np.abs(x - y)) / np.max(np.abs(y))) for x, y in zip(res[o]["x"], base))
    return res


def matrices(a) -> None:
    load0 = os.getloadavg()
    cases = [(t, 3, a.threads, True, "metis") for t in a.thickness]
    if a.two_d:
        cases.append((5.0, 2, 1, False, "amd"))
    out = []
    for t, dim, threads, single, ordering in cases:
        mats = _load(t, dim, a.store)
        pick = [i for i in a.pick if i < len(mats)] or [0]
        sel = [mats[i] for i in pick]
        res = time_options(sel, threads, single, ordering, a.repeat, OPTIONS if dim == 3 else
                           {k: v for k, v in OPTIONS.items() if 1 not in v and 23 not in v})
        out.append(f"\n{dim}D t = {t:g} default silicone Braille dot: {mats[0].shape[0]:,} free dofs, "
                   f"{len(mats)} factorised in the solve, matrices {pick} timed; {threads} thread(s), "
                   f"{'single' if single else 'double'} precision, solver ordering {ordering}\n")
        out.append("| option | analysis ms wall / CPU / main | factor ms wall / CPU / main "
                   "| one solve ms wall / CPU / main | factor nnz | max rel. diff. of x from base | max rel. residual |")
        out.append("|---|---|---|---|---|---|---|")
        for o, r in res.items():
            med = {k: np.median(np.array(r[k]), axis=0) for k in ("ana", "fac", "sol")}
            cell = lambda v, f: " / ".join(format(x, f) for x in v)  # noqa: E731
            out.append(f"| {o} | {cell(med['ana'], '.0f')} | {cell(med['fac'], '.0f')} | {cell(med['sol'], '.1f')} | "
                       f"{r['nnz']:,} | {r['diff']:.1e} | {r['res']:.1e} |")
        print("\n".join(out[-(len(res) + 3):]), flush=True)
    load1 = os.getloadavg()
    print(f"\nload average (1 min) at start {load0[0]:.2f}, at end {load1[0]:.2f}; medians of {a.repeat} rounds, "
          f"options alternating (forward, reversed); a solve is one forward/backward substitution (mean of {SOLVES} "
          "per matrix). CPU: process time (all threads); main: the calling thread's CPU (the rest ran on PARDISO's "
          "other threads: wall on an idle machine is at least the larger share)")


def one(t: float, out: str) -> dict:
    from tactileskin.fe import linsolve, solve
    from tactileskin.scene import Scene

    phase_cpu, phase_main, real = Counter(), Counter(), linsolve._Pardiso._pardiso

    def timed(self, phase, *args):
        c, m = time.process_time(), time.thread_time()
        real(self, phase, *args)
        phase_cpu[phase] += time.process_time() - c
        phase_main[phase] += time.thread_time() - m

    linsolve._Pardiso._pardiso = timed
    sc = Scene(dim=3, indenter="braille", thickness=t, material="silicone")
    c0, w0, m0 = time.process_time(), time.perf_counter(), time.thread_time()
    r = solve(sc)
    cpu, wall, main = time.process_time() - c0, time.perf_counter() - w0, time.thread_time() - m0
    ls = r.stats["linear_solver"]
    pd = (r.fields or {}).get("point_data") or {}
    np.savez(out, peak=np.array([r.peak]), pressure=np.asarray(r.pressure, float),
             displacement=np.asarray(pd.get("displacement_mm", [0.0]), float))
    return dict(cpu=cpu, wall=wall, main=main, newton=r.stats["newton_iterations"], gmres=ls["krylov_iterations"],
                factorizations=ls["factorizations"], pardiso={str(k): v for k, v in phase_cpu.items()},
                pardiso_main={str(k): v for k, v in phase_main.items()})


def whole(a) -> None:
    load0 = os.getloadavg()
    with tempfile.TemporaryDirectory() as tmp:
        for t in a.thickness:
            res, files = {s: [] for s in a.src}, {s: [] for s in a.src}
            for i in range(a.repeat):
                for s in (a.src if i % 2 == 0 else a.src[::-1]):
                    out = os.path.join(tmp, f"t{t:g}_{a.src.index(s)}_{i}.npz")
                    env = dict(os.environ, PYTHONPATH=os.path.abspath(s))
                    env.pop("MKL_NUM_THREADS", None)   # the solver's own thread choice (both cores)
                    p = subprocess.run([sys.executable, __file__, "--one", f"{t:g}", out], env=env, check=True,
                                       capture_output=True, text=True)
                    r = json.loads(p.stdout.strip().splitlines()[-1])
                    res[s].append(r)
                    files[s].append(out)
                    print(f"# t {t:g} round {i + 1}, {s}: wall {r['wall']:.1f} s, CPU {r['cpu']:.1f} s "
                          f"(main thread {r['main']:.1f} s), PARDISO solve CPU {r['pardiso'].get('33', 0.0):.1f} s "
                          f"(main thread {r['pardiso_main'].get('33', 0.0):.1f} s), "
                          f"Newton {r['newton']}, GMRES {r['gmres']}, factorisations {r['factorizations']}",
                          flush=True)
            print(f"\nt = {t:g} mm default silicone dot, {a.repeat} runs per tree, trees alternating\n")
            print("| tree | wall s (median) | wall s (runs) | CPU s (median) | main-thread CPU s (median) | Newton "
                  "| GMRES its | factorisations | PARDISO CPU s: analysis / factor / solve | of which main thread |")
            print("|---|---|---|---|---|---|---|---|---|---|")
            for s, rs in res.items():
                ph = " | ".join(" / ".join(f"{np.median([r[d].get(k, 0.0) for r in rs]):.2f}" for k in ("11", "22", "33"))
                                for d in ("pardiso", "pardiso_main"))
                print(f"| {s} | {np.median([r['wall'] for r in rs]):.1f} | "
                      f"{', '.join(format(r['wall'], '.1f') for r in rs)} | {np.median([r['cpu'] for r in rs]):.1f} | "
                      f"{np.median([r['main'] for r in rs]):.1f} | "
                      f"{sorted({r['newton'] for r in rs})} | {sorted({r['gmres'] for r in rs})} | "
                      f"{sorted({r['factorizations'] for r in rs})} | {ph} |")
            ref = np.load(files[a.src[0]][0])
            for s in a.src:
                d = {"peak": 0.0, "pressure": 0.0, "displacement": 0.0}
                for f in files[s]:
                    z = np.load(f)
                    for k in d:
                        d[k] = max(d[k], float(np.max(np.abs(z[k] - ref[k])) / max(np.max(np.abs(ref[k])), 1e-300)))
                print(f"{s} against the first run of {a.src[0]}: largest relative difference of the peak "
                      f"{d['peak']:.1e}, bone pressure map {d['pressure']:.1e}, displacements {d['displacement']:.1e}")
    load1 = os.getloadavg()
    print(f"\nload average (1 min) at start {load0[0]:.2f}, at end {load1[0]:.2f}. CPU: process time (all "
          "threads); main thread: the Python thread's CPU (PARDISO's master thread too; a lower bound of the wall "
          "time on an idle machine)")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--matrices", action="store_true")
    ap.add_argument("--src", nargs="+")
    ap.add_argument("--thickness", type=float, nargs="+", default=[5.0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--pick", type=lambda s: [int(x) for x in s.split(",")], default=[0, 12, 23])
    ap.add_argument("--2d", dest="two_d", action="store_true")
    ap.add_argument("--store", default=os.path.join(tempfile.gettempdir(), "pardiso_options3d"))
    ap.add_argument("--capture", nargs=3, help=argparse.SUPPRESS)
    ap.add_argument("--one", nargs=2, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.capture:
        _capture(float(a.capture[0]), int(a.capture[1]), a.capture[2])
    elif a.one:
        print(json.dumps(one(float(a.one[0]), a.one[1])))
    elif a.matrices:
        matrices(a)
    elif a.src:
        whole(a)
    else:
        ap.error("give --matrices or --src")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
