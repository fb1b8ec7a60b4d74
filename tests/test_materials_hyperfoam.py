"""Hyperfoam law: consistent tangent, energy, closed forms, small-strain moduli, hard cases."""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

from tactileskin.errors import ParameterError
from tactileskin.materials import (
    EXP_CAP,
    Hyperfoam,
    cauchy_principal,
    energy,
    get_material,
    pk2,
    pk2_tangent,
)
from tactileskin.materials.hyperfoam import pk2_tangent_plane

SILICONE = get_material("silicone").hyperfoam
POLYURETHANE = get_material("polyurethane").hyperfoam
MATERIALS = {"silicone": SILICONE, "polyurethane": POLYURETHANE}
# Admissible |ln J| for well-conditioned random states: alpha*beta*|ln J| <= ~10, so that
# J^(-alpha beta) stays within e^10 (silicone alpha*beta = 379.75, polyurethane 64.6).
LNJ_RANGE = {"silicone": 0.025, "polyurethane": 0.15}


def _rotation(rng, n):
    q, r = np.linalg.qr(rng.standard_normal((n, 3, 3)))
    return q * np.sign(np.diagonal(r, axis1=-2, axis2=-1))[:, None, :]


def random_states(name, n=12, seed=0):
    """C = R diag(l^2) R^T with l1, l2 in [0.7, 1.3] and l3 chosen so ln J is moderate."""
    rng = np.random.default_rng(seed)
    l12 = rng.uniform(0.7, 1.3, (n, 2))
    lnJ = rng.uniform(-1, 1, n) * LNJ_RANGE[name]
    l3 = np.exp(lnJ) / l12.prod(axis=1)
    lam = np.column_stack([l12, l3])
    R = _rotation(rng, n)
    return np.einsum("nia,na,nja->nij", R, lam**2, R)


def special_states(plane_strain=False):
    """Undeformed, uniaxial (two equal stretches, rotated too), equi-triaxial, plane strain."""
    rng = np.random.default_rng(1)
    Cs = [np.eye(3), np.diag([1.1**2, 1.0, 1.0]), np.diag([0.9**2, 0.995**2, 0.995**2]),
          np.diag([1.01**2] * 3), np.diag([0.99**2] * 3)]
    R = _rotation(rng, 1)[0]
    Cs.append(R @ np.diag([1.05**2, 0.98**2, 0.98**2]) @ R.T)   # equal stretches, rotated
    # plane strain: C33 = 1, C13 = C23 = 0, in-plane rotation of (l1, l2)
    for l1, l2 in [(1.08, 0.93), (0.97, 0.97), (1.0, 1.0)]:
        c, s = np.cos(0.7), np.sin(0.7)
        r2 = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
        Cs.append(r2 @ np.diag([l1**2, l2**2, 1.0]) @ r2.T)
    return np.array(Cs)


def _sym_unit(k, l):
    E = np.zeros((3, 3))
    E[k, l] += 0.5
    E[l, k] += 0.5
    return E


def fd_tangent(mat, C, h=1e-6):
    """D_ijkl = 2 dS_ij/dC_kl by central differences along symmetric directions."""
    D = np.zeros(C.shape[:-2] + (3, 3, 3, 3))
    for k in range(3):
        for l in range(3):
            E = _sym_unit(k, l)
            Sp, _ = pk2(mat, C + h * E)
            Sm, _ = pk2(mat, C - h * E)
            D[..., k, l] = (Sp - Sm) / h
    return D


def fd_stress(mat, C, h=1e-6):
    S = np.zeros(C.shape)
    for k in range(3):
        for l in range(3):
            E = _sym_unit(k, l)
            S[..., k, l] = (energy(mat, C + h * E) - energy(mat, C - h * E)) / h
    return S


def _rel_err(a, b, floor=0.0):
    """Worst per-point error, relative to each point's largest entry (at least `floor`)."""
    a = a.reshape(a.shape[0], -1)
    b = b.reshape(b.shape[0], -1)
    return np.max(np.abs(a - b).max(axis=1) / np.maximum(np.abs(b).max(axis=1), floor))


