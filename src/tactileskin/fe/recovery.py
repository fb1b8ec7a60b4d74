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


# -- boundary values by a local least-squares fit ---------------------------------------------

# element centroids per fit: 12 in 2D (about two element rings around a boundary node)
MLS_NEIGHBOURS = {2: 12, 3: 30}


class PointFit:
    """Values at given points of a quadrature-point field by a weighted linear least-squares
    fit to the element averages of the nearest elements (a moving least-squares patch
    recovery, in the reference configuration).

    Why: the mixed P2/P0 pressure is element-constant in its volumetric part, and the global
    L2 projection onto P1 carries that O(h) error to the boundary, where the bone-pressure
    profile is read. The element averages sit at the centroids, and a linear fit through the
    centroids around a boundary node extrapolates them to second order. Measured on the
    paper cases (refinement 3, mesh sizes 0.25, 0.177, 0.125 mm): t3 silicone curved peaks
    0.12226 / 0.12236 / 0.12242 MPa against 0.12130 / 0.12170 / 0.12198 from the
    projection; t1 silicone Braille 0.10254 / 0.10272 / 0.10284 against 0.10063 / 0.10104 /
    0.10180. A linear field is reproduced exactly (the fit is exact for it).

    The fit is linear in the field: `values(q) = C @ qbar`, with C built once per point set.
    """

    def __init__(self, model, points: np.ndarray, k: int | None = None):
        from scipy.spatial import cKDTree

        m = model.m
        w = np.asarray(model.w)
        xq = np.moveaxis(np.asarray(model.basis.mapping.F(model.basis.X)), 0, -1)   # (E, Q, m)
        vol = w.sum(axis=1)
        xc = (w[..., None] * xq).sum(axis=1) / vol[:, None]
        k = min(k or MLS_NEIGHBOURS[m], len(xc))
        pts = np.atleast_2d(np.asarray(points, float))
        dist, idx = cKDTree(xc).query(pts, k=k)
        dist, idx = dist.reshape(len(pts), k), idx.reshape(len(pts), k)
        r = dist.max(axis=1, keepdims=True) * 1.01 + 1e-300
        wt = vol[idx] * (1.0 - (dist / r) ** 2) ** 2                                  # (n, k)
        A = np.concatenate([np.ones((len(pts), k, 1)), (xc[idx] - pts[:, None, :]) / r[..., None]], axis=2)
        M = np.einsum("nk,nki,nkj->nij", wt, A, A)
        e0 = np.zeros((len(pts), m + 1))
        e0[:, 0] = 1.0
        # first row of (A^T W A)^-1 A^T W: the fitted value at the point (pinv: a degenerate
        # patch, e.g. a mesh of a few cells, gives the least-norm fit instead of an error)
        y = (np.linalg.pinv(M) @ e0[..., None])[..., 0]                                 # (n, m+1)
        self.coef = np.einsum("ni,nki,nk->nk", y, A, wt)
        self.idx = idx
        self.w, self.vol = w, vol

    def values(self, q: np.ndarray) -> np.ndarray:
        """Fitted values at the points of the field q (E, Q)."""
        qbar = (self.w * q).sum(axis=1) / self.vol
        return np.einsum("nk,nk->n", self.coef, qbar[self.idx])
