"""Compiled (numba) point loop of the plane-strain hyperfoam law, `hyperfoam.pk2_tangent_plane`.

Same formulas and the same numerical care as the 3x3 path `pk2_tangent` (see the docstring of
tactileskin.materials.hyperfoam): ln c_a = log1p(e_a) from the eigenvalues of C - I, the
exp * expm1 form of c^(alpha/2) - J^(-alpha beta) and of the divided differences (exact down
to coincident stretches, g' at zero gap), the EXP_CAP / LOG_C_CAP guard with finite values
from clipped exponents at inadmissible points.

Cost: one pass over the points with scalar math. The transcendental calls are the cost,
so the exponentials are shared: per term i and in-plane direction a only
c_a^(alpha_i/2) = exp(alpha_i/2 ln c_a), J^(-alpha_i beta) and 1/c_a = exp(-ln c_a) are
evaluated, and every other power (c^(alpha/2 - 1), J^(-alpha beta)/c^2, ...) is a product
of them (a few ulp from the 3x3 path's single exp of the summed exponent). The
differences keep their own expm1 calls. The third principal direction (e_z, c_3 = 1,
ln c_3 = 0) needs no exp at all.

The signature is explicit (one compiled specialisation for any input layout; the cache in
__pycache__ makes later imports load it instead of compiling).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from tactileskin._jit import njit
from tactileskin.errors import TactileSkinError
from tactileskin.materials import hyperfoam as _hf

# hyperfoam's caps, written here: numba freezes a global into the kernels it caches in
# __pycache__ and keys them by this file's bytes alone, so caps imported from hyperfoam.py kept
# their old values there after an edit (the result cache's key named the edited code)
EXP_CAP = 300.0
LOG_C_CAP = 30.0
_CLIP = EXP_CAP + 4.0 * LOG_C_CAP
if (EXP_CAP, LOG_C_CAP, _CLIP) != (_hf.EXP_CAP, _hf.LOG_C_CAP, _hf._CLIP):
    raise TactileSkinError(f"materials/_hyperfoam_nb.py has EXP_CAP = {EXP_CAP:g}, LOG_C_CAP = {LOG_C_CAP:g}, "
                           f"hyperfoam.py {_hf.EXP_CAP:g}, {_hf.LOG_C_CAP:g}: write the same caps in both")

__all__ = ["plane_kernel", "plane_tangent_kernel", "KEPT_PLANE", "MODE_S", "MODE_D2", "MODE_D3"]

MODE_S, MODE_D2, MODE_D3 = 0, 1, 2   # S only; S + in-plane D (16); S + full D (81)

# entries of the full D (index 27 i + 9 j + 3 k + l) with an odd number of out-of-plane indices
_ZERO81 = np.array([2, 5, 6, 7, 11, 14, 15, 16, 18, 19, 21, 22, 26, 29, 32, 33, 34, 38, 41, 42, 43, 45,
                    46, 48, 49, 53, 54, 55, 57, 58, 62, 63, 64, 66, 67, 71, 74, 77, 78, 79], dtype=np.int64)

_SIG = ("void(float64[:, :, :], float64[:], boolean, float64[:], float64[:], float64, "
        "float64[:, :, ::1], float64[:, ::1], boolean[::1], int64, float64[:, ::1], boolean)")
_SIG_D = "void(float64[:, ::1], float64[:], float64[:], float64, float64[:, ::1], int64)"

# the per-point data a plane-strain stress evaluation keeps for a later D at the same state
# (`plane_kernel` with keep, `plane_tangent_kernel`): the projector's (11, 12) = (p11, p12),
# e (2), ln c (2), 1/c (2), then per term J^(-alpha beta), c_0^(alpha/2), c_1^(alpha/2)
KEPT_PLANE = 8


@numba.njit(inline="always")
def _pos(x):
    """exp(x) with the 3x3 path's clip (finite for any exponent of an inadmissible point)."""
    return math.exp(min(x, _CLIP))


@numba.njit(inline="always")
def _diff(ex1, ex2, d):
    """exp(x1) - exp(x2) from ex1 = exp(x1), ex2 = exp(x2) and d = x1 - x2 (no cancellation)."""
    if d <= 0.0:
        return ex2 * math.expm1(max(d, -_CLIP))
    return -(ex1 * math.expm1(max(-d, -_CLIP)))


