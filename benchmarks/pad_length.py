"""The 3D flat pad under a z-cylinder against its 2D plane-strain section, by pad length.

A cylinder whose axis runs along the pad (z) loads the pad uniformly along its length, so the
2D section (plane strain, per mm) is the limit of a long pad, but a finite 3D block has free
ends z = +-L/2, which plane strain has not. This solves the same scene (pad 20 mm wide, t = 2
mm silicone, elastic, cylinder R 5 mm pressed 0.2 mm) as

- the 2D half section on the 3D run's in-plane sizes and on a fine mesh (the reference);
- the 3D quarter model (`fe.solve`, the production path: reaction on the whole indenter)
  with u_z = 0 on its end as well: both ends in plane strain, so it must equal 2D x L up to
  discretisation (checks the 3D force integration, the symmetry planes, the force factor,
  the sensors);
- the 3D quarter model with free ends (`fe.solve` as the CLI runs it) for each length.

and prints per length the whole indenter's force against 2 x (2D half-section force per mm)
x L, the force the two free ends cost (per end, in N and in mm of plane-strain pad), and at
the mid-length section the peak bone pressure and the largest bone shear tau_1 = sigma_xy
(sensors 0.05 mm above the board, x = 0..4 mm) against 2D. If the deficit is the free ends,
F(L) = f_ps L - 2 dF with dF independent of L, and the mid-length section tends to 2D.

    PYTHONPATH=src .venv/bin/python benchmarks/pad_length.py [--lengths 10 20 40 80] \
        [--mesh 0.85/2] [--out benchmarks/results/pad_length.md]
"""

from __future__ import annotations

import argparse
import datetime
import logging
import subprocess
import time

import numpy as np

from tactileskin.fe import Dirichlet, Model, make_result, model_for_scene, read_sensors, run, solve
from tactileskin.fileio import atomic_write_text
from tactileskin.scene import Scene

WIDTH, T, RADIUS, DEPTH = 20.0, 2.0, 5.0, 0.2
FINE_2D = (0.2, 2.0)
SENSORS = {"name": "bone", "kind": "line", "s": [0.0, 4.0], "pitch": 0.5, "height": 0.05}


def scene(dim: int, length: float, mesh: tuple[float, float]) -> Scene:
    sens = dict(SENSORS, z=[0.0]) if dim == 3 else SENSORS
    return Scene(skin="pad", pad_width=WIDTH, pad_length=length, thickness=T, indenter="cylinder",
                 indenter_radius=RADIUS, indenter_axis="z", depth=DEPTH, material="silicone",
                 viscoelastic=False, dim=dim, sensors=[sens], mesh_size=mesh[0], refinement=mesh[1])


def plane_ends(sc: Scene):
    """The 3D quarter model of `sc` with u_z = 0 on end_front too (both ends plane strain),
    reporting as fe.solve does (the whole indenter's force, sensors mirrored)."""
    base, sm = model_for_scene(sc)
    assert sm.z_symmetric and sm.halved and base.force_factor == 4.0
    model = Model(base.mesh, base.boundaries, base.law, list(base.dirichlet) + [Dirichlet("end_front", (2,))],
                  prony=base.prony, formulation=base.formulation, contact=base.contact, order=sc.order,
                  stiffness=base.stiffness)
    model.force_factor, model.profile_sides = base.force_factor, base.profile_sides
    ev, stats = run(model, sc.duration)
    res = make_result(model, ev, stats, s_of_point=sc.section().s_of_point, scene=sc.to_dict())
    res.sensors = read_sensors(sc, model, res, z_symmetric=True)
    return res


