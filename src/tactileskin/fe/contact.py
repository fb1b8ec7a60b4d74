"""Rigid frictionless contact on the quadrature points of a boundary (augmented Lagrangian).

The indenter is any object with `gap(points, d) -> (g, n)` (signed distance, g < 0
penetrating; unit normal out of the indenter). The contact pressure per reference area at
a point is lambda_N = max(0, lambda_k - eps g) with the Uzawa multiplier lambda_k held fixed
during a Newton solve; after it, lambda_k <- lambda_N until the penetration is below the
tolerance and the multipliers settle.

Points in `sticky` keep the linear law lambda_k - eps g within a Newton solve (see
fe.solver.newton: a kink rounded over 1e-4 mm of gap did not stop the active-set cycling
at the contact edge; holding points active did. A softplus over a wider band does not
either, and it presses at positive gaps: over 1e-2 mm of gap the t = 1 curved peak rose
33 %, over 1e-3 mm 0.2 %, with more Newton iterations than the sticky set;
benchmarks/results/contact_newton.md). The tangent may include the curvature
of the indenter surface (dn/dx, by central differences of the normal, since `gap` gives
only g and n); fe.model.Contact says why it is off by default.
"""

from __future__ import annotations

import numpy as np
from skfem import FacetBasis

from tactileskin.fe.assembly import vector_dofs

_FD_STEP = 1e-6  # mm; central difference of the unit normal (error ~ h^2 kappa^3, negligible)


