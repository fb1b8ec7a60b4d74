"""Sensor sampling: locating points in the skin's curved P2 mesh (fe.probe.locate).

Points inside random elements of the `default` 3D mesh of a t = 1 mm silicone Braille dot
(8265 P2 tetrahedra), located and interpolated by fe.probe.interpolation_matrix
with the affine-first search (Newton on the AFFINE_FIRST best candidates by affine coordinates)
and with Newton on all of a point's candidates (the search before it). Prints medians of wall
time per point and the largest difference of the interpolated coordinates (exact in P2).

    .venv/bin/python benchmarks/sensor_sampling.py [--points 20000] [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from tactileskin.fe import model_for_scene, probe
from tactileskin.planner import with_quality
from tactileskin.scene import Scene


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=20000)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args(argv)
    scene = with_quality(Scene(thickness=1.0, indenter="braille", braille_text="⠁", dim=3, viscoelastic=False),
                         "default")
    model, _ = model_for_scene(scene)
    rng = np.random.default_rng(0)
    el = rng.integers(0, model.mesh.t.shape[1], a.points)
    b = rng.dirichlet(np.ones(4), a.points).T
    pts = model.basis.mapping.F(b[1:][:, :, None], el)[:, :, 0].T
    probe.locate(model, pts[:10])  # the KD tree and affine maps: set up once per model
    default = probe.AFFINE_FIRST
    print(f"{model.mesh.t.shape[1]} tetrahedra, {a.points} points, median of {a.repeat}")
    print("| search | ms per point | max |interpolated - point| (mm) |")
    print("|---|---:|---:|")
    for name, first in (("affine first (AFFINE_FIRST = %d)" % default, default), ("Newton on all candidates", 10 ** 9)):
        probe.AFFINE_FIRST = first
        times = []
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            rows = [probe.interpolation_matrix(model, pts[i:i + probe.CHUNK]) for i in range(0, len(pts), probe.CHUNK)]
            times.append(time.perf_counter() - t0)
        got = np.vstack([np.stack([M @ model.mesh.doflocs[i] for i in range(3)], axis=1) for M in rows])
        print(f"| {name} | {1e3 * statistics.median(times) / a.points:.3f} | {np.abs(got - pts).max():.1e} |")
    probe.AFFINE_FIRST = default
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
