"""Sparse symmetric solves of the Newton systems: analyse once, refactorise per iteration.

The free-block sparsity of a Model is fixed for a whole solve (contact blocks lie inside
the element pattern), so the fill-reducing ordering and the symbolic factorisation are
done once per Model and each Newton iteration only refactorises numerically.

Backends:
- "pardiso": MKL PARDISO (real symmetric indefinite, mtype -2: Bunch-Kaufman pivoting)
  called through ctypes on the `mkl` wheel's mkl_rt (x86-64 only). Phases: 11 analysis
  (once), 22 numerical factorisation, 33 solve. Fill-reducing ordering (default_ordering):
  minimum degree for 2D tangents, METIS nested dissection for 3D ones.
- "superlu": scipy's SuperLU, a fresh factorisation each time (any platform).
`backend="auto"` takes PARDISO when mkl_rt loads. Measured (benchmarks/linsolve.py):
numerical refactorisation 3-10x faster than SuperLU on the fingertip tangents, more on 3D.

Methods:
- "direct": every `factor(A)` refactorises; `solve` is one triangular solve pair.
- "reuse": the last factorisation preconditions GMRES on the new matrix (the Newton tangent
  changes little between iterations and increments), and the matrix is refactorised only
  when that stops paying: when a Krylov solve costs more than the average solve since the
  last factorisation (factorisation included, in units of one preconditioned iteration),
  or when GMRES needs as many iterations as a factorisation costs. The cost ratio comes
  from PARDISO's flop counts (deterministic: the same run takes the same path). A system at
  which GMRES failed in the last load increment (counted from `begin_increment`) is
  factorised at once in this one (the 3D dots: t = 5 silicone 41-43 -> 35-36 s wall).
  Measured (benchmarks/results/linsolve3d.md, 3D single dot): linear-solve CPU 1.6x less at
  17.5k free dofs, 1.9x at 57.5k, same Newton iterations. Smoothed-aggregation AMG (pyamg)
  was 6-10x slower than a PARDISO factorisation there and is not used.

Threads: MKL_NUM_THREADS when set (Dask workers and the tests set 1); for the large systems
TACTILESKIN_THREADS before it (sweep workers: their share of the CPUs). Else one, except for
the systems a caller marks large (`threads=`, fe.solver: 3D models solved with method
"reuse"), which get the cores this process may use, at most MAX_THREADS: PARDISO's
factorisation and triangular solves of a 3D tangent scale (t = 3 mm dot, preview, 34k dofs,
2 cores: factor 6.4 -> 3.6 s, solves 10.7 -> 7.0 s; benchmarks/results/threads3d.md), the
2D ones are too small to. Intel OpenMP's threads sleep at once after a parallel region
(KMP_BLOCKTIME=0 unless set): spinning threads took the core the Python thread needed.
"""

from __future__ import annotations

import ctypes
import glob
import logging
import os
import sys
import time
from ctypes.util import find_library

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from tactileskin.threads import available_cpus, forked_from_threads, started_threads, user_setting

log = logging.getLogger(__name__)

BACKENDS = ("auto", "pardiso", "superlu")
METHODS = ("direct", "reuse")
PRECISIONS = ("double", "single")
# PARDISO's fill-reducing orderings (iparm[1]): minimum degree (AMD) and METIS nested dissection
ORDERINGS = {"amd": 0, "metis": 2}

# GMRES with a stale factorisation: stop at this relative residual (what a direct solve of
# the Newton system gives in practice; the Newton iteration counts do not change with it)
KRYLOV_RTOL = 1e-8
# at most this many Krylov vectors (memory: 2 * n each); beyond, refactorise
KRYLOV_MAX = 40
# after n GMRES failures in a row the next min(2^n - 1, this) systems are factorised directly
DIRECT_AFTER_FAILURES_MAX = 15
# a factorisation runs near peak flop rate (BLAS3), a triangular solve is memory bound: time
# ratio = flop ratio / this (measured on 3D Braille tangents: 5.3 at 17.5k free dofs, 5.7 at 57.5k)
FACTOR_EFFICIENCY = 5.5


# PARDISO threads of a large system when MKL_NUM_THREADS is not set
MAX_THREADS = 4


