"""Sphere indenter build: time and STL size of `tactileskin build -i sphere --indenter-radius R`.

Runs the CLI in a subprocess per (tree, R), interleaved over the trees, and reports wall and
CPU seconds (the child's user + system) and the size of indenter_sphere.stl (or the exit
status where the radius is refused). Each tree is a source folder put on PYTHONPATH, so the
code before and after a change is compared on the same machine load:

    .venv/bin/python benchmarks/sphere_build.py --tree old=/path/old/src --tree new=src
    (writes benchmarks/results/sphere_build.md)
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RADII = (2.5, 100.0, 1000.0)
LARGE = 500.0  # radii at least this are run once (the old code's R 1000 build took minutes)


def run(src: str, radius: float) -> dict:
    env = dict(os.environ, PYTHONPATH=src)
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "b"
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        p = subprocess.run([sys.executable, "-m", "tactileskin", "build", "-i", "sphere", "--indenter-radius",
                            f"{radius:g}", "-o", str(out)], env=env, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        stl = out / "indenter_sphere.stl"
        size = stl.stat().st_size if p.returncode == 0 and stl.exists() else None
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    err = p.stderr.strip().splitlines()[-1] if p.returncode else ""
    return {"rc": p.returncode, "wall": wall, "cpu": cpu, "size": size, "err": err}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--tree", action="append", required=True, help="label=source folder")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "sphere_build.md"))
    a = ap.parse_args()
    trees = [t.split("=", 1) for t in a.tree]
    res: dict = {}
    for R in RADII:
        for _ in range(1 if R >= LARGE else a.repeats):
            for label, src in trees:  # interleaved: old, new, old, new
                r = run(src, R)
                res.setdefault((label, R), []).append(r)
                print(label, R, r, flush=True)
    lines = ["# Sphere indenter build (`tactileskin build -i sphere --indenter-radius R`)", "",
             "Produced by benchmarks/sphere_build.py: one subprocess per run, interleaved over the trees; "
             "medians; CPU = the child's user + system seconds; the whole build (skin, base, mold, "
             "indenter) at the default t = 3 mm. 2 shared cores: timings are noisy.", "",
             "| tree | R (mm) | runs | exit | wall (s) | CPU (s) | indenter_sphere.stl |",
             "|---|---:|---:|---:|---:|---:|---|"]
    for (label, R), rs in res.items():
        size = rs[0]["size"]
        what = f"{size / 1e6:.2f} MB" if size is not None else f"none: {rs[0]['err'][:120]}"
        lines.append(f"| {label} | {R:g} | {len(rs)} | {rs[0]['rc']} | {statistics.median(r['wall'] for r in rs):.1f} "
                     f"| {statistics.median(r['cpu'] for r in rs):.1f} | {what} |")
    Path(a.out).write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
