"""Shared machinery of the isotropic hyperelastic laws written in scalar invariants.

A law gives its energy W as a function of a few scalar functions of C (I1 = tr C,
I2 = (I1^2 - tr C^2)/2, J = sqrt(det C), T_a = tr C^(a/2)) and returns, per point, W, its
gradient w_k = dW/dx_k and Hessian w_kl over those scalars. With G_k = dx_k/dC and
H_k = d^2 x_k / dC dC:

    S = 2 dW/dC = 2 sum_k w_k G_k,
    D = 2 dS/dC = 4 (sum_kl w_kl G_k (x) G_l + sum_k w_k H_k),

which has minor and major symmetry by construction. G and H:
    I1: I, 0;   I2: I1 I - C, I (x) I - II;   J: J/2 C^-1, J/4 C^-1 (x) C^-1 - J/2 II_C^-1;
    T_a: (a/2) C^(a/2-1) = sum_p h(c_p) n_p n_p, H from the Daleckii-Krein formula
    (divided differences of h(c) = (a/2) c^(a/2-1), exact down to coincident stretches),
with II_ijkl = (d_ik d_jl + d_il d_jk)/2 and II_A the same with A in place of d.

`isochoric_chain` turns derivatives in the isochoric invariants I1b = J^(-2/3) I1,
I2b = J^(-4/3) I2 (the form neo-Hookean, Mooney-Rivlin and Yeoh are written in) into
derivatives in (I1, I2, J). `plane_from_3d` is the plane-strain wrapper of any 3D law.

Vectorised numpy (no compiled path): these laws cost a few times the hyperfoam's numba
plane loop per point; they are not the paper's law and the solve time is dominated by
assembly and the linear solver at these sizes.

Admissibility: det C <= 0, a non-finite C or detF <= 0 (if given) sets ok = False; those
points are evaluated at C = I (finite, meaningless values), so Newton backtracks.
"""

from __future__ import annotations

import numpy as np

from tactileskin.errors import ParameterError

_I3 = np.eye(3)
_II = 0.5 * (np.einsum("ik,jl->ijkl", _I3, _I3) + np.einsum("il,jk->ijkl", _I3, _I3))
_H_I2 = np.einsum("ij,kl->ijkl", _I3, _I3) - _II


def _outer(A, B):
    return A[..., :, :, None, None] * B[..., None, None, :, :]


def _sym_box(A):
    """II_A: (A_ik A_jl + A_il A_jk) / 2 for symmetric A (..., 3, 3)."""
    return 0.5 * (np.einsum("...ik,...jl->...ijkl", A, A) + np.einsum("...il,...jk->...ijkl", A, A))