def default_threads(large: bool) -> int:
    """PARDISO threads for a system: for a large one TACTILESKIN_THREADS if set (sweep
    workers get their share of the CPUs there), else MKL_NUM_THREADS if set (a positive
    integer), else 1, or for a large system the CPUs this process may run on (at most
    MAX_THREADS)."""
    user = user_setting(large)
    if user is not None:
        try:
            return max(1, int(user[1]))
        except ValueError:
            log.warning("%s=%r is not a whole number of threads (1 or more); using 1 thread", *user)
            return 1
    if not large:
        return 1
    return max(1, min(available_cpus(), MAX_THREADS))


def default_ordering(dim: int) -> str:
    """PARDISO's ordering for a model of dimension dim. On the 2D fingertip tangents (1.9-10.5k
    free dofs) minimum degree left 6-17 % fewer factor nonzeros than METIS: factorisation +
    solve 7-12 % less CPU, analysis 37-47 % less (benchmarks/pardiso_ordering.py). Nested
    dissection is the choice for 3D meshes' separators."""
    return "amd" if dim == 2 else "metis"


class SingularMatrix(RuntimeError):
    """The numerical factorisation failed (zero pivot or a solver error)."""


# -- MKL PARDISO ------------------------------------------------------------------------------

_MKL = None