# --- parameters ------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs", [
    dict(mu=(0.1,), alpha=(2.0,), nu=0.5),
    dict(mu=(0.1,), alpha=(2.0,), nu=-1.0),
    dict(mu=(0.1,), alpha=(0.0,), nu=0.3),
    dict(mu=(float("nan"),), alpha=(2.0,), nu=0.3),
    dict(mu=(0.1,), alpha=(float("inf"),), nu=0.3),
    dict(mu=(0.1, 0.2), alpha=(2.0,), nu=0.3),
    dict(mu=(), alpha=(), nu=0.3),
    dict(mu=(-0.1,), alpha=(2.0,), nu=0.3),
    dict(mu=(0.1,), alpha=(2.0,), nu="soft"),
])
def test_invalid_parameters_raise(kwargs):
    with pytest.raises(ParameterError):
        Hyperfoam(**kwargs)


def test_table_i_derived_moduli():
    # design.md table, quoted to 3 significant digits
    assert SILICONE.beta == pytest.approx(24.5, rel=1e-12)
    assert POLYURETHANE.beta == pytest.approx(0.47 / 0.06, rel=1e-12)
    assert SILICONE.mu0 == pytest.approx(0.090, abs=5e-4)
    assert SILICONE.K0 == pytest.approx(4.47, abs=5e-3)
    assert POLYURETHANE.mu0 == pytest.approx(0.163, abs=5e-4)
    assert POLYURETHANE.K0 == pytest.approx(2.66, abs=5e-3)


# --- consistent tangent and energy --------------------------------------------------------

@pytest.mark.parametrize("name", MATERIALS)
def test_tangent_matches_finite_differences_random(name):
    mat = MATERIALS[name]
    C = random_states(name)
    S, D, ok = pk2_tangent(mat, C)
    assert ok.all()
    # central FD, h = 1e-6: truncation ~ h^2 (alpha beta)^2 ~ 1e-7 at worst, rounding
    # ~ eps |S| / h ~ 1e-10; the analytic tangent must agree to 1e-6 relative.
    assert _rel_err(fd_tangent(mat, C), D) < 1e-6


@pytest.mark.parametrize("name", MATERIALS)
def test_tangent_matches_finite_differences_equal_stretches(name):
    mat = MATERIALS[name]
    C = special_states()
    S, D, ok = pk2_tangent(mat, C)
    assert ok.all()
    assert np.isfinite(D).all() and np.isfinite(S).all()
    assert _rel_err(fd_tangent(mat, C), D) < 1e-6


@pytest.mark.parametrize("name", MATERIALS)
def test_tangent_symmetries(name):
    mat = MATERIALS[name]
    C = np.concatenate([random_states(name, 6), special_states()])
    _, D, _ = pk2_tangent(mat, C)
    scale = np.abs(D).max(axis=(1, 2, 3, 4))[:, None, None, None, None]
    # built symmetric by construction: only rounding (a few eps) may differ
    assert np.abs(D - D.transpose(0, 2, 1, 3, 4)).max() <= 1e-13 * scale.max()
    assert np.all(np.abs(D - D.transpose(0, 1, 2, 4, 3)) <= 1e-13 * scale)
    assert np.all(np.abs(D - D.transpose(0, 3, 4, 1, 2)) <= 1e-13 * scale)


@pytest.mark.parametrize("name", MATERIALS)
def test_stress_is_energy_derivative(name):
    mat = MATERIALS[name]
    C = np.concatenate([random_states(name, 6, seed=3), special_states()[1:]])
    S, ok = pk2(mat, C)
    # same FD budget as the tangent test; at (nearly) stress-free states the FD truncation
    # error (h^2 times the third derivative of U, ~1e-11 MPa) is absolute, so scale by at
    # least mu0 * 1e-3
    assert _rel_err(fd_stress(mat, C), S, floor=1e-3 * mat.mu0) < 1e-6


