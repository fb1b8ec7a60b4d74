"""Element kernels of total-Lagrangian finite strain, vectorised over elements and points.

Pure numpy functions of arrays; nothing here knows about meshes or boundary conditions.

Shapes: E elements, Q quadrature points, A local scalar nodes, m the model dimension
(2: plane strain with F33 = 1; 3). Element dofs are interleaved: local dof a*m + i is
displacement component i of node a, so element vectors are (E, A*m).

Two formulations share one code path:

- displacement: F from the displacement gradient.
- mixed (three-field Hu-Washizu with element-constant dilatation theta and pressure, both
  condensed): F_bar = (theta/J)^(1/m) F with theta = volume average of J over the element.
  In plane strain only the in-plane block is scaled, so det F_bar = theta. With P2
  displacements and P0 dilatation/pressure this is inf-sup stable and free of volumetric
  locking. The condensed potential is sum_q w_q W(F_bar_q); its exact first and second
  derivatives are below (phi = ln(theta/J)/m, alpha = e^phi, tau = P_bar : F_bar):

      dW   = alpha P_bar : dF + tau dphi
      d2W  = dF_bar : AA_bar : dF_bar + tau (dphi^2 + d2phi) + 2 dphi alpha P_bar : dF
      dF_bar = alpha (dF + F dphi),   m dphi = dtheta/theta - tr(F^-1 dF)
      m d2phi = d2theta/theta - dtheta^2/theta^2 + tr(F^-1 dF F^-1 dF)
      d2theta = avg_q J [tr(F^-1 dF)^2 - tr(F^-1 dF F^-1 dF)]

  The same formulas hold with a stress that has a constant (history) part, as in QLV.

Kinematics, residual and tangent run compiled element loops (fe._kernels_nb, numba) when
COMPILED is true (the default); the numpy implementations stay as the reference
(residual_numpy, tangent_numpy, Kinematics with COMPILED false) that the tests compare with.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from tactileskin.fe import _kernels_nb

# compiled element loops (the numpy code below is the reference they are tested against)
COMPILED = True


def _c(x: np.ndarray) -> np.ndarray:
    """C-contiguous float64 (the compiled loops take no strided views)."""
    return np.ascontiguousarray(x, dtype=np.float64)


def deformation_gradient(ue: np.ndarray, G: np.ndarray) -> np.ndarray:
    """In-plane/3D deformation gradient (E, Q, m, m) from element displacements (E, A, m)
    and reference shape-function gradients G (E, Q, A, m)."""
    m = ue.shape[-1]
    # F_ij = d_ij + sum_a ue_ai G_aj: one (m, A) @ (A, m) product per point
    return np.eye(m) + np.swapaxes(ue, 1, 2)[:, None] @ G


def embed3(M: np.ndarray, fill33: float = 1.0) -> np.ndarray:
    """Embed an in-plane (..., 2, 2) tensor in (..., 3, 3) with M33 = fill33; 3D passes through."""
    if M.shape[-1] == 3:
        return M
    out = np.zeros(M.shape[:-2] + (3, 3))
    out[..., :2, :2] = M
    out[..., 2, 2] = fill33
    return out


def _det_inv(F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """det F and F^-1 of (..., m, m), m = 2 or 3, by cofactors (numpy's LU-based det/inv
    cost a LAPACK call per 2x2/3x3 matrix). Call only where det F != 0."""
    if F.shape[-1] == 2:
        a, b, c, d = F[..., 0, 0], F[..., 0, 1], F[..., 1, 0], F[..., 1, 1]
        det = a * d - b * c
        adj = np.stack([d, -b, -c, a], axis=-1).reshape(F.shape)
        return det, adj / det[..., None, None]
    r0, r1, r2 = F[..., 0, :], F[..., 1, :], F[..., 2, :]
    # columns of the adjugate are cross products of the rows
    adjT = np.stack([np.cross(r1, r2), np.cross(r2, r0), np.cross(r0, r1)], axis=-2)   # cof(F)
    det = np.sum(r0 * adjT[..., 0, :], axis=-1)
    return det, np.swapaxes(adjT, -1, -2) / det[..., None, None]


def _det(F: np.ndarray) -> np.ndarray:
    if F.shape[-1] == 2:
        return F[..., 0, 0] * F[..., 1, 1] - F[..., 0, 1] * F[..., 1, 0]
    r0, r1, r2 = F[..., 0, :], F[..., 1, :], F[..., 2, :]
    return np.sum(r0 * np.cross(r1, r2), axis=-1)


def _wsum(w: np.ndarray, X: np.ndarray) -> np.ndarray:
    """sum_q w_q X_q for w (E, Q) and X (E, Q, d): one (1, Q) @ (Q, d) product per element."""
    return (w[:, None, :] @ X)[:, 0, :]


class Kinematics:
    """Kinematic quantities of one trial displacement, shared by residual, tangent and output."""

    def __init__(self, ue: np.ndarray, G: np.ndarray, w: np.ndarray, mixed: bool):
        self.m = ue.shape[-1]
        self.mixed = mixed
        self.G, self.w = G, w
        if COMPILED:
            self._init_compiled(ue)
        else:
            self._init_numpy(ue)

    def _init_compiled(self, ue):
        G, w, m = _c(self.G), _c(self.w), self.m
        self.G, self.w = G, w
        E, Q = w.shape
        self.F = np.empty((E, Q, m, m))
        self.J = np.empty((E, Q))
        Finv, alpha, C = np.empty((E, Q, m, m)), np.empty((E, Q)), np.empty((E, Q, 3, 3))
        Fbar, theta = (np.empty((E, Q, m, m)), np.empty(E)) if self.mixed else (self.F, np.empty(0))
        loop = _kernels_nb.entry("kinematics", G)
        self.admissible = bool(loop(_c(ue), G, w, self.mixed, self.F, self.J, Finv, alpha, Fbar, C, theta))
        if not self.admissible:
            return
        self.Finv, self.alpha, self.Fbar, self.C = Finv, alpha, Fbar, C
        if self.mixed:
            self.theta = theta
            self.Jbar = np.broadcast_to(theta[:, None], self.J.shape)
        else:
            self.Jbar = self.J

    @cached_property
    def h(self) -> np.ndarray:
        """Spatial gradients h_a = G_a F^-1, (E, Q, A, m) (the numpy reference uses them)."""
        return self.G @ self.Finv

    def _init_numpy(self, ue):
        G, w, m, mixed = self.G, self.w, self.m, self.mixed
        self.F = deformation_gradient(ue, G)
        with np.errstate(over="ignore", invalid="ignore"):   # a wild trial state: caught below
            self.J = _det(self.F)
        self.admissible = bool(np.all(self.J > 0.0) and np.all(np.isfinite(self.J)))
        if not self.admissible:
            return
        self.J, self.Finv = _det_inv(self.F)
        # spatial gradients h_a = G_a F^-1, (E, Q, A, m)
        self.h = G @ self.Finv
        if mixed:
            V = w.sum(axis=1)
            self.theta = (w * self.J).sum(axis=1) / V                       # (E,)
            self.alpha = (self.theta[:, None] / self.J) ** (1.0 / m)         # (E, Q)
            self.Fbar = self.alpha[..., None, None] * self.F
            self.Jbar = np.broadcast_to(self.theta[:, None], self.J.shape)
        else:
            self.alpha = np.ones_like(self.J)
            self.Fbar = self.F
            self.Jbar = self.J
        Cm = np.swapaxes(self.Fbar, -1, -2) @ self.Fbar
        self.C = embed3(Cm)                                                  # C_bar (E, Q, 3, 3)

    def phi_grad(self) -> np.ndarray:
        """dphi as element vectors (E, Q, A*m); zero in the displacement formulation."""
        E, Q, A, m = self.h.shape
        L = self.h.reshape(E, Q, A * m)
        if not self.mixed:
            return np.zeros_like(L)
        V = self.w.sum(axis=1)
        v2 = _wsum(self.w * self.J, L) / V[:, None]                         # dtheta
        self._v2, self._L = v2, L
        return (v2[:, None, :] / self.theta[:, None, None] - L) / m


def _nodal(kin: Kinematics, P: np.ndarray) -> np.ndarray:
    """alpha P : dF per dof, (E, Q, A*m): sum_J P_iJ G_aJ at local dof (a, i)."""
    E, Q, A, m = kin.G.shape
    return kin.alpha[..., None] * (kin.G @ np.swapaxes(P, -1, -2)).reshape(E, Q, A * m)


def residual(kin: Kinematics, S: np.ndarray) -> np.ndarray:
    """Internal force element vectors (E, A*m) from the in-plane PK2 stress S (E, Q, m, m)."""
    if not COMPILED:
        return residual_numpy(kin, S)
    E, Q, A, m = kin.G.shape
    theta = kin.theta if kin.mixed else np.empty(0)
    loop = _kernels_nb.entry("residual", kin.G)
    return loop(_c(kin.G), _c(kin.w), _c(kin.Fbar), _c(kin.Finv), _c(kin.alpha), _c(kin.J), _c(theta),
                _c(S), kin.mixed, np.empty((E, A * m)))


def residual_numpy(kin: Kinematics, S: np.ndarray) -> np.ndarray:
    """The numpy reference of `residual`."""
    P = kin.Fbar @ S                                                         # P_bar
    p = _nodal(kin, P)
    if kin.mixed:
        tau = np.sum(P * kin.Fbar, axis=(-2, -1))
        p = p + tau[..., None] * kin.phi_grad()
    return _wsum(kin.w, p)


def _sumq(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """sum_q left_q^T right_q for (E, Q, k, nd) stacks, as one batched matmul (E, nd, nd)."""
    E, Q, k, nd = left.shape
    return np.swapaxes(left.reshape(E, Q * k, nd), 1, 2) @ right.reshape(E, Q * k, nd)


# Voigt pairs (I, J), I <= J, of a symmetric m x m tensor
_VOIGT = {2: (np.array([0, 1, 0]), np.array([0, 1, 1])),
          3: (np.array([0, 1, 2, 1, 0, 0]), np.array([0, 1, 2, 2, 2, 1]))}
# elements per block of the tangent: its temporaries (~(Q * 2 * 6 + 3) * nd doubles per
# element) then stay cache-sized; whole-mesh temporaries of 3D meshes run to 100 MB
_TANGENT_BLOCK_DOUBLES = 1 << 17


def tangent(kin: Kinematics, S: np.ndarray, D: np.ndarray) -> np.ndarray:
    """Consistent element stiffness (E, A*m, A*m); S (E,Q,m,m), D = dS/dE (E,Q,m,m,m,m),
    D with minor symmetry. Compiled (fe._kernels_nb) unless COMPILED is false; the same
    algebra as `tangent_numpy`, which documents it."""
    if not COMPILED:
        return tangent_numpy(kin, S, D)
    E, Q, A, m = kin.G.shape
    theta = kin.theta if kin.mixed else np.empty(0)
    loop = _kernels_nb.entry("tangent", kin.G)
    return loop(_c(kin.G), _c(kin.w), _c(kin.F), _c(kin.Fbar), _c(kin.Finv), _c(kin.alpha), _c(kin.J),
                _c(theta), _c(S), _c(D), kin.mixed, np.empty((E, A * m, A * m)))


def tangent_numpy(kin: Kinematics, S: np.ndarray, D: np.ndarray) -> np.ndarray:
    """Consistent element stiffness (E, A*m, A*m); S (E,Q,m,m), D = dS/dE (E,Q,m,m,m,m).

    D must have minor symmetry (any D = 2 dS/dC of a symmetric S has). With B the map from
    dofs to dF (dF_iJ = d_ik G_aJ at dof (a, k)) and AA_iJkL = d_ik S_JL + Fb_iI Fb_kK D_IJKL,
    the displacement part sum_q w B^T AA B is evaluated as
        material:  Y^T Dv Y, Y_(IJ),(a,i) = Fb_iI G_aJ + Fb_iJ G_aI (Voigt pairs IJ),
        geometric: (G S G^T)_ab d_ik,
    and the mixed B_bar = alpha (B + F dphi) adds the rank-one terms of AA F (no AA formed).
    Evaluated in blocks of elements (see _TANGENT_BLOCK_DOUBLES).
    """
    E, Q, A, m = kin.G.shape
    nd = A * m
    K = np.empty((E, nd, nd))
    fields = {"G": kin.G, "w": kin.w, "Fb": kin.Fbar, "S": S, "D": D}
    if kin.mixed:
        fields.update(F=kin.F, alpha=kin.alpha, J=kin.J, h=kin.h, theta=kin.theta,
                      dphi=kin.phi_grad(), L=kin._L, v2=kin._v2, Cb=kin.C[..., :m, :m])
    blk = max(8, _TANGENT_BLOCK_DOUBLES // ((2 * Q * len(_VOIGT[m]) + 3) * nd))
    for s in range(0, E, blk):
        _tangent_block(K[s:s + blk], kin.mixed, **{k: v[s:s + blk] for k, v in fields.items()})
    return K


def _tangent_block(K, mixed, G, w, Fb, S, D, F=None, alpha=None, J=None, h=None, theta=None,
                   dphi=None, L=None, v2=None, Cb=None):
    """The tangent of a block of elements into K (E, nd, nd); see `tangent`."""
    E, Q, A, m = G.shape
    nd = A * m
    w0 = w
    if mixed:
        w = w * alpha**2
    vi, vj = _VOIGT[m]
    nv = len(vi)
    FbT = np.swapaxes(Fb, -1, -2)                                            # [I, i]
    GT = np.ascontiguousarray(np.swapaxes(G, -1, -2))                        # [J, a]
    Y = np.empty((E, Q, nv, A, m))
    for r in range(nv):
        I, J_ = vi[r], vj[r]
        for i in range(m):
            y = Y[:, :, r, :, i]
            np.multiply(FbT[:, :, I, i, None], GT[:, :, J_, :], out=y)
            if I == J_:
                y *= 2.0
            else:
                y += FbT[:, :, J_, i, None] * GT[:, :, I, :]
    Y = Y.reshape(E, Q, nv, nd)
    half = np.where(vi == vj, 0.5, 1.0)
    wDv = D[:, :, vi[:, None], vj[:, None], vi[None, :], vj[None, :]] * (
        w[..., None, None] * (half[:, None] * half[None, :]))
    np.matmul(np.swapaxes(Y.reshape(E, Q * nv, nd), 1, 2), (wDv @ Y).reshape(E, Q * nv, nd), out=K)
    Kg = _sumq((w[..., None, None] * S) @ GT, GT)                            # (E, A, A)
    Kv = K.reshape(E, A, m, A, m)
    for i in range(m):
        Kv[:, :, i, :, i] += Kg
    if not mixed:
        return
    # B^T AA F = g, F : AA F = s with AA F = Fb (D : C_bar + S) / alpha (S symmetric)
    DC = (D.reshape(E, Q, m * m, m * m) @ Cb.reshape(E, Q, m * m, 1)).reshape(E, Q, m, m)
    v = Fb @ (DC + S) / alpha[..., None, None]
    g = (G @ np.swapaxes(v, -1, -2)).reshape(E, Q, nd)
    s = np.sum(F * v, axis=(-2, -1))
    P = Fb @ S
    tau = np.sum(P * Fb, axis=(-2, -1))
    p = alpha[..., None] * (G @ np.swapaxes(P, -1, -2)).reshape(E, Q, nd)
    wt = w0 * tau
    V = w0.sum(axis=1)
    coef = wt.sum(axis=1) / (m * theta) / V
    wJ = w0 * J
    # alpha^2 (g dphi + dphi g + s dphi dphi) + tau dphi dphi + dphi p + p dphi
    #   = dphi r + r dphi,  r = p + tau dphi / 2 + alpha^2 (g + s dphi / 2)
    a2 = alpha**2
    r = p + (0.5 * (tau + a2 * s))[..., None] * dphi + a2[..., None] * g
    wd = w0[..., None] * dphi
    K += _sumq(np.stack([wd, r, coef[:, None, None] * wJ[..., None] * L], axis=2),
               np.stack([r, wd, L], axis=2))
    # tr(F^-1 dF F^-1 dF) terms: sum_q c_q h_q,bi h_q,ak at [(a,i),(b,k)]
    c = wt / m - coef[:, None] * wJ
    hq = h.reshape(E, Q, 1, nd)
    N = _sumq(c[..., None, None] * hq, hq)                                   # [(a,k),(b,i)]
    Kv += N.reshape(E, A, m, A, m).transpose(0, 1, 4, 3, 2)
    K -= ((wt.sum(axis=1) / m / theta**2)[:, None] * v2)[:, :, None] * v2[:, None, :]


def cauchy(kin: Kinematics, S3: np.ndarray) -> np.ndarray:
    """Cauchy stress (E, Q, 3, 3) = F_bar S F_bar^T / J_bar from the full 3x3 PK2 S3."""
    Fb3 = embed3(kin.Fbar)
    return np.einsum("...iI,...IJ,...jJ->...ij", Fb3, S3, Fb3) / kin.Jbar[..., None, None]


def mean_pressure(sigma: np.ndarray) -> np.ndarray:
    """Abaqus PRESS: P = -(sxx + syy + szz)/3, positive in compression."""
    return -np.trace(sigma, axis1=-2, axis2=-1) / 3.0
