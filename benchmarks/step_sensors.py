"""Placing sensors on a STEP skin (skins.file.FileCoordinates on the CAD faces): the half tube
(outer R 8, inner R 6 bonded, 8 mm long; the tests' shell.step) with a 273-sensor grid (s in
[-5, 5] x z in [-3, 3], pitch 0.5) at depth 0.5 or height 0.5, with and without taxels 0.4 (3 x 3
points: each taxel's point a normal line of 16 CAD-read samples). The scene's analysis is done
once; each run times sensors.sites_for (the placement alone), medians of `--runs`. `--save F`
writes every position, sample and normal (npz) and `--compare F` checks them bit for bit
against a saved run (the same placement before and after a speed change).

    .venv/bin/python benchmarks/step_sensors.py [--runs 3] [--save out.npz | --compare out.npz]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

CASES = {"depth 0.5": {"depth": 0.5}, "height 0.5": {"height": 0.5},
         "depth 0.5, taxel 0.4": {"depth": 0.5, "taxel": 0.4},
         "height 0.5, taxel 0.4": {"height": 0.5, "taxel": 0.4}}


def make_step(path: Path) -> Path:
    import build123d as bd

    tube = bd.Cylinder(8, 8) - bd.Cylinder(6, 8)
    bd.export_step(tube - bd.Box(20, 10, 20, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER)), str(path))
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--save")
    ap.add_argument("--compare")
    a = ap.parse_args(argv)
    from tactileskin import sensors
    from tactileskin.scene import Scene

    with tempfile.TemporaryDirectory() as tmp:
        step = make_step(Path(tmp) / "shell.step")
        scene = Scene(skin="file", skin_file=str(step), skin_bonded="normal:-y:89.99")
        coords = sensors.coordinates_for(scene)  # the analysis (meshing, top, thickness): once
        out, times = {}, {}
        for name, extra in CASES.items():
            lay = {"name": "g", "kind": "grid", "s": [-5.0, 5.0], "z": [-3.0, 3.0], "pitch": [0.5], **extra}
            lays = sensors.layouts([lay])
            times[name] = []
            for _ in range(a.runs):
                coords.__dict__.pop("_surface_memo", None)
                t0 = time.perf_counter()
                st = sensors.resolve(lays, coords, 3)
                times[name].append(time.perf_counter() - t0)
            for k in ("xyz", "samples", "normal", "t1", "depth"):
                out[f"{name}/{k}"] = getattr(st, k)
            print(f"{name:24s} {len(st.ids)} sensors  median {statistics.median(times[name]):.3f} s  "
                  f"({', '.join(f'{t:.3f}' for t in times[name])})", flush=True)
    if a.save:
        np.savez(a.save, **out)
    if a.compare:
        ref = np.load(a.compare)
        same = {k: np.array_equal(ref[k], v, equal_nan=True) for k, v in out.items()}
        print("bit-identical to", a.compare, ":", all(same.values()), [k for k, v in same.items() if not v])
        return 0 if all(same.values()) else 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
