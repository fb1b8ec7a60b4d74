"""Compiled element kernels (fe._kernels_nb) against the literal reference
(tests/reference_kernels.py), and their tangent against central differences of their residual."""

import numpy as np
import pytest
import reference_kernels as ref
from skfem import MeshTet, MeshTri

from tactileskin.fe import Dirichlet, Model, kernels, material_law
from tactileskin.materials import get_material


def _random_state(E, Q, A, m, seed, scale=0.05):
    """Synthetic element data: gradients G with sum_a G_a = 0 (as shape functions have),
    positive weights, a small random displacement (J > 0), a symmetric S independent of D,
    and a D with the minor and major symmetries of a hyperelastic tangent (the tangent
    assumes them) but no further structure."""
    rng = np.random.default_rng(seed)
    G = rng.standard_normal((E, Q, A, m))
    G -= G.mean(axis=2, keepdims=True)
    w = rng.uniform(0.5, 1.5, (E, Q))
    ue = scale * rng.standard_normal((E, A, m))
    S = rng.standard_normal((E, Q, m, m))
    S = S + np.swapaxes(S, -1, -2)
    D = rng.standard_normal((E, Q, m, m, m, m))
    D = D + D.transpose(0, 1, 3, 2, 4, 5)
    D = D + D.transpose(0, 1, 2, 3, 5, 4)
    D = D + D.transpose(0, 1, 4, 5, 2, 3)
    return ue, G, w, S, D


