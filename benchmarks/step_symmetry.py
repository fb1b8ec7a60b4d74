"""Wall time of a symmetric STEP skin solved whole against as its quarter (mesh.skinfile's
symmetry cut), at the `preview` 3D preset: a 20 x 20 mm pad with a domed top (3 mm thick on
the axis, a sphere of radius 60 mm: 1.32 mm at the corners), bonded on y = 0, pressed by the
flat plate and by a single Braille dot to the default 20 % of t (viscoelastic, as the CLI).
Each run in a fresh subprocess (the STEP's checks, meshing and solve all timed, one BLAS
thread); the medians of `--runs` runs go to benchmarks/results/step_symmetry.md.

    .venv/bin/python benchmarks/step_symmetry.py [--runs 3] [--indenter flat braille]
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "step_symmetry.md"
W, H, R = 20.0, 3.0, 60.0  # pad side (x and z), thickness on the axis, dome radius (mm)


def make_step(path: Path) -> Path:
    import build123d as bd

    base = bd.Box(W, H, W, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    bd.export_step(base & bd.Pos(0, H - R, 0) * bd.Sphere(R), str(path))
    return path


def one(step: str, indenter: str, whole: bool) -> dict:
    from tactileskin.fe import solve
    from tactileskin.mesh import build_mesh
    from tactileskin.scene import Scene, preset_mesh

    w0 = time.perf_counter()
    sc = Scene(skin="file", skin_file=step, indenter=indenter)
    h, r = preset_mesh("preview", 3, indenter, sc.thickness, "file")
    sc = sc.replace(mesh_size=h, refinement=r)
    sm = build_mesh(sc, use_symmetry=not whole)
    res = solve(sc, mesh=sm)
    return dict(indenter=indenter, model="whole" if whole else ("quarter" if sm.halved and sm.z_symmetric
                                                                 else "half" if sm.halved else "whole"),
                mesh=[h, r], dofs=res.stats["dofs"], wall=time.perf_counter() - w0,
                incr=res.stats["increments"], newton=res.stats["newton_iterations"], reaction=res.reaction,
                peak=res.peak, span=res.span, status=res.status)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--indenter", nargs="+", default=["flat", "braille"])
    ap.add_argument("--one", nargs=3, metavar=("STEP", "INDENTER", "WHOLE"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        print(json.dumps(one(a.one[0], a.one[1], a.one[2] == "1")))
        return 0
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        step = str(make_step(Path(tmp) / "domed_pad.step"))
        for ind in a.indenter:
            for whole in (True, False):
                runs = []
                for _ in range(a.runs):
                    out = subprocess.run([sys.executable, __file__, "--one", step, ind, "1" if whole else "0"],
                                         env=env, capture_output=True, text=True, check=True)
                    runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
                    print(ind, runs[-1]["model"], f"{runs[-1]['wall']:.1f} s", flush=True)
                rows.append({**runs[0], "walls": [r["wall"] for r in runs],
                             "wall": statistics.median(r["wall"] for r in runs)})
    lines = ["# A symmetric STEP skin whole vs its quarter (benchmarks/step_symmetry.py)", "",
             f"{_dt.date.today()}: `benchmarks/step_symmetry.py --runs {a.runs}`; a {W:g} x {W:g} mm pad, "
             f"domed top ({H:g} mm on the axis, R {R:g} mm), silicone, depth 20 % of t, `preview` 3D sizes; "
             "each run in its own process (STEP checks + mesh + solve), wall time median of the runs "
             "(2 cores shared with other jobs).", "",
             "| indenter | model | mesh h / ratio | dofs | wall s (median; runs) | incr. / Newton | reaction N | "
             "peak MPa | span mm | status |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['indenter']} | {r['model']} | {r['mesh'][0]:g} / {r['mesh'][1]:g} | {r['dofs']:,} | "
                     f"{r['wall']:.1f} ({', '.join(f'{w:.1f}' for w in r['walls'])}) | {r['incr']} / {r['newton']} | "
                     f"{r['reaction']:.4f} | {r['peak']:.5f} | {r['span']:.3f} | {r['status']} |")
    for ind in a.indenter:
        w = {r["model"]: r["wall"] for r in rows if r["indenter"] == ind}
        if "whole" in w and len(w) == 2:
            other = next(k for k in w if k != "whole")
            lines.append(f"\n{ind}: the {other} model is {w['whole'] / w[other]:.1f}x faster than the whole.")
    OUT.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