@numba.njit(inline="always")
def _log_c(e):
    """(ln c, e, admissible) of one eigenvalue e of C - I, with the 3x3 path's guard/clip."""
    lc_raw = math.log1p(e) if e > -1.0 else -2.0 * LOG_C_CAP
    ok = e > -1.0 and abs(lc_raw) <= LOG_C_CAP
    lc = min(max(lc_raw, -LOG_C_CAP), LOG_C_CAP)
    if lc_raw != lc:
        e = math.expm1(lc)   # e consistent with the clipped log: divided differences stay finite
    return lc, e, ok


@numba.njit(inline="always")
def _pair(k, q, cqa, cqb, ea, eb, la, lb, ell, evab):
    """k (g[c_a, c_b] + J^(-alpha beta) / (c_a c_b)): one term of gamma_ab, a != b.
    cqa = c_a^q, ell = ln(c_a / c_b), evab = J^(-alpha beta) / (c_a c_b)."""
    gap = ea - eb
    if abs(gap) <= 1e-14 * max(1.0 + ea, 1.0 + eb):
        dd = q * _pos((q - 1.0) * 0.5 * (la + lb))           # g' at the mean
    else:
        dd = _diff(cqa, cqb, q * ell) / gap
    return k * (dd + evab)


@numba.njit(inline="always")
def _plane_gamma(k, q, mu_i, beta, ev, pw0, pw1, ic0, ic1, e0, e1, lc0, lc1, ell01):
    """One term's share of gamma (00, 11, 22, 01, 02, 12) and of qv = J dp/dJ."""
    cq0 = pw0 * ic0                                          # c^q, q = alpha/2 - 1
    cq1 = pw1 * ic1
    # diagonal: g'(c_a) + J^(-alpha beta) / c_a^2
    d00 = k * (q * cq0 * ic0 + ev * ic0 * ic0)
    d11 = k * (q * cq1 * ic1 + ev * ic1 * ic1)
    d22 = k * (q + ev)
    # pairs (0,1), (0,2), (1,2); c_3 = 1: ln(c_a / c_3) = ln c_a
    d01 = _pair(k, q, cq0, cq1, e0, e1, lc0, lc1, ell01, ev * ic0 * ic1)
    d02 = _pair(k, q, cq0, 1.0, e0, 0.0, lc0, 0.0, lc0, ev * ic0)
    d12 = _pair(k, q, cq1, 1.0, e1, 0.0, lc1, 0.0, lc1, ev * ic1)
    return d00, d11, d22, d01, d02, d12, 2.0 * mu_i * beta * ev   # qv's term: J dp/dJ