def _load_mkl():
    """The mkl_rt library, or None if it is not installed."""
    global _MKL
    if _MKL is not None:
        return _MKL or None
    cands = [os.environ.get("TACTILESKIN_MKL_RT"), find_library("mkl_rt")]
    cands += sorted(glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*")), key=len)
    cands += sorted(glob.glob(os.path.join(sys.prefix, "Library", "bin", "mkl_rt*.dll")), key=len)
    os.environ.setdefault("KMP_BLOCKTIME", "0")  # read when Intel OpenMP starts
    for path in cands:
        if not path:
            continue
        try:
            lib = ctypes.CDLL(path)
            lib.pardiso  # noqa: B018 (the symbol must exist)
        except (OSError, AttributeError):
            continue
        i32p = ctypes.POINTER(ctypes.c_int32)
        lib.pardiso.argtypes = [ctypes.POINTER(ctypes.c_int64), i32p, i32p, i32p, i32p, i32p,
                                ctypes.c_void_p, i32p, i32p, i32p, i32p, i32p, i32p,
                                ctypes.c_void_p, ctypes.c_void_p, i32p]
        lib.pardiso.restype = None
        if "MKL_NUM_THREADS" not in os.environ:
            # one thread unless asked: the 2D systems gain little from more, and on a busy
            # machine (sweep workers, shared CI) OpenMP spinning made the solves 3-10x slower
            try:
                lib.MKL_Set_Num_Threads(ctypes.c_int(1))
            except AttributeError:
                pass
        log.debug("MKL PARDISO from %s", path)
        _MKL = lib
        return lib
    _MKL = False
    return None


def pardiso_available() -> bool:
    return _load_mkl() is not None


_PARDISO_ERRORS = {-1: "input inconsistent", -2: "not enough memory", -3: "reordering problem",
                   -4: "zero pivot, numerical factorization or iterative refinement problem",
                   -5: "unclassified internal error", -6: "reordering failed",
                   -7: "diagonal matrix is singular", -8: "32-bit integer overflow",
                   -9: "not enough memory for OOC", -10: "error opening OOC files",
                   -11: "read/write error with OOC files"}


class _Pardiso:
    """One PARDISO handle for a fixed upper-triangular CSR structure."""

    def __init__(self, n: int, indptr: np.ndarray, indices: np.ndarray, threads: int = 1, single: bool = False,
                 ordering: str = "metis", iparm: dict | None = None):
        """single: factorise and solve in single precision (values, right-hand sides and
        solutions float32 inside; `solve` returns float64). ordering: a key of ORDERINGS.
        iparm: further components {index: value} (0-based, set before the analysis)."""
        self.lib = _load_mkl()
        self.n = n
        self.threads = threads
        self.dtype = np.float32 if single else np.float64
        self.indptr = np.ascontiguousarray(indptr, np.int32)
        self.indices = np.ascontiguousarray(indices, np.int32)
        self.pt = np.zeros(64, np.int64)
        self.iparm = np.zeros(64, np.int32)
        ip = self.iparm
        ip[0] = 1    # non-default iparm
        ip[1] = ORDERINGS[ordering]
        # 0: iterative refinement only after perturbed pivots (2 steps then). A fixed 2 steps
        # doubled the solve time (t5 tangent, 15.8k dofs: 13.4 -> 6.5 ms) for the same residual
        ip[7] = 0
        ip[9] = 8    # pivot perturbation 1e-8 (the symmetric indefinite default)
        ip[20] = 1   # Bunch-Kaufman 1x1/2x2 pivoting
        ip[17] = -1  # report the number of nonzeros in the factors
        ip[18] = -1  # report the factorisation MFlops
        ip[34] = 1   # zero-based indexing
        ip[27] = 1 if single else 0
        # iparm[24] (substitution algorithm) stays 0: on the default t = 5 dot (2 threads) 1 took
        # more wall at low load (22.7 -> 26.4 s; solve phase 13.6 -> 17.6 s CPU), less only on a
        # loaded machine; iparm[23] = 1, iparm[1] = 3 and AMD did not pay on the 3D tangents
        # either (benchmarks/results/pardiso_options3d.md)
        for k, v in (iparm or {}).items():
            ip[k] = v
        self.perturbed = 0
        self._alive = False
        self._call(11, np.zeros(0, self.dtype), np.zeros(0, self.dtype))
        self._alive = True
        self.factor_nnz = int(self.iparm[17])
        self.factor_mflops = float(self.iparm[18])

    def _call(self, phase: int, a: np.ndarray, b: np.ndarray, x: np.ndarray | None = None) -> int:
        i32 = ctypes.c_int32
        err = i32(0)
        p = lambda v: ctypes.byref(i32(v))  # noqa: E731
        i32p = ctypes.POINTER(i32)
        setter = getattr(self.lib, "MKL_Set_Num_Threads_Local", None)
        threads = 1 if forked_from_threads() else self.threads   # (tactileskin.threads)
        if threads > 1:
            started_threads()
        prev = setter(i32(threads)) if setter is not None else None
        try:
            self._pardiso(phase, a, b, x, err, p, i32p)
        finally:
            if setter is not None:
                setter(i32(prev))
        if err.value != 0:
            raise SingularMatrix(f"PARDISO phase {phase}: error {err.value} "
                                 f"({_PARDISO_ERRORS.get(err.value, 'unknown')})")
        return err.value

    def _pardiso(self, phase, a, b, x, err, p, i32p) -> None:
        self.lib.pardiso(self.pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), p(1), p(1), p(-2),
                         p(phase), p(self.n), a.ctypes.data if a.size else None,
                         self.indptr.ctypes.data_as(i32p), self.indices.ctypes.data_as(i32p),
                         None, p(1), self.iparm.ctypes.data_as(i32p), p(0),
                         b.ctypes.data if b.size else None,
                         x.ctypes.data if x is not None and x.size else None, ctypes.byref(err))

    def factor(self, data: np.ndarray) -> None:
        self.data = np.ascontiguousarray(data, self.dtype)
        self._call(22, self.data, np.zeros(0, self.dtype))
        self.perturbed = int(self.iparm[13])

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.ascontiguousarray(b, self.dtype)
        x = np.zeros_like(b)
        self._call(33, self.data, b, x)
        return x.astype(np.float64, copy=False)

    def close(self) -> None:
        if self._alive:
            self._alive = False
            try:
                self._call(-1, np.zeros(0), np.zeros(0))
            except SingularMatrix:  # releasing memory cannot fail usefully
                pass

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: ctypes/numpy may already be gone
            pass


# -- GMRES with a reused factorisation --------------------------------------------------------

def givens_column(h: np.ndarray, hn: float, k: int, H: np.ndarray, cs: np.ndarray, sn: np.ndarray,
                  g: np.ndarray) -> bool:
    """GMRES's k-th Hessenberg column (h, hn) through the previous Givens rotations and a new
    one that zeroes hn, stored in H[:k + 2, k], cs[k], sn[k]; the residual vector g rotated
    (|g[k + 1]| is the new residual norm). False at a breakdown (the column is zero)."""
    col = np.concatenate([h, [hn]])
    for j in range(k):
        col[j], col[j + 1] = cs[j] * col[j] + sn[j] * col[j + 1], -sn[j] * col[j] + cs[j] * col[j + 1]
    r = float(np.hypot(col[k], col[k + 1]))
    if r == 0.0:
        return False
    cs[k], sn[k] = col[k] / r, col[k + 1] / r
    col[k], col[k + 1] = r, 0.0
    H[:k + 2, k] = col
    g[k + 1] = -sn[k] * g[k]
    g[k] = cs[k] * g[k]
    return True


