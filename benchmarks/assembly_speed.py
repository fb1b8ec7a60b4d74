"""Per-iteration sparse work of a 3D Newton iteration, old against new on the same data
(run: python benchmarks/assembly_speed.py).

Builds the model of the t = 5 mm single Braille dot at the `default` 3D preset (issue 13's
T3 case; --thickness for another), its element tangents at a small random displacement, and
times each isolated function, median of --repeat calls, CPU (process time, all threads) and
wall ms, calls of the old and new versions alternating so that both see the same load:
  Pattern()        the set-up of the CSR pattern: np.unique of the dof-level (row, col) keys
                   (old) against the node graph (new);
  Pattern.data     the CSR scatter of the element matrices: np.bincount (old) against the
                   row-parallel scatter of fe._sparse_nb (new), 1 and 2 numba threads;
  kernels.tangent  the element matrices into a new array per call (old) against into the
                   model's reused buffer (new; the new array's page faults), 2 threads;
  GMRES's product  the free tangent times a vector: scipy's csr_matvec (old, what GMRES
                   uses) against a numba loop over row ranges (candidate, not adopted; uint32
                   indices: with int32 numba checks for negative indices, 1.7x slower),
                   1 and 2 threads.
with the largest difference between the two (0: the same bits). Prints the load average.

    .venv/bin/python benchmarks/assembly_speed.py [--thickness 5] [--repeat 9]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np


def timed(fns: dict, repeat: int) -> dict:
    """{name: (CPU ms, wall ms)} medians, the functions called in turn (after one warm-up)."""
    for f in fns.values():
        f()
    cpu = {k: [] for k in fns}
    wall = {k: [] for k in fns}
    for _ in range(repeat):
        for k, f in fns.items():
            c0, w0 = time.process_time(), time.perf_counter()
            f()
            cpu[k].append(time.process_time() - c0)
            wall[k].append(time.perf_counter() - w0)
    return {k: (1e3 * float(np.median(cpu[k])), 1e3 * float(np.median(wall[k]))) for k in fns}


def dot_state(doc: str, argv=None):
    """(args, model, evaluation) of the benchmarks on the `default` single dot: --thickness
    (mm, default 5) and --repeat parsed, the model made, and evaluated (no tangent) at 0.1 x
    kernels.trial_state, a state with every element deformed."""
    from kernels import trial_state  # benchmarks/kernels.py

    from tactileskin.fe import model_for_scene
    from tactileskin.scene import Scene

    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--thickness", type=float, default=5.0)
    ap.add_argument("--repeat", type=int, default=9)
    a = ap.parse_args(argv)
    sc = Scene(dim=3, indenter="braille", thickness=a.thickness, material="silicone", braille_text="")
    model, _ = model_for_scene(sc)
    return a, model, model.evaluate(0.1 * trial_state(model), 0.0, 1.0, tangent=False)


def row(name, old, new, diff=""):
    print(f"{name:34s} {old[0]:9.2f} {old[1]:9.2f} {new[0]:9.2f} {new[1]:9.2f} {old[1] / new[1]:7.2f}x  {diff}")


def _csr_matvec(indptr, indices, data, x, y, bounds):
    """y = A x row range by row range on numba's threads (compiled on first use)."""
    global _csr_matvec
    import numba as nb

    @nb.njit(cache=True, parallel=True, error_model="numpy")
    def kernel(indptr, indices, data, x, y, bounds):
        for c in nb.prange(bounds.shape[0] - 1):
            for r in range(bounds[c], bounds[c + 1]):
                s = 0.0
                for j in range(indptr[r], indptr[r + 1]):
                    s += data[j] * x[indices[j]]
                y[r] = s
        return y

    _csr_matvec = kernel
    return kernel(indptr, indices, data, x, y, bounds)


def main(argv=None) -> int:
    from tactileskin.fe import kernels
    from tactileskin.fe.assembly import Pattern
    from tactileskin.threads import numba_threads

    a, model, ev = dot_state(__doc__, argv)
    p, m = model.pattern, model.m
    with numba_threads(2):
        D = model._law(ev.kin.C, True)[1]
        Ke = kernels.tangent(ev.kin, ev.S[..., :m, :m], np.ascontiguousarray(D[..., :m, :m, :m, :m]))
    E = len(Ke)
    print(f"t = {a.thickness:g} mm default dot: {model.ndof:,} dofs ({p.nfree:,} free), {E:,} P2 tets, "
          f"{Ke.size:,} element entries into {len(p.indices):,} CSR positions; load average "
          f"{os.getloadavg()[0]:.2f}; medians of {a.repeat}, ms")
    print(f"{'function':34s} {'old CPU':>9s} {'old wall':>9s} {'new CPU':>9s} {'new wall':>9s} {'wall':>8s}")

    n, edofs, nd, nnz = model.ndof, model.edofs, model.edofs.shape[1], len(p.indices)

    def old_pattern():  # the former Pattern.__init__'s keys and inverse (its argsort)
        keys = (np.repeat(edofs, nd, axis=1).astype(np.int64) * n + np.tile(edofs, (1, nd))).ravel()
        return np.unique(keys, return_inverse=True)

    keys, inv = old_pattern()
    assert np.array_equal(keys, p.keys)
    t = timed({"old": old_pattern, "new": lambda: Pattern(n, edofs, model.free, m)}, max(3, a.repeat // 3))
    row("Pattern() set-up", t["old"], t["new"], f"(medians of {max(3, a.repeat // 3)})")
    inv = inv.ravel()
    old_data = lambda: np.bincount(inv, weights=Ke.ravel(), minlength=nnz)  # noqa: E731
    ref = old_data()
    for th in (1, 2):
        with numba_threads(th):
            t = timed({"old": old_data, "new": lambda: p.data(Ke)}, a.repeat)
            diff = np.abs(p.data(Ke) - ref).max()
        row(f"Pattern.data ({th} thread{'s' if th > 1 else ''})", t["old"], t["new"], f"max |diff| {diff:.1e}")
    with numba_threads(2):
        Sm, Dm = ev.S[..., :m, :m], np.ascontiguousarray(D[..., :m, :m, :m, :m])
        buf = np.empty_like(Ke)
        t = timed({"old": lambda: kernels.tangent(ev.kin, Sm, Dm),
                   "new": lambda: kernels.tangent(ev.kin, Sm, Dm, out=buf)}, a.repeat)
        diff = np.abs(kernels.tangent(ev.kin, Sm, Dm, out=buf) - Ke).max()
    row("kernels.tangent (2 threads)", t["old"], t["new"], f"max |diff| {diff:.1e}")
    Af = p.free_matrix(p.data(Ke))
    x = np.random.default_rng(1).standard_normal(Af.shape[0])
    ip, ix = Af.indptr.view(np.uint32), Af.indices.view(np.uint32)
    for th in (1, 2):
        bounds = np.searchsorted(Af.indptr, np.arange(th + 1) * Af.nnz / th).astype(np.int64)
        bounds[0], bounds[-1] = 0, Af.shape[0]
        with numba_threads(th):
            t = timed({"old": lambda: Af.dot(x), "new": lambda: _csr_matvec(ip, ix, Af.data, x, np.empty_like(x),
                                                                            bounds)}, 5 * a.repeat)
            diff = np.abs(_csr_matvec(ip, ix, Af.data, x, np.empty_like(x), bounds) - Af.dot(x)).max()
        row(f"free K @ x, numba ({th} thread{'s' if th > 1 else ''})", t["old"], t["new"], f"max |diff| {diff:.1e}")
    print(f"load average at the end {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