@numba.njit(inline="always")
def _plane_d(p11, p12, g00, g11, g22, g01, g02, g12, ic0, ic1, qv, Dp, mode):
    """D (16 for MODE_D2, 81 for MODE_D3) of one point into Dp from its principal directions
    (p11, p12: n_1 n_1's 11 and 12), gamma and qv."""
    P1_0, P1_1, P1_2 = p11, p12, 1.0 - p11
    P0_0, P0_1, P0_2 = 1.0 - p11, -p12, p11
    # T = P^T gamma P over the in-plane directions, P[a] = (11, 12, 22) of n_a n_a
    X00 = g00 * P0_0 + g01 * P1_0
    X01 = g00 * P0_1 + g01 * P1_1
    X02 = g00 * P0_2 + g01 * P1_2
    X10 = g01 * P0_0 + g11 * P1_0
    X11 = g01 * P0_1 + g11 * P1_1
    X12 = g01 * P0_2 + g11 * P1_2
    T00 = P0_0 * X00 + P1_0 * X10
    T01 = P0_0 * X01 + P1_0 * X11
    T02 = P0_0 * X02 + P1_0 * X12
    T10 = P0_1 * X00 + P1_1 * X10
    T11 = P0_1 * X01 + P1_1 * X11
    T12 = P0_1 * X02 + P1_1 * X12
    T20 = P0_2 * X00 + P1_2 * X10
    T21 = P0_2 * X01 + P1_2 * X11
    T22 = P0_2 * X02 + P1_2 * X12
    Ci0 = ic0 * P0_0 + ic1 * P1_0                        # C^-1 in-plane (11, 12, 22)
    Ci1 = ic0 * P0_1 + ic1 * P1_1
    Ci2 = ic0 * P0_2 + ic1 * P1_2
    qC0, qC1, qC2 = qv * Ci0, qv * Ci1, qv * Ci2
    # D_abcd = T[(ac),(bd)] + T[(ad),(bc)] + qv Cinv_ab Cinv_cd, (ab) -> 0 (11), 1 (12), 2 (22)
    d0000 = T00 + T00 + qC0 * Ci0
    d0001 = T01 + T10 + qC0 * Ci1
    d0010 = T10 + T01 + qC0 * Ci1
    d0011 = T11 + T11 + qC0 * Ci2
    d0100 = T01 + T01 + qC1 * Ci0
    d0101 = T02 + T11 + qC1 * Ci1
    d0110 = T11 + T02 + qC1 * Ci1
    d0111 = T12 + T12 + qC1 * Ci2
    d1000 = T10 + T10 + qC1 * Ci0
    d1001 = T11 + T20 + qC1 * Ci1
    d1010 = T20 + T11 + qC1 * Ci1
    d1011 = T21 + T21 + qC1 * Ci2
    d1100 = T11 + T11 + qC2 * Ci0
    d1101 = T12 + T21 + qC2 * Ci1
    d1110 = T21 + T12 + qC2 * Ci1
    d1111 = T22 + T22 + qC2 * Ci2
    if mode == MODE_D2:
        Dp[0], Dp[1], Dp[2], Dp[3] = d0000, d0001, d0010, d0011
        Dp[4], Dp[5], Dp[6], Dp[7] = d0100, d0101, d0110, d0111
        Dp[8], Dp[9], Dp[10], Dp[11] = d1000, d1001, d1010, d1011
        Dp[12], Dp[13], Dp[14], Dp[15] = d1100, d1101, d1110, d1111
        return
    for j in _ZERO81:
        Dp[j] = 0.0
    # in-plane block: index 27 i + 9 j + 3 k + l
    Dp[0], Dp[1], Dp[3], Dp[4] = d0000, d0001, d0010, d0011
    Dp[9], Dp[10], Dp[12], Dp[13] = d0100, d0101, d0110, d0111
    Dp[27], Dp[28], Dp[30], Dp[31] = d1000, d1001, d1010, d1011
    Dp[36], Dp[37], Dp[39], Dp[40] = d1100, d1101, d1110, d1111
    # D_ab33 = D_33ab = qv Cinv_ab; D_3333 = 2 gamma_33 + qv
    Dp[8], Dp[17], Dp[35], Dp[44] = qC0, qC1, qC1, qC2
    Dp[72], Dp[73], Dp[75], Dp[76] = qC0, qC1, qC1, qC2
    Dp[80] = 2.0 * g22 + qv
    # D_a3b3 = D_a33b = D_3ab3 = D_3a3b = sum_c gamma_c3 P_c,ab
    G0 = g02 * P0_0 + g12 * P1_0
    G1 = g02 * P0_1 + g12 * P1_1
    G2 = g02 * P0_2 + g12 * P1_2
    Dp[20], Dp[23], Dp[47], Dp[50] = G0, G1, G1, G2        # D_a3b3
    Dp[24], Dp[25], Dp[51], Dp[52] = G0, G1, G1, G2        # D_a33b
    Dp[56], Dp[59], Dp[65], Dp[68] = G0, G1, G1, G2        # D_3ab3
    Dp[60], Dp[61], Dp[69], Dp[70] = G0, G1, G1, G2        # D_3a3b