def gmres(matvec, psolve, b: np.ndarray, rtol: float, maxiter: int):
    """Right-preconditioned GMRES (x0 = 0, no restart): minimises |b - A x| over the Krylov
    space of A M^-1, so the residual it reports is the true one (up to rounding).
    Returns (x, iterations, converged)."""
    bn = float(np.linalg.norm(b))
    if bn == 0.0:
        return np.zeros_like(b), 0, True
    V = np.empty((maxiter + 1, b.size))   # pages are touched only as the basis grows
    Z = np.empty((maxiter, b.size))
    V[0] = b / bn
    H = np.zeros((maxiter + 1, maxiter))
    cs, sn = np.zeros(maxiter), np.zeros(maxiter)
    g = np.zeros(maxiter + 1)
    g[0] = bn
    k = 0
    for k in range(maxiter):
        Z[k] = psolve(V[k])
        w = matvec(Z[k])
        Vk = V[:k + 1]
        h = Vk @ w                      # classical Gram-Schmidt, twice (as stable as MGS,
        w -= h @ Vk                     # two matrix products instead of k vector updates)
        h2 = Vk @ w
        w -= h2 @ Vk
        h += h2
        hn = float(np.linalg.norm(w))
        if not givens_column(h, hn, k, H, cs, sn, g):
            break
        if abs(g[k + 1]) <= rtol * bn or hn == 0.0:
            k += 1
            break
        V[k + 1] = w / hn
    else:
        k = maxiter
    if k == 0:
        return np.zeros_like(b), 0, False
    y = np.linalg.solve(np.triu(H[:k, :k]), g[:k])
    x = y @ Z[:k]
    return x, k, abs(g[k]) <= rtol * bn


# -- the solver a Model uses --------------------------------------------------------------------

