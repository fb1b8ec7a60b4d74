"""Mesh benchmark: cell/node counts, quality, accuracy and wall time for t = 1, 3, 5 mm.

Usage: python benchmarks/mesh.py [--repeat 3] [--size3d 0.5] [--refinement3d 2]
2D at the scene defaults (mesh_size 0.25 mm, refinement 3); 3D at a coarser size (the
default size gives ~10^6 P2 tetrahedra). Wall time is the median of --repeat builds.
"""

from __future__ import annotations

import argparse
import statistics
import time

from rich.console import Console
from rich.table import Table

from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene


def run(repeat: int, size3d: float, ref3d: float) -> Table:
    table = Table(title=f"tactileskin meshes (median of {repeat} builds)")
    for col in ("dim", "t (mm)", "size / refined (mm)", "cells", "nodes", "estimate",
                "min SICN", "min scaled Jac.", "interface rel. err", "wall (s)"):
        table.add_column(col, justify="right")
    cases = [(2, t, None, None) for t in (1.0, 3.0, 5.0)] + [(3, t, size3d, ref3d) for t in (1.0, 3.0, 5.0)]
    for dim, t, size, ref in cases:
        scene = Scene(thickness=t, dim=dim)
        kw = {} if size is None else {"mesh_size": size, "refinement": ref}
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            sm = build_mesh(scene, **kw)
            times.append(time.perf_counter() - t0)
        q, sec = sm.quality, sm.section
        lz = 1.0 if dim == 2 else (0.5 if sm.z_symmetric else 1.0) * sm.length
        err = abs(sm.boundary_measure("bone_interface") / lz / sec.interface_length - 1.0)
        table.add_row(str(dim), f"{t:g}", f"{sm.sizes['coarse']:g} / {sm.sizes['fine']:.3g}",
                      str(q["elements"]), str(q["nodes"]), str(sm.sizes["estimate"]),
                      f"{q['min_sicn']:.3f}", f"{q['min_scaled_jacobian']:.3f}", f"{err:.1e}",
                      f"{statistics.median(times):.2f}")
    return table


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--size3d", type=float, default=0.5)
    ap.add_argument("--refinement3d", type=float, default=2.0)
    a = ap.parse_args()
    Console(width=160).print(run(a.repeat, a.size3d, a.refinement3d))