@njit(_SIG, cache=True, nogil=True, error_model="numpy")
def plane_kernel(C2, detF, has_detF, mu, alpha, beta, S, D, ok, mode, K, keep):
    """Plane-strain S (n, 3, 3), D (n, 16) or (n, 81) (mode MODE_D2 / MODE_D3; untouched for
    MODE_S) and ok (n,) of the points C2 (n, 2, 2), written into S, D, ok; with `keep` (MODE_S)
    the data K (n, KEPT_PLANE + 3 terms) from which `plane_tangent_kernel` gives D."""
    n = C2.shape[0]
    m = mu.shape[0]
    for p in range(n):
        c00, c01, c10, c11 = C2[p, 0, 0], C2[p, 0, 1], C2[p, 1, 0], C2[p, 1, 1]
        finite = (math.isfinite(c00) and math.isfinite(c01) and math.isfinite(c10)
                  and math.isfinite(c11))
        if not finite:                                       # flagged (ok False): any finite values
            c00 = c01 = c10 = c11 = 1.0
        # closed-form eigenvalues of the in-plane block of C - I: the one of larger magnitude
        # from mid +- r (r half the gap), the other from the determinant (no cancellation)
        a = c00 - 1.0
        b = c11 - 1.0
        c = 0.5 * (c01 + c10)
        h = 0.5 * (a - b)
        r = math.hypot(h, c)
        mid = 0.5 * (a + b)
        big = mid + r if mid >= 0.0 else mid - r
        det = a * b - c * c
        small = det / big if big != 0.0 else 0.0
        if mid >= 0.0:
            e0, e1 = small, big
        else:
            e0, e1 = big, small
        if r == 0.0:
            cos2, sin2 = 1.0, 0.0
        else:
            cos2, sin2 = h / r, c / r
        p11 = 0.5 * (1.0 + cos2)
        p12 = 0.5 * sin2
        # projectors n_a n_a as (11, 12, 22): direction 1 (larger e) is (I + R(2 theta)) / 2,
        # tan 2 theta = c / h; direction 0 its complement
        P1_0, P1_1, P1_2 = p11, p12, 1.0 - p11
        P0_0, P0_1, P0_2 = 1.0 - p11, -p12, p11
        lc0, e0, ok0 = _log_c(e0)
        lc1, e1, ok1 = _log_c(e1)
        okp = finite and ok0 and ok1
        if has_detF:
            okp = okp and detF[p] > 0.0
        lJ = 0.5 * (lc0 + lc1 + 0.0)
        ic0 = math.exp(-lc0)                                 # 1 / c_a
        ic1 = math.exp(-lc1)
        tangent = mode != MODE_S
        ell01 = math.log1p((e0 - e1) / (1.0 + e1)) if tangent else 0.0   # ln(c_0 / c_1)
        f0 = f1 = f2 = 0.0
        g00 = g11 = g22 = g01 = g02 = g12 = 0.0
        qv = 0.0
        if keep:
            Kp = K[p]
            Kp[0], Kp[1], Kp[2], Kp[3] = p11, p12, e0, e1
            Kp[4], Kp[5], Kp[6], Kp[7] = lc0, lc1, ic0, ic1
        for i in range(m):
            al = alpha[i]
            k = 2.0 * mu[i] / al
            xv = -al * beta * lJ
            h0 = 0.5 * al * lc0
            h1 = 0.5 * al * lc1
            if xv > EXP_CAP or h0 > EXP_CAP or h1 > EXP_CAP:
                okp = False
            ev = _pos(xv)                                    # J^(-alpha beta)
            pw0 = _pos(h0)                                   # c_a^(alpha/2)
            pw1 = _pos(h1)
            bl = beta * lJ
            # f(c_a) term: k (c^(alpha/2) - J^(-alpha beta)) / c = k (exp(x1) - exp(x2)),
            # x1 = (alpha/2 - 1) ln c, x2 = -alpha beta ln J - ln c, x1 - x2 = alpha (ln c/2 + beta ln J)
            f0 += k * _diff(pw0 * ic0, ev * ic0, al * (0.5 * lc0 + bl))
            f1 += k * _diff(pw1 * ic1, ev * ic1, al * (0.5 * lc1 + bl))
            f2 += k * _diff(1.0, ev, al * (0.0 + bl))
            if keep:
                Kp[KEPT_PLANE + 3 * i], Kp[KEPT_PLANE + 3 * i + 1], Kp[KEPT_PLANE + 3 * i + 2] = ev, pw0, pw1
            if tangent:
                d00, d11, d22, d01, d02, d12, dq = _plane_gamma(k, 0.5 * al - 1.0, mu[i], beta, ev, pw0, pw1,
                                                                ic0, ic1, e0, e1, lc0, lc1, ell01)
                g00 += d00
                g11 += d11
                g22 += d22
                g01 += d01
                g02 += d02
                g12 += d12
                qv += dq
        ok[p] = okp
        S[p, 0, 0] = f0 * P0_0 + f1 * P1_0
        S[p, 0, 1] = S[p, 1, 0] = f0 * P0_1 + f1 * P1_1
        S[p, 1, 1] = f0 * P0_2 + f1 * P1_2
        S[p, 2, 2] = f2
        S[p, 0, 2] = S[p, 1, 2] = S[p, 2, 0] = S[p, 2, 1] = 0.0
        if tangent:
            _plane_d(p11, p12, g00, g11, g22, g01, g02, g12, ic0, ic1, qv, D[p], mode)


