"""Per-call cost of the element work of one Newton iteration (run: python benchmarks/kernels.py).

Prints median CPU times (ms; process time, steadier than wall time on a shared machine)
over repeated calls of Kinematics, the material law
(fe.material_law, as the Model calls it, and the general 3x3 hyperfoam.pk2_tangent),
kernels.residual and kernels.tangent, mixed formulation, on
  2D: the default mesh of Scene(thickness=1, material="silicone", indenter="flat")
      (P2 triangles, 3 points);
  3D: a structured P2 tet box, 12^3 cubes x 6 = 10,368 tets (4 points).
The trial state is a homogeneous 5 % deformation plus small random nodal noise (J > 0).

Options: --repeat N (default 15); --no-scene (2D on a structured 31 x 31 x 2 triangle mesh,
no gmsh); --baseline REV: also time the source tree of git revision REV (extracted to a
temporary folder), alternating baseline and current runs --rounds times (default 2) and
printing the median per row, so that both see the same load on a shared machine (the 2D
mesh is then the structured one unless --scene: the scene's mesh depends on the tree);
--solve: also the median of 3 fe.solve calls of the 2D scene.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def median_ms(fn, repeat):
    fn()  # warm-up
    t = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        t.append(time.process_time() - t0)
    return 1e3 * float(np.median(t))


def trial_state(model, seed=0):
    rng = np.random.default_rng(seed)
    X = model.basis.doflocs.T
    m = model.m
    A = 0.05 * rng.standard_normal((m, m))
    h = float(np.median(model.w.sum(axis=1))) ** (1.0 / m)
    u = X @ A.T + 0.02 * h * rng.standard_normal(X.shape)
    return u.ravel()


def rows_for(label, model, hf, repeat):
    from tactileskin.fe import kernels, material_law
    from tactileskin.materials import pk2_tangent

    m = model.m
    u = trial_state(model)
    ue = u.reshape(-1, m)[model.sdofs]
    law = material_law(hf)
    kin = kernels.Kinematics(ue, model.G, model.w, model.mixed)
    assert kin.admissible
    S3, D, ok = law(kin.C)
    assert np.all(ok)
    S, Dm = S3[..., :m, :m], np.ascontiguousarray(D[..., :m, :m, :m, :m])
    E, Q = model.w.shape
    out = [
        ("Kinematics", median_ms(lambda: kernels.Kinematics(ue, model.G, model.w, model.mixed), repeat)),
        ("fe.material_law", median_ms(lambda: law(kin.C), repeat)),
        ("pk2_tangent (3x3 path)", median_ms(lambda: pk2_tangent(hf, kin.C), repeat)),
        ("kernels.residual", median_ms(lambda: kernels.residual(kin, S), repeat)),
        ("kernels.tangent", median_ms(lambda: kernels.tangent(kin, S, Dm), repeat)),
    ]
    return [[label, f"{E} x {Q}", name, t] for name, t in out]


def measure(repeat, no_scene):
    from skfem import MeshTet, MeshTri

    from tactileskin.fe import Dirichlet, Model, material_law
    from tactileskin.materials import get_material

    hf = get_material("silicone").hyperfoam
    if no_scene:
        mesh = MeshTri.init_tensor(np.linspace(0, 1, 32), np.linspace(0, 1, 32))
        model2 = Model(mesh, {"l": mesh.facets_satisfying(lambda x: x[0] < 1e-9)}, material_law(hf),
                       [Dirichlet("l", (0,))])
    else:
        from tactileskin.fe import model_for_scene
        from tactileskin.scene import Scene
        model2 = model_for_scene(Scene(thickness=1, material="silicone", indenter="flat"))[0]
    mesh3 = MeshTet.init_tensor(*(np.linspace(0, 1, 13),) * 3)
    model3 = Model(mesh3, {"l": mesh3.facets_satisfying(lambda x: x[0] < 1e-9)}, material_law(hf),
                   [Dirichlet("l", (0,))])
    return rows_for("2D P2 tri", model2, hf, repeat) + rows_for("3D P2 tet", model3, hf, repeat)


def solve_median():
    from tactileskin.fe import solve
    from tactileskin.mesh import build_mesh
    from tactileskin.scene import Scene

    sc = Scene(thickness=1, material="silicone", indenter="flat")
    sm = build_mesh(sc)
    t = []
    for _ in range(3):
        t0 = time.perf_counter()
        r = solve(sc, sm)
        t.append(time.perf_counter() - t0)
    return (f"fe.solve {sc.label()}: median of 3 = {np.median(t):.2f} s ({r.stats['dofs']} dofs, "
            f"{r.stats['newton_iterations']} Newton iterations, peak {r.peak:.10g} MPa)")


def compare(a):
    """Alternate subprocess runs of the baseline tree and of this tree; print medians."""
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(__file__).resolve().parents[1]
        arch = subprocess.run(["git", "-C", str(root), "archive", a.baseline, "src", "geometry"],
                              check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=arch, check=True)
        base_env = dict(os.environ, PYTHONPATH=str(Path(tmp) / "src"))
        cmd = [sys.executable, __file__, "--json", "--repeat", str(a.repeat)] + ([] if a.scene else ["--no-scene"])
        runs = {"base": [], "new": []}
        for _ in range(a.rounds):
            for key, env in (("base", base_env), ("new", None)):
                out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout
                runs[key].append(json.loads(out.strip().splitlines()[-1]))
    print(f"CPU ms, median of {a.rounds} alternating runs x {a.repeat} calls")
    print(f"{'mesh':<11}{'elements x points':>18}  {'call':<24}{a.baseline[:10]:>11}{'now':>9}{'speed-up':>10}")
    for i, row in enumerate(runs["new"][0]):
        tb = float(np.median([r[i][3] for r in runs["base"]]))
        tn = float(np.median([r[i][3] for r in runs["new"]]))
        print(f"{row[0]:<11}{row[1]:>18}  {row[2]:<24}{tb:>9.2f}ms{tn:>7.2f}ms{tb / tn:>9.1f}x")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--no-scene", action="store_true")
    ap.add_argument("--solve", action="store_true")
    ap.add_argument("--baseline", default=None, help="git revision to compare with")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--scene", action="store_true", help="with --baseline: the scene's 2D mesh")
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.baseline:
        compare(a)
    else:
        rows = measure(a.repeat, a.no_scene)
        if a.json:
            print(json.dumps(rows))
            return
        print(f"{'mesh':<11}{'elements x points':>18}  {'call':<24}{'CPU ms':>10}")
        for label, size, name, t in rows:
            print(f"{label:<11}{size:>18}  {name:<24}{t:>10.2f}")
    if a.solve:
        print(solve_median())


if __name__ == "__main__":
    main()
