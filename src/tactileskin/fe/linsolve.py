"""Sparse symmetric solves of the Newton systems: analyse once, refactorise per iteration.

The free-block sparsity of a Model is fixed for a whole solve (contact blocks lie inside
the element pattern), so the fill-reducing ordering and the symbolic factorisation are
done once per Model and each Newton iteration only refactorises numerically.

Backends:
- "pardiso": MKL PARDISO (real symmetric indefinite, mtype -2: Bunch-Kaufman pivoting,
  METIS nested-dissection ordering) called through ctypes on the `mkl` wheel's mkl_rt
  (x86-64 only). Phases: 11 analysis (once), 22 numerical factorisation, 33 solve.
- "superlu": scipy's SuperLU, a fresh factorisation each time (any platform).
`backend="auto"` takes PARDISO when mkl_rt loads. Measured (benchmarks/linsolve.py):
numerical refactorisation 3-10x faster than SuperLU on the fingertip tangents, more on 3D.

Threads: one, unless MKL_NUM_THREADS is set (Dask workers set it to 1 anyway).
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

log = logging.getLogger(__name__)

BACKENDS = ("auto", "pardiso", "superlu")


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

    def __init__(self, n: int, indptr: np.ndarray, indices: np.ndarray):
        self.lib = _load_mkl()
        self.n = n
        self.indptr = np.ascontiguousarray(indptr, np.int32)
        self.indices = np.ascontiguousarray(indices, np.int32)
        self.pt = np.zeros(64, np.int64)
        self.iparm = np.zeros(64, np.int32)
        ip = self.iparm
        ip[0] = 1    # non-default iparm
        ip[1] = 2    # METIS nested dissection
        # 0: iterative refinement only after perturbed pivots (2 steps then). A fixed 2 steps
        # doubled the solve time (t5 tangent, 15.8k dofs: 13.4 -> 6.5 ms) for the same residual
        ip[7] = 0
        ip[9] = 8    # pivot perturbation 1e-8 (the symmetric indefinite default)
        ip[20] = 1   # Bunch-Kaufman 1x1/2x2 pivoting
        ip[34] = 1   # zero-based indexing
        self.perturbed = 0
        self._alive = False
        self._call(11, np.zeros(0), np.zeros(0))
        self._alive = True

    def _call(self, phase: int, a: np.ndarray, b: np.ndarray, x: np.ndarray | None = None) -> int:
        i32 = ctypes.c_int32
        err = i32(0)
        p = lambda v: ctypes.byref(i32(v))  # noqa: E731
        i32p = ctypes.POINTER(i32)
        self.lib.pardiso(self.pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), p(1), p(1), p(-2),
                         p(phase), p(self.n), a.ctypes.data if a.size else None,
                         self.indptr.ctypes.data_as(i32p), self.indices.ctypes.data_as(i32p),
                         None, p(1), self.iparm.ctypes.data_as(i32p), p(0),
                         b.ctypes.data if b.size else None,
                         x.ctypes.data if x is not None and x.size else None, ctypes.byref(err))
        if err.value != 0:
            raise SingularMatrix(f"PARDISO phase {phase}: error {err.value} "
                                 f"({_PARDISO_ERRORS.get(err.value, 'unknown')})")
        return err.value

    def factor(self, data: np.ndarray) -> None:
        self.data = np.ascontiguousarray(data, float)
        self._call(22, self.data, np.zeros(0))
        self.perturbed = int(self.iparm[13])

    def solve(self, b: np.ndarray) -> np.ndarray:
        b = np.ascontiguousarray(b, float)
        x = np.zeros_like(b)
        self._call(33, self.data, b, x)
        return x

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


# -- the solver a Model uses --------------------------------------------------------------------

class SymmetricSolver:
    """Factorise and solve symmetric matrices of one fixed CSR sparsity (sorted indices).

    `factor(A)` takes a CSR matrix with exactly the structure given at construction (values
    change from call to call); `solve(b)` uses the last factorisation.
    """

    def __init__(self, structure: sp.csr_matrix, backend: str = "auto"):
        if backend not in BACKENDS:
            from tactileskin.errors import ParameterError

            raise ParameterError("linear solver backend", backend, ", ".join(BACKENDS))
        if backend == "auto":
            backend = "pardiso" if pardiso_available() else "superlu"
        if backend == "pardiso" and not pardiso_available():
            from tactileskin.errors import ParameterError

            raise ParameterError("linear solver backend", backend,
                                 "'superlu' or 'auto' (MKL's mkl_rt is not installed here)")
        self.backend = backend
        self.n = structure.shape[0]
        self.factorizations = 0
        self.timing = {"factor": 0.0, "solve": 0.0}  # s
        self._lu = None
        if backend == "pardiso":
            A = structure.tocsr()
            rows = np.repeat(np.arange(self.n), np.diff(A.indptr))
            upper = A.indices >= rows
            self._upper = np.flatnonzero(upper)
            indptr = np.concatenate([[0], np.cumsum(np.bincount(rows[upper], minlength=self.n))])
            self._pardiso = _Pardiso(self.n, indptr, A.indices[upper])

    def factor(self, A: sp.csr_matrix) -> "SymmetricSolver":
        self.factorizations += 1
        t0 = time.perf_counter()
        try:
            if self.backend == "pardiso":
                self._pardiso.factor(A.data[self._upper])
                if self._pardiso.perturbed:
                    log.debug("PARDISO: %d perturbed pivots", self._pardiso.perturbed)
                return self
            # symmetric ordering, diagonal pivots preferred (less fill)
            self._lu = spla.splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.01,
                                 options={"SymmetricMode": True})
            return self
        finally:
            self.timing["factor"] += time.perf_counter() - t0

    def solve(self, b: np.ndarray) -> np.ndarray:
        t0 = time.perf_counter()
        try:
            if self.backend == "pardiso":
                return self._pardiso.solve(b)
            if self._lu is None:
                raise SingularMatrix("solve before factor")
            return self._lu.solve(b)
        finally:
            self.timing["solve"] += time.perf_counter() - t0

    def close(self) -> None:
        if self.backend == "pardiso":
            self._pardiso.close()