@njit(_SIG_D, cache=True, nogil=True, error_model="numpy")
def plane_tangent_kernel(K, mu, alpha, beta, D, mode):
    """D (n, 16) or (n, 81) (MODE_D2 / MODE_D3) of the points whose data K `plane_kernel`
    kept: its tangent branch without the eigenproblem, logarithms, powers and stress, the same
    arithmetic on the same values (so the same bits as `plane_kernel` with that mode)."""
    m = mu.shape[0]
    for p in range(K.shape[0]):
        Kp = K[p]
        p11, p12, e0, e1 = Kp[0], Kp[1], Kp[2], Kp[3]
        lc0, lc1, ic0, ic1 = Kp[4], Kp[5], Kp[6], Kp[7]
        ell01 = math.log1p((e0 - e1) / (1.0 + e1))
        g00 = g11 = g22 = g01 = g02 = g12 = 0.0
        qv = 0.0
        for i in range(m):
            al = alpha[i]
            k = 2.0 * mu[i] / al
            ev, pw0, pw1 = Kp[KEPT_PLANE + 3 * i], Kp[KEPT_PLANE + 3 * i + 1], Kp[KEPT_PLANE + 3 * i + 2]
            d00, d11, d22, d01, d02, d12, dq = _plane_gamma(k, 0.5 * al - 1.0, mu[i], beta, ev, pw0, pw1,
                                                            ic0, ic1, e0, e1, lc0, lc1, ell01)
            g00 += d00
            g11 += d11
            g22 += d22
            g01 += d01
            g02 += d02
            g12 += d12
            qv += dq
        _plane_d(p11, p12, g00, g11, g22, g01, g02, g12, ic0, ic1, qv, D[p], mode)


# D_ijkl (index 27 i + 9 j + 3 k + l) = T[6 (ik) + (jl)] + T[6 (il) + (jk)] + qv Ci[(ij)] Ci[(kl)],
# (ab) the symmetric pair number of _PAIR_I / _PAIR_J (as hyperfoam._I6, _J6)
_PAIR_I = np.array([0, 1, 2, 1, 0, 0], dtype=np.int64)
_PAIR_J = np.array([0, 1, 2, 2, 2, 1], dtype=np.int64)


def _tables():
    V = np.empty((3, 3), np.int64)
    V[_PAIR_I, _PAIR_J] = V[_PAIR_J, _PAIR_I] = np.arange(6)
    i, j, k, l = np.indices((3, 3, 3, 3)).reshape(4, -1)
    return 6 * V[i, k] + V[j, l], 6 * V[i, l] + V[j, k], V[i, j], V[k, l]


_T1, _T2, _CI1, _CI2 = _tables()


