"""Per-call cost of the element work of one Newton iteration (run: python benchmarks/kernels.py).

Prints median wall times (ms) over repeated calls of Kinematics, the material law
(hyperfoam pk2_tangent through fe.material_law, and the general 3x3 path for comparison),
kernels.residual and kernels.tangent, on
  2D: the default mesh of Scene(thickness=1, material="silicone", indenter="flat")
      (P2 triangles, 3 points), mixed formulation;
  3D: a structured P2 tet box (4 points), mixed formulation.
The trial state is a homogeneous 5 % deformation plus small random nodal noise (J > 0).
Options: --repeat N (default 15), --no-scene (2D on a structured mesh, no gmsh), --solve
(also the median of 3 fe.solve calls of the 2D scene).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from skfem import MeshTet, MeshTri

from tactileskin.fe import Dirichlet, Model, kernels, material_law
from tactileskin.materials import get_material, pk2_tangent


def median_ms(fn, repeat):
    fn()  # warm-up
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        t.append(time.perf_counter() - t0)
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
        ("material_law (used by Model)", median_ms(lambda: law(kin.C), repeat)),
        ("pk2_tangent (general 3x3)", median_ms(lambda: pk2_tangent(hf, kin.C), repeat)),
        ("kernels.residual", median_ms(lambda: kernels.residual(kin, S), repeat)),
        ("kernels.tangent", median_ms(lambda: kernels.tangent(kin, S, Dm), repeat)),
    ]
    return [(label, f"{E} x {Q}", name, t) for name, t in out]


def scene_model(scene):
    from tactileskin.fe import model_for_scene
    return model_for_scene(scene)[0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--no-scene", action="store_true")
    ap.add_argument("--solve", action="store_true")
    a = ap.parse_args()
    hf = get_material("silicone").hyperfoam
    if a.no_scene:
        mesh = MeshTri.init_tensor(np.linspace(0, 1, 32), np.linspace(0, 1, 32))
        model2 = Model(mesh, {"l": mesh.facets_satisfying(lambda x: x[0] < 1e-9)}, material_law(hf),
                       [Dirichlet("l", (0,))])
    else:
        from tactileskin.scene import Scene
        model2 = scene_model(Scene(thickness=1, material="silicone", indenter="flat"))
    mesh3 = MeshTet.init_tensor(*(np.linspace(0, 1, 13),) * 3)
    model3 = Model(mesh3, {"l": mesh3.facets_satisfying(lambda x: x[0] < 1e-9)}, material_law(hf),
                   [Dirichlet("l", (0,))])
    rows = rows_for("2D P2 tri", model2, hf, a.repeat) + rows_for("3D P2 tet", model3, hf, a.repeat)
    print(f"{'mesh':<11}{'elements x points':>18}  {'call':<30}{'median ms':>10}")
    for label, size, name, t in rows:
        print(f"{label:<11}{size:>18}  {name:<30}{t:>10.2f}")
    if a.solve:
        from tactileskin.fe import solve
        from tactileskin.scene import Scene
        sc = Scene(thickness=1, material="silicone", indenter="flat")
        from tactileskin.mesh import build_mesh
        sm = build_mesh(sc)
        t = []
        for _ in range(3):
            t0 = time.perf_counter()
            r = solve(sc, sm)
            t.append(time.perf_counter() - t0)
        print(f"fe.solve {sc.label()}: median of 3 = {np.median(t):.2f} s "
              f"({r.stats['dofs']} dofs, {r.stats['newton_iterations']} Newton iterations, peak {r.peak:.6g} MPa)")


if __name__ == "__main__":
    main()