class Kinematics:
    """Scalar functions of C and their first/second derivatives, computed once per call."""

    def __init__(self, C, detF=None):
        C = np.asarray(C, dtype=float)
        if C.ndim < 2 or C.shape[-2:] != (3, 3):
            raise ParameterError("C.shape", C.shape, "(..., 3, 3)")
        self.lead = C.shape[:-2]
        C = C.reshape((-1, 3, 3))
        finite = np.all(np.isfinite(C), axis=(-2, -1))
        C = np.where(finite[:, None, None], C, _I3)
        C = 0.5 * (C + np.swapaxes(C, -1, -2))
        detC = np.linalg.det(C)
        ok = finite & (detC > 0.0)
        if detF is not None:
            ok &= np.broadcast_to(np.asarray(detF, dtype=float), self.lead).reshape(-1) > 0.0
        self.ok = ok
        self.C = np.where(ok[:, None, None], C, _I3)
        self.detC = np.where(ok, detC, 1.0)
        self._cache = {}

    # --- scalars --------------------------------------------------------------------------
    @property
    def J(self):
        return np.sqrt(self.detC)

    @property
    def I1(self):
        return np.trace(self.C, axis1=-2, axis2=-1)

    @property
    def I2(self):
        I1 = self.I1
        return 0.5 * (I1 * I1 - np.einsum("...ij,...ji->...", self.C, self.C))

    @property
    def Cinv(self):
        if "Cinv" not in self._cache:
            Ci = np.linalg.inv(self.C)
            self._cache["Cinv"] = 0.5 * (Ci + np.swapaxes(Ci, -1, -2))
        return self._cache["Cinv"]

    def spectral(self):
        """(e, Q, lc): eigenvalues e of C - I (accurate at small strain), eigenvectors, ln c."""
        if "spec" not in self._cache:
            e, Q = np.linalg.eigh(self.C - _I3)
            e = np.maximum(e, -1.0 + 1e-300)
            self._cache["spec"] = (e, Q, np.log1p(e))
        return self._cache["spec"]

    def T(self, a):
        """tr C^(a/2) = sum_p c_p^(a/2)."""
        _, _, lc = self.spectral()
        return np.exp(0.5 * a * lc).sum(axis=-1)

    # --- derivatives ----------------------------------------------------------------------
    def G(self, name, a=None):
        if name == "I1":
            return np.broadcast_to(_I3, self.C.shape)
        if name == "I2":
            return self.I1[:, None, None] * _I3 - self.C
        if name == "J":
            return 0.5 * self.J[:, None, None] * self.Cinv
        if name == "T":
            e, Q, lc = self.spectral()
            h = 0.5 * a * np.exp((0.5 * a - 1.0) * lc)
            return (Q * h[:, None, :]) @ np.swapaxes(Q, -1, -2)
        raise KeyError(name)

    def H(self, name, a=None):
        """Second derivative (n, 3, 3, 3, 3), or None where it vanishes."""
        if name == "I1":
            return None
        if name == "I2":
            return np.broadcast_to(_H_I2, self.C.shape[:1] + (3, 3, 3, 3))
        if name == "J":
            J = self.J[:, None, None, None, None]
            Ci = self.Cinv
            return 0.25 * J * _outer(Ci, Ci) - 0.5 * J * _sym_box(Ci)
        if name == "T":
            return self._H_T(a)
        raise KeyError(name)

    def _H_T(self, a):
        """d^2 tr C^(a/2) / dC dC = d h(C) / dC, h(c) = (a/2) c^q, q = a/2 - 1 (Daleckii-Krein):
        1/2 sum_pq Gam_pq (n_p,i n_p,k n_q,j n_q,l + n_p,i n_p,l n_q,j n_q,k)."""
        e, Q, lc = self.spectral()
        q = 0.5 * a - 1.0
        k = 0.5 * a
        gam = np.empty(e.shape + (3,))
        for p in range(3):
            for r in range(3):
                if p == r:
                    gam[:, p, p] = k * q * np.exp((q - 1.0) * lc[:, p])
                    continue
                gap = e[:, p] - e[:, r]                     # c_p - c_r without cancellation
                ell = np.log1p(gap / (1.0 + e[:, r]))        # ln(c_p / c_r)
                same = np.abs(gap) <= 1e-14 * np.maximum(1.0 + e[:, p], 1.0 + e[:, r])
                # c_p^q - c_r^q = c_r^q expm1(q ell): accurate for any gap
                num = np.exp(q * lc[:, r]) * np.expm1(q * ell)
                dd = np.where(same, q * np.exp((q - 1.0) * 0.5 * (lc[:, p] + lc[:, r])),
                              num / np.where(same, 1.0, gap))
                gam[:, p, r] = k * dd
        t1 = np.einsum("npq,nip,nkp,njq,nlq->nijkl", gam, Q, Q, Q, Q, optimize=True)
        return 0.5 * (t1 + np.swapaxes(t1, -1, -2))


def assemble(kin: Kinematics, names, grad, hess, *, tangent=True):
    """S (n, 3, 3) and D (n, 3, 3, 3, 3) (or None) from the law's gradient (n, m) and Hessian
    (n, m, m) over the scalars `names` (each "I1", "I2", "J" or ("T", a))."""
    Gs, Hs = [], []
    for nm in names:
        key, a = (nm, None) if isinstance(nm, str) else nm
        Gs.append(kin.G(key, a))
        Hs.append(kin.H(key, a) if tangent else None)
    S = 2.0 * sum(grad[:, i, None, None] * G for i, G in enumerate(Gs))
    if not tangent:
        return S, None
    D = np.zeros(S.shape[:1] + (3, 3, 3, 3))
    m = len(names)
    for i in range(m):
        if Hs[i] is not None:
            D += grad[:, i, None, None, None, None] * Hs[i]
        for j in range(m):
            w = hess[:, i, j]
            if np.any(w):
                D += w[:, None, None, None, None] * _outer(Gs[i], Gs[j])
    return S, 4.0 * D


def isochoric_chain(I1, I2, J, w1, w2, w11, w12, w22):
    """Gradient (n, 3) and Hessian (n, 3, 3) over (I1, I2, J) of W(I1b, I2b) given its
    derivatives in I1b = J^(-2/3) I1, I2b = J^(-4/3) I2 (w2, w12, w22 may be 0)."""
    a1, a2 = J ** (-2.0 / 3.0), J ** (-4.0 / 3.0)
    I1b, I2b = a1 * I1, a2 * I2
    # first and second partials of I1b and I2b over (I1, I2, J)
    d1 = np.stack([a1, 0.0 * J, -2.0 / 3.0 * I1b / J], axis=-1)
    d2 = np.stack([0.0 * J, a2, -4.0 / 3.0 * I2b / J], axis=-1)
    h1 = np.zeros(J.shape + (3, 3))
    h1[:, 0, 2] = h1[:, 2, 0] = -2.0 / 3.0 * a1 / J
    h1[:, 2, 2] = 10.0 / 9.0 * I1b / J**2
    h2 = np.zeros(J.shape + (3, 3))
    h2[:, 1, 2] = h2[:, 2, 1] = -4.0 / 3.0 * a2 / J
    h2[:, 2, 2] = 28.0 / 9.0 * I2b / J**2
    w1, w2, w11, w12, w22 = (np.broadcast_to(x, J.shape) for x in (w1, w2, w11, w12, w22))
    grad = w1[:, None] * d1 + w2[:, None] * d2
    hess = (w11[:, None, None] * d1[:, :, None] * d1[:, None, :]
            + w12[:, None, None] * (d1[:, :, None] * d2[:, None, :] + d2[:, :, None] * d1[:, None, :])
            + w22[:, None, None] * d2[:, :, None] * d2[:, None, :]
            + w1[:, None, None] * h1 + w2[:, None, None] * h2)
    return grad, hess, I1b, I2b


