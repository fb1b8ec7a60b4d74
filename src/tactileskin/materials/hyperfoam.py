"""Storakers hyperfoam (Abaqus HYPERFOAM), any number of terms, as pure vectorised functions.

    U = sum_i 2 mu_i / alpha_i^2 [ l1^a_i + l2^a_i + l3^a_i - 3 + (J^(-a_i beta) - 1) / beta ],
    beta = nu / (1 - 2 nu).

Written in the eigenvalues c_a = l_a^2 of the right Cauchy-Green tensor C:
U = sum_a phi(c_a) + V(J), phi(c) = sum_i 2 mu_i/alpha_i^2 (c^(alpha_i/2) - 1),
V(J) = sum_i 2 mu_i/(alpha_i^2 beta) (J^(-alpha_i beta) - 1).  Then

    S = sum_a f(c_a) n_a n_a,   f(c) = sum_i k_i (c^(alpha_i/2) - J^(-alpha_i beta)) / c,
    k_i = 2 mu_i / alpha_i,

and D = 2 dS/dC follows from the Daleckii-Krein formula (divided differences of
g(c) = sum_i k_i c^(alpha_i/2 - 1)) plus the standard volumetric tangent.

Numerical care (see docs/architecture.md, "hard cases"):
* Everything is evaluated from ln c_a = log1p(e_a), where e_a are the eigenvalues of C - I
  (not of C): at strain 1e-8 the eigenvalues of C carry an absolute error of 1e-16,
  i.e. a relative error of 1e-8 in the strain, those of C - I do not.
* alpha -> 0 (silicone alpha_1 = 0.001): c^(alpha/2) - J^(-alpha beta) is formed as
  exp(x2) * expm1(x1 - x2) with x1 - x2 = alpha (ln l + beta ln J) computed directly, so
  the 1/alpha in k_i never meets a cancelled difference. The energy uses
  psi2(x) = (expm1(x) - x)/x^2, free of 1/alpha and of 1/beta.
* Divided differences (g(c_a) - g(c_b))/(c_a - c_b) use the same exp * expm1 form, which is
  accurate for any gap down to exact coincidence (equal stretches, the undeformed state);
  at exactly zero gap the derivative g'(c_a) is used. No threshold approximation, no NaN.
* Overflow guard: an exponent (-alpha_i beta ln J or alpha_i/2 ln c_a) above EXP_CAP, or
  |ln c_a| above LOG_C_CAP, or c_a <= 0, or a non-finite C, or detF <= 0 (if given) marks
  the point inadmissible (ok=False); its values are computed from clipped exponents, so
  they are finite but meaningless. EXP_CAP = 300 is far beyond any physical state: it means
  a stress of ~1e130 MPa (silicone term 2, alpha beta = 379.75: J < exp(-300/379.75) = 0.454;
  the confined-compression stress is already 4e5 MPa at J = 0.95).

Three implementations: `pk2_tangent` (3x3 eigh, numpy: the readable one, the oracle of the
other two, and the energy's), and two compiled point loops of `_hyperfoam_nb`, several times
faster (benchmarks/hyperfoam_law.py): `pk2_tangent_solid` (any 3x3 C: the eigenproblem by
Jacobi rotations; the `Hyperfoam.pk2_tangent` of the 3D solver) and `pk2_tangent_plane`
(plane strain: e_z is a principal direction with c_3 = 1, so the 2x2 eigenproblem has a
closed form); tangent=False skips D in both. In numpy, per-term arrays put the term axis
first; large inputs are evaluated in blocks of _BLOCK points written straight into the
outputs.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tactileskin.errors import ParameterError

log = logging.getLogger(__name__)

EXP_CAP = 300.0    # largest admissible exponent: e^300 ~ 2e130 (finite even when squared)
LOG_C_CAP = 30.0   # |ln c_a| <= 30: principal stretches in [3.1e-7, 3.3e6]
_CLIP = EXP_CAP + 4.0 * LOG_C_CAP  # internal clip: every exp() argument stays below this

__all__ = ["Hyperfoam", "energy", "pk2_tangent", "pk2_tangent_plane", "pk2", "pk2_kept_solid", "tangent_kept_solid", "pk2_kept_plane", "tangent_kept_plane",
           "cauchy_principal", "EXP_CAP", "LOG_C_CAP"]


# Abaqus's hyperfoam takes N <= 6 terms and published fits use 1-3; each term costs an exp()
# per principal stretch at every quadrature point of every assembly, so 8 leaves headroom
# while bounding that cost.
MAX_TERMS = 8
# |alpha| above this overflows lambda^alpha at moderate stretch (1.5^100 = 4e17); published
# hyperfoam and Ogden fits stay within +-30
MAX_ALPHA = 100.0


def _as_float_tuple(name, value) -> tuple[float, ...]:
    try:
        t = tuple(float(v) for v in np.atleast_1d(np.asarray(value, dtype=float)).ravel())
    except (TypeError, ValueError):
        raise ParameterError(name, value, "a sequence of finite numbers") from None
    return t


@dataclass(frozen=True)
class Hyperfoam:
    """Storakers hyperfoam parameters. mu (MPa) and alpha: one entry per term; nu: Poisson ratio."""

    mu: tuple[float, ...]
    alpha: tuple[float, ...]
    nu: float

    law: ClassVar[str] = "hyperfoam"

    def __post_init__(self):
        mu = _as_float_tuple("mu", self.mu)
        alpha = _as_float_tuple("alpha", self.alpha)
        if len(mu) == 0:
            raise ParameterError("mu", self.mu, "at least one term")
        if len(mu) > MAX_TERMS:
            raise ParameterError("mu", f"{len(mu)} terms", f"at most {MAX_TERMS} terms")
        if len(alpha) != len(mu):
            raise ParameterError("alpha", self.alpha, f"{len(mu)} values (one per mu term)")
        for i, (m, a) in enumerate(zip(mu, alpha)):
            if not math.isfinite(m) or m == 0.0:
                raise ParameterError(f"mu[{i}]", m, "a finite non-zero number (MPa)")
            if not math.isfinite(a) or a == 0.0 or abs(a) > MAX_ALPHA:
                raise ParameterError(f"alpha[{i}]", a, f"a non-zero number in [-{MAX_ALPHA:g}, {MAX_ALPHA:g}]")
        try:
            nu = float(self.nu)
        except (TypeError, ValueError):
            raise ParameterError("nu", self.nu, "(-1, 0.5)") from None
        if not (-1.0 < nu < 0.5):
            raise ParameterError("nu", self.nu, "(-1, 0.5)")
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "alpha", alpha)
        object.__setattr__(self, "nu", nu)
        if not (self.mu0 > 0.0):
            raise ParameterError("mu", mu, "sum(mu_i) > 0 (initial shear modulus)",
                                 "each term's mu_i*alpha_i sign convention as in Abaqus")
        if not (self.K0 > 0.0):
            raise ParameterError("nu", nu, "a value giving a positive initial bulk modulus")

    @property
    def beta(self) -> float:
        return self.nu / (1.0 - 2.0 * self.nu)

    @property
    def mu0(self) -> float:
        """Initial shear modulus sum(mu_i) (MPa)."""
        return float(sum(self.mu))

    @property
    def K0(self) -> float:
        """Initial bulk modulus sum(2 mu_i (1/3 + beta)) (MPa)."""
        return float(sum(2.0 * m * (1.0 / 3.0 + self.beta) for m in self.mu))

    @property
    def n_terms(self) -> int:
        return len(self.mu)

    def to_dict(self) -> dict:
        return {"mu": list(self.mu), "alpha": list(self.alpha), "nu": self.nu}

    @classmethod
    def from_dict(cls, d, what="hyperfoam") -> "Hyperfoam":
        """From a TOML table {mu, alpha, nu} (keys and types checked, ranges by the class)."""
        from tactileskin import validate

        hf = validate.table(d, what)
        validate.known_keys(hf, ("mu", "alpha", "nu"), what)
        missing = [k for k in ("mu", "alpha", "nu") if k not in hf]
        if missing:
            raise ParameterError(what, sorted(hf), "keys mu, alpha, nu", "missing " + ", ".join(missing))
        return cls(validate.number_list(hf["mu"], "mu", MAX_TERMS, min_len=1),
                   validate.number_list(hf["alpha"], "alpha", MAX_TERMS, min_len=1),
                   validate.number(hf["nu"], "nu"))

    # the law interface of materials.laws (the module functions below do the work)
    def energy(self, C, *, detF=None):
        return energy(self, C, detF=detF)

    def pk2(self, C, *, detF=None):
        return pk2(self, C, detF=detF)

    def pk2_tangent(self, C, *, detF=None, tangent=True):
        """The compiled 3x3 point loop (`pk2_tangent_solid`); tangent=False skips D."""
        return pk2_tangent_solid(self, C, detF=detF, tangent=tangent)

    def pk2_kept(self, C, *, detF=None):
        """(S, ok, kept): S of `pk2_tangent(tangent=False)` and the spectral data from which
        `tangent_kept(kept)` gives D at the same C (`pk2_kept_solid`)."""
        return pk2_kept_solid(self, C, detF=detF)

    def tangent_kept(self, kept, in_plane: bool = False):
        """D from the data `pk2_kept` or `pk2_kept_plane` kept; in_plane: only the in-plane
        block D[..., :2, :2, :2, :2] (the same bits; a 2D model's tangent needs no more)."""
        if isinstance(kept, PlaneKept):
            return tangent_kept_plane(self, kept, in_plane=in_plane)
        D = tangent_kept_solid(self, kept)
        return np.ascontiguousarray(D[..., :2, :2, :2, :2]) if in_plane else D

    def pk2_tangent_plane(self, C2, *, detF=None, out_of_plane=False, tangent=True):
        return pk2_tangent_plane(self, C2, detF=detF, out_of_plane=out_of_plane, tangent=tangent)

    def pk2_kept_plane(self, C2, *, detF=None, out_of_plane=False):
        """(S, ok, kept): S of `pk2_tangent_plane(tangent=False)` and the data from which
        `tangent_kept(kept)` gives its D at the same C2 (`pk2_kept_plane`)."""
        return pk2_kept_plane(self, C2, detF=detF, out_of_plane=out_of_plane)

    # fitting (materials.fit): x = (mu_1..mu_n, alpha_1..alpha_n), nu given
    @staticmethod
    def fit_start(mu0, terms=2):
        alphas = [2.0, -2.0, 5.0, -4.0, 8.0, 1.0][:terms]
        x0 = np.array([mu0 / terms] * terms + alphas)
        return x0, (np.full(2 * terms, -np.inf), np.full(2 * terms, np.inf))

    @classmethod
    def from_fit(cls, x, nu):
        n = len(x) // 2
        return cls(tuple(x[:n]), tuple(x[n:]), nu)


# --- scalar helpers (elementwise) ---------------------------------------------------------

def _exp(x):
    return np.exp(np.minimum(x, _CLIP))


def _diffexp(x1, x2, d):
    """exp(x1) - exp(x2) with d = x1 - x2 supplied accurately (no cancellation)."""
    neg = d <= 0.0
    base = np.where(neg, x2, x1)
    dd = np.where(neg, d, -d)
    mag = _exp(base) * np.expm1(np.maximum(dd, -_CLIP))
    return np.where(neg, mag, -mag)


def _psi2(x):
    """(expm1(x) - x) / x^2, accurate for all x (series near 0); psi2(0) = 1/2."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 0.5
    xs = np.where(small, x, 0.0)
    # Horner on sum_{k>=2} x^(k-2)/k!; 20 terms: truncation 0.5^19/21! ~ 4e-26
    acc = np.zeros_like(xs)
    for k in range(21, 1, -1):
        acc = acc * xs + 1.0 / math.factorial(k)
    xl = np.where(small, 1.0, np.minimum(x, _CLIP))
    big = (np.expm1(xl) - xl) / (xl * xl)
    return np.where(small, acc, big)


# --- kinematics ---------------------------------------------------------------------------

def _spectral(C, detF=None):
    """Eigen-decomposition of C - I. Returns e (...,3), Q (...,3,3) (columns n_a), lc, lJ, ok."""
    C = np.asarray(C, dtype=float)
    if C.shape[-2:] != (3, 3):
        raise ParameterError("C.shape", C.shape, "(..., 3, 3)")
    finite = np.all(np.isfinite(C), axis=(-2, -1))
    E = C - np.eye(3)
    E = np.where(finite[..., None, None], E, 0.0)
    E = 0.5 * (E + np.swapaxes(E, -1, -2))
    e, Q = np.linalg.eigh(E)
    ok = finite & np.all(e > -1.0, axis=-1)
    pd = e > -1.0
    lc_raw = np.where(pd, np.log1p(np.where(pd, e, 0.0)), -2.0 * LOG_C_CAP)
    ok &= np.all(np.abs(lc_raw) <= LOG_C_CAP, axis=-1)
    lc = np.clip(lc_raw, -LOG_C_CAP, LOG_C_CAP)
    # keep e consistent with the clipped logarithms so that divided differences stay finite
    e = np.where(lc_raw == lc, e, np.expm1(lc))
    if detF is not None:
        ok &= np.asarray(detF) > 0.0
    lJ = 0.5 * lc.sum(axis=-1)
    return e, Q, lc, lJ, ok


_IA, _IB, _ID = np.array([0, 0, 1]), np.array([1, 2, 2]), np.arange(3)


def _spectral_sum(Q, w):
    """sum_a w_a n_a n_a^T for eigenvector columns Q (..., 3, 3) and weights w (..., 3)."""
    return (Q * w[..., None, :]) @ np.swapaxes(Q, -1, -2)


def _params(mat: Hyperfoam):
    mu = np.asarray(mat.mu)
    alpha = np.asarray(mat.alpha)
    return mu, alpha, 2.0 * mu / alpha, mat.beta


def _terms(v, like):
    """Per-term parameters (m,) shaped (m, 1, ..., 1) to broadcast against `like`.

    The term axis leads: numpy's inner loops then run over the contiguous points instead of
    over the 1-3 terms (several times faster than a trailing term axis)."""
    return np.reshape(v, (-1,) + (1,) * np.ndim(like))


def _guard(ok, alpha, beta, lc, lJ):
    """Flag exponents above EXP_CAP (both the deviatoric and the volumetric ones)."""
    xv = -_terms(alpha, lJ) * beta * lJ                      # (m, ...)
    xd = 0.5 * _terms(alpha, lc) * lc                        # (m, ..., 3)
    ok = ok & np.all(xv <= EXP_CAP, axis=0) & np.all(xd <= EXP_CAP, axis=(0, -1))
    return ok


# --- public functions ---------------------------------------------------------------------

def energy(mat: Hyperfoam, C, *, detF=None):
    """Strain energy density U (MPa) for C (..., 3, 3). Inadmissible states give finite values."""
    _, _, lc, lJ, _ = _spectral(C, detF)   # clipped logs: finite everywhere
    mu, alpha, _, beta = _params(mat)
    la = 0.5 * lc[..., :, None]                              # ln(stretch), (..., 3, 1)
    dev = np.sum(la * la * _psi2(alpha * la), axis=-2)       # (..., m)
    vol = beta * lJ[..., None] ** 2 * _psi2(-alpha * beta * lJ[..., None])
    return np.sum(2.0 * mu * (dev + vol), axis=-1)


def _principal_f(mu, alpha, k, beta, lc, lJ):
    """f(c_a) = sum_i k_i (c_a^(alpha_i/2) - J^(-alpha_i beta)) / c_a, shape (..., 3)."""
    a = _terms(alpha, lc)                                    # (m, 1, ..., 1)
    lJ3 = lJ[..., None]
    x1 = (0.5 * a - 1.0) * lc
    x2 = -a * beta * lJ3 - lc
    d = a * (0.5 * lc + beta * lJ3)
    return np.sum(_terms(k, lc) * _diffexp(x1, x2, d), axis=0)


def pk2(mat: Hyperfoam, C, *, detF=None):
    """Second Piola-Kirchhoff stress S (..., 3, 3) and ok mask (no tangent)."""
    e, Q, lc, lJ, ok = _spectral(C, detF)
    mu, alpha, k, beta = _params(mat)
    ok = _guard(ok, alpha, beta, lc, lJ)
    f = _principal_f(mu, alpha, k, beta, lc, lJ)
    return _spectral_sum(Q, f), ok


def _gamma(mu, alpha, k, beta, e, lc, lJ):
    """Divided differences gamma (..., 3, 3) and qv = J dp/dJ (...) of the spectral tangent.

    gamma_ab: divided differences of g(c) + p/c at fixed J, where g(c) = sum k_i c^(q_i),
    q_i = alpha_i/2 - 1, and p = -sum k_i J^(-alpha_i beta) (the volumetric part of S is p C^-1).
    """
    kt = _terms(k, lc)                                       # (m, 1, ..., 1): term axis first
    q = _terms(0.5 * alpha - 1.0, lc)
    xv = -_terms(alpha, lJ) * beta * lJ                      # (m, ...)
    ev = _exp(xv)                                            # J^(-alpha_i beta)
    xv3 = xv[..., None]                                      # (m, ..., 1)
    # diagonal a = b: g'(c_a) + J^(-alpha beta) / c_a^2
    gdiag = np.sum(kt * (q * _exp((q - 1.0) * lc) + _exp(xv3 - 2.0 * lc)), axis=0)
    # off-diagonal pairs (0,1), (0,2), (1,2): exp * expm1 form, exact down to zero gap
    ea, eb = e[..., _IA], e[..., _IB]
    la, lb = lc[..., _IA], lc[..., _IB]                      # (..., 3)
    gap = ea - eb                                            # c_a - c_b, from eigenvalues of C - I
    ell = np.log1p(gap / (1.0 + eb))                         # ln(c_a / c_b), accurate for small gaps
    same = np.abs(gap) <= 1e-14 * np.maximum(1.0 + ea, 1.0 + eb)
    safe_gap = np.where(same, 1.0, gap)
    dd = np.where(same, q * _exp((q - 1.0) * 0.5 * (la + lb)),   # g' at the mean
                  _diffexp(q * la, q * lb, q * ell) / safe_gap)
    goff = np.sum(kt * (dd + _exp(xv3 - la - lb)), axis=0)
    gamma = np.empty(lc.shape[:-1] + (3, 3))
    gamma[..., _ID, _ID] = gdiag
    gamma[..., _IA, _IB] = goff
    gamma[..., _IB, _IA] = goff
    qv = np.sum(_terms(2.0 * mu * beta, lJ) * ev, axis=0)    # J dp/dJ
    return gamma, qv


def _log_debug_inadmissible(ok):
    if not np.all(ok):
        log.debug("hyperfoam: %d of %d states inadmissible (beyond the overflow guard or J <= 0)",
                  int(np.size(ok) - np.count_nonzero(ok)), int(np.size(ok)))


# points from which pk2_tangent_solid runs on numba's threads (47,600 points, S + D: 29 -> 16 ms
# on 2 threads)
PARALLEL_MIN_POINTS = 8000

# Points per block: the tangent's temporaries of one block (~100 kB each) stay in cache
# and below glibc's mmap threshold; whole-array temporaries of 10^4 points cost 2-4x more
# time (page faults of freshly mapped memory) than the arithmetic itself.
_BLOCK = 2048


def _blocked(fn, X, detF, tails):
    """Evaluate fn(X_block, detF_block, outs_block) on blocks of _BLOCK points of X (..., k, k);
    fn writes its results into outs_block, views of arrays (n_block,) + tail for each tail in
    `tails` (the last one boolean: the ok mask). Returns the outputs shaped (...,) + tail."""
    lead = X.shape[:-2]
    n = math.prod(lead)
    Xf = X.reshape((n,) + X.shape[-2:])
    df = None if detF is None else np.broadcast_to(np.asarray(detF), lead).reshape(n)
    outs = [np.empty((n,) + t, dtype=float) for t in tails[:-1]] + [np.empty((n,) + tails[-1], bool)]
    for s in range(0, n, _BLOCK):
        fn(Xf[s:s + _BLOCK], None if df is None else df[s:s + _BLOCK], [o[s:s + _BLOCK] for o in outs])
    return tuple(o.reshape(lead + o.shape[1:]) for o in outs)


def _check_shape(name, X, k):
    if X.ndim < 2 or X.shape[-2:] != (k, k):
        raise ParameterError(f"{name}.shape", X.shape, f"(..., {k}, {k})")


def pk2_tangent(mat: Hyperfoam, C, *, detF=None):
    """S (..., 3, 3), D = 2 dS/dC (..., 3, 3, 3, 3) and ok (...) for C (..., 3, 3).

    D has minor and major symmetry. Plane strain: pass C with C33 = 1, C13 = C23 = 0
    (or, faster, the in-plane block to `pk2_tangent_plane`).
    detF (optional, shape (...)): flags det F <= 0, which C = F^T F cannot reveal.
    """
    C = np.asarray(C, dtype=float)
    _check_shape("C", C, 3)
    S, D, ok = _blocked(lambda Cb, db, out: _pk2_tangent(mat, Cb, db, out), C, detF,
                        [(3, 3), (3, 3, 3, 3), ()])
    _log_debug_inadmissible(ok)
    return S, D, ok


def _pk2_tangent(mat, C, detF, out):
    """pk2_tangent of points C (n, 3, 3), written into out = [S, D, ok] (n, ...)."""
    S, D, ok_out = out
    e, Q, lc, lJ, ok = _spectral(C, detF)
    mu, alpha, k, beta = _params(mat)
    ok = _guard(ok, alpha, beta, lc, lJ)

    f = _principal_f(mu, alpha, k, beta, lc, lJ)            # (..., 3)
    gamma, qv = _gamma(mu, alpha, k, beta, e, lc, lJ)

    # D_ijkl = T[(ik),(jl)] + T[(il),(jk)] + qv Cinv_ij Cinv_kl with
    # T = sum_ab gamma_ab P_a x P_b, P_a = n_a n_a in symmetric storage (6 components)
    lead = gamma.shape[:-2]
    Pm = Q[..., _I6, :] * Q[..., _J6, :]                     # [(ik), a]
    T = (Pm @ gamma @ np.swapaxes(Pm, -1, -2)).reshape(lead + (36,))
    S6 = (Pm @ f[..., None])[..., 0]
    Ci6 = (Pm @ np.exp(-lc)[..., None])[..., 0]
    qC = qv[..., None] * Ci6
    # gathers straight into the outputs (mode="clip": indices are in range, no buffering)
    np.take(S6, _V9, axis=-1, out=S.reshape(lead + (9,)), mode="clip")
    Df = D.reshape(lead + (81,))
    np.add(np.take(T, _T1_3, axis=-1, mode="clip"), np.take(T, _T2_3, axis=-1, mode="clip"), out=Df)
    Df += qC[..., _C1_3] * Ci6[..., _C2_3]
    ok_out[...] = ok


def _tables3():
    """Gather indices of the 3D tangent (symmetric 3x3 stored as the 6 pairs _I6, _J6)."""
    V = np.empty((3, 3), int)
    V[_I6, _J6] = V[_J6, _I6] = np.arange(6)
    i, j, k, l = np.indices((3, 3, 3, 3)).reshape(4, -1)
    return 6 * V[i, k] + V[j, l], 6 * V[i, l] + V[j, k], V[i, j], V[k, l], V.ravel()


_I6, _J6 = np.array([0, 1, 2, 1, 0, 0]), np.array([0, 1, 2, 2, 2, 1])
_T1_3, _T2_3, _C1_3, _C2_3, _V9 = _tables3()


def _kernel_inputs(X, k, detF):
    """(lead shape, n, X as (n, k, k), detF as (n,) or empty, has_detF) for the compiled loops."""
    from tactileskin.materials import _hyperfoam_nb as nb

    lead = X.shape[:-2]
    n = math.prod(lead)
    Xk = nb.as_kernel_input(X, (n, k, k))
    if detF is None:
        return lead, n, Xk, np.empty(0), False
    return lead, n, Xk, nb.as_kernel_input(np.broadcast_to(np.asarray(detF, dtype=float), lead), (n,)), True


def pk2_tangent_solid(mat: Hyperfoam, C, *, detF=None, tangent: bool = True):
    """`pk2_tangent` by the compiled point loop of `_hyperfoam_nb` (`solid_kernel`: the
    eigenproblem of C - I by Jacobi rotations, the same formulas and guards; ~3x cheaper than
    the eigh path, which is its oracle: same values to rounding, identical ok flags,
    tests/test_hyperfoam_nb.py). tangent=False skips D and returns (S, None, ok). From
    PARALLEL_MIN_POINTS points on numba's threads (threads.numba_parallel_threads(); the same bits)."""
    C = np.asarray(C, dtype=float)
    _check_shape("C", C, 3)
    S, D, ok, _ = _solid(mat, C, detF, tangent, False)
    return S, D, ok


def pk2_kept_solid(mat: Hyperfoam, C, *, detF=None):
    """(S, ok, kept): S and ok as `pk2_tangent_solid(..., tangent=False)` (the same bits) and
    the per-point spectral data `kept` (..., 18) from which `tangent_kept_solid` gives D at
    this C without solving the eigenproblem again (Newton's accepted iterate: the residual
    of the line search, then the tangent at the same state)."""
    C = np.asarray(C, dtype=float)
    _check_shape("C", C, 3)
    S, _, ok, kept = _solid(mat, C, detF, False, True)
    return S, ok, kept


def tangent_kept_solid(mat: Hyperfoam, kept):
    """D (..., 3, 3, 3, 3) from the spectral data `kept` (..., 18) of `pk2_kept_solid` for
    the same material: the same bits as `pk2_tangent_solid(C)[1]` at the C that kept it."""
    from tactileskin.materials import _hyperfoam_nb as nb
    from tactileskin.threads import numba_parallel_threads

    kept = np.asarray(kept)
    if kept.dtype != np.float64 or kept.shape[-1:] != (nb.KEPT,):
        raise ParameterError("kept", f"{kept.dtype} {kept.shape}", f"float64 (..., {nb.KEPT}) from pk2_kept_solid")
    lead = kept.shape[:-1]
    n = math.prod(lead)
    Kk = np.ascontiguousarray(kept.reshape(n, nb.KEPT))
    D = np.empty((n, 81))
    args = (Kk, np.asarray(mat.mu, dtype=float), np.asarray(mat.alpha, dtype=float), float(mat.beta), D)
    threads = numba_parallel_threads()
    if threads > 1 and n >= PARALLEL_MIN_POINTS:
        nb.solid_tangent_kernel_parallel(*args, 4 * threads)
    else:
        nb.solid_tangent_kernel(*args)
    return D.reshape(lead + (3, 3, 3, 3))


def _solid(mat: Hyperfoam, C, detF, tangent: bool, keep: bool):
    """(S, D or None, ok, kept or None) of C by the compiled point loop."""
    from tactileskin.materials import _hyperfoam_nb as nb
    from tactileskin.threads import numba_parallel_threads

    lead, n, Ck, dk, has_detF = _kernel_inputs(C, 3, detF)
    Ck, dk = np.ascontiguousarray(Ck), np.ascontiguousarray(dk)   # one compiled specialisation
    S = np.empty((n, 3, 3))
    D = np.empty((n, 81)) if tangent else np.empty((0, 0))
    K = np.empty((n, nb.KEPT)) if keep else np.empty((0, 0))
    ok = np.empty(n, dtype=bool)
    args = (Ck, dk, has_detF, np.asarray(mat.mu, dtype=float), np.asarray(mat.alpha, dtype=float),
            float(mat.beta), S, D, ok, tangent, K, keep)
    threads = numba_parallel_threads()
    if threads > 1 and n >= PARALLEL_MIN_POINTS:
        nb.solid_kernel_parallel(*args, 4 * threads)
    else:
        nb.solid_kernel(*args)
    ok = ok.reshape(lead)
    _log_debug_inadmissible(ok)
    return (S.reshape(lead + (3, 3)), (D.reshape(lead + (3, 3, 3, 3)) if tangent else None), ok,
            K.reshape(lead + (nb.KEPT,)) if keep else None)


# --- plane strain ---------------------------------------------------------------------------

def pk2_tangent_plane(mat: Hyperfoam, C2, *, detF=None, out_of_plane: bool = False,
                      tangent: bool = True):
    """Plane-strain `pk2_tangent` from the in-plane block C2 (..., 2, 2) of C (C33 = 1).

    Same formulas and guards as `pk2_tangent`, with the 2x2 eigenproblem solved in closed
    form (the third principal direction is e_z, c_3 = 1). Returns S (..., 3, 3) (S33 is the
    out-of-plane stress, S13 = S23 = 0), D = 2 dS/dC (..., 2, 2, 2, 2), the in-plane block,
    and ok (...). out_of_plane=True returns the full D (..., 3, 3, 3, 3) instead.
    tangent=False skips D and returns (S, None, ok) (residual-only evaluations).

    Evaluated by the compiled point loop of `_hyperfoam_nb`; `pk2_tangent` of the embedded
    3x3 C is its oracle (same values to rounding, identical ok flags; tests/test_hyperfoam_nb.py).
    """
    from tactileskin.materials import _hyperfoam_nb as nb

    if not tangent:
        mode, cols = nb.MODE_S, 0
    elif out_of_plane:
        mode, cols = nb.MODE_D3, 81
    else:
        mode, cols = nb.MODE_D2, 16
    lead, S, D, ok, _ = _plane_points(mat, C2, detF, mode, cols, keep=False)
    D = D.reshape(lead + _plane_d_shape(out_of_plane)) if tangent else None
    return S, D, ok


def _plane_d_shape(full: bool) -> tuple:
    return (3, 3, 3, 3) if full else (2, 2, 2, 2)


def _plane_points(mat: Hyperfoam, C2, detF, mode, d_cols: int, keep: bool):
    """`_hyperfoam_nb.plane_kernel` over the points of C2 (..., 2, 2): (lead shape, S (..., 3, 3),
    D (n, d_cols) or empty, ok (...), the kept data K (n, KEPT_PLANE + 3 terms) or empty)."""
    C2 = np.asarray(C2, dtype=float)
    _check_shape("C2", C2, 2)
    # imported on first use: numba's start-up and the cache load (~0.5-1 s) are not paid
    # by programs that never evaluate the law
    from tactileskin.materials import _hyperfoam_nb as nb

    lead, n, Ck, dk, has_detF = _kernel_inputs(C2, 2, detF)
    S = np.empty((n, 3, 3))
    ok = np.empty(n, dtype=bool)
    D = np.empty((n, d_cols)) if d_cols else np.empty((0, 0))
    K = np.empty((n, nb.KEPT_PLANE + 3 * mat.n_terms)) if keep else np.empty((0, 0))
    nb.plane_kernel(Ck, dk, has_detF, np.asarray(mat.mu, dtype=float), np.asarray(mat.alpha, dtype=float),
                    float(mat.beta), S, D, ok, mode, K, keep)
    ok = ok.reshape(lead)
    _log_debug_inadmissible(ok)
    return lead, S.reshape(lead + (3, 3)), D, ok, K


class PlaneKept:
    """What a plane-strain stress evaluation keeps for the D at its state (`pk2_kept_plane`):
    the per-point data K (n, KEPT_PLANE + 3 terms), the points' shape, the D asked for (the
    in-plane block or the full D) and the material it was evaluated with."""

    __slots__ = ("K", "lead", "out_of_plane", "params")

    def __init__(self, K, lead, out_of_plane, params):
        self.K, self.lead, self.out_of_plane, self.params = K, lead, out_of_plane, params


def _plane_params(mat: Hyperfoam) -> tuple:
    return tuple(float(x) for x in mat.mu), tuple(float(x) for x in mat.alpha), float(mat.beta)


def pk2_kept_plane(mat: Hyperfoam, C2, *, detF=None, out_of_plane: bool = False):
    """(S, ok, kept): S and ok as `pk2_tangent_plane(..., tangent=False)` (the same bits) and
    the per-point data `kept` (a PlaneKept: the principal directions, logarithms and powers)
    from which `tangent_kept_plane` gives D (the in-plane block, or with out_of_plane the full
    D) at this C2 without a second point loop of S (Newton's accepted iterate: the residual of
    the line search, then the tangent at the same state)."""
    from tactileskin.materials import _hyperfoam_nb as nb

    lead, S, _, ok, K = _plane_points(mat, C2, detF, nb.MODE_S, 0, keep=True)
    return S, ok, PlaneKept(K, lead, bool(out_of_plane), _plane_params(mat))


def tangent_kept_plane(mat: Hyperfoam, kept: PlaneKept, *, in_plane: bool = False):
    """D (..., 2, 2, 2, 2), or (..., 3, 3, 3, 3) if kept with out_of_plane and not in_plane,
    from the data of `pk2_kept_plane` for the same material: the same bits as
    `pk2_tangent_plane(C2)[1]` (or its in-plane block) at the C2 that kept it."""
    from tactileskin.materials import _hyperfoam_nb as nb

    if not isinstance(kept, PlaneKept) or kept.params != _plane_params(mat):
        raise ParameterError("kept", type(kept).__name__ if not isinstance(kept, PlaneKept) else "another material's",
                             "the PlaneKept of pk2_kept_plane for this material")
    n = kept.K.shape[0]
    full = kept.out_of_plane and not in_plane
    mode, D = (nb.MODE_D3, np.empty((n, 81))) if full else (nb.MODE_D2, np.empty((n, 16)))
    nb.plane_tangent_kernel(kept.K, np.asarray(mat.mu, dtype=float), np.asarray(mat.alpha, dtype=float),
                            float(mat.beta), D, mode)
    return D.reshape(kept.lead + _plane_d_shape(full))


def cauchy_principal(mat: Hyperfoam, stretches):
    """Principal Cauchy stresses (..., 3) for principal stretches (..., 3) (closed form).

    sigma_j = (2/J) sum_i (mu_i/alpha_i)(l_j^alpha_i - J^(-alpha_i beta)), in log space.
    Raises ParameterError for non-positive stretches or states beyond the overflow guard.
    """
    lam = np.asarray(stretches, dtype=float)
    if lam.shape[-1:] != (3,):
        raise ParameterError("stretches.shape", lam.shape, "(..., 3)")
    if not np.all(lam > 0.0) or not np.all(np.isfinite(lam)):
        raise ParameterError("stretches", "non-positive or non-finite values", "finite stretches > 0")
    mu, alpha, k, beta = _params(mat)
    ll = np.log(lam)[..., :, None]
    lJ = np.sum(np.log(lam), axis=-1)[..., None, None]
    x1 = alpha * ll - lJ
    x2 = -alpha * beta * lJ - lJ
    if np.any(x1 > EXP_CAP) or np.any(x2 > EXP_CAP):
        raise ParameterError("stretches", "state beyond the overflow guard",
                             f"exponents <= {EXP_CAP:g} (see hyperfoam.EXP_CAP)")
    d = alpha * (ll + beta * lJ)
    return np.sum(k * _diffexp(x1, x2, d), axis=-1)
