"""Time of the `default` 3D Braille solve (issue 13's speed target), one case per process.

For each thickness (and text, material) solves Scene(dim=3, indenter="braille") at the
scene defaults (the `default` 3D preset, data/presets.json) in a fresh subprocess and
reports dofs, CPU s (time.process_time of the solve, one BLAS thread), wall s, increments,
Newton iterations, peak and span, and the per-phase wall times; writes the table to
benchmarks/results/braille3d_default.md.

    .venv/bin/python benchmarks/braille3d_default.py [--thickness 1 3] [--text ""] \
        [--material silicone polyurethane] [--repeat 2] [--section "what changed"]

Each run adds a section under the title of benchmarks/results/braille3d_default.md (the earlier
sections, and the notes written into them, are kept).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "braille3d_default.md"


def one(t: float, text: str, material: str) -> dict:
    from tactileskin.fe import solve
    from tactileskin.scene import Scene

    sc = Scene(dim=3, indenter="braille", thickness=t, material=material, braille_text=text)
    c0, w0 = time.process_time(), time.perf_counter()
    r = solve(sc)
    return dict(t=t, text=text, material=material, mesh=[sc.mesh_size, sc.refinement], dofs=r.stats["dofs"],
                cpu=time.process_time() - c0, wall=time.perf_counter() - w0, incr=r.stats["increments"],
                newton=r.stats["newton_iterations"], peak=r.peak, span=r.span,
                rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
                phases=r.stats.get("phases_s"))


def table(rows: list[dict]) -> str:
    out = ["| t mm | material | text | mesh | dofs | CPU s | wall s | incr. / Newton | peak MPa | span mm | RSS MB | phases (wall s) |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        ph = ", ".join(f"{k} {v:.1f}" for k, v in (r.get("phases") or {}).items() if k != "total")
        out.append(f"| {r['t']:g} | {r['material']} | {r['text'] or 'dot'} | {r['mesh'][0]:g} / {r['mesh'][1]:g} | "
                   f"{r['dofs']:,} | {r['cpu']:.1f} | {r['wall']:.1f} | {r['incr']} / {r['newton']} | "
                   f"{r['peak']:.5f} | {r['span']:.3f} | {r['rss_mb']:.0f} | {ph} |")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", type=float, nargs="+", default=[1.0, 3.0])
    ap.add_argument("--text", default="")
    ap.add_argument("--material", nargs="+", default=["silicone"])
    ap.add_argument("--repeat", type=int, default=1, help="runs of each case, interleaved")
    ap.add_argument("--section", help="title of the new section in the results file")
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        print(json.dumps(one(a.thickness[0], a.text, a.material[0])))
        return 0
    rows = []
    load0 = os.getloadavg()[0]
    for t, m in [(t, m) for _ in range(a.repeat) for t in a.thickness for m in a.material]:
        cmd = [sys.executable, __file__, "--one", "--thickness", f"{t:g}", "--text", a.text, "--material", m]
        p = subprocess.run(cmd, check=True, capture_output=True, text=True,
                           env=dict(os.environ, PYTHONPATH=str(ROOT / "src")))
        rows.append(json.loads(p.stdout.strip().splitlines()[-1]))
        print(table(rows[-1:]).splitlines()[-1], flush=True)
    from tactileskin.fileio import atomic_write_text

    # a new section under the title; the earlier sections (measurements and their reading, by
    # hand) are kept
    title = "# `default` 3D Braille solve times (benchmarks/braille3d_default.py)\n\n"
    old = OUT.read_text(encoding="utf-8") if OUT.exists() else title
    rest = old[len(title):] if old.startswith(title) else old
    section = (f"## {a.section or 'Run'} ({_dt.date.today().isoformat()})\n\n"
               f"`{' '.join(['benchmarks/braille3d_default.py'] + (argv if argv is not None else sys.argv[1:]))}`; "
               f"load average before the run {load0:.1f}, after {os.getloadavg()[0]:.1f}.\n\n" + table(rows) + "\n\n")
    atomic_write_text(OUT, title + section + rest)
    return 0


if __name__ == "__main__":
    sys.exit(main())
