"""The sensor-array design chart at a coarse 3D mesh, with the surrogate-validation table.

    PYTHONPATH=src python benchmarks/array_chart.py [--thickness 1,3] [--cache DIR]

Writes benchmarks/results/array_chart.md (the report section, the time it took, CPU and
wall) and the figures/CSV into benchmarks/results/array_chart/. Solves go through the
result cache (--cache), so a rerun only classifies.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from tactileskin import fileio  # noqa: E402
from tactileskin.array.chart import ChartConfig, compute, validate_surrogate  # noqa: E402
from tactileskin.cache import ResultCache  # noqa: E402
from tactileskin.report.array_chart import markdown, write_figures  # noqa: E402

HERE = Path(__file__).resolve().parent / "results"
CAVEATS = """### Caveats

- Coarse 3D mesh (1.2 mm / refinement 2, ~15k dofs): the dot's contact patch (radius ~0.55 mm
  at t = 1) spans about two elements; the maps' shapes, not only their peaks, are mesh-dependent.
- The letters set rests on the superposition surrogate, whose error against full solves is in
  the validation table above: where it exceeds 5 % of the peak the letters chart is indicative
  only (full solves of all letters were not affordable here; main's 3D solver also fails on some
  letters, e.g. 'b': "profile plane z=-1.17 is invalid" on the quarter model).
- Flat and curved are 2D plane-strain profiles extruded along z: they differ from the dot in
  magnitude by an order, so the paper set is told apart at any pitch while magnitude is read.
"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--thickness", default="1,3")
    ap.add_argument("--validate-thickness", default="1,3")
    ap.add_argument("--texts", default="⠿,l,c")
    ap.add_argument("--cache", default="/tmp/tactileskin_array_cache")
    a = ap.parse_args()
    ts = tuple(float(x) for x in a.thickness.split(","))
    cfg = ChartConfig(thicknesses=ts)
    cache = ResultCache(a.cache)
    w0, c0 = time.perf_counter(), time.process_time()
    solved = []

    def progress(msg: str) -> None:
        print(msg, flush=True)
        if msg.startswith("  done"):
            solved.append(msg)

    chart = compute(cfg, cache, progress=progress)
    w1, c1 = time.perf_counter(), time.process_time()
    rows = []
    for t in (float(x) for x in a.validate_thickness.split(",")):
        texts = [x for x in a.texts.split(",") if x]
        rows += validate_surrogate([t], "silicone", texts, cfg, cache, progress=print)
    w2, c2 = time.perf_counter(), time.process_time()
    out = HERE / "array_chart"
    fileio.make_dirs(out)
    fileio.atomic_write_text(out / "accuracies.csv", chart.to_csv())
    write_figures(chart, out)
    text = ("# Sensor-array design chart (coarse 3D mesh)\n\n"
            f"Command: `PYTHONPATH=src python benchmarks/array_chart.py --thickness {a.thickness} "
            f"--validate-thickness {a.validate_thickness} --texts {a.texts}`. Chart {w1 - w0:.0f} s wall "
            f"({c1 - c0:.0f} s CPU in this process; solves run in it, serially), validation "
            f"{w2 - w1:.0f} s wall; {len(solved)} solves computed in this run, the rest read from the cache "
            "(a coarse 3D single dot at t = 1 took 32 s CPU / 56 s wall on this shared 2-core machine; "
            "the t = 3 dot 378 s wall). "
            "Figures and CSV: benchmarks/results/array_chart/.\n\n" + markdown(chart, rows) + "\n" + CAVEATS)
    fileio.atomic_write_text(HERE / "array_chart.md", text)
    print(text)


if __name__ == "__main__":
    main()
