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
"""

from __future__ import annotations

import numpy as np


def deformation_gradient(ue: np.ndarray, G: np.ndarray) -> np.ndarray:
    """In-plane/3D deformation gradient (E, Q, m, m) from element displacements (E, A, m)
    and reference shape-function gradients G (E, Q, A, m)."""
    m = ue.shape[-1]
    return np.eye(m) + np.einsum("eai,eqaj->eqij", ue, G)


def embed3(M: np.ndarray, fill33: float = 1.0) -> np.ndarray:
    """Embed an in-plane (..., 2, 2) tensor in (..., 3, 3) with M33 = fill33; 3D passes through."""
    if M.shape[-1] == 3:
        return M
    out = np.zeros(M.shape[:-2] + (3, 3))
    out[..., :2, :2] = M
    out[..., 2, 2] = fill33
    return out


class Kinematics:
    """Kinematic quantities of one trial displacement, shared by residual, tangent and output."""

    def __init__(self, ue: np.ndarray, G: np.ndarray, w: np.ndarray, mixed: bool):
        self.m = m = ue.shape[-1]
        self.mixed = mixed
        self.G, self.w = G, w
        self.F = deformation_gradient(ue, G)
        self.J = np.linalg.det(self.F)
        self.admissible = bool(np.all(self.J > 0.0) and np.all(np.isfinite(self.J)))
        if not self.admissible:
            return
        self.Finv = np.linalg.inv(self.F)
        # spatial gradients h_a = G_a F^-1, (E, Q, A, m)
        self.h = np.einsum("eqaj,eqji->eqai", G, self.Finv)
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
        Fb3 = embed3(self.Fbar)
        self.C = np.einsum("...ki,...kj->...ij", Fb3, Fb3)                  # C_bar (E, Q, 3, 3)

    def phi_grad(self) -> np.ndarray:
        """dphi as element vectors (E, Q, A*m); zero in the displacement formulation."""
        E, Q, A, m = self.h.shape
        L = self.h.reshape(E, Q, A * m)
        if not self.mixed:
            return np.zeros_like(L)
        V = self.w.sum(axis=1)
        v2 = np.einsum("eq,eqd->ed", self.w * self.J, L) / V[:, None]       # dtheta
        self._v2, self._L = v2, L
        return (v2[:, None, :] / self.theta[:, None, None] - L) / m


def residual(kin: Kinematics, S: np.ndarray) -> np.ndarray:
    """Internal force element vectors (E, A*m) from the in-plane PK2 stress S (E, Q, m, m)."""
    E, Q, A, m = kin.G.shape
    P = kin.Fbar @ S                                                         # P_bar
    p = kin.alpha[..., None] * np.einsum("eqij,eqaj->eqai", P, kin.G).reshape(E, Q, A * m)
    f = np.einsum("eq,eqd->ed", kin.w, p)
    if kin.mixed:
        tau = np.einsum("eqij,eqij->eq", P, kin.Fbar)
        f += np.einsum("eq,eqd->ed", kin.w * tau, kin.phi_grad())
    return f


def _sumq(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """sum_q left_q^T right_q for (E, Q, k, nd) stacks, as one batched matmul (E, nd, nd)."""
    E, Q, k, nd = left.shape
    return np.swapaxes(left.reshape(E, Q * k, nd), 1, 2) @ right.reshape(E, Q * k, nd)


def tangent(kin: Kinematics, S: np.ndarray, D: np.ndarray) -> np.ndarray:
    """Consistent element stiffness (E, A*m, A*m); S (E,Q,m,m), D = dS/dE (E,Q,m,m,m,m)."""
    E, Q, A, m = kin.G.shape
    nd = A * m
    mm = m * m
    Fb = kin.Fbar
    # AA_iJkL = d_ik S_JL + Fb_iI Fb_kK D_IJKL as an (m*m, m*m) matrix per point
    Fk = np.einsum("eqiI,eqkK->eqikIK", Fb, Fb).reshape(E, Q, mm, mm)       # [(i,k),(I,K)]
    Dr = D.transpose(0, 1, 2, 4, 3, 5).reshape(E, Q, mm, mm)                # [(I,K),(J,L)]
    AA = (Fk @ Dr).reshape(E, Q, m, m, m, m).transpose(0, 1, 2, 4, 3, 5)     # [i,J,k,L]
    AA = AA + np.eye(m)[None, None, :, None, :, None] * S[:, :, None, :, None, :]
    AA = AA.reshape(E, Q, mm, mm)
    # B: dF_iJ from local dof (a, k) = d_ik G_aJ   -> (E, Q, m*m, nd)
    B = np.zeros((E, Q, m, m, A, m))
    for i in range(m):
        B[:, :, i, :, :, i] = np.swapaxes(kin.G, 2, 3)
    B = B.reshape(E, Q, mm, nd)
    w = kin.w
    if not kin.mixed:
        return _sumq(B * w[..., None, None], AA @ B)
    dphi = kin.phi_grad()                                                    # (E, Q, nd)
    Bbar = kin.alpha[..., None, None] * (B + kin.F.reshape(E, Q, mm)[..., None] * dphi[..., None, :])
    K = _sumq(Bbar * w[..., None, None], AA @ Bbar)
    P = Fb @ S
    tau = np.einsum("eqij,eqij->eq", P, Fb)
    p = kin.alpha[..., None] * np.einsum("eqij,eqaj->eqai", P, kin.G).reshape(E, Q, nd)
    L, v2, th = kin._L, kin._v2, kin.theta
    wt = w * tau
    V = w.sum(axis=1)
    coef = wt.sum(axis=1) / (m * th) / V
    wJ = w * kin.J
    # tau dphi dphi + dphi p + p dphi = dphi r + r dphi, r = p + tau dphi / 2
    r = p + 0.5 * tau[..., None] * dphi
    wd = (w[..., None] * dphi)[:, :, None, :]
    K += _sumq(wd, r[:, :, None, :])
    K += _sumq(r[:, :, None, :], wd)
    # tr(F^-1 dF F^-1 dF) terms: sum_q c_q h_q,bi h_q,ak at [(a,i),(b,k)]
    c = wt / m - coef[:, None] * wJ
    hq = kin.h.reshape(E, Q, 1, nd)
    N = _sumq(c[..., None, None] * hq, hq)                                   # [(a,k),(b,i)]
    K += N.reshape(E, A, m, A, m).transpose(0, 1, 4, 3, 2).reshape(E, nd, nd)
    K -= (wt.sum(axis=1) / m / th**2)[:, None, None] * (v2[:, :, None] * v2[:, None, :])
    K += coef[:, None, None] * _sumq((wJ[..., None] * L)[:, :, None, :], L[:, :, None, :])
    return K


def cauchy(kin: Kinematics, S3: np.ndarray) -> np.ndarray:
    """Cauchy stress (E, Q, 3, 3) = F_bar S F_bar^T / J_bar from the full 3x3 PK2 S3."""
    Fb3 = embed3(kin.Fbar)
    return np.einsum("...iI,...IJ,...jJ->...ij", Fb3, S3, Fb3) / kin.Jbar[..., None, None]


def mean_pressure(sigma: np.ndarray) -> np.ndarray:
    """Abaqus PRESS: P = -(sxx + syy + szz)/3, positive in compression."""
    return -np.trace(sigma, axis1=-2, axis2=-1) / 3.0