@numba.njit(inline="always")
def _rotate(A, V, p, q):
    """One Jacobi rotation zeroing A[p, q] of the symmetric 3x3 A (both triangles kept),
    accumulated into the eigenvector columns V (Numerical Recipes' stable form)."""
    apq = A[p, q]
    h = A[q, q] - A[p, p]
    g = 100.0 * abs(apq)
    if abs(h) + g == abs(h):
        t = apq / h
    else:
        th = 0.5 * h / apq
        t = 1.0 / (abs(th) + math.sqrt(1.0 + th * th))
        if th < 0.0:
            t = -t
    c = 1.0 / math.sqrt(1.0 + t * t)
    s = t * c
    tau = s / (1.0 + c)
    A[p, p] -= t * apq
    A[q, q] += t * apq
    A[p, q] = A[q, p] = 0.0
    r = 3 - p - q                                            # the third index
    arp, arq = A[r, p], A[r, q]
    A[r, p] = A[p, r] = arp - s * (arq + tau * arp)
    A[r, q] = A[q, r] = arq + s * (arp - tau * arq)
    for k in range(3):
        vp, vq = V[k, p], V[k, q]
        V[k, p] = vp - s * (vq + tau * vp)
        V[k, q] = vq + s * (vp - tau * vq)


@numba.njit(inline="always")
def _eigh3(A, V):
    """Eigenvalues (the diagonal of A on return) and orthonormal eigenvectors (columns of V)
    of the symmetric 3x3 A by cyclic Jacobi: backward stable like LAPACK's eigh, and exact
    (no rotation) for an already diagonal A, such as C - I at rest or in plane strain.
    Off-diagonal entries negligible beside both diagonal ones are dropped after three sweeps."""
    for i in range(3):
        for j in range(3):
            V[i, j] = 1.0 if i == j else 0.0
    for sweep in range(60):
        if A[0, 1] == 0.0 and A[0, 2] == 0.0 and A[1, 2] == 0.0:
            return
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = A[p, q]
            if apq == 0.0:
                continue
            g = 100.0 * abs(apq)
            if sweep > 2 and abs(A[p, p]) + g == abs(A[p, p]) and abs(A[q, q]) + g == abs(A[q, q]):
                A[p, q] = A[q, p] = 0.0
            else:
                _rotate(A, V, p, q)


@numba.njit(inline="always")
def _point_scratch():
    """Per-thread scratch of the 3D point loops (`_solid`, `_solid_d`): V (3, 3), e, ln c,
    1/c, c^q, c^(alpha/2), gamma's diagonal (3 each), P (3, 6), T (36), C^-1 pairs (6)."""
    return (np.empty((3, 3)), np.empty(3), np.empty(3), np.empty(3), np.empty(3), np.empty(3),
            np.empty(3), np.empty((3, 6)), np.empty(36), np.empty(6))


