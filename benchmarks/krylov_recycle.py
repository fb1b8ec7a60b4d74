"""Krylov subspace recycling across the Newton systems of the t = 5 mm `default` 3D dot
(issue 13, target T3): does carrying directions from one GMRES solve to the next cut the
iterations that the stale single-precision PARDISO factorisation leaves?

The whole solve runs once with fe.linsolve.SymmetricSolver hooked: every factor(A) (the
free-block data; the CSR pattern is fixed), solve(b, rtol) and begin_increment is recorded
(89 matrices of 2.5M nonzeros: ~1.8 GB in memory). The sequence is then replayed through a
fresh SymmetricSolver (same refactorisation rule, same per-system tolerance) whose GMRES is
replaced by a deflated/augmented right-preconditioned GMRES (GCRO form, Parks et al. 2006):
with a kept set U (k vectors), C = orth(A U) (k products with A, no preconditioner solve),
x0 = U C^T b, then GMRES on (I - C C^T) A M^-1; x = x0 + (Z - U B) y. Strategies for U:

- plain:  none (fe.linsolve.gmres; the library's behaviour)
- sol:k   the last k solutions (Newton updates)
- both:k  the last k solutions and Krylov corrections (x - x0)
- err:k   the last k preconditioner errors x - M^-1 b (one extra triangular solve each)
- kry:k   the last k preconditioned Krylov vectors Z (the whole previous search spaces;
          GCRO-DR's harmonic Ritz vectors are a k-dimensional compression of these)

Iteration and factorisation counts are deterministic; times are medians per operation on a
shared machine (load average printed). The estimated PARDISO-phase time prices each
strategy's counts with the plain replay's medians (factorisation, iteration) plus the
measured median cost of one product column A u; "measured" is the replay's own factor +
solve wall time.

    .venv/bin/python benchmarks/krylov_recycle.py [--strategies plain sol:10 both:10 kry:20 kry:40] [--limit N]
"""

from __future__ import annotations

import argparse
import collections
import os
import time

import numpy as np
import scipy.sparse as sp

from tactileskin.fe import linsolve as L

OPS = collections.defaultdict(list)   # operation -> wall times (s)


def _t(key, f, *a):
    t = time.perf_counter()
    r = f(*a)
    OPS[key].append(time.perf_counter() - t)
    return r


def agmres(A, psolve, b, rtol, maxiter, U=None):
    """Right-preconditioned GMRES (x0 = 0 in the Krylov part, no restart) augmented with the
    rows of U: minimises |b - A x| over span(U) + K((I - C C^T) A M^-1, r0), C = orth(A U).
    Returns (x, iterations, converged, Krylov vectors Z, Krylov correction dx)."""
    bn = float(np.linalg.norm(b))
    if bn == 0.0:
        return np.zeros_like(b), 0, True, None, None
    C = np.zeros((0, b.size))
    Uo, x0, r0 = C, np.zeros_like(b), b
    if U is not None and len(U):
        t = time.perf_counter()
        AU = A @ np.ascontiguousarray(U.T)      # n x k: one pass over A
        OPS["product column"].append((time.perf_counter() - t) / U.shape[0])
        G = AU.T @ AU                           # orthonormalise through the Gram matrix (k small)
        ev, W = np.linalg.eigh(G)
        keep = ev > 1e-12 * ev[-1]
        W = W[:, keep] / np.sqrt(ev[keep])
        C = np.ascontiguousarray((AU @ W).T)
        Uo = np.ascontiguousarray(W.T @ U)      # A Uo^T = C^T
        cb = C @ b
        x0, r0 = cb @ Uo, b - cb @ C
        OPS["augmentation set-up"].append(time.perf_counter() - t)
    rn0 = float(np.linalg.norm(r0))
    if rn0 <= rtol * bn:
        return x0, 0, True, np.zeros((0, b.size)), np.zeros_like(b)
    V, Z = np.empty((maxiter + 1, b.size)), np.empty((maxiter, b.size))
    V[0] = r0 / rn0
    H, Bc = np.zeros((maxiter + 1, maxiter)), np.zeros((len(C), maxiter))
    cs, sn, g = np.zeros(maxiter), np.zeros(maxiter), np.zeros(maxiter + 1)
    g[0] = rn0
    k = 0
    for k in range(maxiter):
        Z[k] = _t("triangular solve pair", psolve, V[k])
        w = _t("product", A.dot, Z[k])
        t = time.perf_counter()
        Vk = V[:k + 1]
        bc = C @ w
        w -= bc @ C
        h = Vk @ w
        w -= h @ Vk
        bc2 = C @ w                              # twice (classical Gram-Schmidt, as the library)
        w -= bc2 @ C
        Bc[:, k] = bc + bc2
        h2 = Vk @ w
        w -= h2 @ Vk
        h += h2
        OPS["orthogonalisation"].append(time.perf_counter() - t)
        hn = float(np.linalg.norm(w))
        if not L.givens_column(h, hn, k, H, cs, sn, g):
            break
        if abs(g[k + 1]) <= rtol * bn or hn == 0.0:
            k += 1
            break
        V[k + 1] = w / hn
    else:
        k = maxiter
    if k == 0:
        return x0, 0, False, Z[:0], np.zeros_like(b)
    y = np.linalg.solve(np.triu(H[:k, :k]), g[:k])
    dx = y @ Z[:k] - (Bc[:, :k] @ y) @ Uo
    return x0 + dx, k, abs(g[k]) <= rtol * bn, Z[:k], dx


