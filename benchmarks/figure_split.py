"""Time a sweep's figures and renders (what it draws after its last solve) drawn in this
process alone against half of them in a fork()ed child (report.background), interleaved.

The records are the paper sweep's 18 cases at a quality preset, solved into --cache once (or
read from it). Each repetition draws into a new folder with a new, empty figure cache, so
nothing is copied from a kept drawing. Prints wall and CPU seconds (this process and its
children) per mode, medians, and checks that both modes wrote the same bytes.

    .venv/bin/python benchmarks/figure_split.py [--quality preview] [--cache /tmp/figure_split] [--repeat 5]
"""

from __future__ import annotations

import argparse
import resource
import statistics
import tempfile
import time
from pathlib import Path

from tactileskin import threads
from tactileskin.cli.sweep import scenes_from_options
from tactileskin.report import outputs
from tactileskin.sweep import ResultCache, run_sweep


def cpu() -> float:
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def draw(records, rows, split: bool) -> tuple[float, float, dict]:
    real = threads.other_threads
    if not split:
        threads.other_threads = lambda: ["serial"]  # Background then draws here
    try:
        with tempfile.TemporaryDirectory() as d:
            out, cache = Path(d) / "out", ResultCache(Path(d) / "cache")
            out.mkdir()
            w0, c0 = time.perf_counter(), cpu()
            renders = []
            figs = outputs._figures(records, rows, out, cache,
                                    meanwhile=lambda: renders.extend(outputs._renders(records, out, cache)))
            wall, used = time.perf_counter() - w0, cpu() - c0
            files = {p.name: p.read_bytes() for p in figs + renders}
    finally:
        threads.other_threads = real
    return wall, used, files


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quality", default="preview")
    ap.add_argument("--cache", default=str(Path(tempfile.gettempdir()) / "figure_split"))
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()

    cache = ResultCache(Path(a.cache))
    outcomes = run_sweep(scenes_from_options({"quality": a.quality}), cache)
    records, rows, failures = outputs.collect(outcomes, cache)
    assert not failures, failures
    times = {False: [], True: []}
    ref = None
    draw(records, rows, False)  # imports and font caches warm for both modes
    for _ in range(a.repeat):
        for split in (False, True):
            wall, used, files = draw(records, rows, split)
            times[split].append((wall, used))
            ref = ref or files
            assert files == ref, "the two modes wrote different bytes"
    print(f"{len(rows)} cases at {a.quality}: {len(ref)} files; medians of {a.repeat}, interleaved\n")
    print("| mode | wall (s) | CPU (s, incl. child) |")
    print("|---|---|---|")
    for split, name in ((False, "this process alone"), (True, f"first {outputs.BACKGROUND_JOBS} figures in a child")):
        print(f"| {name} | {statistics.median(w for w, _ in times[split]):.2f} "
              f"| {statistics.median(c for _, c in times[split]):.2f} |")


if __name__ == "__main__":
    main()
