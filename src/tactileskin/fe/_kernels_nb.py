"""Compiled (numba) element loops behind fe.kernels: kinematics, residual and tangent.

The formulas and dof ordering of the fe.kernels docstring (tests/reference_kernels.py
transcribes them literally and is the oracle of these loops); one element at a time, all
points of it, with scratch arrays allocated once per call (whole-mesh temporaries of a
vectorised version dominated its cost). Every argument must be a C-contiguous float64
array; fe.kernels makes them so.

Tangent algebra. With B the map from dofs to dF (dF_iJ = d_ik G_aJ at dof (a, k)) and
AA_iJkL = d_ik S_JL + Fb_iI Fb_kK D_IJKL, the displacement part sum_q w B^T AA B is
    material:  Y^T Dv Y, Y_(IJ),(a,i) = Fb_iI G_aJ + Fb_iJ G_aI (Voigt pairs IJ, D with
               minor symmetry; Dv carries 1/2 on the diagonal pairs),
    geometric: (G S G^T)_ab d_ik,
and the mixed B_bar = alpha (B + F dphi) adds rank-one terms built from AA F =
Fb (D : C_bar + S) / alpha (no AA formed; D with major symmetry):
    alpha^2 (g dphi + dphi g + s dphi dphi) + tau dphi dphi + dphi p + p dphi
        = dphi r + r dphi,  r = p + tau dphi / 2 + alpha^2 (g + s dphi / 2),
    g = B^T AA F, s = F : AA F, p = alpha B^T P_bar,
plus the d2phi terms: sum_q c_q h_bi h_ak at [(a,i),(b,k)] (the tr(F^-1 dF F^-1 dF) part,
h = G F^-1, c_q = w tau / m - coef w J) and the dtheta products.

The tangent of an element is one BLAS product Lft^T Rgt (np.dot, no allocation) over rows
collected from its points (Lft row | Rgt row):
    Voigt rows     Y_r  |  (w alpha^2 Dv Y)_r                       (material part)
    mixed rows     w L  |  rr,   rr | w L,   u | Rt,   Rt | u        (rank-one terms)
plus the geometric term (G S G^T)_ab d_ik (accumulated per element) and the h h term, a
permutation of M = sum_q c_q L_q L_q (a second BLAS product). Point by point loops with
short inner loops ran at ~1 flop/ns here; the BLAS products at ~20.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from tactileskin._jit import njit

# The loops take the dimension m and the nodes per element A as arguments; the entry points
# below pass them as constants for P2 triangles (2, 6) and P2 tets (3, 10), so LLVM unrolls
# the 2- and 3-trip loops (runtime trip counts cost ~5x: a vectorised body plus remainder
# and alias checks for every tiny loop), and read them from the shapes otherwise.
_impl = njit(cache=True, error_model="numpy", inline="always")
_jit = njit(cache=True, error_model="numpy")


@_impl
def _voigt(r, m):
    """Voigt pair (I, J) number r: (00, 11, 01) in 2D, (00, 11, 22, 12, 02, 01) in 3D
    (arithmetic, not a table: folds to constants)."""
    if r < m:
        return r, r
    if m == 2:
        return 0, 1
    return (1 if r == 3 else 0), (1 if r == 5 else 2)


@_impl
def _kinematics(ue, G, w, mixed, F, J, Finv, alpha, Fbar, C, theta, m, A):
    """Fill F, J (always) and, if every J is finite and > 0, Finv, alpha, Fbar, C (E,Q,3,3)
    and theta (mixed). Returns admissibility. Determinant and inverse by cofactors (the
    columns of the adjugate are cross products of the rows of F)."""
    E, Q = w.shape
    ok = True
    for e in range(E):
        for q in range(Q):
            for i in range(m):
                for j in range(m):
                    s = 0.0
                    for a in range(A):
                        s += ue[e, a, i] * G[e, q, a, j]
                    F[e, q, i, j] = (1.0 if i == j else 0.0) + s
            f = F[e, q]
            if m == 2:
                d = f[0, 0] * f[1, 1] - f[0, 1] * f[1, 0]
            else:
                d = (f[0, 0] * (f[1, 1] * f[2, 2] - f[1, 2] * f[2, 1])
                     + f[0, 1] * (f[1, 2] * f[2, 0] - f[1, 0] * f[2, 2])
                     + f[0, 2] * (f[1, 0] * f[2, 1] - f[1, 1] * f[2, 0]))
            J[e, q] = d
            if not (d > 0.0 and d < np.inf):   # also catches NaN
                ok = False
    if not ok:
        return False
    for e in range(E):
        for q in range(Q):
            f = F[e, q]
            fi = Finv[e, q]
            d = J[e, q]
            if m == 2:
                fi[0, 0] = f[1, 1] / d
                fi[0, 1] = -f[0, 1] / d
                fi[1, 0] = -f[1, 0] / d
                fi[1, 1] = f[0, 0] / d
            else:
                # Finv_ij = cof(F)_ji / det; cof rows are cross products of F's rows
                fi[0, 0] = (f[1, 1] * f[2, 2] - f[1, 2] * f[2, 1]) / d
                fi[1, 0] = (f[1, 2] * f[2, 0] - f[1, 0] * f[2, 2]) / d
                fi[2, 0] = (f[1, 0] * f[2, 1] - f[1, 1] * f[2, 0]) / d
                fi[0, 1] = (f[2, 1] * f[0, 2] - f[2, 2] * f[0, 1]) / d
                fi[1, 1] = (f[2, 2] * f[0, 0] - f[2, 0] * f[0, 2]) / d
                fi[2, 1] = (f[2, 0] * f[0, 1] - f[2, 1] * f[0, 0]) / d
                fi[0, 2] = (f[0, 1] * f[1, 2] - f[0, 2] * f[1, 1]) / d
                fi[1, 2] = (f[0, 2] * f[1, 0] - f[0, 0] * f[1, 2]) / d
                fi[2, 2] = (f[0, 0] * f[1, 1] - f[0, 1] * f[1, 0]) / d
        if mixed:
            V = 0.0
            s = 0.0
            for q in range(Q):
                V += w[e, q]
                s += w[e, q] * J[e, q]
            th = s / V
            theta[e] = th
            for q in range(Q):
                alpha[e, q] = (th / J[e, q]) ** (1.0 / m)
        else:
            for q in range(Q):
                alpha[e, q] = 1.0
        for q in range(Q):
            al = alpha[e, q]
            for i in range(m):
                for j in range(m):
                    Fbar[e, q, i, j] = al * F[e, q, i, j]
            c = C[e, q]
            for i in range(3):
                for j in range(3):
                    c[i, j] = 0.0
            if m == 2:
                c[2, 2] = 1.0
            fb = Fbar[e, q]
            for i in range(m):
                for j in range(m):
                    s = 0.0
                    for k in range(m):
                        s += fb[k, i] * fb[k, j]
                    c[i, j] = s
    return True


@_impl
def _residual(G, w, Fbar, Finv, alpha, J, theta, S, mixed, out, m, A):
    """Internal force element vectors into out (E, A*m); S (E, Q, m, m) in-plane PK2."""
    E, Q = w.shape
    nd = A * m
    P = np.empty((m, m))
    v2 = np.empty(nd)
    tl = np.empty(nd)
    for e in range(E):
        for d in range(nd):
            out[e, d] = 0.0
            v2[d] = 0.0
            tl[d] = 0.0
        V = 0.0
        wt = 0.0
        for q in range(Q):
            fb = Fbar[e, q]
            s_ = S[e, q]
            tau = 0.0
            for i in range(m):
                for j in range(m):
                    s = 0.0
                    for k in range(m):
                        s += fb[i, k] * s_[k, j]
                    P[i, j] = s
                    tau += s * fb[i, j]
            w0 = w[e, q]
            c = w0 * alpha[e, q]
            for a in range(A):
                for i in range(m):
                    s = 0.0
                    for j in range(m):
                        s += G[e, q, a, j] * P[i, j]
                    out[e, a * m + i] += c * s
            if mixed:
                wJ = w0 * J[e, q]
                wtau = w0 * tau
                V += w0
                wt += wtau
                for a in range(A):
                    for i in range(m):
                        h = 0.0
                        for j in range(m):
                            h += G[e, q, a, j] * Finv[e, q, j, i]
                        v2[a * m + i] += wJ * h
                        tl[a * m + i] += wtau * h
        if mixed:
            # sum_q w tau dphi_q, dphi_q = (v2 / theta - L_q) / m
            c = wt / (m * V * theta[e])
            for d in range(nd):
                out[e, d] += c * v2[d] - tl[d] / m
    return out


@_impl
def _tangent(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, out, m, A):
    """Consistent element stiffness into out (E, A*m, A*m); S (E,Q,m,m), D (E,Q,m,m,m,m)
    with minor (and, mixed, major) symmetry. The algebra of the module docstring."""
    E, Q = w.shape
    nd = A * m
    nv = m * (m + 1) // 2
    nrow = Q * (nv + 2) + 2 if mixed else Q * nv
    Lft = np.zeros((nrow, nd))   # K = Lft^T @ Rgt is one BLAS call
    LT = Lft.T
    Rgt = np.zeros((nrow, nd))
    Lq = np.empty((Q, nd))
    tauq = np.empty(Q)
    v2 = np.empty(nd)
    u = np.empty(nd)
    Rbar = np.empty(nd)
    wDv = np.empty((nv, nv))
    P = np.empty((m, m))
    Cb = np.empty((m, m))
    DCS = np.empty((m, m))
    vv = np.empty((m, m))
    SG = np.empty((m, A))        # ww S G^T of this point
    Kg = np.empty((A, A))        # sum_q (G ww S G^T)_ab, put on every diagonal component
    M = np.empty((nd, nd))       # sum_q c_q L_q L_q = LcT @ Lq; the h h term is M with i, k swapped
    LcT = np.empty((nd, Q))
    fb = np.empty((m, m))
    s_ = np.empty((m, m))
    Dq = np.empty((m, m, m, m))
    # inner loops run over a contiguous index of length A or nd (LLVM vectorises them)
    for e in range(E):
        for a in range(A):
            for b in range(A):
                Kg[a, b] = 0.0
        V = 0.0
        wt = 0.0
        th = 1.0
        coef = 0.0
        if mixed:
            # pass 1: L_q = h_q (spatial gradients), tau_q and the element sums
            for d in range(nd):
                v2[d] = 0.0
                Rbar[d] = 0.0
            for q in range(Q):
                tau = 0.0
                for i in range(m):
                    for j in range(m):
                        s = 0.0
                        for k in range(m):
                            s += Fbar[e, q, i, k] * S[e, q, k, j]
                        tau += s * Fbar[e, q, i, j]
                tauq[q] = tau
                w0 = w[e, q]
                V += w0
                wt += w0 * tau
                wJ = w0 * J[e, q]
                for a in range(A):
                    for i in range(m):
                        h = 0.0
                        for j in range(m):
                            h += G[e, q, a, j] * Finv[e, q, j, i]
                        Lq[q, a * m + i] = h
                        v2[a * m + i] += wJ * h
            th = theta[e]
            for d in range(nd):
                v2[d] /= V
                u[d] = v2[d] / (m * th)
            coef = wt / (m * th) / V
        # pass 2: rows of every point, geometric and h h terms
        row = 0
        for q in range(Q):
            # this point's Fbar, S, D in scratch (copies, not views: a view costs a refcount)
            for i in range(m):
                for j in range(m):
                    fb[i, j] = Fbar[e, q, i, j]
                    s_[i, j] = S[e, q, i, j]
                    for k in range(m):
                        for l_ in range(m):
                            Dq[i, j, k, l_] = D[e, q, i, j, k, l_]
            w0 = w[e, q]
            al = alpha[e, q]
            ww = w0 * al * al if mixed else w0
            for rr_ in range(nv):
                I, J_ = _voigt(rr_, m)
                for a in range(A):
                    gJ = G[e, q, a, J_]
                    gI = G[e, q, a, I]
                    for i in range(m):
                        Lft[row + rr_, a * m + i] = fb[i, I] * gJ + fb[i, J_] * gI
            for rr_ in range(nv):
                I, J_ = _voigt(rr_, m)
                hr = 0.5 if rr_ < m else 1.0
                for s2 in range(nv):
                    K_, L_ = _voigt(s2, m)
                    wDv[rr_, s2] = Dq[I, J_, K_, L_] * (ww * (hr * (0.5 if s2 < m else 1.0)))
            for rr_ in range(nv):
                for f in range(nd):
                    Rgt[row + rr_, f] = 0.0
                for s2 in range(nv):
                    c = wDv[rr_, s2]
                    for f in range(nd):
                        Rgt[row + rr_, f] += c * Lft[row + s2, f]
            row += nv
            # geometric: (G ww S G^T)_ab
            for J_ in range(m):
                for b in range(A):
                    s = 0.0
                    for L_ in range(m):
                        s += s_[J_, L_] * G[e, q, b, L_]
                    SG[J_, b] = ww * s
            for a in range(A):
                for J_ in range(m):
                    g = G[e, q, a, J_]
                    for b in range(A):
                        Kg[a, b] += g * SG[J_, b]
            if not mixed:
                continue
            tau = tauq[q]
            Jq = J[e, q]
            for i in range(m):
                for j in range(m):
                    s = 0.0
                    c2 = 0.0
                    for k in range(m):
                        s += fb[i, k] * s_[k, j]
                        c2 += fb[k, i] * fb[k, j]
                    P[i, j] = s
                    Cb[i, j] = c2
            # v = AA F = Fb (D : C_bar + S) / alpha; s = F : v
            for I in range(m):
                for J_ in range(m):
                    s = 0.0
                    for K_ in range(m):
                        for L_ in range(m):
                            s += Dq[I, J_, K_, L_] * Cb[K_, L_]
                    DCS[I, J_] = s + s_[I, J_]
            sF = 0.0
            for i in range(m):
                for j in range(m):
                    s = 0.0
                    for k in range(m):
                        s += fb[i, k] * DCS[k, j]
                    vv[i, j] = s / al
                    sF += F[e, q, i, j] * vv[i, j]
            a2 = al * al
            cd = 0.5 * (tau + a2 * sF)
            cJ = 0.5 * coef * Jq
            for a in range(A):
                for i in range(m):
                    pp = 0.0
                    gg = 0.0
                    for j in range(m):
                        g = G[e, q, a, j]
                        pp += g * P[i, j]
                        gg += g * vv[i, j]
                    d = a * m + i
                    L = Lq[q, d]
                    dphi = u[d] - L / m
                    rd = al * pp + cd * dphi + a2 * gg
                    Rbar[d] += w0 * rd
                    Lft[row, d] = w0 * L
                    Rgt[row, d] = -rd / m + cJ * L
            for d in range(nd):
                Lft[row + 1, d] = Rgt[row, d]
                Rgt[row + 1, d] = Lft[row, d]
            row += 2
            # tr(F^-1 dF F^-1 dF) terms c_q h_ak h_bi at [(a,i),(b,k)]: M[(a,k),(b,i)]
            c = w0 * tau / m - coef * w0 * Jq
            for d in range(nd):
                LcT[d, q] = c * Lq[q, d]
        if mixed:
            # u Rbar + Rbar u - (wt / m / theta^2) v2 v2 = u Rt + Rt u
            c = 0.5 * wt / th
            for d in range(nd):
                Rt = Rbar[d] - c * v2[d]
                Lft[row, d] = u[d]
                Rgt[row, d] = Rt
                Lft[row + 1, d] = Rt
                Rgt[row + 1, d] = u[d]
        Ke = out[e]
        np.dot(LT, Rgt, Ke)
        if mixed:
            np.dot(LcT, Lq, M)
        for a in range(A):
            for i in range(m):
                for b in range(A):
                    Ke[a * m + i, b * m + i] += Kg[a, b]
        if mixed:
            for a in range(A):
                for i in range(m):
                    for b in range(A):
                        for k in range(m):
                            Ke[a * m + i, b * m + k] += M[a * m + k, b * m + i]
    return out


@_jit
def kinematics_2_6(ue, G, w, mixed, F, J, Finv, alpha, Fbar, C, theta):
    return _kinematics(ue, G, w, mixed, F, J, Finv, alpha, Fbar, C, theta, 2, 6)


@_jit
def kinematics_3_10(ue, G, w, mixed, F, J, Finv, alpha, Fbar, C, theta):
    return _kinematics(ue, G, w, mixed, F, J, Finv, alpha, Fbar, C, theta, 3, 10)


@_jit
def kinematics_any(ue, G, w, mixed, F, J, Finv, alpha, Fbar, C, theta):
    return _kinematics(ue, G, w, mixed, F, J, Finv, alpha, Fbar, C, theta, G.shape[3], G.shape[2])


@_jit
def residual_2_6(G, w, Fbar, Finv, alpha, J, theta, S, mixed, out):
    return _residual(G, w, Fbar, Finv, alpha, J, theta, S, mixed, out, 2, 6)


@_jit
def residual_3_10(G, w, Fbar, Finv, alpha, J, theta, S, mixed, out):
    return _residual(G, w, Fbar, Finv, alpha, J, theta, S, mixed, out, 3, 10)


@_jit
def residual_any(G, w, Fbar, Finv, alpha, J, theta, S, mixed, out):
    return _residual(G, w, Fbar, Finv, alpha, J, theta, S, mixed, out, G.shape[3], G.shape[2])


@_jit
def tangent_2_6(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, out):
    return _tangent(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, out, 2, 6)


@_jit
def tangent_3_10(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, out):
    return _tangent(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, out, 3, 10)


@_jit
def tangent_any(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, out):
    return _tangent(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, out,
                    G.shape[3], G.shape[2])


@njit(cache=True, error_model="numpy", parallel=True)
def tangent_3_10_parallel(G, w, F, Fbar, Finv, alpha, J, theta, S, D, mixed, out, chunks):
    """tangent_3_10 on `chunks` contiguous element ranges run by numba's threads (each range
    with its own scratch arrays; numba.set_num_threads sets how many run at once). The same
    arithmetic per element as the serial loop, so the same bits."""
    E = w.shape[0]
    for c in nb.prange(chunks):
        a, b = c * E // chunks, (c + 1) * E // chunks
        _tangent(G[a:b], w[a:b], F[a:b], Fbar[a:b], Finv[a:b], alpha[a:b], J[a:b],
                 theta[a:b] if mixed else theta, S[a:b], D[a:b], mixed, out[a:b], 3, 10)
    return out


_ENTRY = {"kinematics": {(2, 6): kinematics_2_6, (3, 10): kinematics_3_10},
          "residual": {(2, 6): residual_2_6, (3, 10): residual_3_10},
          "tangent": {(2, 6): tangent_2_6, (3, 10): tangent_3_10}}
_ANY = {"kinematics": kinematics_any, "residual": residual_any, "tangent": tangent_any}


def entry(name: str, G: np.ndarray):
    """The compiled `name` loop for shape-function gradients G (E, Q, A, m)."""
    return _ENTRY[name].get((G.shape[3], G.shape[2]), _ANY[name])