def test_undeformed_state_is_stress_free_with_linear_moduli():
    for mat in MATERIALS.values():
        S, D, ok = pk2_tangent(mat, np.eye(3))
        assert ok and np.all(S == 0.0) and np.isfinite(D).all()
        # D = 2 mu0 I_sym + lambda I x I with lambda = 2 beta mu0 = K0 - 2 mu0 / 3
        mu = D[0, 1, 0, 1]
        lam = D[0, 0, 1, 1]
        assert mu == pytest.approx(mat.mu0, rel=1e-12)
        assert lam + 2.0 * mu / 3.0 == pytest.approx(mat.K0, rel=1e-12)
        assert D[0, 0, 0, 0] == pytest.approx(lam + 2 * mu, rel=1e-12)
        assert D[0, 1, 1, 2] == pytest.approx(0.0, abs=1e-14)


def test_small_strain_limit_matches_linear_elasticity():
    # at strain 1e-7 the response is linear to O(strain): relative tolerance 1e-5
    rng = np.random.default_rng(7)
    eps = rng.standard_normal((3, 3)) * 1e-7
    eps = 0.5 * (eps + eps.T)
    C = np.eye(3) + 2.0 * eps
    for mat in MATERIALS.values():
        S, _ = pk2(mat, C)
        lam = 2.0 * mat.beta * mat.mu0
        S_lin = 2.0 * mat.mu0 * eps + lam * np.trace(eps) * np.eye(3)
        assert np.abs(S - S_lin).max() < 1e-5 * np.abs(S_lin).max()


# --- closed forms -----------------------------------------------------------------------

def _cauchy_mp(mat, lam, dps=40):
    """Reference principal Cauchy stress sigma_j = (2/J) sum (mu/alpha)(l_j^alpha - J^(-alpha beta))."""
    with mp.workdps(dps):
        lam = [mp.mpf(float(x)) for x in lam]
        J = lam[0] * lam[1] * lam[2]
        beta = mp.mpf(mat.nu) / (1 - 2 * mp.mpf(mat.nu))
        out = []
        for lj in lam:
            s = mp.mpf(0)
            for m, a in zip(mat.mu, mat.alpha):
                m, a = mp.mpf(m), mp.mpf(a)
                s += (m / a) * (lj**a - J ** (-a * beta))
            out.append(float(2 * s / J))
        return np.array(out)


def _cauchy_from_pk2(mat, lam, R=None):
    F = np.diag(lam)
    if R is not None:
        F = R @ F            # rotation must not change the principal values
    C = F.T @ F
    S, ok = pk2(mat, C)
    sig = F @ S @ F.T / np.prod(lam)
    if R is not None:
        sig = R.T @ sig @ R
    return np.diag(sig), ok, sig


CLOSED_FORM_STATES = {
    "uniaxial": [(1.2, 0.93, 0.93), (0.8, 1.05, 1.05), (1.02, 0.995, 0.995)],
    "confined": [(0.99, 1, 1), (0.98, 1, 1), (0.95, 1, 1), (1.03, 1, 1)],
    "volumetric": [(0.995,) * 3, (1.01,) * 3, (0.98,) * 3],
}


@pytest.mark.parametrize("kind", CLOSED_FORM_STATES)
@pytest.mark.parametrize("name", MATERIALS)
def test_principal_cauchy_closed_form(name, kind):
    mat = MATERIALS[name]
    R = _rotation(np.random.default_rng(5), 1)[0]
    for lam in CLOSED_FORM_STATES[kind]:
        ref = _cauchy_mp(mat, lam)
        scale = np.abs(ref).max()
        # cauchy_principal: same formula in log space, accurate to a few eps
        assert np.abs(cauchy_principal(mat, lam) - ref).max() <= 1e-12 * scale
        # through C, eigh and F S F^T / J, rotated: roundoff of the O(1) rotation and of
        # the eigen-decomposition amplified by alpha*beta ~ 380 for silicone: 1e-10
        for rot in (None, R):
            diag, ok, sig = _cauchy_from_pk2(mat, np.array(lam, float), rot)
            assert ok
            assert np.abs(diag - ref).max() <= 1e-10 * scale, (lam, diag, ref)
            assert np.abs(sig - np.diag(diag)).max() <= 1e-10 * scale