@numba.njit(inline="always")
def _solid(C, detF, has_detF, mu, alpha, beta, S, D, ok, tangent, K, keep, first, last):
    """The point loop of solid_kernel over the points first .. last - 1 (keep: the spectral
    data into K, see KEPT)."""
    m = mu.shape[0]
    A = np.empty((3, 3))
    f = np.empty(3)
    V, e, lc, ic, cq, pw, gd, P, T, Ci = _point_scratch()
    for p in range(first, last):
        finite = True
        for i in range(3):
            for j in range(3):
                if not math.isfinite(C[p, i, j]):
                    finite = False
        for i in range(3):
            for j in range(3):
                A[i, j] = 0.5 * (C[p, i, j] + C[p, j, i]) - (1.0 if i == j else 0.0) if finite else 0.0
        _eigh3(A, V)
        okp = finite
        for a in range(3):
            lca, ea, oka = _log_c(A[a, a])
            lc[a], e[a] = lca, ea
            okp = okp and oka
            ic[a] = math.exp(-lca)
        if has_detF:
            okp = okp and detF[p] > 0.0
        lJ = 0.5 * (lc[0] + lc[1] + lc[2])
        bl = beta * lJ
        f[0] = f[1] = f[2] = 0.0
        gd[0] = gd[1] = gd[2] = 0.0
        g01 = g02 = g12 = 0.0
        qv = 0.0
        if tangent:
            ell01 = math.log1p((e[0] - e[1]) / (1.0 + e[1]))     # ln(c_a / c_b)
            ell02 = math.log1p((e[0] - e[2]) / (1.0 + e[2]))
            ell12 = math.log1p((e[1] - e[2]) / (1.0 + e[2]))
        for i in range(m):
            al = alpha[i]
            k = 2.0 * mu[i] / al
            xv = -al * bl
            if xv > EXP_CAP:
                okp = False
            ev = _pos(xv)                                    # J^(-alpha beta)
            q = 0.5 * al - 1.0
            for a in range(3):
                h = 0.5 * al * lc[a]
                if h > EXP_CAP:
                    okp = False
                pw[a] = _pos(h)                              # c_a^(alpha/2)
                cq[a] = pw[a] * ic[a]                        # c_a^q
                # k (c^(alpha/2) - J^(-alpha beta)) / c = k (exp(x1) - exp(x2)), x1 - x2 = alpha (ln c/2 + beta ln J)
                f[a] += k * _diff(cq[a], ev * ic[a], al * (0.5 * lc[a] + bl))
            if tangent:
                d01, d02, d12 = _gamma_term(k, q, cq, ic, ev, e, lc, ell01, ell02, ell12, gd)
                g01 += d01
                g02 += d02
                g12 += d12
                qv += 2.0 * mu[i] * beta * ev                # J dp/dJ
        ok[p] = okp
        for i in range(3):
            for j in range(i, 3):
                sij = f[0] * V[i, 0] * V[j, 0] + f[1] * V[i, 1] * V[j, 1] + f[2] * V[i, 2] * V[j, 2]
                S[p, i, j] = S[p, j, i] = sij
        if keep:
            Kp = K[p]
            for i in range(3):
                for j in range(3):
                    Kp[3 * i + j] = V[i, j]
            for a in range(3):
                Kp[9 + a], Kp[12 + a], Kp[15 + a] = e[a], lc[a], ic[a]
        if not tangent:
            continue
        _d_point(V, gd, g01, g02, g12, ic, qv, P, T, Ci, D[p])


@numba.njit(inline="always")
def _gamma_term(k, q, cq, ic, ev, e, lc, ell01, ell02, ell12, gd):
    """One term's share of the divided differences gamma: adds the diagonal into gd, returns
    the pairs (0,1), (0,2), (1,2)."""
    for a in range(3):
        gd[a] += k * (q * cq[a] * ic[a] + ev * ic[a] * ic[a])
    return (_pair(k, q, cq[0], cq[1], e[0], e[1], lc[0], lc[1], ell01, ev * ic[0] * ic[1]),
            _pair(k, q, cq[0], cq[2], e[0], e[2], lc[0], lc[2], ell02, ev * ic[0] * ic[2]),
            _pair(k, q, cq[1], cq[2], e[1], e[2], lc[1], lc[2], ell12, ev * ic[1] * ic[2]))


@numba.njit(inline="always")
def _d_point(V, gd, g01, g02, g12, ic, qv, P, T, Ci, Dp):
    """D (81) of one point from its eigenvectors V, gamma and qv (P, T, Ci: scratch)."""
    for a in range(3):                                       # P[a] = n_a n_a in pairs (ab)
        for r in range(6):
            P[a, r] = V[_PAIR_I[r], a] * V[_PAIR_J[r], a]
    for r in range(6):
        Ci[r] = ic[0] * P[0, r] + ic[1] * P[1, r] + ic[2] * P[2, r]
        x0 = gd[0] * P[0, r] + g01 * P[1, r] + g02 * P[2, r]   # (gamma P)[a, r]
        x1 = g01 * P[0, r] + gd[1] * P[1, r] + g12 * P[2, r]
        x2 = g02 * P[0, r] + g12 * P[1, r] + gd[2] * P[2, r]
        for c in range(6):
            T[6 * c + r] = P[0, c] * x0 + P[1, c] * x1 + P[2, c] * x2
    for j in range(81):
        Dp[j] = T[_T1[j]] + T[_T2[j]] + qv * Ci[_CI1[j]] * Ci[_CI2[j]]


# the per-point spectral data a stress evaluation keeps for a later D at the same state
# (`_solid` with keep, `_solid_d`): eigenvectors V (9, row-major), e (3), ln c (3), 1/c (3)
KEPT = 18


