"""Vector dof numbering and fast sparse assembly into a fixed CSR pattern.

scikit-fem provides the scalar basis (shape functions, quadrature, element dofs); the
vector field uses interleaved numbering dof = m * scalar_dof + component. The sparsity
pattern is computed once; each assembly is one `np.bincount` into the CSR data array,
and the free-free block is extracted with a precomputed index (no sparse slicing).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def vector_dofs(scalar_dofs: np.ndarray, m: int) -> np.ndarray:
    """Interleaved vector dofs of scalar dofs (..., ) -> (..., m)."""
    return scalar_dofs[..., None] * m + np.arange(m)


class Pattern:
    """CSR sparsity of a global matrix built from element blocks with given dof maps."""

    def __init__(self, n: int, element_dofs: np.ndarray, free: np.ndarray):
        """element_dofs (E, nd) global dofs per element; free: sorted free dof indices."""
        self.n = n
        self.edofs = element_dofs
        nd = element_dofs.shape[1]
        rows = np.repeat(element_dofs, nd, axis=1).ravel()
        cols = np.tile(element_dofs, (1, nd)).ravel()
        keys = rows.astype(np.int64) * n + cols
        self.keys, self._inv = np.unique(keys, return_inverse=True)
        r = self.keys // n
        self.indices = (self.keys % n).astype(np.int32)
        self.indptr = np.concatenate([[0], np.cumsum(np.bincount(r, minlength=n))]).astype(np.int32)
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
        """CSR data from element matrices (E, nd, nd)."""
        return np.bincount(self._inv, weights=Ke.ravel(), minlength=len(self.keys))

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