def test_silicone_confined_compression_lock_up():
    # design.md: about -0.1 MPa at 0.99, -2.9 at 0.98, -4e5 at 0.95 (axial stress)
    s = [cauchy_principal(SILICONE, (lam, 1.0, 1.0))[0] for lam in (0.99, 0.98, 0.95)]
    assert s[0] == pytest.approx(-0.0995, rel=1e-3)
    assert s[1] == pytest.approx(-2.910, rel=1e-3)
    assert s[2] == pytest.approx(-3.912e5, rel=1e-3)


def test_plane_strain_out_of_plane_stress_is_kept():
    # plane strain, lambda_3 = 1: sigma_zz = (2/J) sum (mu/alpha)(1 - J^(-alpha beta)) != 0
    for mat in MATERIALS.values():
        lam = (1.05, 0.97, 1.0)
        diag, ok, _ = _cauchy_from_pk2(mat, np.array(lam))
        ref = _cauchy_mp(mat, lam)
        assert abs(ref[2]) > 1e-3
        assert diag[2] == pytest.approx(ref[2], rel=1e-10)


# --- hard case 2: alpha = 0.001 -----------------------------------------------------------

def _pk2_mp(mat, C, dps=50):
    """Reference S = sum_a f(c_a) n_a n_a^T in 50-digit arithmetic from the same double C."""
    with mp.workdps(dps):
        E = mp.matrix([[mp.mpf(float(C[i, j])) - (1 if i == j else 0) for j in range(3)] for i in range(3)])
        e, Q = mp.eigsy(E)
        beta = mp.mpf(mat.nu) / (1 - 2 * mp.mpf(mat.nu))
        c = [1 + e[a] for a in range(3)]
        J = mp.sqrt(c[0] * c[1] * c[2])
        f = []
        for ca in c:
            s = mp.mpf(0)
            for m, a in zip(mat.mu, mat.alpha):
                m, a = mp.mpf(m), mp.mpf(a)
                s += 2 * m / a * (ca ** (a / 2) - J ** (-a * beta)) / ca
            f.append(s)
        S = mp.matrix(3, 3)
        for i in range(3):
            for j in range(3):
                S[i, j] = sum(f[a] * Q[i, a] * Q[j, a] for a in range(3))
        return np.array([[float(S[i, j]) for j in range(3)] for i in range(3)])


@pytest.mark.parametrize("strain", [1e-8, 1e-6, 1e-4, 1e-2, 0.1, 0.5])
def test_small_alpha_stress_accuracy(strain):
    """Hard case 2: stress accurate to 1e-10 relative for alpha = 0.001, strains 1e-8 .. 0.5."""
    rng = np.random.default_rng(int(-np.log10(strain) * 10))
    R = _rotation(rng, 1)[0]
    mats = [Hyperfoam((0.08,), (0.001,), 0.49), SILICONE, Hyperfoam((0.08,), (0.001,), 0.0)]
    # distinct principal log-strains of order `strain`, one volumetric-neutral state, one not
    for logl in (np.array([1.0, -0.6, -0.4]) * strain, np.array([1.0, 0.3, -0.5]) * strain * 1e-2):
        if strain > 0.1 and logl.sum() != 0:
            continue  # silicone term 2 at ln J = 0.004: fine, but keep the set small
        C = R @ np.diag(np.exp(2 * logl)) @ R.T
        C = 0.5 * (C + C.T)
        for mat in mats:
            S, ok = pk2(mat, C)
            ref = _pk2_mp(mat, C)
            assert ok
            assert np.abs(S - ref).max() <= 1e-10 * np.abs(ref).max(), (mat, strain)