@numba.njit(inline="always")
def _solid_d(K, mu, alpha, beta, D, first, last):
    """D of points first .. last - 1 from their kept spectral data K (n, KEPT): the tangent
    branch of `_solid` without the eigenproblem, logarithms and stress, the same arithmetic
    (so the same bits as `_solid` with tangent at the state that wrote K)."""
    m = mu.shape[0]
    V, e, lc, ic, cq, pw, gd, P, T, Ci = _point_scratch()
    for p in range(first, last):
        Kp = K[p]
        for i in range(3):
            for j in range(3):
                V[i, j] = Kp[3 * i + j]
        for a in range(3):
            e[a], lc[a], ic[a] = Kp[9 + a], Kp[12 + a], Kp[15 + a]
        lJ = 0.5 * (lc[0] + lc[1] + lc[2])
        bl = beta * lJ
        gd[0] = gd[1] = gd[2] = 0.0
        g01 = g02 = g12 = 0.0
        qv = 0.0
        ell01 = math.log1p((e[0] - e[1]) / (1.0 + e[1]))
        ell02 = math.log1p((e[0] - e[2]) / (1.0 + e[2]))
        ell12 = math.log1p((e[1] - e[2]) / (1.0 + e[2]))
        for i in range(m):
            al = alpha[i]
            k = 2.0 * mu[i] / al
            ev = _pos(-al * bl)
            q = 0.5 * al - 1.0
            for a in range(3):
                pw[a] = _pos(0.5 * al * lc[a])
                cq[a] = pw[a] * ic[a]
            d01, d02, d12 = _gamma_term(k, q, cq, ic, ev, e, lc, ell01, ell02, ell12, gd)
            g01 += d01
            g02 += d02
            g12 += d12
            qv += 2.0 * mu[i] * beta * ev
        _d_point(V, gd, g01, g02, g12, ic, qv, P, T, Ci, D[p])


# compiled on first call (no signature): programs that never solve in 3D do not pay its ~6 s
# compile on a fresh install; hyperfoam.pk2_tangent_solid passes one layout (C-contiguous)
@njit(cache=True, nogil=True, error_model="numpy")
def solid_kernel(C, detF, has_detF, mu, alpha, beta, S, D, ok, tangent, K, keep):
    """S (n, 3, 3), D (n, 81) (untouched unless `tangent`), ok (n,) and, with `keep`, the
    spectral data K (n, KEPT) of the points C (n, 3, 3), written into S, D, ok, K:
    `hyperfoam.pk2_tangent` point by point, with the eigenproblem of C - I solved by `_eigh3`."""
    _solid(C, detF, has_detF, mu, alpha, beta, S, D, ok, tangent, K, keep, 0, C.shape[0])


@njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def solid_kernel_parallel(C, detF, has_detF, mu, alpha, beta, S, D, ok, tangent, K, keep, chunks):
    """solid_kernel on `chunks` contiguous point ranges run by numba's threads (as many at
    once as numba.set_num_threads allows); the same arithmetic per point, so the same bits."""
    n = C.shape[0]
    for c in numba.prange(chunks):
        _solid(C, detF, has_detF, mu, alpha, beta, S, D, ok, tangent, K, keep, c * n // chunks,
               (c + 1) * n // chunks)


@njit(cache=True, nogil=True, error_model="numpy")
def solid_tangent_kernel(K, mu, alpha, beta, D):
    """D (n, 81) of the points whose spectral data K (n, KEPT) `solid_kernel` kept."""
    _solid_d(K, mu, alpha, beta, D, 0, K.shape[0])


@njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def solid_tangent_kernel_parallel(K, mu, alpha, beta, D, chunks):
    """solid_tangent_kernel on `chunks` point ranges on numba's threads (the same bits)."""
    n = K.shape[0]
    for c in numba.prange(chunks):
        _solid_d(K, mu, alpha, beta, D, c * n // chunks, (c + 1) * n // chunks)


def as_kernel_input(x, shape):
    """x as a float64 array of `shape` the compiled kernel accepts (writable: numba rejects
    read-only arrays such as np.broadcast_to views); a view where possible."""
    x = np.asarray(x, dtype=float).reshape(shape)
    if not x.flags.writeable:
        x = np.array(x)
    return x
