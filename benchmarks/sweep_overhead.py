"""Where the CPU of a preview sweep goes beyond meshing and solving: the sweep runner's own
overhead (issue 13 T10: `./dev run` <= 4 s wall on 2 cores, where CPU is wall).

`breakdown`: the 18 preview cases (`tactileskin sweep --quality preview`'s grid) through
`run_sweep` from an empty cache, in a fresh process, each part timed where it runs:
- main process: CPU of run_sweep (all its threads: the client's, the scheduler's), of the
  cluster's start, of the cache's store/lookup/lock calls;
- each worker (fork()ed): per case the task thread's CPU for the code check (code_changes),
  the two cache_key calls, the solve (of it the numba dispatchers' compile / load from numba's
  cache, counted apart); the worker process's CPU (tasks + dask's threads), collected before
  the cluster closes;
- the children's CPU left when the workers' own (at their report) is taken off: their
  shutdown, other children (the nannies run in the main process).
`pickle`: bytes and CPU of pickling / unpickling the results the workers send back.
`pool`: a prototype only (not the package's code): the same cases on a plain fork() process
pool (multiprocessing, 2 processes, the main process storing as run_sweep's finish does),
CPU (self + children) and wall, interleaved with the Dask runner.
`serial`: run_sweep(serial=True), for the same numbers without Dask.
`idle`: CPU per second of an idle sweep cluster (Dask's periodic monitors).

    PYTHONPATH=src .venv/bin/python benchmarks/sweep_overhead.py [--runs 3] [--write] [--compare OLD/src,NEW/src]
        (--write: the tables into benchmarks/results/sweep_overhead.md)
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results" / "sweep_overhead.md"


def _cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _cpu_self() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def scenes():
    from tactileskin.sweep import expand_grid

    return expand_grid(quality="preview")  # the CLI's `sweep --quality preview` grid (18 2D cases)


# --- instrumentation (patched into the modules before the workers fork, so they have it too) ---
# on the sys module, not this one: a function Dask sends to the workers (client.run) is pickled
# by value with this (__main__) module's globals, so a worker would report the main's copy
STATS: dict[str, list[float]] = sys.__dict__.setdefault("_sweep_overhead_stats", defaultdict(list))


def _timed(mod, name, label, clock=time.thread_time):
    fn = getattr(mod, name)

    def wrapper(*a, **kw):
        t0 = clock()
        try:
            return fn(*a, **kw)
        finally:  # the stats through `sys`: a by-value copy of this function still finds them
            sys._sweep_overhead_stats[label].append(clock() - t0)

    setattr(mod, name, wrapper)
    return fn


def _instrument():
    import numba.core.dispatcher as nd

    import tactileskin.cache as cache
    import tactileskin.sweep as sw

    _timed(sw, "code_changes", "worker: code_changes")
    _timed(sw, "cache_key", "worker: cache_key")
    _timed(sw, "solve_case", "worker: solve (mesh + solve)")
    _timed(cache.ResultCache, "store", "main: cache.store", time.process_time)
    _timed(cache.ResultCache, "lookup", "main: cache.lookup", time.process_time)
    _timed(cache.ResultCache, "lock", "main: cache.lock", time.process_time)
    _timed(sw._Runner, "_start", "main: cluster start", time.process_time)
    if hasattr(sw, "_load_compiled_loops"):  # (the code before it had none)
        _timed(sw, "_load_compiled_loops", "main: compiled loops loaded before fork (in cluster start)", time.process_time)
    # numba: a dispatcher's compile() of a new type signature (loaded from numba's on-disk cache)
    real = nd.Dispatcher.compile
    depth, main_pid = [0], os.getpid()

    def compile_(self, sig):
        depth[0] += 1
        t0 = time.thread_time()
        try:
            return real(self, sig)
        finally:
            depth[0] -= 1
            if depth[0] == 0:
                where = "main" if os.getpid() == main_pid else "worker"  # (a fork()ed worker keeps a copy)
                sys._sweep_overhead_stats[f"{where}: numba compile/load"].append(time.thread_time() - t0)

    nd.Dispatcher.compile = compile_


def _worker_report():
    import os as _os

    import resource as _r
    import sys as _sys

    ru = _r.getrusage(_r.RUSAGE_SELF)
    import gc

    from numba.core.dispatcher import Dispatcher

    disp = [o for o in gc.get_objects() if isinstance(o, Dispatcher)]
    _sys._sweep_overhead_stats["worker: numba cache misses (compiled anew)"] = [
        float(sum(sum(d._cache_misses.values()) for d in disp))]
    return {"pid": _os.getpid(), "cpu": ru.ru_utime + ru.ru_stime,
            "stats": {k: v for k, v in _sys._sweep_overhead_stats.items() if k.startswith("worker")}}


def breakdown(root: Path) -> dict:
    """One instrumented Dask run from an empty cache; returns the numbers."""
    import tactileskin.sweep as sw
    from tactileskin.cache import ResultCache

    scs = scenes()
    got = {}
    real_close = sw._Runner.close

    def close(self):
        if self.client is not None:
            got["workers"] = self.client.run(_worker_report)
        real_close(self)

    sw._Runner.close = close
    STATS.clear()
    c0, ch0, w0 = time.process_time(), _cpu_children(), time.perf_counter()
    outcomes = sw.run_sweep(scs, ResultCache(root / "cache"), workers=2)
    wall = time.perf_counter() - w0
    main_cpu = time.process_time() - c0
    sw._Runner.close = real_close
    time.sleep(1.0)  # the nannies exit and are reaped
    children = _cpu_children() - ch0
    assert all(o.status == "done" for o in outcomes), [o.error for o in outcomes if o.status != "done"]
    return {"wall": wall, "main_cpu": main_cpu, "children": children, "main": {k: v for k, v in STATS.items()
                                                                                if k.startswith("main")},
            "workers": got["workers"]}


def run_pool(root: Path) -> tuple[float, float]:
    """Prototype: a fork() process pool instead of Dask (not the package's code). (wall, CPU)."""
    import multiprocessing as mp

    from tactileskin.cache import ResultCache
    from tactileskin.sweep import _cost_rank, _load_compiled_loops

    scs = scenes()
    # timed from here, as run_plain times run_sweep, whose cluster start imports the solver
    # and loads the compiled loops, and which computes the keys
    c0, ch0, w0 = time.process_time(), _cpu_children(), time.perf_counter()
    import tactileskin.fe  # noqa: F401 - imported before fork, as the Dask runner does
    import tactileskin.mesh  # noqa: F401

    _load_compiled_loops()  # as the Dask runner does before its workers fork
    cache = ResultCache(root / "cache")
    keys = [cache.key(s) for s in scs]
    order = sorted(range(len(scs)), key=lambda i: -_cost_rank(scs[i]))
    with mp.get_context("fork").Pool(2, initializer=_pool_init) as pool:
        for i, packed in pool.imap_unordered(_pool_task, [(i, scs[i], keys[i]) for i in order]):
            lock = cache.lock(keys[i], blocking=True)
            cache.store(scs[i], packed[1], keys[i])
            assert cache.lookup(scs[i], keys[i]) is not None
            lock.release()
    wall = time.perf_counter() - w0
    return wall, (time.process_time() - c0) + (_cpu_children() - ch0)


def _pool_init():
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")


def _pool_task(args):
    from tactileskin.sweep import _run_one_safely

    i, sc, key = args
    return i, _run_one_safely(sc, key)


def run_plain(root: Path, serial: bool) -> tuple[float, float]:
    """run_sweep as the package has it, uninstrumented: (wall, CPU self + children)."""
    from tactileskin.cache import ResultCache
    from tactileskin.sweep import run_sweep

    scs = scenes()
    c0, ch0, w0 = time.process_time(), _cpu_children(), time.perf_counter()
    outcomes = run_sweep(scs, ResultCache(root / "cache"), workers=2, serial=serial)
    wall = time.perf_counter() - w0
    time.sleep(1.0)
    assert all(o.status == "done" for o in outcomes)
    return wall, (time.process_time() - c0) + (_cpu_children() - ch0)


def pickle_cost() -> tuple[int, float, float]:
    """Bytes, dumps and loads CPU (s, summed over the 18 results) of the results a worker sends back."""
    from tactileskin.fe import solve

    size = dumps = loads = 0.0
    for sc in scenes():
        r = solve(sc)
        t0 = time.process_time()
        b = pickle.dumps(("done", r, 0.0, "", {}), protocol=5)
        t1 = time.process_time()
        pickle.loads(b)
        t2 = time.process_time()
        size += len(b)
        dumps += t1 - t0
        loads += t2 - t1
    return int(size), dumps, loads


RUNNERS = {"dask": "run_sweep, Dask (2 workers)", "pool": "fork() pool prototype (2 processes)",
           "serial": "run_sweep, serial"}


def _one(name: str, root: Path) -> None:
    """In a fresh process: one run of runner `name`; prints its wall and CPU."""
    if name == "idle":
        return print(json.dumps(idle_rates()))
    if name == "breakdown":
        _instrument()
        return print(json.dumps(breakdown(root)))
    w, c = run_pool(root) if name == "pool" else run_plain(root, serial=name == "serial")
    print(json.dumps({"wall": w, "cpu": c}))


def _fresh(name: str, root: Path, src: str | None = None) -> tuple[float, float]:
    env = dict(os.environ, PYTHONPATH=src) if src else None
    p = subprocess.run([sys.executable, __file__, "--one", name, "--dir", str(root)], capture_output=True,
                       text=True, env=env)
    if p.returncode:
        sys.exit(f"{name} failed: {p.stderr[-2000:]}")
    shutil.rmtree(root, ignore_errors=True)
    d = json.loads(p.stdout.strip().splitlines()[-1])
    return d["wall"], d["cpu"]


def idle_rates(seconds: float = 6.0) -> dict:
    """CPU s per s of an idle sweep cluster (2 workers): this process's, the workers' sum."""
    from tactileskin.sweep import _Runner

    def cpu():
        import resource as r

        u = r.getrusage(r.RUSAGE_SELF)
        return u.ru_utime + u.ru_stime

    runner = _Runner([], [], serial=False, scheduler=None, workers=2)
    try:
        client = runner._start(2)
        time.sleep(1.0)
        c0, w0 = _cpu_self(), client.run(cpu)
        time.sleep(seconds)
        c1, w1 = _cpu_self(), client.run(cpu)
    finally:
        runner.close()
    return {"main": (c1 - c0) / seconds, "workers": sum(w1[k] - w0[k] for k in w1) / seconds}


def _fresh_json(name: str, root: Path, src: str | None) -> dict:
    """Part `name` run in a fresh process (its JSON answer)."""
    env = dict(os.environ, PYTHONPATH=src) if src else None
    p = subprocess.run([sys.executable, __file__, "--one", name, "--dir", str(root)], capture_output=True, text=True,
                       env=env)
    if p.returncode:
        sys.exit(f"{name} failed: {p.stderr[-2000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def _fresh_idle(src: str | None) -> dict:
    return _fresh_json("idle", Path("."), src)


def _fmt(xs):
    return f"{statistics.median(xs):.2f} ({', '.join(f'{x:.2f}' for x in xs)})"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--parts", default="idle,pickle,ab,breakdown")
    ap.add_argument("--compare", default=None,
                    help="OLD/src,NEW/src: also the CLI preview sweep of each, interleaved (sweep_command.py)")
    ap.add_argument("--write", action="store_true")
    ap.add_argument("--src", default=None, help="tactileskin source folder for the A/B runs (PYTHONPATH)")
    ap.add_argument("--one", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--dir", default=None, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.one:
        return _one(a.one, Path(a.dir))
    parts = a.parts.split(",")
    tmp = Path(tempfile.mkdtemp(prefix="sweep_overhead-"))
    lines = [f"`{' '.join(['benchmarks/sweep_overhead.py', *sys.argv[1:]])}`, 2-core machine, load before "
             f"{os.getloadavg()[0]:.1f}.", ""]
    try:
        if "pickle" in parts:
            size, d, lo = pickle_cost()
            lines += ["## Results sent back (18 preview results)", "",
                      f"{size / 1e3:.0f} kB pickled in all; dumps {d:.3f} s, loads {lo:.3f} s CPU (sum).", ""]
        if "ab" in parts:
            rows = defaultdict(lambda: ([], []))
            for k in range(a.runs):
                for name in RUNNERS:
                    w, c = _fresh(name, tmp / f"ab-{k}-{name}", a.src)
                    rows[name][0].append(w)
                    rows[name][1].append(c)
            lines += ["## Runner A/B, interleaved (each run a fresh process, empty cache; run_sweep or the pool "
                      "alone: the CLI's imports and outputs not included)", "",
                      "| runner | wall s, median (runs) | CPU s self + children, median (runs) |", "|---|---|---|"]
            lines += [f"| {RUNNERS[n]} | {_fmt(w)} | {_fmt(c)} |" for n, (w, c) in rows.items()]
            lines.append("")
        if "idle" in parts:
            srcs = a.compare.split(",") if a.compare else [a.src]
            rates = {src: [] for src in srcs}
            for _ in range(a.runs):
                for src in srcs:  # interleaved
                    rates[src].append(_fresh_idle(src))
            lines += ["## An idle local cluster of 2 workers (CPU s per s of wall, median of runs)", "",
                      "| code | main process (scheduler, nannies, client) | workers (sum) |", "|---|---|---|"]
            lines += [f"| {src or 'this'} | {statistics.median(r['main'] for r in rs):.4f} | "
                      f"{statistics.median(r['workers'] for r in rs):.4f} |" for src, rs in rates.items()]
            lines.append("")
        if a.compare:
            import contextlib
            import io

            sys.path.insert(0, str(Path(__file__).resolve().parent))
            import sweep_command

            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                sweep_command.timings(a.runs, ["preview"], tmp / "compare", a.compare.split(","))
            lines += ["## The CLI, `tactileskin sweep --quality preview` from an empty out, old vs new code "
                      "(benchmarks/sweep_command.py's timing, interleaved)", "", buf.getvalue().strip(), ""]
        if "breakdown" in parts:
            b = _fresh_json("breakdown", tmp / "breakdown", a.src)  # fork()ed workers: a process that solved spawns
            ws = b["workers"]
            lines += [f"## Breakdown of one Dask run (instrumented; 2 fork()ed workers){' of ' + a.src if a.src else ''}",
                      "",
                      f"wall {b['wall']:.2f} s; main process CPU {b['main_cpu']:.2f} s; children (nannies + "
                      f"workers) CPU {b['children']:.2f} s.", "",
                      "| where | part | calls | CPU s |", "|---|---|---|---|"]
            for k, v in sorted(b["main"].items()):
                lines.append(f"| main | {k[6:]}{' (in the loading above)' if 'numba' in k else ''} | {len(v)} | {sum(v):.3f} |")
            tracked = sum(sum(v) for k, v in b["main"].items() if "start" not in k and "before fork" not in k and "numba" not in k)
            lines.append(f"| main | rest of run_sweep (dask client + scheduler threads, unpickling) | | "
                         f"{b['main_cpu'] - tracked - sum(b['main'].get('main: cluster start', [])):.3f} |")
            wsum = 0.0
            for addr, w in sorted(ws.items()):
                st = w["stats"]
                wsum += w["cpu"]
                for k, v in sorted(st.items()):
                    first = f" (first case {v[0]:.3f})" if "solve" in k else ""
                    if "misses" in k:
                        lines.append(f"| worker {w['pid']} | {k[8:]} | {v[0]:.0f} | |")
                        continue
                    lines.append(f"| worker {w['pid']} | {k[8:]} | {len(v)} | {sum(v):.3f}{first} |")
                task = sum(sum(v) for k, v in st.items() if k.startswith("worker: ") and "numba" not in k)
                lines.append(f"| worker {w['pid']} | process total (task + dask threads) | | {w['cpu']:.3f} |")
                lines.append(f"| worker {w['pid']} | of it outside the tasks (dask's threads, start-up) | | "
                             f"{w['cpu'] - task:.3f} |")
            lines.append(f"| other children | children CPU less the workers' own at their report (their shutdown after it, other children) | | {b['children'] - wsum:.3f} |")
            lines.append("")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    text = "\n".join(lines)
    print(text)
    if a.write:
        _write(lines)


def _sections(text: str) -> dict:
    """{'## heading': section text} of a results file, in order."""
    out, head = {}, None
    for line in text.splitlines():
        if line.startswith("## "):
            head = line
        if head is not None:
            out.setdefault(head, []).append(line)
    return {h: "\n".join(ls).strip() for h, ls in out.items()}


def _write(lines: list[str]) -> None:
    """The sections of this run into RESULTS; the file's other sections (parts not run now)
    stay, each under the command line that produced it."""
    head = lines[0]
    new = {h: f"{t}\n\n({head})" for h, t in _sections("\n".join(lines)).items()}
    old = _sections(RESULTS.read_text(encoding="utf-8")) if RESULTS.exists() else {}
    merged = {**old, **new}
    RESULTS.write_text("# Sweep runner overhead (preview, 18 2D cases)\n\n" + __doc__.split("\n\n", 1)[1]
                       .split("\n    PYTHONPATH")[0].strip() + "\n\n" + "\n\n".join(merged.values()) + "\n",
                       encoding="utf-8")


if __name__ == "__main__":
    main()
