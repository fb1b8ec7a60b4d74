"""Wall time of the sweep command itself (`tactileskin sweep --out DIR --quality Q`), the
number issue 13's 2D target T10 is about (preview <= 4 s, default <= 8 s), as a user runs it:
a fresh process each time, from an empty cache and as a cached rerun of the same folder.

benchmarks/paper_sweep.py times the cases' meshing and solving one by one; this one times
the whole command (imports, the Dask cluster, solving, results, figures, renders, report);
`default` runs the 18 2D cases (--braille-dim 2).
The machine may be shared: the 1-minute load average before each run is printed with it,
and the CPU seconds (user + sys of the command and its workers) are a steadier measure.

    .venv/bin/python benchmarks/sweep_command.py [--runs 3] [--modes preview,preview-cached,default]
        (mode -resolve1: a finished sweep rerun with one case's cache entry removed, solved again)
    .venv/bin/python benchmarks/sweep_command.py --compare OLD/src,NEW/src [--modes preview]  # A/B, interleaved
    .venv/bin/python benchmarks/sweep_command.py --phases [--cached] [--quality preview]   # one run, per phase
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


# `preview` is `./dev run`'s command; at `default` the Braille cases would be 2D and 3D (24
# cases, ~100 s): T10 is about the 18 2D cases
EXTRA = {"default": ["--braille-dim", "2"]}


def _become_subreaper() -> bool:
    """Make this process the reaper of its orphaned descendants (Linux): a forkserver (dask's
    multiprocessing-method) outlives the command briefly and is reaped by init, and its CPU
    time, its workers' included, would be missing from RUSAGE_CHILDREN."""
    try:
        import ctypes

        return ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0) == 0  # PR_SET_CHILD_SUBREAPER
    except (OSError, AttributeError):
        return False


SUBREAPER = _become_subreaper()


def _reap_orphans(timeout: float = 60.0) -> None:
    """Wait for the command's orphaned descendants, so that their CPU time is counted."""
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            time.sleep(0.05)
    print(f"warning: descendants of the command still ran {timeout:g} s after it; their CPU is not counted",
          file=sys.stderr)


def run_command(out: Path, quality: str, src: str | None = None) -> tuple[float, float, float]:
    """(wall s, CPU s of the command and its children, load average before) of one sweep;
    `src`: the tactileskin source folder to run (PYTHONPATH), else the one installed."""
    env = dict(os.environ, PYTHONPATH=src) if src else None
    load = os.getloadavg()[0]
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "tactileskin", "sweep", "--out", str(out), "--quality", quality,
                        *EXTRA.get(quality, [])],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    wall = time.perf_counter() - t0
    _reap_orphans()
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode not in (0, 3):
        sys.exit(f"sweep failed ({p.returncode}): {p.stderr[-2000:]}")
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return wall, cpu, load


# the case whose cache entry `-resolve1` removes: solved again, to the same numbers (no render)
RESOLVED_CASE = "t1-silicone-curved-2d"


def _drop_entry(out: Path, case: str) -> None:
    """Remove a finished sweep's cache entry of `case` (results.csv names its key)."""
    import csv

    with open(out / "results.csv", encoding="utf-8") as f:
        key = next(r["key"] for r in csv.DictReader(f) if r["case"] == case)
    shutil.rmtree(out / "cache" / key)


def timings(runs: int, modes: list[str], root: Path, srcs: list[str | None]) -> None:
    """Per mode, `runs` runs of each source folder in `srcs`, interleaved (a, b, a, b, ...) so
    that a shared machine's load falls on both alike."""
    print("| command | code | wall s, median (runs) | CPU s, median (runs) | load before |")
    print("|---|---|---|---|---|")
    for mode in modes:
        quality = mode.split("-")[0]
        walls, cpus, loads = ({j: [] for j in range(len(srcs))} for _ in range(3))
        for k in range(runs):
            for j, src in enumerate(srcs):
                out = root / f"{quality}-{j}-{k}"
                if mode.endswith("-cached") or mode.endswith("-resolve1"):
                    if not out.exists():
                        run_command(out, quality, src)  # fills the cache; not timed
                    if mode.endswith("-resolve1"):
                        _drop_entry(out, RESOLVED_CASE)
                else:
                    shutil.rmtree(out, ignore_errors=True)
                w, c, ld = run_command(out, quality, src)
                walls[j].append(w)
                cpus[j].append(c)
                loads[j].append(ld)
        for j, src in enumerate(srcs):
            print(f"| {mode} | {src or 'installed'} | {statistics.median(walls[j]):.2f} "
                  f"({', '.join(f'{w:.2f}' for w in walls[j])}) | {statistics.median(cpus[j]):.2f} "
                  f"({', '.join(f'{c:.2f}' for c in cpus[j])}) | {', '.join(f'{x:.1f}' for x in loads[j])} |",
                  flush=True)


