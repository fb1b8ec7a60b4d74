"""The paper sweep with its Braille cases as 3D dots and as the 2D ridge, as a user runs it:
`tactileskin sweep --braille-dim both --quality default` into a new folder with an empty
cache, on the default two single-threaded workers. Issue 13's target: the six Braille cases in
3D and the 12 flat/curved 2D cases in <= 2 min wall.

    .venv/bin/python benchmarks/paper_sweep_3d.py [--quality default]

Writes benchmarks/results/paper_sweep_3d.md: the wall time, each case's solve time (from the
progress lines), and the report's 2D-against-3D table and verdict lines.
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
OUT = ROOT / "benchmarks" / "results" / "paper_sweep_3d.md"
EXE = Path(sys.executable).with_name("tactileskin")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quality", default="default")
    a = ap.parse_args(argv)
    args = ["sweep", "--braille-dim", "both", "--quality", a.quality]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "sweep"
        w0 = time.perf_counter()
        p = subprocess.run([str(EXE), *args, "-o", str(out)], capture_output=True, text=True)
        wall = time.perf_counter() - w0
        if p.returncode not in (0, 3):
            raise SystemExit(f"tactileskin sweep failed ({p.returncode}): {p.stderr.strip()[-500:]}")
        cases = [ln.strip() for ln in (p.stderr + p.stdout).splitlines() if re.match(r"\s+(done|failed) ", ln)]
        report = (out / "report.md").read_text(encoding="utf-8")
    i = report.find("## Braille: 2D ridge against 3D dots")
    j = report.find("## Against the paper")
    verdicts = [ln for ln in report.splitlines() if ln.startswith(("No verdict", "Verdicts the 3D", "No discrimination",
                                                                   "Discrimination verdicts"))]
    three = [c for c in cases if "-3d" in c]
    text = "\n".join([
        "# The paper sweep with Braille as 3D dots (benchmarks/paper_sweep_3d.py)", "",
        f"Measured {_dt.date.today().isoformat()}: `tactileskin {' '.join(args)}` from an empty cache, "
        "default workers (two single-threaded processes on 2 cores).", "",
        f"**Wall time: {wall:.0f} s ({wall / 60:.1f} min)** for {len(cases)} cases, of which {len(three)} 3D "
        f"(target for the 18 paper cases with Braille in 3D: <= 120 s: {'met' if wall <= 120 else 'not met'}).", "",
        "Cases in the order they finished (solve wall s):", "", *[f"- {c}" for c in cases], "",
        report[i:j].strip() if i >= 0 else "(no 2D/3D section)", "",
        "Verdicts of the report's paper checks and discrimination, with each model:", "", *[f"- {v}" for v in verdicts], ""])
    from tactileskin.fileio import atomic_write_text

    atomic_write_text(OUT, text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