def numbers(res, dim: int, length: float) -> dict:
    return {"F": res.reaction, "f": res.reaction / length if dim == 3 else 2.0 * res.reaction,
            "peak": res.peak, "tau": float(np.max(np.abs(res.sensors.tau_1))), "dofs": res.stats["dofs"]}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[10.0, 20.0, 40.0, 80.0])
    ap.add_argument("--mesh", default="0.85/2", help="3D size / refinement (the 3D preview's)")
    ap.add_argument("--out", default=None, help="markdown file for the table")
    a = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    mesh = tuple(float(v) for v in a.mesh.split("/"))
    t0 = time.perf_counter()
    ref = numbers(solve(scene(2, 20.0, FINE_2D)), 2, 20.0)
    same = numbers(solve(scene(2, 20.0, mesh)), 2, 20.0)
    lp = 20.0 if 20.0 in a.lengths else a.lengths[0]
    ps = numbers(plane_ends(scene(3, lp, mesh)), 3, lp)
    rows = [(L, numbers(solve(scene(3, L, mesh)), 3, L)) for L in a.lengths]
    wall = time.perf_counter() - t0

    def r(v, w):
        return f"{v / w:.3f}"

    lines = [f"# 3D pad under a z-cylinder vs its 2D section, by pad length (benchmarks/pad_length.py, "
             f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, commit {_commit()})", "",
             f"Pad {WIDTH:g} mm wide, t = {T:g} mm silicone (hyperfoam, elastic), cylinder R {RADIUS:g} mm "
             f"along z pressed {DEPTH:g} mm; 3D quarter model at {a.mesh} (the 3D preview's sizes), "
             f"2D reference at {FINE_2D[0]:g}/{FINE_2D[1]:g}. F: the whole indenter's force (N); "
             f"f = F / L (N/mm), 2D: 2 x the half section's. Peak: bone pressure at the mid-length "
             f"section; tau: max |sigma_xy| of sensors 0.05 mm above the board at mid-length, "
             f"x = 0..4 mm. dF: the force one free end costs, (f_ps L - F) / 2, f_ps from the 3D "
             f"model with both ends in plane strain.", "",
             "| model | L (mm) | L / t | dofs | F (N) | f / f_2D | f / f_ps | dF per end (N) | dF / f_ps (mm) "
             "| peak / 2D | tau / 2D |", "|---|---|---|---|---|---|---|---|---|---|---|",
             f"| 2D, {FINE_2D[0]:g}/{FINE_2D[1]:g} (reference) | - | - | {ref['dofs']} | {ref['f']:.5f} / mm | 1 | "
             f"{r(ref['f'], ps['f'])} | - | - | 1 ({ref['peak']:.5f} MPa) | 1 ({ref['tau']:.5f} MPa) |",
             f"| 2D, {a.mesh} | - | - | {same['dofs']} | {same['f']:.5f} / mm | {r(same['f'], ref['f'])} | "
             f"{r(same['f'], ps['f'])} | - | - | {r(same['peak'], ref['peak'])} | {r(same['tau'], ref['tau'])} |",
             f"| 3D, both ends u_z = 0 | {lp:g} | {lp / T:g} | {ps['dofs']} | {ps['F']:.4f} | "
             f"{r(ps['f'], ref['f'])} | 1 | - | - | {r(ps['peak'], ref['peak'])} | {r(ps['tau'], ref['tau'])} |"]
    for L, n in rows:
        dF = 0.5 * (ps["f"] * L - n["F"])
        lines.append(f"| 3D, free ends | {L:g} | {L / T:g} | {n['dofs']} | {n['F']:.4f} | {r(n['f'], ref['f'])} | "
                     f"{r(n['f'], ps['f'])} | {dF:.4f} | {dF / ps['f']:.3f} | {r(n['peak'], ref['peak'])} | "
                     f"{r(n['tau'], ref['tau'])} |")
    if len(rows) >= 2:
        (L1, n1), (L2, n2) = rows[-2], rows[-1]
        slope = (n2["F"] - n1["F"]) / (L2 - L1)
        lines += ["", f"Slope of F(L) between the two longest pads: {slope:.5f} N/mm = {slope / ps['f']:.4f} f_ps "
                  f"= {slope / ref['f']:.4f} f_2D (a fixed cost per end: the slope is the plane-strain force per mm)."]
    lines += ["", f"Run: `PYTHONPATH=src .venv/bin/python benchmarks/pad_length.py --lengths "
              f"{' '.join(f'{v:g}' for v in a.lengths)} --mesh {a.mesh}` ({wall:.0f} s wall, one process, "
              f"shared 2-core machine)."]
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        atomic_write_text(a.out, text)


def _commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


if __name__ == "__main__":
    main()