def test_small_alpha_energy_is_accurate():
    mat = Hyperfoam((0.08,), (0.001,), 0.49)
    for strain in (1e-8, 1e-4, 0.3):
        lam = np.exp(np.array([1.0, -0.7, 0.2]) * strain)
        C = np.diag(lam**2)
        with mp.workdps(50):
            beta = mp.mpf(mat.nu) / (1 - 2 * mp.mpf(mat.nu))
            a, m = mp.mpf(mat.alpha[0]), mp.mpf(mat.mu[0])
            L = [mp.mpf(float(x)) for x in np.sqrt(np.diag(C))]
            J = L[0] * L[1] * L[2]
            U = 2 * m / a**2 * (sum(x**a for x in L) - 3 + (J ** (-a * beta) - 1) / beta)
        assert energy(mat, C) == pytest.approx(float(U), rel=1e-10)


# --- hard case 1: overflow guard -----------------------------------------------------------

def _all_finite(*arrays):
    return all(np.isfinite(a).all() for a in arrays)


def test_overflow_guard_flags_and_stays_finite():
    C = np.array([
        np.diag([0.1**2, 1, 1]),        # J = 0.1: -alpha beta ln J = 874 (silicone term 2), 149 (PU)
        np.diag([1e-3**2, 1, 1]),       # J = 1e-3: 2623 (silicone), 446 (PU)
        np.diag([-0.1, 1, 1]),          # not positive definite
        np.zeros((3, 3)),               # J = 0
        np.diag([1e8**2, 1, 1]),        # absurd stretch, |ln c| > LOG_C_CAP
        np.full((3, 3), np.nan),        # garbage in
        np.diag([np.inf, 1, 1]),
    ])
    expected_ok = {"silicone": [False] * 7, "polyurethane": [True] + [False] * 6}
    for name, mat in MATERIALS.items():
        with np.errstate(over="raise", invalid="raise", divide="raise"):  # underflow is harmless
            S, D, ok = pk2_tangent(mat, C)
            U = energy(mat, C)
        assert ok.tolist() == expected_ok[name]
        assert _all_finite(S, D, U)
    # admissible but stiff: silicone at J = 0.5 is below the guard (exponent 263 < 300)
    S, D, ok = pk2_tangent(SILICONE, np.diag([0.5**2, 1, 1]))
    assert ok and _all_finite(S, D)
    assert -379.75 * np.log(0.5) < EXP_CAP < -379.75 * np.log(0.1)


def test_negative_det_f_is_flagged():
    C = np.stack([np.eye(3), np.diag([1.1, 1.0, 0.9])])
    S, D, ok = pk2_tangent(POLYURETHANE, C, detF=np.array([-1.0, np.sqrt(0.99)]))
    assert ok.tolist() == [False, True]
    assert _all_finite(S, D)


def test_cauchy_principal_rejects_bad_stretches():
    with pytest.raises(ParameterError):
        cauchy_principal(SILICONE, (0.0, 1.0, 1.0))
    with pytest.raises(ParameterError):
        cauchy_principal(SILICONE, (0.1, 1.0, 1.0))   # beyond the overflow guard


def test_vectorised_shapes():
    C = np.broadcast_to(np.diag([1.1, 0.95, 1.0]), (4, 5, 3, 3))
    S, D, ok = pk2_tangent(POLYURETHANE, C)
    assert S.shape == (4, 5, 3, 3) and D.shape == (4, 5, 3, 3, 3, 3) and ok.shape == (4, 5)
    S1, D1, _ = pk2_tangent(POLYURETHANE, C[0, 0])
    assert S1.shape == (3, 3) and D1.shape == (3, 3, 3, 3)
    assert np.array_equal(S[2, 3], S1)
    assert energy(POLYURETHANE, C).shape == (4, 5)


@pytest.mark.parametrize("name", MATERIALS)
def test_tangent_is_continuous_through_coincident_stretches(name):
    """Hard case 3: as two eigenvalues of C merge (relative gap 1e-3 .. 1e-16 .. 0) the
    tangent tends smoothly to the coincident one: |D(gap) - D(0)| = O(gap), no blow-up."""
    mat = MATERIALS[name]
    R = _rotation(np.random.default_rng(11), 1)[0]
    c = 0.99**2
    D0 = pk2_tangent(mat, R @ np.diag([c, c, 1.0]) @ R.T)[1]
    for gap in (1e-3, 1e-6, 1e-9, 1e-12, 1e-14, 1e-16):
        D = pk2_tangent(mat, R @ np.diag([c * (1 + gap), c, 1.0]) @ R.T)[1]
        # the change is dominated by J: d ln J = gap/2, amplified by alpha*beta = 380 (silicone),
        # measured 190 gap (polyurethane 27 gap); allow 300 gap + 1e-12 (rounding of rotated C)
        assert np.abs(D - D0).max() <= (300 * gap + 1e-12) * np.abs(D0).max(), gap