def phases(quality: str, root: Path, cached: bool = False) -> None:
    """One empty-cache run (or with `cached`, a rerun of a finished sweep, which is run first
    in a separate process) in this process, each phase of the main process timed (the
    workers' solving is the part of `run_sweep` after the cluster is up)."""
    out = root / f"phases-{quality}{'-cached' if cached else ''}"
    shutil.rmtree(out, ignore_errors=True)
    if cached:
        run_command(out, quality)
    t_start = time.perf_counter()
    marks: list[tuple[str, float, float]] = []

    def timed(mod, name, label=None):
        fn = getattr(mod, name)

        def wrapper(*a, **kw):
            t0 = time.perf_counter()
            try:
                return fn(*a, **kw)
            finally:
                marks.append((label or name, t0 - t_start, time.perf_counter() - t0))

        setattr(mod, name, wrapper)

    from tactileskin import cli  # noqa: F401 - the CLI's own imports, timed as one phase
    t_imports = time.perf_counter() - t_start
    import tactileskin.report.figures as figures
    import tactileskin.report.markdown as markdown
    import tactileskin.report.outputs as outputs
    import tactileskin.report.render as render
    import tactileskin.sweep as sweep

    timed(sweep, "run_sweep")
    timed(sweep._Runner, "_start", "cluster start")
    timed(outputs, "write_outputs")
    timed(outputs, "_write_parquet", "parquet")
    for name in ("thickness_figure", "profiles_figure", "metric_figure"):
        timed(figures, name)
    timed(render, "render_case")
    timed(markdown, "build_report")
    rc = cli.main(["sweep", "--out", str(out), "--quality", quality, *EXTRA.get(quality, [])])
    total = time.perf_counter() - t_start
    print(f"\nquality {quality}{', cached rerun' if cached else ''}, exit {rc}, load after "
          f"{os.getloadavg()[0]:.1f}; main process timeline (s):\n")
    print("| phase | start | seconds |")
    print("|---|---|---|")
    print(f"| imports (tactileskin.cli) | 0.0 | {t_imports:.2f} |")
    sums: dict[str, list[float]] = {}
    for label, start, secs in marks:
        sums.setdefault(label, [start, 0.0])[1] += secs
    for label, (start, secs) in sorted(sums.items(), key=lambda kv: kv[1][0]):
        print(f"| {label} | {start:.2f} | {secs:.2f} |")
    print(f"| total | | {total:.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--modes", default="preview,preview-cached,default")
    ap.add_argument("--phases", action="store_true", help="one run with a per-phase timeline instead")
    ap.add_argument("--quality", default="preview")
    ap.add_argument("--cached", action="store_true", help="with --phases: time a cached rerun")
    ap.add_argument("--compare", default=None,
                    help="comma-separated tactileskin source folders (PYTHONPATH) to time interleaved")
    ap.add_argument("--dir", default=None, help="folder for the outputs (default: a new temporary one)")
    a = ap.parse_args()
    root = Path(a.dir) if a.dir else Path(tempfile.mkdtemp(prefix="sweep_command-"))
    root.mkdir(parents=True, exist_ok=True)
    if a.phases:
        phases(a.quality, root, a.cached)
    else:
        timings(a.runs, a.modes.split(","), root, a.compare.split(",") if a.compare else [None])


if __name__ == "__main__":
    main()
