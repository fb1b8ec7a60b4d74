"""Readable reference of the element kernels (the oracle for the compiled fe._kernels_nb).

A literal transcription of the formulas in the fe.kernels docstring: F, F_bar, B (dF per
dof), AA = dP/dF and B_bar written out with numpy's det/inv and einsum, no algebraic
regrouping. The library keeps only the compiled loops; tests compare them with this.
Shapes as in fe.kernels: ue (E, A, m), G (E, Q, A, m), w (E, Q), S (E, Q, m, m) in-plane
PK2, D (E, Q, m, m, m, m) = dS/dE with minor symmetry.
"""

from __future__ import annotations

import numpy as np


def kinematics(ue, G, w, mixed):
    """F, J, Finv, theta (mixed), alpha, Fbar, C (E, Q, 3, 3: C_bar, C33 = 1 in plane
    strain) and Jbar of the displacement ue."""
    E, Q, A, m = G.shape
    F = np.eye(m) + np.einsum("eai,eqaj->eqij", ue, G)
    J = np.linalg.det(F)
    out = {"F": F, "J": J, "Finv": np.linalg.inv(F)}
    if mixed:
        theta = (w * J).sum(axis=1) / w.sum(axis=1)
        alpha = (theta[:, None] / J) ** (1.0 / m)
        out.update(theta=theta, Jbar=np.broadcast_to(theta[:, None], J.shape))
    else:
        alpha = np.ones_like(J)
        out["Jbar"] = J
    Fbar = alpha[..., None, None] * F
    C = np.zeros((E, Q, 3, 3))
    C[..., 2, 2] = 1.0
    C[..., :m, :m] = np.einsum("eqki,eqkj->eqij", Fbar, Fbar)
    out.update(alpha=alpha, Fbar=Fbar, C=C)
    return out


def residual_tangent(ue, G, w, mixed, S, D):
    """Internal force element vectors f (E, A*m) and consistent element stiffness K
    (E, A*m, A*m) of the condensed potential sum_q w_q W(F_bar_q)."""
    E, Q, A, m = G.shape
    nd = A * m
    kin = kinematics(ue, G, w, mixed)
    F, J, alpha, Fb = kin["F"], kin["J"], kin["alpha"], kin["Fbar"]
    h = np.einsum("eqaj,eqji->eqai", G, kin["Finv"])                  # spatial gradients
    P = Fb @ S
    AA = np.einsum("eqiI,eqkK,eqIJKL->eqiJkL", Fb, Fb, D) + np.einsum("ik,eqJL->eqiJkL", np.eye(m), S)
    AA = AA.reshape(E, Q, m * m, m * m)
    B = np.einsum("ik,eqaJ->eqiJak", np.eye(m), G).reshape(E, Q, m * m, nd)
    p = np.einsum("eqiJ,eqiJd->eqd", P, B.reshape(E, Q, m, m, nd))
    if not mixed:
        return (np.einsum("eq,eqd->ed", w, p),
                np.einsum("eq,eqrd,eqrs,eqsf->edf", w, B, AA, B, optimize=True))
    L = h.reshape(E, Q, nd)
    V = w.sum(axis=1)
    theta = kin["theta"]
    v2 = np.einsum("eq,eqd->ed", w * J, L) / V[:, None]                 # dtheta
    dphi = (v2[:, None, :] / theta[:, None, None] - L) / m
    tau = np.einsum("eqij,eqij->eq", P, Fb)
    f = np.einsum("eq,eqd->ed", w, alpha[..., None] * p + tau[..., None] * dphi)
    Bbar = alpha[..., None, None] * (B + F.reshape(E, Q, m * m)[..., None] * dphi[..., None, :])
    K = np.einsum("eq,eqrd,eqrs,eqsf->edf", w, Bbar, AA, Bbar, optimize=True)
    pa = alpha[..., None] * p
    K += np.einsum("eq,eqd,eqf->edf", w, dphi, pa) + np.einsum("eq,eqd,eqf->edf", w, pa, dphi)
    # tau (dphi dphi + d2phi), m d2phi = d2theta/theta - dtheta^2/theta^2 + tr(F^-1 dF F^-1 dF)
    # with d2theta = avg_q J [tr(F^-1 dF)^2 - tr(F^-1 dF F^-1 dF)]
    K += np.einsum("eq,eqd,eqf->edf", w * tau, dphi, dphi)
    hh_q = np.einsum("eqak,eqbi->eqaibk", h, h).reshape(E, Q, nd, nd)   # tr(F^-1 dF F^-1 dF)
    LL_q = np.einsum("eqd,eqf->eqdf", L, L)
    d2theta = np.einsum("eq,eqdf->edf", w * J, LL_q - hh_q) / V[:, None, None]
    trace2 = np.einsum("eq,eqdf->edf", w * tau, hh_q)
    wt = (w * tau).sum(axis=1)
    K += (wt[:, None, None] * (d2theta / theta[:, None, None]
                                - v2[:, :, None] * v2[:, None, :] / theta[:, None, None] ** 2)
          + trace2) / m
    return f, K
