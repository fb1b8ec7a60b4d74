"""Vector dof numbering and fast sparse assembly into a fixed CSR pattern.

scikit-fem provides the scalar basis (shape functions, quadrature, element dofs); the
vector field uses interleaved numbering dof = m * scalar_dof + component. The sparsity
pattern is computed once, from the node graph (fe._sparse_nb); each assembly is one
compiled scatter into the CSR data array, parallel over node rows, and the free-free block
is extracted with a precomputed index (no sparse slicing).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from tactileskin.fe import _sparse_nb
from tactileskin.fe.kernels import PARALLEL_MIN_ELEMENTS
from tactileskin.threads import numba_parallel_threads


def vector_dofs(scalar_dofs: np.ndarray, m: int) -> np.ndarray:
    """Interleaved vector dofs of scalar dofs (..., ) -> (..., m)."""
    return scalar_dofs[..., None] * m + np.arange(m)


class Pattern:
    """CSR sparsity of a global matrix built from element blocks with given dof maps."""

    def __init__(self, n: int, element_dofs: np.ndarray, free: np.ndarray, m: int = 1):
        """element_dofs (E, nd) global dofs per element, interleaved vector dofs of m
        components (vector_dofs(scalar_dofs, m)); free: sorted free dof indices."""
        self.n = n
        self.edofs = element_dofs
        E, nd = element_dofs.shape
        A = nd // m
        sd = element_dofs[:, ::m] // m
        if nd % m or n % m or not np.array_equal(vector_dofs(sd, m).reshape(E, nd), element_dofs):
            raise ValueError(f"element dofs are not interleaved vector dofs of {m} components")
        # the node graph (E A^2 keys; the dof-level np.unique of E (A m)^2 keys took 0.6 s on
        # the 3D t = 5 dot) and each element entry's place in its node row
        ns = n // m
        skeys = (np.repeat(sd, A, axis=1).astype(np.int64) * ns + np.tile(sd, (1, A))).ravel()
        skeys, sinv = np.unique(skeys, return_inverse=True)
        srow = skeys // ns
        sindptr = np.concatenate([[0], np.cumsum(np.bincount(srow, minlength=ns))])
        sinv = sinv.ravel()
        self._off = (sinv - sindptr[srow[sinv]]).reshape(E, A, A).astype(np.int32)
        indptr, self.indices = _sparse_nb.vector_pattern(sindptr, skeys % ns, m)
        self.indptr = indptr.astype(np.int32)
        r = np.repeat(np.arange(n), np.diff(indptr))
        self.keys = r * n + self.indices   # row-major sorted (row, col) keys, for add()
        # the elements around each node, ascending (the scatter's order of additions)
        order = np.argsort(sd.ravel(), kind="stable")
        self._nptr = np.concatenate([[0], np.cumsum(np.bincount(sd.ravel(), minlength=ns))])
        self._ne, self._na = (order // A).astype(np.int32), (order % A).astype(np.int32)
        # on numba's threads as the tangent kernel is (P2 tets from PARALLEL_MIN_ELEMENTS), else
        # on this thread: a 2D solve starts no OpenMP pool (a fork()ed child of it hung)
        self._scatter = _sparse_nb.scatter(m, A)
        self._scatter_threads = (_sparse_nb.scatter_3_10_threads
                                 if (m, A) == (3, 10) and E >= PARALLEL_MIN_ELEMENTS else None)
        # free-free block
        is_free = np.zeros(n, bool)
        is_free[free] = True
        newidx = -np.ones(n, np.int64)
        newidx[free] = np.arange(len(free))
        c = self.indices
        keep = is_free[r] & is_free[c]
        self._keep = np.flatnonzero(keep)
        nf = len(free)
        rf = newidx[r[keep]]
        self._ff_indices = newidx[c[keep]].astype(np.int32)
        self._ff_indptr = np.concatenate([[0], np.cumsum(np.bincount(rf, minlength=nf))]).astype(np.int32)
        self.nfree = nf
        self._add_dofs, self._add_pos = None, None   # Pattern.add's positions of its last dofs

    def data(self, Ke: np.ndarray) -> np.ndarray:
        """CSR data from element matrices (E, nd, nd), on numba's threads for large P2-tet
        models (the bits of np.bincount over the entries' positions: the same additions in the
        same order, whatever the threads)."""
        Ke = np.ascontiguousarray(Ke, np.float64)
        if Ke.shape != self.edofs.shape + self.edofs.shape[1:]:
            raise ValueError(f"element matrices of shape {Ke.shape} for element dofs {self.edofs.shape}")
        f = self._scatter_threads if self._scatter_threads is not None and numba_parallel_threads() > 1 \
            else self._scatter
        return f(Ke, self._nptr, self._ne, self._na, self._off, self.indptr, np.empty(len(self.keys)))

    def add(self, data: np.ndarray, dofs: np.ndarray, Kb: np.ndarray) -> None:
        """Add blocks Kb (B, k, k) with dofs (B, k) (must lie inside the pattern). The data
        positions of the last dofs given are kept: the contact blocks of a model always come
        with the same dofs (the 3D dot's: 29 ms of searchsorted per tangent)."""
        if self._add_dofs is None or not np.array_equal(self._add_dofs, dofs):
            k = dofs.shape[1]
            keys = (np.repeat(dofs, k, axis=1).astype(np.int64) * self.n + np.tile(dofs, (1, k))).ravel()
            self._add_dofs, self._add_pos = np.array(dofs), np.searchsorted(self.keys, keys)
        np.add.at(data, self._add_pos, Kb.ravel())

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))

    def free_matrix(self, data: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((data[self._keep], self._ff_indices, self._ff_indptr),
                             shape=(self.nfree, self.nfree))


def assemble_vector(n: int, element_dofs: np.ndarray, fe: np.ndarray) -> np.ndarray:
    return np.bincount(element_dofs.ravel(), weights=fe.ravel(), minlength=n)