def _rel(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


# (m, A, Q): P2 triangle and P2 tet (the specialised loops) and a P1 triangle (generic loop)
SHAPES = [(2, 6, 3), (3, 10, 4), (2, 3, 1)]


@pytest.mark.parametrize("mixed", [True, False], ids=["mixed", "displacement"])
@pytest.mark.parametrize("m,A,Q", SHAPES, ids=["tri6", "tet10", "tri3"])
def test_compiled_matches_reference(m, A, Q, mixed):
    """Same formulas, different order of floating-point operations: agreement to 1e-12
    relative to the largest entry (observed ~1e-15). S and D are passed as strided views
    (as Model passes S[..., :m, :m]) to exercise the contiguous copies."""
    ue, G, w, S, D = _random_state(37, Q, A, m, seed=10 * m + A)
    S3 = np.zeros((37, Q, 4, 4))
    S3[..., :m, :m] = S
    D3 = np.zeros((37, Q, 4, 4, 4, 4))
    D3[..., :m, :m, :m, :m] = D
    Sv, Dv = S3[..., :m, :m], D3[..., :m, :m, :m, :m]
    assert not Sv.flags.c_contiguous and not Dv.flags.c_contiguous

    kin = kernels.Kinematics(ue, G, w, mixed)
    assert kin.admissible
    f, K = kernels.residual(kin, Sv), kernels.tangent(kin, Sv, Dv)
    kin_r = ref.kinematics(ue, G, w, mixed)
    f_r, K_r = ref.residual_tangent(ue, G, w, mixed, S, D)
    assert K.shape == (37, A * m, A * m) and f.shape == (37, A * m)
    assert set(kin_r) == {"F", "J", "Finv", "alpha", "Fbar", "C", "Jbar"} | ({"theta"} if mixed else set())
    for name, value in kin_r.items():
        assert _rel(getattr(kin, name), value) <= 1e-13, name
    assert _rel(f, f_r) <= 1e-12
    assert _rel(K, K_r) <= 1e-12
    # the mixed terms matter (with one point per element theta = J: nothing to condense)
    if mixed and Q > 1:
        kin_d = kernels.Kinematics(ue, G, w, False)
        assert _rel(kernels.tangent(kin_d, S, D), K) > 1e-3


@pytest.mark.parametrize("mixed", [True, False], ids=["mixed", "displacement"])
def test_threaded_tet_tangent_has_the_serial_bits(mixed, monkeypatch):
    """Above PARALLEL_MIN_ELEMENTS the P2-tet tangent runs on numba's threads, element ranges
    apart: the same arithmetic per element, so bit for bit the serial loop's (and uneven
    ranges: 2001 elements in 8 chunks)."""
    from tactileskin.threads import numba_threads

    E = kernels.PARALLEL_MIN_ELEMENTS + 1
    ue, G, w, S, D = _random_state(E, 4, 10, 3, seed=5)
    kin = kernels.Kinematics(ue, G, w, mixed)
    with numba_threads(1):
        K1 = kernels.tangent(kin, S, D)
    with numba_threads(2):
        K2 = kernels.tangent(kin, S, D)
    assert np.array_equal(K1, K2)
    monkeypatch.setattr(kernels, "PARALLEL_MIN_ELEMENTS", 10 ** 9)   # the serial path, threads or not
    with numba_threads(2):
        assert np.array_equal(kernels.tangent(kin, S, D), K1)


@pytest.mark.parametrize("bad", [-2.0, np.nan])
def test_compiled_kinematics_flags_inadmissible_states(bad):
    """An inverted (J < 0) or non-finite point makes the whole state inadmissible (Model
    then rejects the trial state)."""
    ue, G, w, _, _ = _random_state(5, 3, 6, 2, seed=3)
    ue[2] = 0.0
    G[2, 1] = 0.0
    ue[2, 0] = [bad, 0.0]
    G[2, 1, 0] = [1.0, 0.0]     # F11 = 1 + bad at element 2, point 1: J = 1 + bad
    kin = kernels.Kinematics(ue, G, w, True)
    assert not kin.admissible
    assert kernels.Kinematics(ue[:2], G[:2], w[:2], True).admissible


def _law_state(kind, mixed, seed):
    mesh = (MeshTri.init_tensor(*(np.linspace(0, 1, 3),) * 2) if kind == "tri"
            else MeshTet.init_tensor(*(np.linspace(0, 1, 2),) * 3))
    law = material_law(get_material("polyurethane").hyperfoam)
    model = Model(mesh, {"x0": mesh.facets_satisfying(lambda x: x[0] < 1e-9)}, law,
                  [Dirichlet("x0", (0,))], formulation="mixed" if mixed else "displacement")
    ue = 0.03 * np.random.default_rng(seed).standard_normal(model.sdofs.shape + (model.m,))
    return model, law, ue


def _forces(model, law, ue):
    m = model.m
    kin = kernels.Kinematics(ue, model.G, model.w, model.mixed)
    assert kin.admissible
    S3, D3, ok = law(kin.C)
    assert ok.all()
    return kin, S3[..., :m, :m], D3[..., :m, :m, :m, :m]


@pytest.mark.parametrize("mixed", [True, False], ids=["mixed", "displacement"])
@pytest.mark.parametrize("kind", ["tri", "tet"])
def test_compiled_tangent_is_the_derivative_of_the_compiled_residual(kind, mixed):
    """Elements are independent, so perturbing local dof d of every element at once gives
    column d of every element tangent. The central-difference error of an exact tangent
    is truncation, C h^2 (round-off eps |f| / h is ~1e-10 relative here): observed C h^2
    relative to max|K| = 8e-5 .. 3e-4 at h = 1e-4 (polyurethane is stiff in volume), and
    100x smaller at h = 1e-5. So: below 1e-3 at 1e-4, and the error falls by 100 +- 50 %
    from h = 1e-4 to 1e-5; a wrong tangent leaves an O(1) error that does not fall with h."""
    model, law, ue = _law_state(kind, mixed, seed=5)
    kin, S, D = _forces(model, law, ue)
    K = kernels.tangent(kin, S, D)
    E, A, m = ue.shape
    err = []
    for h in (1e-4, 1e-5):
        Kfd = np.empty_like(K)
        for a in range(A):
            for i in range(m):
                fs = []
                for sgn in (1.0, -1.0):
                    up = ue.copy()
                    up[:, a, i] += sgn * h
                    kin_p, S_p, _ = _forces(model, law, up)
                    fs.append(kernels.residual(kin_p, S_p))
                Kfd[:, :, a * m + i] = (fs[0] - fs[1]) / (2 * h)
        err.append(_rel(K, Kfd))
    assert err[0] < 1e-3
    assert 50.0 < err[0] / err[1] < 150.0


@pytest.mark.parametrize("kind", ["tri", "tet"])
def test_tangent_into_a_given_buffer_and_the_models_reused_buffer(kind):
    """kernels.tangent(out=buf) writes every entry of buf (NaN-filled here) with the bits of
    a fresh call, and refuses a buffer it could overrun; Model.tangent reuses one buffer: two
    tangents at different states, the second's data the same as a fresh model's."""
    model, law, ue = _law_state(kind, True, seed=7)
    kin, S, D = _forces(model, law, ue)
    K = kernels.tangent(kin, S, D)
    buf = np.full_like(K, np.nan)
    assert kernels.tangent(kin, S, D, out=buf) is buf
    assert np.array_equal(buf, K)
    for bad in (np.empty(K.shape[:2] + (K.shape[2] - 1,)), np.empty(K.shape, np.float32),
                np.empty(K.shape[::-1]).T):
        with pytest.raises(ValueError):
            kernels.tangent(kin, S, D, out=bad)
    rng = np.random.default_rng(8)
    u1, u2 = (0.02 * rng.standard_normal(model.ndof) for _ in range(2))
    K1 = model.tangent(model.evaluate(u1, 0.0, 1.0, tangent=False)).copy()
    K2 = model.tangent(model.evaluate(u2, 0.0, 1.0, tangent=False))
    fresh, _, _ = _law_state(kind, True, seed=7)
    assert np.array_equal(K2, fresh.tangent(fresh.evaluate(u2, 0.0, 1.0, tangent=False)))
    assert not np.array_equal(K1, K2)
    assert model._Ke is not None and not np.shares_memory(model._Ke, K2)