# --- plane strain fast path ------------------------------------------------------------

def _embed(C2):
    C = np.zeros(C2.shape[:-2] + (3, 3))
    C[..., :2, :2] = C2
    C[..., 2, 2] = 1.0
    return C


def _rot2(theta, M):
    c, s = np.cos(theta), np.sin(theta)
    R = np.array([[c, -s], [s, c]])
    return R @ M @ R.T


def plane_states(name, n=40, seed=5):
    """In-plane C2: random (rotated, moderate J), undeformed, equal and nearly equal in-plane
    stretches (relative gaps 1e-16 .. 1e-6), one in-plane stretch 1 (c = c_3), shear only."""
    rng = np.random.default_rng(seed)
    l1 = rng.uniform(0.8, 1.25, n)
    l2 = np.exp(rng.uniform(-1, 1, n) * LNJ_RANGE[name]) / l1
    Cs = [_rot2(t, np.diag([a * a, b * b])) for t, a, b in zip(rng.uniform(0, np.pi, n), l1, l2)]
    Cs += [np.eye(2), np.diag([0.99**2] * 2), _rot2(0.3, np.diag([1.01**2] * 2)),
           np.diag([1.0, 0.98**2]), np.array([[1.0, 0.02], [0.02, 1.0]])]
    Cs += [_rot2(0.9, np.diag([0.995**2 * (1 + g), 0.995**2])) for g in (1e-16, 1e-14, 1e-12, 1e-9, 1e-6)]
    return np.array(Cs)


def guard_states():
    """Just inside / outside every guard, plus garbage: the ok masks must be identical."""
    lnj_cap = -EXP_CAP / (15.5 * SILICONE.beta)      # silicone term 2: J^(-alpha beta) = e^300
    return np.array([
        np.diag([np.exp(2 * (lnj_cap + 1e-3)), 1.0]),  # J just above the silicone cap
        np.diag([np.exp(2 * (lnj_cap - 1e-3)), 1.0]),  # just below
        np.diag([np.exp(29.99), 1.0]),                  # |ln c| just inside LOG_C_CAP
        np.diag([np.exp(30.01), 1.0]),                  # just outside
        np.diag([np.exp(-30.01), 1.0]),
        np.diag([-0.1, 1.0]),                           # not positive definite
        np.zeros((2, 2)),
        np.full((2, 2), np.nan),
        np.diag([np.inf, 1.0]),
    ])


def _max_rel(a, b, ok):
    """Worst per-point difference relative to the point's largest entry (admissible points;
    a point with b = 0, the undeformed S, must match exactly)."""
    a = a.reshape(a.shape[0], -1)[ok]
    b = b.reshape(b.shape[0], -1)[ok]
    return np.max(np.abs(a - b).max(axis=1) / np.maximum(np.abs(b).max(axis=1), np.finfo(float).tiny))


