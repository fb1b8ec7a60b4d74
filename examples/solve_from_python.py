"""Solve one indentation from Python and open its result the way ParaView would.

A 1 mm silicone skin pressed 20 % by the flat plate (the paper's Fig. 9A case), at the
`preview` mesh quality. Writes profile.csv, summary.json, result.vtu and (history=True)
the time series result.pvd into OUT_DIR (default: a temporary folder), then checks:

- peak_mpa: the peak bone pressure. The `default` mesh gives 0.3165 MPa and `preview`
  stays within 3.6 % of the mesh-converged value (docs/speed_vs_error.md).
EXPECT peak_mpa 0.300 0.330
- top_drop_over_depth: result.vtu holds the reference mesh plus displacement_mm; the top
  of the skin at x = 0, moved by its displacement, sits under the plate: its drop over the
  indentation depth is 1 up to the contact's penetration (measured 0.2 um, 0.1 % of the
  0.2 mm depth). Points already deformed, then warped again, would give about 2.
EXPECT top_drop_over_depth 0.995 1.005
- contact_force_over_reaction: equilibrium; the contact pressure integrated over the
  contact points (trapezoid) against the bone's reaction. The trapezoid misses the strips
  before the first and after the last contact point (about 0.05 mm each), hence below 1.
EXPECT contact_force_over_reaction 0.93 1.02
- vtu_contact_force_over_reaction: result.vtu's contact_pressure_MPa on the outer_surface
  cells (per reference area) times the cells' lengths, what ParaView's Integrate Variables
  gives: the whole contact force; the plate's normal is vertical, so it is the reaction to
  the chord-versus-arc length of the facets (measured 2e-5).
EXPECT vtu_contact_force_over_reaction 0.999 1.001

Also draws the profile with result.plot() into OUT_DIR/profile.svg.

    python examples/solve_from_python.py [OUT_DIR]
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import meshio
import numpy as np

import tactileskin as ts


def main(out: Path) -> None:
    scene = ts.Scene(thickness=1.0, material="silicone", indenter="flat")
    result = ts.solve(scene, quality="preview", history=True)
    print(result)  # one line: the metrics, status and sizes
    folder = result.write(out)

    vtu = meshio.read(folder / "result.vtu")
    X, u = vtu.points, vtu.point_data["displacement_mm"]
    top = np.argmax(X[:, 1])  # the undeformed top of the skin, on the symmetry line
    drop = -u[top, 1]
    force = np.trapezoid(result.contact_pressure, result.contact_x)
    lines = vtu.cells_dict["line"]
    chord = np.linalg.norm(X[lines[:, 1]] - X[lines[:, 0]], axis=1)
    vtu_force = float(np.sum(chord * vtu.cell_data_dict["contact_pressure_MPa"]["line"]))
    result.plot(out / "profile.svg")  # matplotlib; returns (figure, axes) for more drawing
    print(f"wrote {sorted(p.name for p in folder.iterdir())}")
    print(f"RESULT peak_mpa={result.peak:.6g}")
    print(f"RESULT top_drop_over_depth={drop / scene.indentation:.6g}")
    print(f"RESULT contact_force_over_reaction={force / result.reaction:.6g}")
    print(f"RESULT vtu_contact_force_over_reaction={vtu_force / result.reaction:.6g}")


if __name__ == "__main__":
    if len(sys.argv) > 1:
        main(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            main(Path(tmp) / "solve")
