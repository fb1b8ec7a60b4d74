"""The free end of the flat t = 1 slab next to the bone: mixed against displacement formulation.

calculix_compare3d.md found tactileskin's mixed (mean-dilatation) displacements up to 15 % of
max |u| away from ccx's C3D10 (and from tactileskin's own displacement formulation, which ccx
matches there) at the free end z = 10 mm within ~1 mm of the bone. This solves the polyurethane
flat plate at t = 1 (elastic) with both formulations on the given meshes and prints, per mesh,
the section peak, the force and the end-face displacement (u_y, u_z) at a few points near the
bone (linear interpolation over the end face's nodes): does the gap close with the mesh?

    PYTHONPATH=src python benchmarks/free_end_corner3d.py 0.85/2 0.6/2 0.45/2
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from scipy.interpolate import LinearNDInterpolator

sys.path.insert(0, str(Path(__file__).parent))
from calculix_compare3d import make_scene, ts_solve  # noqa: E402

from tactileskin.mesh import build_mesh  # noqa: E402
from tactileskin.mesh.skinmesh import facet_nodes  # noqa: E402

# (x, y) on the end face z = 10 mm; the bone is at y ~ 6.0 near x = 0, the skin top at 7.0
POINTS = np.array([[0.0, 6.2], [0.3, 6.2], [0.5, 6.15], [0.3, 6.5], [0.0, 6.8]])


def main(argv=None) -> int:
    meshes = (argv if argv is not None else sys.argv[1:]) or ["0.85/2", "0.6/2"]
    for mesh in meshes:
        sc = make_scene("flat", 1.0, "preview", mesh)
        sm = build_mesh(sc)
        nodes = np.unique(facet_nodes(sm.mesh, sm.boundaries["end_front"], 3, sm.order))
        X = sm.mesh.doflocs.T[nodes]
        for form in ("mixed", "displacement"):
            res, _, cpu, _ = ts_solve(sc.replace(formulation=form), sm)
            U = np.asarray(res.fields["point_data"]["displacement_mm"])[nodes]
            uy = LinearNDInterpolator(X[:, :2], U[:, 1])(POINTS)
            uz = LinearNDInterpolator(X[:, :2], U[:, 2])(POINTS)
            print(json.dumps({"mesh": mesh, "form": form, "dofs": 3 * sm.mesh.doflocs.shape[1],
                              "peak": round(float(res.peak), 5), "force": round(float(res.reaction), 4),
                              "points_xy": POINTS.tolist(), "uy_end": np.round(uy, 4).tolist(),
                              "uz_end": np.round(uz, 4).tolist(), "cpu_s": round(cpu)}), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
