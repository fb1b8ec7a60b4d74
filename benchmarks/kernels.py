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
no gmsh); --thickness T (the 2D scene's skin thickness, default 1); --compiled: the compiled
loops (fe._kernels_nb) with their largest difference from the oracle tests/reference_kernels.py
on the first --oracle-elements (default 300) elements, plus the one-off JIT compile time
(fresh NUMBA_CACHE_DIR) and the cached-load time of the compiled loops, each measured in a
new process; --baseline REV: fe/kernels.py
and materials/hyperfoam.py of git revision REV against this tree's, on the same models and states, calls alternating so that both see
the same load on a shared machine (2D: the structured mesh, or the scene's with --scene);
--solve: also the median of 3 fe.solve calls of the 2D scene.
"""

from __future__ import annotations

import argparse
import importlib.util
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


def _model2(no_scene, thickness, hf):
    from skfem import MeshTri

    from tactileskin.fe import Dirichlet, Model, material_law
    if no_scene:
        mesh = MeshTri.init_tensor(np.linspace(0, 1, 32), np.linspace(0, 1, 32))
        return Model(mesh, {"l": mesh.facets_satisfying(lambda x: x[0] < 1e-9)}, material_law(hf),
                     [Dirichlet("l", (0,))])
    from tactileskin.fe import model_for_scene
    from tactileskin.scene import Scene
    return model_for_scene(Scene(thickness=thickness, material="silicone", indenter="flat"))[0]


def _model3(hf):
    from skfem import MeshTet

    from tactileskin.fe import Dirichlet, Model, material_law
    mesh3 = MeshTet.init_tensor(*(np.linspace(0, 1, 13),) * 3)
    return Model(mesh3, {"l": mesh3.facets_satisfying(lambda x: x[0] < 1e-9)}, material_law(hf),
                 [Dirichlet("l", (0,))])


def compiled_vs_reference(a):
    """The compiled kernels' CPU times and their difference from the oracle
    (tests/reference_kernels.py) on the first --oracle-elements elements of each model. The
    oracle is a literal einsum transcription, not a speed baseline: it is not timed (the
    compiled loops' speed-up over the vectorised numpy kernels they replaced is in
    benchmarks/results/kernels.md, measured when both existed)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    import reference_kernels as ref

    from tactileskin.fe import kernels, material_law
    from tactileskin.materials import get_material

    hf = get_material("silicone").hyperfoam
    law = material_law(hf)
    n = a.oracle_elements
    print(f"CPU ms, medians of {a.repeat} calls of the compiled kernels; max rel diff against "
          f"the oracle on the first {n} elements")
    print(f"{'mesh':<11}{'elements x points':>18}  {'call':<18}{'compiled':>10}{'max rel diff':>14}")
    for label, model in (("2D P2 tri", _model2(a.no_scene, a.thickness, hf)), ("3D P2 tet", _model3(hf))):
        m = model.m
        ue = trial_state(model).reshape(-1, m)[model.sdofs]
        kin = kernels.Kinematics(ue, model.G, model.w, model.mixed)
        S3, D, _ = law(kin.C)
        # as Model.tangent passes them: S a strided view, D a contiguous product
        S, Dm = S3[..., :m, :m], 1.0 * D[..., :m, :m, :m, :m]
        kin_r = ref.kinematics(ue[:n], model.G[:n], model.w[:n], model.mixed)
        f_r, K_r = ref.residual_tangent(ue[:n], model.G[:n], model.w[:n], model.mixed, S[:n], Dm[:n])

        def rel(x, r):
            return float(np.abs(x[:n] - r).max() / np.abs(r).max())

        rows = [("Kinematics", lambda: kernels.Kinematics(ue, model.G, model.w, model.mixed),
                 lambda k: max(rel(getattr(k, name), v) for name, v in kin_r.items())),
                ("kernels.residual", lambda: kernels.residual(kin, S), lambda r: rel(r, f_r)),
                ("kernels.tangent", lambda: kernels.tangent(kin, S, Dm), lambda r: rel(r, K_r))]
        E, Q = model.w.shape
        size = f"{E} x {Q}"
        total = 0.0
        for name, fn, diff in rows:
            t = median_ms(fn, a.repeat)
            total += t
            d = diff(fn())
            print(f"{label:<11}{size:>18}  {name:<18}{t:>8.2f}ms{d:>14.1e}")
        print(f"{label:<11}{size:>18}  {'sum':<18}{total:>8.2f}ms")
    with tempfile.TemporaryDirectory() as cache:
        for what in ("first call, empty cache (JIT compile)", "first call, cache written above (load)"):
            out = subprocess.run([sys.executable, __file__, "--jit-probe"], check=True, capture_output=True,
                                 text=True, env={**os.environ, "NUMBA_CACHE_DIR": cache}).stdout
            t = json.loads(out)
            print(f"{what}: " + ", ".join(f"{k} {v:.2f} s" for k, v in t.items()))


def jit_probe():
    """Wall time of the first Kinematics/residual/tangent call per element kind in this
    process (numba import excluded), printed as JSON."""
    import numba  # noqa: F401  (imported before the clock starts)

    from tactileskin.fe import kernels
    out = {}
    for m, A, Q in ((2, 6, 3), (3, 10, 4)):
        rng = np.random.default_rng(0)
        G = rng.standard_normal((4, Q, A, m))
        w, ue = np.ones((4, Q)), 0.01 * rng.standard_normal((4, A, m))
        S, D = np.zeros((4, Q, m, m)), np.zeros((4, Q) + (m,) * 4)
        t0 = time.perf_counter()
        kin = kernels.Kinematics(ue, G, w, True)
        t1 = time.perf_counter()
        kernels.residual(kin, S)
        t2 = time.perf_counter()
        kernels.tangent(kin, S, D)
        t3 = time.perf_counter()
        out.update({f"{m}D kinematics": t1 - t0, f"{m}D residual": t2 - t1, f"{m}D tangent": t3 - t2})
    print(json.dumps(out))


def measure(repeat, no_scene, thickness=1):
    from tactileskin.materials import get_material

    hf = get_material("silicone").hyperfoam
    return (rows_for("2D P2 tri", _model2(no_scene, thickness, hf), hf, repeat)
            + rows_for("3D P2 tet", _model3(hf), hf, repeat))


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
    from tactileskin.fe import kernels, material_law
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
    model2, model3 = _model2(not a.scene, a.thickness, hf), _model3(hf)
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
    ap.add_argument("--thickness", type=float, default=1, help="the 2D scene's skin thickness (mm)")
    ap.add_argument("--compiled", action="store_true", help="compiled kernels against the test oracle")
    ap.add_argument("--oracle-elements", type=int, default=300, help="elements compared with the oracle")
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--jit-probe", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.jit_probe:
        jit_probe()
        return
    if a.compiled:
        compiled_vs_reference(a)
    elif a.baseline:
        compare(a)
    else:
        rows = measure(a.repeat, a.no_scene, a.thickness)
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