class Recycling(L.SymmetricSolver):
    """SymmetricSolver whose GMRES carries a recycled set between solves."""

    def setup(self, kind: str, kmax: int):
        self.kind, self.kmax, self.U, self.columns, self.extra_solves = kind, kmax, [], 0, 0
        return self

    def _gmres(self, A, b, rtol, limit):
        U = np.array(self.U) if self.kind != "plain" and self.U else None
        self.columns += 0 if U is None else len(U)
        x, k, ok, Z, dx = agmres(A, self._direct, b, rtol, limit, U)
        self.krylov_iterations += k
        if ok and np.all(np.isfinite(x)):
            ok = np.linalg.norm(A @ x - b) <= 10.0 * rtol * np.linalg.norm(b)
        if ok and self.kind != "plain":
            if self.kind == "sol":
                new = [x]
            elif self.kind == "both":
                new = [x, dx]
            elif self.kind == "err":
                new = [x - self._direct(b)]
                self.extra_solves += 1
            else:
                new = list(Z)
            self.U += [v / np.linalg.norm(v) for v in new if np.linalg.norm(v) > 0]
            self.U = self.U[-self.kmax:]
        return x, k, bool(ok and np.all(np.isfinite(x)))


def record():
    """Solve the t = 5 dot with SymmetricSolver hooked; returns (pattern, events, stats)."""
    from tactileskin.fe import solve
    from tactileskin.scene import Scene

    ev, pat = [], {}
    f0, s0, b0 = L.SymmetricSolver.factor, L.SymmetricSolver.solve, L.SymmetricSolver.begin_increment

    def factor(self, A):
        pat.setdefault("p", (A.indptr.copy(), A.indices.copy(), A.shape))
        ev.append(("factor", A.data.copy()))
        return f0(self, A)

    def solve_(self, b, rtol=None):
        ev.append(("solve", b.copy(), rtol))
        return s0(self, b, rtol)

    def begin(self):
        ev.append(("begin",))
        return b0(self)

    L.SymmetricSolver.factor, L.SymmetricSolver.solve, L.SymmetricSolver.begin_increment = factor, solve_, begin
    try:
        sc = Scene(dim=3, indenter="braille", thickness=5, material="silicone", braille_text="")
        w = time.perf_counter()
        r = solve(sc)
        w = time.perf_counter() - w
    finally:
        L.SymmetricSolver.factor, L.SymmetricSolver.solve, L.SymmetricSolver.begin_increment = f0, s0, b0
    st = r.stats
    return pat["p"], ev, dict(wall=w, newton=st["newton_iterations"], increments=st["increments"],
                              free=st["free_dofs"], peak=float(r.peak), **st["linear_solver"])


