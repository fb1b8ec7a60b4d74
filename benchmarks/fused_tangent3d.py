"""The 3D tangent into its CSR data: element matrices then the node-row scatter (what
Model.tangent does) against a fused loop that scatters each element's matrix while it is in
cache, no (E, 30, 30) array (run: python benchmarks/fused_tangent3d.py).

Builds the model of the t = 5 mm single Braille dot at the `default` 3D preset (issue 13's
T3 case; --thickness for another) at a small random displacement and times, median of
--repeat calls, CPU (process time) and wall ms, on one thread (no thread scheduling in the
numbers: what is compared is the memory traffic), the three alternating:
  separate  kernels.tangent into a reused buffer, then fe._sparse_nb.scatter_3_10;
  fused     blocks of 16 elements through fe._kernels_nb._tangent, each block's matrices
            added into the CSR data at once, elements in ascending order (the same bits);
  kernel    kernels.tangent alone (the share of the scatter is separate - kernel).
with the largest difference between separate and fused (0: the same bits). A candidate,
not adopted: benchmarks/results/braille3d_default.md, twenty-second session.

    .venv/bin/python benchmarks/fused_tangent3d.py [--thickness 5] [--repeat 9]
"""

from __future__ import annotations

import os

import numba as nb
import numpy as np

from tactileskin.fe._kernels_nb import _tangent

_BLOCK = 16


@nb.njit(cache=True, error_model="numpy")
def fused_3_10(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, sd, off, indptr, out):
    """The CSR data of the P2-tet tangent, each block's element matrices added while in cache."""
    E = w.shape[0]
    out[:] = 0.0
    buf = np.empty((_BLOCK, 30, 30))
    for e0 in range(0, E, _BLOCK):
        e1 = min(e0 + _BLOCK, E)
        _tangent(G[e0:e1], w[e0:e1], F[e0:e1], Fbar[e0:e1], Finv[e0:e1], alpha[e0:e1], J[e0:e1],
                 theta[e0:e1] if mixed else theta, S[e0:e1], D[e0:e1], mixed, buf[:e1 - e0], 3, 10)
        for e in range(e0, e1):
            Ke = buf[e - e0]
            for a in range(10):
                s = sd[e, a]
                for i in range(3):
                    r = indptr[s * 3 + i]
                    for b in range(10):
                        base = r + off[e, a, b] * 3
                        for k in range(3):
                            out[base + k] += Ke[a * 3 + i, b * 3 + k]
    return out


def main(argv=None) -> int:
    from assembly_speed import dot_state, timed  # benchmarks/assembly_speed.py

    from tactileskin.fe import _sparse_nb, kernels
    from tactileskin.threads import numba_threads

    a, model, ev = dot_state(__doc__, argv)
    p, m = model.pattern, model.m
    kin = ev.kin
    S = np.ascontiguousarray(ev.S[..., :m, :m])
    with numba_threads(1):
        D = np.ascontiguousarray(model._law(kin.C, True)[1])
    sd = np.ascontiguousarray(p.edofs[:, ::m] // m)
    buf = np.empty((len(sd), 30, 30))
    theta = kin.theta if kin.mixed else np.empty(0)

    def separate():
        kernels.tangent(kin, S, D, out=buf)
        return _sparse_nb.scatter_3_10(buf, p._nptr, p._ne, p._na, p._off, p.indptr, np.empty(len(p.indices)))

    def fused():
        return fused_3_10(kin.G, kin.w, kin.F, kin.Fbar, kin.Finv, kin.alpha, kin.J, theta, S, D, kin.mixed,
                          sd, p._off, p.indptr, np.empty(len(p.indices)))

    with numba_threads(1):
        diff = np.abs(separate() - fused()).max()
        t = timed({"separate": separate, "fused": fused, "kernel": lambda: kernels.tangent(kin, S, D, out=buf)},
                  a.repeat)
    print(f"t = {a.thickness:g} mm default dot: {model.ndof:,} dofs, {len(sd):,} P2 tets; one thread; load average "
          f"{os.getloadavg()[0]:.2f}; medians of {a.repeat}, ms")
    for k, (c, w) in t.items():
        print(f"{k:10s} CPU {c:8.2f}  wall {w:8.2f}")
    print(f"max |separate - fused| {diff:.1e}; load average at the end {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
