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
no gmsh); --baseline REV: fe/kernels.py and materials/hyperfoam.py of git revision REV
against this tree's, on the same models and states, calls alternating so that both see
the same load on a shared machine (2D: the structured mesh, or the scene's with --scene);
--solve: also the median of 3 fe.solve calls of the 2D scene.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
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


def _load(name, path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


def paired_ms(fa, fb, repeat):
    """Median CPU ms of fa and of fb, called alternately (both see the same machine load)."""
    fa(), fb()
    ta, tb = [], []
    for _ in range(repeat):
        for fn, t in ((fa, ta), (fb, tb)):
            t0 = time.process_time()
            fn()
            t.append(time.process_time() - t0)
    return 1e3 * float(np.median(ta)), 1e3 * float(np.median(tb))


def compare(a):
    """The element kernels and the hyperfoam law of git revision REV (fe/kernels.py and
    materials/hyperfoam.py loaded from it) against this tree's, call by call on the same
    models (this tree's Model, meshes and states)."""
    from skfem import MeshTet, MeshTri

    from tactileskin.fe import Dirichlet, Model, kernels, material_law
    from tactileskin.materials import get_material

    root = Path(__file__).resolve().parents[1]
    with tempfile.TemporaryDirectory() as tmp:
        mods = {}
        for key, rel in (("kernels", "src/tactileskin/fe/kernels.py"),
                         ("hyperfoam", "src/tactileskin/materials/hyperfoam.py")):
            text = subprocess.run(["git", "-C", str(root), "show", f"{a.baseline}:{rel}"],
                                  check=True, capture_output=True, text=True).stdout
            path = Path(tmp) / f"baseline_{key}.py"
            path.write_text(text)
            mods[key] = _load(f"baseline_{key}", path)
    kb, hb = mods["kernels"], mods["hyperfoam"]
    hf = get_material("silicone").hyperfoam
    hf_b = hb.Hyperfoam(hf.mu, hf.alpha, hf.nu)
    law_b = lambda C: hb.pk2_tangent(hf_b, C)  # noqa: E731 (the baseline's material_law)
    if a.scene:
        from tactileskin.fe import model_for_scene
        from tactileskin.scene import Scene
        model2 = model_for_scene(Scene(thickness=1, material="silicone", indenter="flat"))[0]
    else:
        mesh = MeshTri.init_tensor(np.linspace(0, 1, 32), np.linspace(0, 1, 32))
        model2 = Model(mesh, {"l": mesh.facets_satisfying(lambda x: x[0] < 1e-9)}, material_law(hf),
                       [Dirichlet("l", (0,))])
    mesh3 = MeshTet.init_tensor(*(np.linspace(0, 1, 13),) * 3)
    model3 = Model(mesh3, {"l": mesh3.facets_satisfying(lambda x: x[0] < 1e-9)}, material_law(hf),
                   [Dirichlet("l", (0,))])
    print(f"CPU ms, medians of {a.repeat} alternating calls; baseline = {a.baseline}")
    print(f"{'mesh':<11}{'elements x points':>18}  {'call':<18}{'baseline':>10}{'now':>9}{'speed-up':>10}")
    for label, model in (("2D P2 tri", model2), ("3D P2 tet", model3)):
        m = model.m
        ue = trial_state(model).reshape(-1, m)[model.sdofs]
        law = material_law(hf)
        kin = kernels.Kinematics(ue, model.G, model.w, model.mixed)
        kin_b = kb.Kinematics(ue, model.G, model.w, model.mixed)
        S3, D, _ = law(kin.C)
        S, Dm = S3[..., :m, :m], np.ascontiguousarray(D[..., :m, :m, :m, :m])
        rows = [
            ("Kinematics", lambda: kb.Kinematics(ue, model.G, model.w, model.mixed),
             lambda: kernels.Kinematics(ue, model.G, model.w, model.mixed)),
            ("material law", lambda: law_b(kin.C), lambda: law(kin.C)),
            ("kernels.residual", lambda: kb.residual(kin_b, S), lambda: kernels.residual(kin, S)),
            ("kernels.tangent", lambda: kb.tangent(kin_b, S, Dm), lambda: kernels.tangent(kin, S, Dm)),
        ]
        tot_b = tot_n = 0.0
        E, Q = model.w.shape
        size = f"{E} x {Q}"
        for name, fb, fn in rows:
            tb, tn = paired_ms(fb, fn, a.repeat)
            tot_b, tot_n = tot_b + tb, tot_n + tn
            print(f"{label:<11}{size:>18}  {name:<18}{tb:>8.2f}ms{tn:>7.2f}ms{tb / tn:>9.1f}x")
        print(f"{label:<11}{size:>18}  {'sum':<18}{tot_b:>8.2f}ms{tot_n:>7.2f}ms{tot_b / tot_n:>9.1f}x")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--no-scene", action="store_true")
    ap.add_argument("--solve", action="store_true")
    ap.add_argument("--baseline", default=None, help="git revision to compare with")
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