def replay(pattern, events, kind: str, kmax: int, limit: int | None):
    indptr, indices, shape = pattern
    mat = lambda d: sp.csr_matrix((d, indices, indptr), shape=shape)  # noqa: E731
    OPS.clear()
    s = Recycling(mat(events[0][1]), "pardiso", "reuse", threads=L.default_threads(True),
                  precision="single").setup(kind, kmax)
    worst, solves = 0.0, 0
    for e in events:
        if e[0] == "begin":
            s.begin_increment()
        elif e[0] == "factor":
            s.factor(mat(e[1]))
        else:
            x = s.solve(e[1], e[2])
            rt = L.KRYLOV_RTOL if e[2] is None else min(max(e[2], L.KRYLOV_RTOL), 1e-2)
            worst = max(worst, np.linalg.norm(s._A @ x - e[1]) / np.linalg.norm(e[1]) / rt)
            solves += 1
            if limit and solves >= limit:
                break
    s.close()
    med = {k: float(np.median(v)) for k, v in OPS.items()}
    return dict(kind=kind, k=kmax, its=s.krylov_iterations, fact=s.factorizations, cols=s.columns,
                extra=s.extra_solves, factor_s=s.timing["factor"], solve_s=s.timing["solve"], med=med,
                worst=worst, n_fact_calls=s.factorizations)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--strategies", nargs="+", default=["plain", "sol:10", "both:10", "err:10", "kry:20", "kry:40"])
    ap.add_argument("--limit", type=int, default=None, help="replay only the first N solves")
    a = ap.parse_args(argv)
    load0 = os.getloadavg()
    pattern, events, st = record()
    print(f"whole solve (hooked): wall {st['wall']:.1f} s, {st['increments']} increments, {st['newton']} Newton, "
          f"{st['free']} free dofs, {st['factorizations']} factorisations, {st['krylov_iterations']} GMRES its, "
          f"peak {st['peak']:.10g} MPa", flush=True)
    rows = []
    for spec in a.strategies:
        kind, _, k = spec.partition(":")
        rows.append(replay(pattern, events, kind, int(k or 0), a.limit))
        r = rows[-1]
        print(f"  {spec}: {r['its']} its, {r['fact']} factorisations, {r['cols']} product columns, "
              f"worst residual/tolerance {r['worst']:.3f}, factor {r['factor_s']:.1f} s, solve {r['solve_s']:.1f} s",
              flush=True)
    base = rows[0]["med"]
    t_fact = rows[0]["factor_s"] / max(rows[0]["fact"], 1)
    t_it = sum(base.get(k, 0.0) for k in ("triangular solve pair", "product", "orthogonalisation"))
    print(f"\nload average {load0[0]:.2f} -> {os.getloadavg()[0]:.2f}; medians (plain replay): factorisation "
          f"{t_fact * 1e3:.0f} ms, iteration {t_it * 1e3:.1f} ms (triangular solves "
          f"{base.get('triangular solve pair', 0) * 1e3:.1f}, product {base.get('product', 0) * 1e3:.2f}, "
          f"orthogonalisation {base.get('orthogonalisation', 0) * 1e3:.2f})\n")
    print("| strategy | GMRES its | factorisations | extra products (columns A u; triangular solves) | "
          "median ms per product column / per orthogonalisation | est. PARDISO phase s | measured factor + solve s |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        m = r["med"]
        est = r["fact"] * t_fact + r["its"] * t_it + r["extra"] * base.get("triangular solve pair", 0) \
            + r["cols"] * m.get("product column", 0.0) \
            + r["its"] * max(0.0, m.get("orthogonalisation", 0.0) - base.get("orthogonalisation", 0.0))
        name = r["kind"] + (f":{r['k']}" if r["k"] else "")
        print(f"| {name} | {r['its']} | {r['fact']} | {r['cols']}; {r['extra']} | "
              f"{m.get('product column', 0) * 1e3:.2f} / {m.get('orthogonalisation', 0) * 1e3:.2f} | {est:.1f} | "
              f"{r['factor_s'] + r['solve_s']:.1f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