class ContactSurface:
    def __init__(self, mesh, element, facets: np.ndarray, m: int, intorder: int = 3):
        fb = FacetBasis(mesh, element, facets=facets, intorder=intorder)
        self.m = m
        self.X = np.moveaxis(np.asarray(fb.global_coordinates()), 0, -1)        # (Fc, Qc, m)
        self.N = np.stack([np.asarray(fb.basis[a][0]) for a in range(fb.Nbfun)], axis=-1)  # (Fc, Qc, A)
        self.w = np.asarray(fb.dx)                                             # (Fc, Qc)
        if m == 3:  # for the current area in 3D (current_pressure): cell gradients, reference normal
            self.dN = np.stack([np.moveaxis(np.asarray(fb.basis[a][0].grad), 0, -1) for a in range(fb.Nbfun)],
                               axis=2)                                         # (Fc, Qc, A, 3)
            self.N0 = np.moveaxis(np.asarray(fb.normals), 0, -1)               # (Fc, Qc, 3)
        self.sdofs = fb.element_dofs.T                                         # (Fc, A)
        self.vdofs = vector_dofs(self.sdofs, m).reshape(len(self.sdofs), -1)   # (Fc, A*m)
        # tangent of the reference boundary (2D) to convert to current-area pressure
        self.lam = np.zeros(self.w.shape)
        self.scale = np.ones(self.w.shape)  # per-point penalty factor (fe.solver raises it)
        self.shape = self.w.shape
        # the last (surface dofs' displacements, indenter, travel) and its (x, g, n): a tangent
        # at the iterate whose residual was just evaluated needs the same gaps (2D preview
        # sweep: 556 gap evaluations); `Us` is compared bit for bit
        self._last_gap = None
        self._paths = {}   # einsum contraction paths of the tangent blocks, per operand shapes

    def displacement(self, u: np.ndarray) -> np.ndarray:
        U = u.reshape(-1, self.m)
        return np.einsum("fqa,fai->fqi", self.N, U[self.sdofs])

    def _gap(self, u, indenter, d):
        """(x, g, n) at the contact points: current positions, gaps and normals (the last
        evaluation's when the surface displacements, indenter and travel are the same)."""
        # float64 as the einsum below computes anyway: its bits compare as int64, whatever u's dtype
        Us = np.asarray(u, dtype=np.float64).reshape(-1, self.m)[self.sdofs]
        last = self._last_gap
        if (last is not None and last[1] is indenter and last[2] == d
                and np.array_equal(last[0].view(np.int64), Us.view(np.int64))):
            return last[3]
        x = self.X + np.einsum("fqa,fai->fqi", self.N, Us)
        g, n = indenter.gap(x, d)
        for a in (x, g, n):   # shared by the evaluations of this state: nobody may write them
            a.flags.writeable = False
        self._last_gap = (Us, indenter, float(d), (x, g, n))
        return x, g, n

    def _einsum(self, spec, *ops):
        """np.einsum(spec, *ops, optimize=True) with its path planned once per operand shapes
        (the planning cost ~0.1 ms per contact tangent; the same path, so the same bits)."""
        key = (spec,) + tuple(o.shape for o in ops)
        path = self._paths.get(key)
        if path is None:
            path = self._paths[key] = np.einsum_path(spec, *ops, optimize=True)[0]
        return np.einsum(spec, *ops, optimize=path)

    def evaluate(self, u, indenter, d: float, eps, lam_k: np.ndarray, tangent: bool,
                 sticky: np.ndarray | None = None, curvature: bool = False):
        """Residual contribution (Fc, A*m), tangent blocks (Fc, A*m, A*m) or None, and the
        point data (g, lambda_N, x, n). eps: the penalty (MPa/mm), a scalar or one per point.

        sticky (Fc, Qc) bool: points held active (the linear law lambda_k - eps g, which may
        turn slightly tensile) — the solver's guard against active-set cycling."""
        x, g, n = self._gap(u, indenter, d)
        xN = lam_k - eps * g
        lamN, slope = np.maximum(0.0, xN), (xN > 0.0).astype(float)
        if sticky is not None:
            lamN = np.where(sticky, xN, lamN)
            slope = np.where(sticky, 1.0, slope)
        active = slope > 0.0
        Fc, Qc, A = self.N.shape
        m = self.m
        # R_c = - int lambda_N n_i N_a
        fc = -np.einsum("fq,fqi,fqa->fai", self.w * lamN, n, self.N).reshape(Fc, A * m)
        Kc = None
        if tangent:
            Kpt = (eps * slope)[..., None, None] * np.einsum("fqi,fqk->fqik", n, n)
            if curvature and np.any(active):
                dn = self._dn_dx(x, indenter, d, active)
                Kpt = Kpt - lamN[..., None, None] * dn
            # only facets with a pressed (or held) point have a block: the rest of the outer
            # surface is zero (a 3D dot: a few % of its facets; 15 ms per tangent before)
            Kc = np.zeros((Fc, A * m, A * m))
            on = np.flatnonzero(np.any(Kpt != 0.0, axis=(1, 2, 3)))
            if on.size:
                Kc[on] = self._einsum("fq,fqa,fqb,fqik->faibk", self.w[on], self.N[on], self.N[on],
                                      Kpt[on]).reshape(len(on), A * m, A * m)
        return fc, Kc, (g, lamN, x, n)

    def _dn_dx(self, x, indenter, d, active):
        m = self.m
        dn = np.zeros(x.shape + (m,))
        xa = x[active]
        out = np.zeros((len(xa), m, m))
        for k in range(m):
            e = np.zeros(m)
            e[k] = _FD_STEP
            _, n1 = indenter.gap(xa + e, d)
            _, n0 = indenter.gap(xa - e, d)
            out[:, :, k] = (n1 - n0) / (2 * _FD_STEP)
        out = 0.5 * (out + np.swapaxes(out, 1, 2))  # Hessian of a distance: symmetric
        dn[active] = out
        return dn

    def current_pressure(self, u, lamN) -> np.ndarray:
        """Contact pressure per current area: lambda_N * dA0/da (2D: reference/current length)."""
        if self.m == 3:
            # lambda_N is per reference area: on a t = 1 silicone sphere at preview the pressed
            # facets' area grows 4-18 %, which contact.csv read as pressure. da/dA = |cof(F) N|
            # (Nanson, F from the cell's gradient), averaged over the facet (its current /
            # reference area) as 2D takes one chord ratio per facet: pointwise, the P2
            # gradient's stretch zigzags between neighbouring facets (2D plate: 2-7 % about the mean)
            U = u.reshape(-1, 3)[self.sdofs]                                   # (Fc, A, 3)
            F = np.eye(3) + np.einsum("fai,fqaj->fqij", U, self.dN)
            cofN = np.linalg.det(F)[..., None] * np.linalg.solve(np.swapaxes(F, -1, -2), self.N0[..., None])[..., 0]
            ratio = (self.w * np.linalg.norm(cofN, axis=-1)).sum(axis=1) / self.w.sum(axis=1)
            return lamN / np.maximum(ratio, 1e-300)[:, None]
        # stretch of the boundary: |dx/dS| from the displacement derivative along the facet,
        # estimated by the ratio of current/reference distances between neighbouring points
        X, x = self.X, self.X + self.displacement(u)
        dX = np.gradient(X, axis=1) if X.shape[1] > 1 else None
        if dX is None:
            return lamN
        dx = np.gradient(x, axis=1)
        ratio = np.linalg.norm(dX, axis=-1) / np.maximum(np.linalg.norm(dx, axis=-1), 1e-300)
        return lamN * ratio
