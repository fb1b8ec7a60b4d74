"""Wall time of the full default sensor-array chart from an empty cache (issue 15's target:
t = 0.5, 1, 2, 3, 5 mm x both paper materials x the default pitches and noise levels in
<= 10 min on this 2-core machine), as a user runs it: `tactileskin array` in a fresh output
folder with its own new cache, the 3D solves on the default one-worker-per-core cluster.

    .venv/bin/python benchmarks/array_chart_time.py [--max-depth 0.4] [--validate ⠿,l --validate-thickness 0.5,2,5]

Writes benchmarks/results/array_chart_time.md: the command, the wall time, the solve time of
each case (from the progress lines) and the chart's report section (array_chart.md).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "array_chart_time.md"
EXE = Path(sys.executable).with_name("tactileskin")
EXIT_SUSPECT = 3  # tactileskin.cli.array.EXIT_SUSPECT


def run(args: list[str], out: Path) -> tuple[float, str]:
    w0 = time.perf_counter()
    p = subprocess.run([str(EXE), "array", "-o", str(out), *args], capture_output=True, text=True)
    wall = time.perf_counter() - w0
    if p.returncode not in (0, EXIT_SUSPECT):  # 3: written, with parts marked suspect (in the report)
        raise SystemExit(f"tactileskin array failed ({p.returncode}): {p.stderr.strip()[-500:]}")
    return wall, p.stderr + p.stdout


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", default="0.5,1,2,3,5")
    ap.add_argument("--materials", default="silicone,polyurethane")
    ap.add_argument("--max-depth", default="0.4")
    ap.add_argument("--validate", default="")
    ap.add_argument("--validate-thickness", default="0.5,2,5")
    a = ap.parse_args(argv)
    chart_args = ["-t", a.thickness, "-m", a.materials] + (["--max-depth", a.max_depth] if a.max_depth else [])
    parts = [f"# Full sensor-array chart from an empty cache (benchmarks/array_chart_time.py)\n",
             f"Measured {_dt.date.today().isoformat()}; `tactileskin array {' '.join(chart_args)}` into a new folder "
             "(its own empty cache), default workers (one single-threaded process per core, 2 here).\n"]
    with tempfile.TemporaryDirectory() as tmp:
        wall, log = run(chart_args, Path(tmp) / "chart")
        solves = [ln.strip() for ln in log.splitlines() if re.match(r"\s+(done|cached|failed) ", ln)]
        parts += [f"**Wall time: {wall:.0f} s ({wall / 60:.1f} min)** for {len(solves)} cases "
                  f"(target <= 600 s: {'met' if wall <= 600 else 'not met'}).\n",
                  "Cases in the order they finished (solve wall s, two at a time):\n",
                  "\n".join(f"- {s}" for s in solves) + "\n",
                  (Path(tmp) / "chart" / "array_chart.md").read_text(encoding="utf-8")]
        if a.validate:
            vargs = ["-t", a.validate_thickness, "-m", "silicone", "--set", "letters", "--validate", a.validate] + \
                    (["--max-depth", a.max_depth] if a.max_depth else [])
            vwall, vlog = run(vargs, Path(tmp) / "validate")
            parts += [f"\n## Surrogate validation at t = {a.validate_thickness} mm (silicone, pad)\n",
                      f"`tactileskin array {' '.join(vargs)}`: {vwall:.0f} s wall from an empty cache.\n",
                      _validation_section((Path(tmp) / "validate" / "array_chart.md").read_text(encoding="utf-8"))]
    from tactileskin.fileio import atomic_write_text

    atomic_write_text(OUT, "\n".join(parts) + "\n")
    print(OUT.read_text(encoding="utf-8"))
    return 0


def _validation_section(md: str) -> str:
    """The validation table(s) of a chart report."""
    i = md.find("### Surrogate")
    if i < 0:
        i = md.find("alidation")
        i = md.rfind("\n###", 0, i) + 1 if i >= 0 else -1
    return md[i:] if i >= 0 else "(no validation section in the report)"


if __name__ == "__main__":
    sys.exit(main())