class SymmetricSolver:
    """Factorise and solve symmetric matrices of one fixed CSR sparsity (sorted indices).

    `factor(A)` takes a CSR matrix with exactly the structure given at construction (values
    change from call to call); `solve(b)` solves with the last matrix given: directly with
    its factorisation, or (method "reuse") by GMRES preconditioned with an older one.
    """

    def __init__(self, structure: sp.csr_matrix, backend: str = "auto", method: str = "direct",
                 factor_cost: float | None = None, threads: int = 1, precision: str = "double",
                 ordering: str = "metis"):
        """factor_cost: the cost of one factorisation in preconditioned GMRES iterations (the
        refactorisation rule's unit); None: estimated from PARDISO's flop counts. threads:
        PARDISO's (default_threads gives the usual choice). precision "single" (PARDISO,
        method "reuse" only): the factorisation is single precision and only preconditions:
        every solve is GMRES in double precision, to the same tolerance. ordering: PARDISO's
        fill-reducing ordering, "metis" or "amd" (default_ordering gives the usual choice;
        SuperLU keeps its own)."""
        from tactileskin.errors import ParameterError

        if method not in METHODS:
            raise ParameterError("linear solver method", method, ", ".join(METHODS))
        if precision not in PRECISIONS:
            raise ParameterError("linear solver precision", precision, ", ".join(PRECISIONS))
        if precision == "single" and method != "reuse":
            raise ParameterError("linear solver precision", precision,
                                 "'double' for method 'direct' (single precision only preconditions GMRES)")
        if backend not in BACKENDS:
            raise ParameterError("linear solver backend", backend, ", ".join(BACKENDS))
        if ordering not in ORDERINGS:
            raise ParameterError("linear solver ordering", ordering, ", ".join(ORDERINGS))
        if backend == "auto":
            backend = "pardiso" if pardiso_available() else "superlu"
        if backend != "pardiso":
            precision = "double"   # SuperLU here is double only
        if backend == "pardiso" and not pardiso_available():
            raise ParameterError("linear solver backend", backend,
                                 "'superlu' or 'auto' (MKL's mkl_rt is not installed here)")
        self.backend = backend
        self.method = method
        self.n = structure.shape[0]
        self.factorizations = 0       # numerical factorisations done
        self.krylov_iterations = 0    # GMRES iterations (method "reuse")
        self.timing = {"factor": 0.0, "solve": 0.0}  # s (wall)
        self.cpu = {"factor": 0.0, "solve": 0.0}     # s (this process's CPU time)
        self._lu = None
        self._A = None                # the matrix `solve` answers for
        self._fresh = False           # the factorisation is of _A
        self._stale = True            # refactorise at the next factor()
        self._cycle = [0.0, 0]        # cost (in preconditioned iterations) and solves since the factorisation
        self._failures = 0            # consecutive GMRES solves that did not converge
        self._direct_left = 0         # factor() calls that refactorise without trying GMRES first
        # the factor() calls of the current increment (begin_increment), and the indices among
        # them at which GMRES failed (or was not tried for that reason) in this and the last one
        self._seq, self._failed_now, self._failed_last = 0, set(), set()
        self._ratio = factor_cost     # factorisation cost / iteration cost
        if backend == "pardiso":
            A = structure.tocsr()
            rows = np.repeat(np.arange(self.n), np.diff(A.indptr))
            upper = A.indices >= rows
            self._upper = np.flatnonzero(upper)
            indptr = np.concatenate([[0], np.cumsum(np.bincount(rows[upper], minlength=self.n))])
            self._pattern = (indptr, A.indices[upper])
            self._pardiso = _Pardiso(self.n, indptr, A.indices[upper], threads, single=precision == "single",
                                     ordering=ordering)
        self.threads = threads if backend == "pardiso" else 1
        self.precision = precision
        self.ordering = ordering if backend == "pardiso" else "superlu"

    def begin_increment(self) -> None:
        """A new load increment's Newton solve starts. With method "reuse", the system at which
        GMRES failed in the last increment is factorised directly in this one: the 3D Braille
        dots' second Newton system failed in 7 of 8 increments at t = 3 mm and in most of the 13
        at t = 5 (15 failures; the first step moves the contact set), each failure costing its
        Krylov limit (28-37 iterations) and the factorisation anyway
        (benchmarks/results/linsolve3d.md)."""
        self._failed_last, self._failed_now, self._seq = self._failed_now, set(), 0

    def factor(self, A: sp.csr_matrix) -> "SymmetricSolver":
        """Take A as the matrix to solve with; factorise it unless the old factorisation is
        to be reused (method "reuse" and it has not gone stale)."""
        self._A = A
        seq, self._seq = self._seq, self._seq + 1
        learned = self.method == "reuse" and seq in self._failed_last
        if learned:  # kept for the next increment: a system factorised so is not tried
            self._failed_now.add(seq)
        if self.method == "direct" or self._stale or self._direct_left > 0 or learned:
            self._direct_left = max(0, self._direct_left - 1)
            return self._factor(A)
        self._fresh = False
        return self

    def _factor(self, A: sp.csr_matrix) -> "SymmetricSolver":
        self.factorizations += 1
        self._fresh, self._stale = True, False
        self._cycle = [self._cost_ratio(A) + 1.0, 1]
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            if self.backend == "pardiso":
                try:
                    self._pardiso.factor(A.data[self._upper])
                except SingularMatrix:
                    # no usable factorisation: not a preconditioner for the next solves either
                    self._fresh, self._stale = False, True
                    raise
                if self._pardiso.perturbed:
                    log.debug("PARDISO: %d perturbed pivots", self._pardiso.perturbed)
                return self
            # symmetric ordering, diagonal pivots preferred (less fill)
            self._lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.01,
                                 options={"SymmetricMode": True})
            return self
        finally:
            self.timing["factor"] += time.perf_counter() - t0
            self.cpu["factor"] += time.process_time() - c0

    def _cost_ratio(self, A) -> float:
        """Cost of a factorisation in preconditioned GMRES iterations (one triangular solve
        pair + one product with A), from PARDISO's flop counts. SuperLU reports none: then
        KRYLOV_MAX (reuse is only taken with PARDISO unless forced)."""
        if self._ratio is None:
            if self.backend == "pardiso":
                nnz_f, mflops = self._pardiso.factor_nnz, self._pardiso.factor_mflops
            else:
                nnz_f, mflops = None, None
            if not nnz_f or not mflops or nnz_f <= 0 or mflops <= 0:
                return float(KRYLOV_MAX)
            it_flops = 4.0 * nnz_f + 2.0 * A.nnz
            self._ratio = 1e6 * mflops / it_flops / FACTOR_EFFICIENCY
        return self._ratio

    def _direct(self, b: np.ndarray) -> np.ndarray:
        if self.backend == "pardiso":
            return self._pardiso.solve(b)
        if self._lu is None:
            raise SingularMatrix("solve before factor")
        return self._lu.solve(b)

    def solve(self, b: np.ndarray, rtol: float | None = None) -> np.ndarray:
        """x with A x = b for the last A given to factor(). rtol: the relative residual a
        GMRES solve may stop at (default KRYLOV_RTOL; never looser than 1e-2); direct solves
        are exact to rounding whatever it is."""
        rtol = KRYLOV_RTOL if rtol is None else min(max(rtol, KRYLOV_RTOL), 1e-2)
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            if self._A is None or (self._fresh and self.precision == "double"):
                return self._direct(b)
            A = self._A
            limit = int(min(KRYLOV_MAX, max(2, np.ceil(self._cost_ratio(A)))))
            x, k, ok = self._gmres(A, b, rtol, limit)
            failed = not ok and not self._fresh
            if failed:
                # a failed solve costs its iterations and a factorisation; while the tangent
                # keeps changing that much (the Braille plate's first contact: 10 failures in
                # a row) refactorise directly for the next 1, 3, 7 ... systems
                self._failures += 1
                self._direct_left = min(2 ** self._failures - 1, DIRECT_AFTER_FAILURES_MAX)
                self._failed_now.add(self._seq - 1)
                log.debug("GMRES: no convergence in %d iterations with the old factorisation; refactorising"
                          " (directly for the next %d)", k, self._direct_left)
                t0, c0 = self._factor_within_solve(A, t0, c0)
                if self.precision == "double":
                    return self._direct(b)
                x, k, ok = self._gmres(A, b, rtol, limit)   # with the fresh single-precision one
            if not ok:
                # the single-precision factorisation of this very matrix does not precondition
                # it (pivots lost to rounding): double precision from now on
                log.info("PARDISO single precision does not precondition this tangent; switching to double")
                self._pardiso.close()
                self._pardiso = _Pardiso(self.n, *self._pattern, self.threads, ordering=self.ordering)
                self.precision = "double"
                t0, c0 = self._factor_within_solve(A, t0, c0)
                return self._direct(b)
            if not failed:
                self._failures = 0
            if self._fresh:      # single precision: the fresh factorisation's own matrix
                return x
            cost, solves = self._cycle
            cost, solves = cost + k, solves + 1
            self._cycle = [cost, solves]
            if k > cost / solves:  # this solve cost more than the average: refactorising pays
                self._stale = True
            log.debug("GMRES: %d iterations with the old factorisation%s", k,
                      " (stale: refactorise next)" if self._stale else "")
            return x
        finally:
            self.timing["solve"] += time.perf_counter() - t0
            self.cpu["solve"] += time.process_time() - c0

    def _factor_within_solve(self, A, t0: float, c0: float) -> tuple[float, float]:
        """Refactorise inside `solve`; returns its start times moved on by the factorisation's
        (which counts as factor time, not solve time)."""
        t1, c1 = time.perf_counter(), time.process_time()
        self._factor(A)
        return t0 + time.perf_counter() - t1, c0 + time.process_time() - c1

    def _gmres(self, A, b, rtol, limit):
        """GMRES preconditioned by the factorisation; (x, iterations, converged) with the
        true residual checked (the Givens estimate can drift: one product)."""
        x, k, ok = gmres(A.dot, self._direct, b, rtol, limit)
        self.krylov_iterations += k
        if ok and np.all(np.isfinite(x)):
            ok = np.linalg.norm(A @ x - b) <= 10.0 * rtol * np.linalg.norm(b)
        return x, k, bool(ok and np.all(np.isfinite(x)))

    def describe(self) -> dict:
        """The method used and its work counts (for result stats)."""
        return {"method": self.method, "backend": self.backend, "threads": self.threads,
                "precision": self.precision, "ordering": self.ordering,
                "factorizations": self.factorizations,
                "krylov_iterations": self.krylov_iterations,
                "cpu_s": {k: round(v, 4) for k, v in self.cpu.items()}}

    def close(self) -> None:
        if self.backend == "pardiso":
            self._pardiso.close()
