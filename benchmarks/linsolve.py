"""Linear-solver backends on real fingertip tangents: analysis, refactorisation, solve.

Takes the first Newton tangent (free block) of a few scenes at their default mesh, then
times SuperLU (a fresh factorisation, what the solver did before fe.linsolve) against
PARDISO (analysis once, then numerical refactorisations). Prints medians of CPU time
(process time: robust on a shared machine when MKL runs one thread) and of wall time.

    MKL_NUM_THREADS=1 .venv/bin/python benchmarks/linsolve.py [--repeat 5] [--3d]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from tactileskin import fe
from tactileskin.fe import linsolve
from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene


def first_tangent(scene):
    """The free-block tangent of the first Newton iteration of `scene` (CSR)."""
    model, _ = fe.model_for_scene(scene, build_mesh(scene))
    ev = model.evaluate(model.u, 0.05 * scene.duration, 0.05 * scene.duration, None, tangent=True)
    return model.pattern.free_matrix(ev.K)


def timed(fn, repeat):
    cpu, wall = [], []
    for _ in range(repeat):
        c0, w0 = time.process_time(), time.perf_counter()
        fn()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    return float(np.median(cpu)), float(np.median(wall))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--3d", dest="three", action="store_true", help="add a 3D slab (t = 1, flat)")
    a = ap.parse_args()
    scenes = [Scene(thickness=t, material="polyurethane", indenter="curved") for t in (1, 3, 5)]
    if a.three:
        scenes.append(Scene(thickness=1, material="silicone", indenter="flat", dim=3))
    print(f"PARDISO available: {linsolve.pardiso_available()}")
    print("| scene | free dofs | nnz | SuperLU factor+solve ms (cpu / wall) | PARDISO analysis ms "
          "| PARDISO refactor+solve ms (cpu / wall) | speed-up (cpu) | max rel. residual |")
    print("|---|---|---|---|---|---|---|---|")
    rng = np.random.default_rng(0)
    for sc in scenes:
        K = first_tangent(sc)
        b = rng.standard_normal(K.shape[0])
        su = linsolve.SymmetricSolver(K, "superlu")
        c_su, w_su = timed(lambda: su.factor(K).solve(b), a.repeat)
        r_su = np.linalg.norm(K @ su.solve(b) - b) / np.linalg.norm(b)
        if not linsolve.pardiso_available():
            print(f"| {sc.label()} | {K.shape[0]} | {K.nnz} | {1e3*c_su:.1f} / {1e3*w_su:.1f} | - | - | - | {r_su:.1e} |")
            continue
        c0, w0 = time.process_time(), time.perf_counter()
        pa = linsolve.SymmetricSolver(K, "pardiso")
        c_an = time.process_time() - c0
        c_pa, w_pa = timed(lambda: pa.factor(K).solve(b), a.repeat)
        r_pa = np.linalg.norm(K @ pa.solve(b) - b) / np.linalg.norm(b)
        print(f"| {sc.label()} | {K.shape[0]} | {K.nnz} | {1e3*c_su:.1f} / {1e3*w_su:.1f} | {1e3*c_an:.1f} "
              f"| {1e3*c_pa:.1f} / {1e3*w_pa:.1f} | {c_su / c_pa:.1f}x | {max(r_su, r_pa):.1e} |")
        pa.close()


if __name__ == "__main__":
    main()