def volumetric(kappa, J):
    """U = kappa/2 (J - 1)^2 (Abaqus's (J - 1)^2 / D1 with D1 = 2 / kappa): U, U', U''."""
    return 0.5 * kappa * (J - 1.0) ** 2, kappa * (J - 1.0), np.full_like(J, kappa)


def finish(kin: Kinematics, S, D):
    """Reshape the flat (n, ...) outputs to the caller's leading shape."""
    lead = kin.lead
    S = S.reshape(lead + (3, 3))
    D = None if D is None else D.reshape(lead + (3, 3, 3, 3))
    return S, D, kin.ok.reshape(lead)


def plane_from_3d(pk2_tangent, C2, *, detF=None, out_of_plane=False, tangent=True):
    """Plane-strain law from a 3D one: C2 (..., 2, 2) embedded in 3x3 with C33 = 1,
    C13 = C23 = 0; returns S (..., 3, 3), D (..., 2, 2, 2, 2) (the in-plane block; the full
    (..., 3, 3, 3, 3) with out_of_plane=True; None with tangent=False) and ok."""
    C2 = np.asarray(C2, dtype=float)
    if C2.ndim < 2 or C2.shape[-2:] != (2, 2):
        raise ParameterError("C2.shape", C2.shape, "(..., 2, 2)")
    C = np.zeros(C2.shape[:-2] + (3, 3))
    C[..., :2, :2] = C2
    C[..., 2, 2] = 1.0
    S, D, ok = pk2_tangent(C, detF=detF, tangent=tangent)
    if D is not None and not out_of_plane:
        D = D[..., :2, :2, :2, :2]
    return S, D, ok


def kappa_from_nu(mu0: float, nu: float) -> float:
    """Small-strain bulk modulus K = 2 mu0 (1 + nu) / (3 (1 - 2 nu))."""
    return 2.0 * mu0 * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu))


def positive(name: str, value, unit: str = "MPa") -> float:
    from tactileskin.errors import check_range

    return check_range(name, value, 0.0, None, lo_open=True, unit=unit)


def finite(name: str, value, unit: str = "MPa") -> float:
    from tactileskin.errors import check_range

    return check_range(name, value, unit=unit)


class InvariantLaw:
    """Mixin of the laws evaluated through `Kinematics` and `assemble`: a law defines
    `_derivs(kin) -> (names, W, grad, hess)` (flat points) and the properties mu0, K0."""

    def _derivs(self, kin):  # pragma: no cover - abstract
        raise NotImplementedError

    def energy(self, C, *, detF=None):
        """Strain energy density W (MPa) for C (..., 3, 3)."""
        kin = Kinematics(C, detF)
        return self._derivs(kin)[1].reshape(kin.lead)

    def pk2_tangent(self, C, *, detF=None, tangent=True):
        """S (..., 3, 3), D = 2 dS/dC (..., 3, 3, 3, 3) (None if tangent=False) and ok (...)."""
        kin = Kinematics(C, detF)
        names, _, grad, hess = self._derivs(kin)
        S, D = assemble(kin, names, grad, hess, tangent=tangent)
        return finish(kin, S, D)

    def pk2(self, C, *, detF=None):
        S, _, ok = self.pk2_tangent(C, detF=detF, tangent=False)
        return S, ok

    def pk2_tangent_plane(self, C2, *, detF=None, out_of_plane=False, tangent=True):
        """Plane strain through the 3D law (`plane_from_3d`)."""
        return plane_from_3d(self.pk2_tangent, C2, detF=detF, out_of_plane=out_of_plane, tangent=tangent)


def read_table(d, keys, what, *, optional=()):
    """Check a law's parameter table: a table, only `keys` + `optional`, all of `keys`."""
    from tactileskin import validate

    d = validate.table(d, what)
    validate.known_keys(d, tuple(keys) + tuple(optional), what)
    missing = [k for k in keys if k not in d]
    if missing:
        raise ParameterError(what, sorted(d), "keys " + ", ".join(keys), "missing " + ", ".join(missing))
    return d
