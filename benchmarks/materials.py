"""Micro-benchmark of the material laws (run: python benchmarks/materials.py [n_points]).

Prints best-of-5 wall times (and the CPU time of pk2_tangent, steadier on a shared machine) for n points (default 1e5) of random moderate deformations:
pk2 (stress only), pk2_tangent (stress + 3x3x3x3 tangent), and one Prony update.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from tactileskin.materials import get_material, pk2, pk2_tangent


def states(n, plane_strain, seed=0):
    rng = np.random.default_rng(seed)
    F = np.eye(3) + 0.05 * rng.standard_normal((n, 3, 3))
    if plane_strain:
        F[:, 2, :] = 0.0
        F[:, :, 2] = 0.0
        F[:, 2, 2] = 1.0
    return np.einsum("nki,nkj->nij", F, F)


def best_of(fn, repeat=5, clock=time.perf_counter):
    times = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return min(times)


def main(n=100_000):
    print(f"{'material':<14}{'kinematics':<14}{'pk2 (s)':>10}{'pk2_tangent (s)':>17}{'prony update (s)':>18}"
          f"{'us/point':>10}{'cpu us/pt':>11}")
    for name in ("silicone", "polyurethane"):
        mat = get_material(name)
        for plane in (False, True):
            C = states(n, plane)
            S, D, ok = pk2_tangent(mat.hyperfoam, C)
            H = mat.prony.initial_state(S.shape)
            t_s = best_of(lambda: pk2(mat.hyperfoam, C))
            t_d = best_of(lambda: pk2_tangent(mat.hyperfoam, C))
            t_p = best_of(lambda: mat.prony.update(H, S, S, 0.01))
            t_c = best_of(lambda: pk2_tangent(mat.hyperfoam, C), clock=time.process_time)
            print(f"{name:<14}{'plane strain' if plane else '3D':<14}{t_s:>10.3f}{t_d:>17.3f}{t_p:>18.3f}"
                  f"{1e6 * t_d / n:>10.2f}{1e6 * t_c / n:>11.2f}")


if __name__ == "__main__":
    main(int(float(sys.argv[1])) if len(sys.argv) > 1 else 100_000)
