"""Hyperfoam law: numpy 3x3 path vs the compiled loops (run: python benchmarks/hyperfoam_law.py).

Prints median CPU times (ms; process time, calls of the two implementations alternating so
that both see the same load on a shared machine) of
  3x3       hyperfoam.pk2_tangent on the embedded C (LAPACK eigh, numpy; the compiled
            loops' test oracle); S only: hyperfoam.pk2,
  compiled  hyperfoam.pk2_tangent_plane (the numba point loop of materials._hyperfoam_nb),
as fe.material_law calls them (out_of_plane=True: S (..., 3, 3), D (..., 3, 3, 3, 3)),
with the tangent (S+D) and without (S only; the compiled tangent=False), on the point count
of the 2D t = 5 mm fingertip model: 3823 P2 triangles x 3 points = 11,469 plane states,
C = F^T F with F = I + 0.05 N(0, 1) per point (in-plane block, C33 = 1), both presets.
Also the maximum difference compiled vs 3x3 (relative to max |S|, max |D|), and the JIT
cost: a fresh compile and a cached load, each in a new process with its own NUMBA_CACHE_DIR.

Second table, 3D: the compiled 3x3 loop hyperfoam.pk2_tangent_solid (Jacobi rotations; the
3D solver's law) against the numpy path on the point count of the default 3D dot at t = 3 mm
(11,900 P2 tets x 4 points = 47,600 states, F = I + 0.05 N(0, 1), 3x3), on numba's default
threads (all CPUs: CPU time counts every thread).

Options: --repeat N (default 25); --points N (default 11469); --points3d N (default 47600).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

_JIT_PROBE = r"""
import time
import tactileskin.materials.hyperfoam  # noqa: F401 (not part of the JIT cost)
t0 = time.perf_counter()
import numba  # noqa: F401
t1 = time.perf_counter()
from tactileskin.materials import _hyperfoam_nb  # explicit signature: compiled or loaded here
t2 = time.perf_counter()
import numpy as np
from tactileskin.materials import get_material
from tactileskin.materials.hyperfoam import pk2_tangent_plane
pk2_tangent_plane(get_material("silicone").hyperfoam, np.eye(2)[None], out_of_plane=True)
t3 = time.perf_counter()
print(f"{t1 - t0:.3f} {t2 - t1:.3f} {t3 - t2:.3f}")
"""


def jit_costs():
    """(numba import, module import = compile or cache load, first call) in s, fresh and cached."""
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for label in ("fresh compile", "cached load"):
            r = subprocess.run([sys.executable, "-c", _JIT_PROBE], env=env, capture_output=True, text=True,
                               check=True)
            out[label] = [float(x) for x in r.stdout.split()]
    return out


def states(n, seed=0):
    rng = np.random.default_rng(seed)
    F = np.eye(2) + 0.05 * rng.standard_normal((n, 2, 2))
    C = np.zeros((n, 3, 3))
    C[:, :2, :2] = np.swapaxes(F, -1, -2) @ F
    C[:, 2, 2] = 1.0
    return C


def paired_ms(fns, repeat):
    """Median CPU ms of each of fns, called in turn repeat times."""
    for fn in fns:
        fn()
    t = [[] for _ in fns]
    for _ in range(repeat):
        for fn, ti in zip(fns, t):
            t0 = time.process_time()
            fn()
            ti.append(time.process_time() - t0)
    return [1e3 * float(np.median(ti)) for ti in t]


def table(title, C, compiled, repeat):
    """Print the S+D and S-only rows of the numpy 3x3 path on C against `compiled(hf, tangent)`."""
    from tactileskin.materials import get_material
    from tactileskin.materials.hyperfoam import pk2, pk2_tangent

    print(f"{title}, median CPU ms of {repeat} alternating calls\n")
    print(f"{'material':<13}{'output':<8}{'3x3':>9}{'compiled':>10}{'speed-up':>10}"
          f"{'max dS/max|S|':>15}{'max dD/max|D|':>15}")
    for name in ("polyurethane", "silicone"):
        hf = get_material(name).hyperfoam
        S, D, ok = compiled(hf)
        S0, D0, ok0 = pk2_tangent(hf, C)
        assert np.array_equal(ok, ok0) and ok.all()
        dS = np.abs(S - S0).max() / np.abs(S0).max()
        dD = np.abs(D - D0).max() / np.abs(D0).max()
        t_3, t_c, t_3_s, t_c_s = paired_ms([
            lambda: pk2_tangent(hf, C),
            lambda: compiled(hf),
            lambda: pk2(hf, C),
            lambda: compiled(hf, False),
        ], repeat)
        print(f"{name:<13}{'S+D':<8}{t_3:>8.2f} {t_c:>9.2f} {t_3 / t_c:>9.1f}x{dS:>15.1e}{dD:>15.1e}")
        print(f"{name:<13}{'S only':<8}{t_3_s:>8.2f} {t_c_s:>9.2f} {t_3_s / t_c_s:>9.1f}x")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=25)
    ap.add_argument("--points", type=int, default=3823 * 3)
    ap.add_argument("--points3d", type=int, default=11900 * 4)
    args = ap.parse_args(argv)

    from tactileskin.materials.hyperfoam import pk2_tangent_plane, pk2_tangent_solid

    C = states(args.points)
    C2 = C[..., :2, :2]               # strided view, as fe.material_law passes it
    plane = lambda hf, tangent=True: pk2_tangent_plane(hf, C2, out_of_plane=True, tangent=tangent)  # noqa: E731
    table(f"{args.points} plane-strain points", C, plane, args.repeat)
    rng = np.random.default_rng(1)
    F3 = np.eye(3) + 0.05 * rng.standard_normal((args.points3d, 3, 3))
    C3 = np.swapaxes(F3, -1, -2) @ F3
    solid = lambda hf, tangent=True: pk2_tangent_solid(hf, C3, tangent=tangent)  # noqa: E731
    table(f"\n{args.points3d} 3D points", C3, solid, args.repeat)
    print("\nJIT (s; new process each): numba import, _hyperfoam_nb import (compile / cache load), first call")
    for label, (a, b, c) in jit_costs().items():
        print(f"  {label:<14} {a:6.3f} {b:6.3f} {c:6.3f}")


if __name__ == "__main__":
    main()