@pytest.mark.parametrize("name", MATERIALS)
def test_plane_strain_path_equals_general_path(name):
    """The closed-form 2x2 path evaluates the same formulas as the 3x3 eigh path: agreement
    to rounding. eigh's eigenvectors carry ~1e-16 absolute error, amplified at most by the
    spread of the principal values (~10 here): 1e-12 relative is a safe, still sharp bound."""
    mat = MATERIALS[name]
    C2 = np.concatenate([plane_states(name), guard_states()])
    detF = np.ones(len(C2))
    detF[3] = -1.0                                              # flagged by detF only
    S, D, ok = pk2_tangent(mat, _embed(C2), detF=detF)
    S2, D2, ok2 = pk2_tangent_plane(mat, C2, detF=detF)
    S3, D3, ok3 = pk2_tangent_plane(mat, C2, detF=detF, out_of_plane=True)
    assert D2.shape == (len(C2), 2, 2, 2, 2) and D3.shape == D.shape and S2.shape == S.shape
    assert np.array_equal(ok2, ok) and np.array_equal(ok3, ok)
    assert np.delete(ok[:len(C2) - 9], 3).all() and not ok[3]  # the ordinary states pass
    assert all(np.isfinite(x).all() for x in (S2, D2, D3))     # inadmissible: finite values
    assert _max_rel(S2, S, ok) < 1e-12
    assert _max_rel(D2, D[..., :2, :2, :2, :2], ok) < 1e-12
    assert _max_rel(D3, D, ok) < 1e-12
    assert np.array_equal(D3[..., :2, :2, :2, :2], D2)
    # plane strain: S13 = S23 = 0 exactly, S33 kept
    assert not np.any(S2[..., 2, :2]) and not np.any(S2[..., :2, 2])


def test_plane_strain_path_at_the_undeformed_state_is_exact():
    for mat in MATERIALS.values():
        S, D, ok = pk2_tangent_plane(mat, np.eye(2), out_of_plane=True)
        S3, D3, _ = pk2_tangent(mat, np.eye(3))
        assert ok and np.all(S == 0.0)
        assert D[0, 1, 0, 1] == pytest.approx(mat.mu0, rel=1e-14)
        assert np.abs(D - D3).max() <= 1e-14 * np.abs(D3).max()


@pytest.mark.parametrize("name", MATERIALS)
def test_plane_strain_tangent_matches_finite_differences(name):
    """D_ijkl = 2 dS_ij/dC_kl over in-plane k, l (and S33's in-plane derivatives) by central
    differences of the plane path itself; same FD budget as the 3D test (1e-6)."""
    mat = MATERIALS[name]
    C2 = plane_states(name, n=8)
    _, D, ok = pk2_tangent_plane(mat, C2, out_of_plane=True)
    assert ok.all()
    h = 1e-6
    Dfd = np.zeros(C2.shape[:-2] + (3, 3, 2, 2))
    for k in range(2):
        for l in range(2):
            E = _sym_unit(k, l)[:2, :2]
            Dfd[..., k, l] = (pk2_tangent_plane(mat, C2 + h * E)[0]
                              - pk2_tangent_plane(mat, C2 - h * E)[0]) / h
    assert _rel_err(Dfd, D[..., :2, :2]) < 1e-6


def test_plane_strain_path_shapes_and_errors():
    C2 = np.broadcast_to(np.diag([1.1, 0.95]), (4, 5, 2, 2))
    S, D, ok = pk2_tangent_plane(POLYURETHANE, C2)
    assert S.shape == (4, 5, 3, 3) and D.shape == (4, 5, 2, 2, 2, 2) and ok.shape == (4, 5)
    S1, D1, _ = pk2_tangent_plane(POLYURETHANE, C2[0, 0])
    assert S1.shape == (3, 3) and D1.shape == (2, 2, 2, 2)
    assert np.array_equal(S[2, 3], S1)
    with pytest.raises(ParameterError):
        pk2_tangent_plane(POLYURETHANE, np.eye(3))


def test_blocked_evaluation_equals_one_block(monkeypatch):
    """Large inputs are evaluated in blocks of _BLOCK points: results must not depend on it."""
    from tactileskin.materials import hyperfoam
    C = np.concatenate([random_states("polyurethane", 7), special_states()])
    C2 = plane_states("polyurethane", n=7)
    detF = np.ones(len(C))
    detF[2] = -1.0
    ref = pk2_tangent(POLYURETHANE, C, detF=detF) + pk2_tangent_plane(POLYURETHANE, C2)
    monkeypatch.setattr(hyperfoam, "_BLOCK", 3)
    got = pk2_tangent(POLYURETHANE, C, detF=detF) + pk2_tangent_plane(POLYURETHANE, C2)
    assert not got[2][2]
    for a, b in zip(got, ref):
        assert a.shape == b.shape and np.array_equal(a, b)
