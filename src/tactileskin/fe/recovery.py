"""Recovery of nodal fields from quadrature-point values by L2 projection.

A field q known at the quadrature points of the model is projected onto the continuous
piecewise-linear space on the same mesh (vertex values): find p_h with (p_h, v) = (q, v)
for all v. P1, not P2: the model's 3-point rule integrates the P1 mass matrix exactly
(degree 2) but would leave the P2 one singular element by element, which shows up as
node-to-node oscillation. Values at the P2 mid-side nodes are interpolated linearly.
The mass matrix is assembled and factorised once per model.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import CellBasis

from tactileskin.fe.model import scalar_element


class Projector:
    def __init__(self, model):
        self.model = model
        q = model.basis.quadrature
        self.basis = CellBasis(model.mesh, scalar_element(model.mesh, 1), quadrature=q)
        b = self.basis
        self.N = np.stack([np.asarray(b.basis[a][0]) for a in range(b.Nbfun)], axis=-1)  # (E, Q, A1)
        self.dofs = b.element_dofs.T
        Me = np.einsum("eq,eqa,eqb->eab", model.w, self.N, self.N)
        A = self.dofs.shape[1]
        rows = np.repeat(self.dofs, A, axis=1).ravel()
        cols = np.tile(self.dofs, (1, A)).ravel()
        M = sp.coo_matrix((Me.ravel(), (rows, cols)), shape=(b.N, b.N)).tocsc()
        self._lu = spla.splu(M)
        # P1 -> P2 interpolation: the model's scalar dofs are located at model.basis.doflocs;
        # P1 interpolation at the P2 nodes of each element (vertices: identity, mid-sides: mean)
        self._p2 = self._interp_matrix()

    def _interp_matrix(self):
        m = self.model
        if m.basis.Nbfun == self.basis.Nbfun:
            return None
        X = m.basis.doflocs
        rows, cols, vals = [], [], []
        # each P2 node of each element: evaluate P1 shape functions there (reference coords)
        el2, el1 = m.sdofs, self.dofs
        ref = np.asarray(m.element.doflocs)                    # (A2, dim) reference coords
        e1 = self.basis.elem
        phi = np.stack([e1.lbasis(ref.T, a)[0] for a in range(el1.shape[1])], axis=-1)  # (A2, A1)
        for a in range(el2.shape[1]):
            for b in range(el1.shape[1]):
                rows.append(el2[:, a]); cols.append(el1[:, b]); vals.append(np.full(len(el2), phi[a, b]))
        n2 = m.nsdof
        M = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n2, self.basis.N)).tocsr()
        # shared nodes were summed once per element: normalise rows
        cnt = np.bincount(el2.ravel(), minlength=n2).astype(float)
        return sp.diags(1.0 / cnt) @ M

    def project(self, q: np.ndarray) -> np.ndarray:
        """Values (model.nsdof,) at the model's scalar nodes of the P1 L2 projection of q (E, Q)."""
        m = self.model
        rhs = np.bincount(self.dofs.ravel(), weights=np.einsum("eq,eq,eqa->ea", m.w, q, self.N).ravel(),
                          minlength=self.basis.N)
        p1 = self._lu.solve(rhs)
        return p1 if self._p2 is None else self._p2 @ p1
