"""CAD benchmark: solid build time, STL tessellation cost and accuracy against tolerance.

For the default part set (t = 3 mm, all indenters, molds) and a few chordal tolerances,
prints per tolerance: tessellation + STL write + trimesh check time, triangle count, the
worst STL-vs-CAD volume difference over the parts, and the largest distance of sampled
facet points of the curved and Braille working faces from their analytic surfaces.
Also the solid build time for t = 1, 3, 5. The production setting is
tactileskin.geometry.export.STL_TOLERANCE.

    .venv/bin/python benchmarks/cad.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import trimesh
from rich.console import Console
from rich.table import Table

from tactileskin.geometry import export
from tactileskin.geometry.indenters import make_indenter
from tactileskin.geometry.parts import build_parts


def main() -> None:
    console = Console()
    t_build = Table(title="solids (build123d), all parts")
    t_build.add_column("t (mm)")
    t_build.add_column("build (s)", justify="right")
    for t in (1.0, 3.0, 5.0):
        t0 = time.perf_counter()
        ps = build_parts(t)
        t_build.add_row(f"{t:g}", f"{time.perf_counter() - t0:.2f}")
    console.print(t_build)

    ps = build_parts(3.0)
    analytic = {p.name: make_indenter(p.parameters["kind"], y0=p.parameters["y0"], dim=3)
                for p in ps if p.name in ("indenter_curved", "indenter_braille")}
    tab = Table(title=f"STL tessellation (angular {export.STL_ANGULAR_TOLERANCE} rad), t = 3 mm, {len(ps)} parts")
    for c in ("tolerance (mm)", "time (s)", "triangles", "max |V_stl/V_cad - 1|", "max face deviation (mm)"):
        tab.add_column(c, justify="right")
    with tempfile.TemporaryDirectory() as d:
        for tol in (0.02, 0.01, 0.005, 0.002, 0.001):
            t0 = time.perf_counter()
            tri, dv, dev = 0, 0.0, 0.0
            for p in ps:
                path = Path(d) / f"{p.name}.stl"
                export.write_stl(p.shape, path, tol)
                m = export.check_stl(path, p.name)
                tri += len(m.faces)
                dv = max(dv, abs(m.volume / p.shape.volume - 1.0))
                if p.name in analytic:
                    down = np.flatnonzero(m.face_normals[:, 1] < -1e-3)
                    pts, _ = trimesh.sample.sample_surface(m.submesh([down], append=True), 20000, seed=0)
                    dev = max(dev, float(np.abs(analytic[p.name].gap(pts, 0.0)[0]).max()))
            tab.add_row(f"{tol:g}", f"{time.perf_counter() - t0:.2f}", f"{tri}", f"{dv:.2e}", f"{dev:.4f}")
    console.print(tab)


if __name__ == "__main__":
    main()
