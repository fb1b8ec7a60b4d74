"""fe.linsolve method "reuse": GMRES preconditioned by an older factorisation gives the direct
solution, refactorises when the preconditioner goes stale, and the Newton solver picks it for
large 3D models only."""

import numpy as np
import pytest
import scipy.sparse as sp

from tactileskin.errors import ParameterError
from tactileskin.fe import linsolve

BACKENDS = ["superlu"] + (["pardiso"] if linsolve.pardiso_available() else [])


def _spd(n: int, rng) -> sp.csr_matrix:
    """Symmetric positive definite: a 2D Laplacian plus a random symmetric perturbation kept
    diagonally dominant."""
    k = int(np.sqrt(n))
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(k, k))
    A = sp.kronsum(T, T).tocsr()
    R = sp.random(k * k, k * k, density=2.0 / (k * k), random_state=rng.integers(1 << 31))
    A = (A + 0.05 * (R + R.T).multiply(A != 0) + 0.5 * sp.eye(k * k)).tocsr()
    A.sort_indices()
    return A


def _scaled(A: sp.csr_matrix, eps: float, rng) -> sp.csr_matrix:
    """Same structure, entries scaled by 1 + eps * f(i, j) with f symmetric in [-1, 1]."""
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    lo, hi = np.minimum(rows, A.indices), np.maximum(rows, A.indices)
    f = np.sin(12.9898 * lo + 78.233 * hi + rng.uniform(0, 2 * np.pi))
    out = A.copy()
    out.data = A.data * (1.0 + eps * f)
    return out


def test_gmres_matches_a_direct_solve_on_spd_and_nonsymmetric_systems():
    rng = np.random.default_rng(3)
    n = 60
    Q = rng.standard_normal((n, n))
    spd = Q @ Q.T + n * np.eye(n)
    nonsym = spd + 5.0 * rng.standard_normal((n, n))
    assert not np.allclose(nonsym, nonsym.T)
    for A in (spd, nonsym):
        b = rng.standard_normal(n)
        x_ref = np.linalg.solve(A, b)
        # preconditioner: the exact inverse of a perturbed matrix (a stale factorisation)
        M = np.linalg.inv(A + 0.5 * np.diag(rng.uniform(0.5, 2.0, n)) * np.diag(A).mean() / n)
        x, its, ok = linsolve.gmres(lambda v: A @ v, lambda v: M @ v, b, 1e-10, n)
        assert ok and 1 < its < n
        assert np.linalg.norm(A @ x - b) <= 1e-10 * np.linalg.norm(b) * 10
        assert np.allclose(x, x_ref, rtol=1e-7, atol=1e-9 * np.abs(x_ref).max())
        # without a preconditioner it takes more iterations for the same answer
        x0, its0, ok0 = linsolve.gmres(lambda v: A @ v, lambda v: v, b, 1e-10, n)
        assert ok0 and its0 > its and np.allclose(x0, x_ref, rtol=1e-6, atol=1e-8 * np.abs(x_ref).max())


def test_gmres_reports_failure_within_its_iteration_budget():
    rng = np.random.default_rng(4)
    A = np.diag(np.linspace(1.0, 1e4, 200))
    b = rng.standard_normal(200)
    x, its, ok = linsolve.gmres(lambda v: A @ v, lambda v: v, b, 1e-12, 5)
    assert not ok and its == 5
    assert np.all(np.isfinite(x))


@pytest.mark.parametrize("backend", BACKENDS)
def test_reuse_solves_like_direct_and_keeps_the_factorisation(backend):
    rng = np.random.default_rng(5)
    A = _spd(900, rng)
    s = linsolve.SymmetricSolver(A, backend, "reuse")
    d = linsolve.SymmetricSolver(A, backend, "direct")
    for k in range(4):
        Ak = A if k == 0 else _scaled(A, 0.02 * k, rng)
        b = rng.standard_normal(900)
        x = s.factor(Ak).solve(b)
        xd = d.factor(Ak).solve(b)
        assert np.linalg.norm(Ak @ x - b) <= 10 * linsolve.KRYLOV_RTOL * np.linalg.norm(b)
        assert np.allclose(x, xd, rtol=1e-6, atol=1e-7 * np.abs(xd).max())
    assert d.factorizations == 4
    assert s.factorizations == 1 and s.krylov_iterations >= 3  # three GMRES solves on one factorisation
    s.close()
    d.close()


def _shifted(A: sp.csr_matrix, shift: float) -> sp.csr_matrix:
    B = A.copy()
    B.data = B.data + shift * (B.indices == np.repeat(np.arange(A.shape[0]), np.diff(A.indptr)))
    return B


@pytest.mark.parametrize("backend", BACKENDS)
def test_stale_factorisation_is_refactorised_at_the_next_matrix(backend):
    """A solve that costs more Krylov iterations than the average since the factorisation
    marks it stale: the next matrix is factorised afresh (and solved directly)."""
    rng = np.random.default_rng(6)
    A = _spd(900, rng)
    # a factorisation costs 15 iterations: after it (15 + 1 for its solve) and a cheap reuse,
    # a solve of 12 iterations is above the average (30 / 3)
    s = linsolve.SymmetricSolver(A, backend, "reuse", factor_cost=15)
    s.factor(A).solve(rng.standard_normal(900))
    s.factor(_shifted(A, 1e-4)).solve(rng.standard_normal(900))  # nearly the same: cheap
    cheap = s.krylov_iterations
    assert s.factorizations == 1 and not s._stale and cheap <= 3
    B = _shifted(A, 1.0)    # changed: GMRES converges, but slowly
    b = rng.standard_normal(900)
    x = s.factor(B).solve(b)
    assert s.factorizations == 1 and s._stale and s.krylov_iterations - cheap > cheap
    assert np.linalg.norm(B @ x - b) <= 10 * linsolve.KRYLOV_RTOL * np.linalg.norm(b)
    x = s.factor(B).solve(b)
    assert s.factorizations == 2 and not s._stale
    assert np.linalg.norm(B @ x - b) <= 1e-12 * np.linalg.norm(b)  # direct


@pytest.mark.parametrize("backend", BACKENDS)
def test_useless_preconditioner_refactorises_at_once(backend):
    """GMRES that does not converge within its budget (the old factorisation is far off):
    refactorise now and solve directly."""
    rng = np.random.default_rng(8)
    A = _spd(900, rng)
    s = linsolve.SymmetricSolver(A, backend, "reuse", factor_cost=15)
    s.factor(A).solve(rng.standard_normal(900))
    B = _shifted(A, -3.0)   # indefinite, far from A
    b = rng.standard_normal(900)
    x = s.factor(B).solve(b)
    assert s.factorizations == 2 and s.krylov_iterations == 15  # the budget: one factorisation's cost
    assert np.linalg.norm(B @ x - b) <= 1e-9 * np.linalg.norm(b)


@pytest.mark.parametrize("backend", BACKENDS)
def test_gmres_failures_in_a_row_back_off_to_direct_factorisations(backend):
    """After n failed GMRES solves in a row the next 2^n - 1 matrices are factorised without a
    GMRES try (a failure costs its budget and a factorisation); a converged GMRES solve ends
    the streak."""
    rng = np.random.default_rng(9)
    A = _spd(900, rng)
    s = linsolve.SymmetricSolver(A, backend, "reuse", factor_cost=15)
    s.factor(A).solve(rng.standard_normal(900))
    shift = [-3.0]

    def far():  # each matrix far from the last factorised one: GMRES cannot converge in 15
        shift[0] -= 3.0
        return _shifted(A, shift[0])

    B = far()
    s.factor(B).solve(rng.standard_normal(900))          # failure 1: 15 iterations wasted
    assert (s.factorizations, s.krylov_iterations) == (2, 15)
    B = far()
    x = s.factor(B).solve(b := rng.standard_normal(900))  # the next one directly
    assert (s.factorizations, s.krylov_iterations) == (3, 15)
    assert np.linalg.norm(B @ x - b) <= 1e-9 * np.linalg.norm(b)
    s.factor(far()).solve(rng.standard_normal(900))      # failure 2: then 3 direct
    assert (s.factorizations, s.krylov_iterations) == (4, 30)
    for k in range(3):
        s.factor(far()).solve(rng.standard_normal(900))
    assert (s.factorizations, s.krylov_iterations) == (7, 30)
    B = _shifted(A, shift[0] + 1e-6)                      # close to the last one: GMRES converges
    x = s.factor(B).solve(b)
    assert s.factorizations == 7 and 30 < s.krylov_iterations <= 33 and s._failures == 0
    assert np.linalg.norm(B @ x - b) <= 10 * linsolve.KRYLOV_RTOL * np.linalg.norm(b)


def test_unknown_method_is_a_parameter_error():
    with pytest.raises(ParameterError, match="linear solver method"):
        linsolve.SymmetricSolver(sp.eye(3, format="csr"), "superlu", "amg")


@pytest.fixture(scope="module")
def slab3d():
    """A short coarse 3D slab model (t = 3 mm flat, 2 mm long, quarter model)."""
    from tactileskin.fe import model_for_scene
    from tactileskin.mesh.slab3d import build_slab_mesh
    from tactileskin.scene import Scene

    sc = Scene(thickness=3, indenter="flat", dim=3, mesh_size=1.0, refinement=1)
    return sc, model_for_scene(sc, build_slab_mesh(sc, length=2.0))[0]


def test_reuse_on_3d_tangents_matches_direct(slab3d):
    sc, model = slab3d
    free = model.pattern

    def tangent(frac, u):
        ev = model.evaluate(u, frac * sc.duration, 0.05 * sc.duration, None, tangent=True)
        assert ev.ok
        return free.free_matrix(ev.K), ev

    K0, ev0 = tangent(0.05, model.u)
    assert abs(K0 - K0.T).max() <= 1e-12 * abs(K0).max()  # symmetric: PARDISO's mtype -2 applies
    rng = np.random.default_rng(7)
    # a second tangent at a displaced state (what the next Newton iteration sees)
    u1 = model.u.copy()
    X = model.basis.doflocs
    smooth = np.zeros_like(u1)
    smooth[1::model.m] = -1e-4 * (X[1] - X[1].min()) * np.cos(X[0])  # a gentle squeeze
    u1[model.free] += smooth[model.free]
    K1, _ = tangent(0.1, u1)
    assert abs(K1 - K0).max() > 1e-6 * abs(K0).max()  # really a different matrix
    backend = BACKENDS[-1]
    # the cost rule would refactorise at once on so small a model: test the Krylov path
    s = linsolve.SymmetricSolver(K0, backend, "reuse", factor_cost=linsolve.KRYLOV_MAX)
    d = linsolve.SymmetricSolver(K0, backend, "direct")
    for K in (K0, K1):
        b = rng.standard_normal(K.shape[0])
        x, xd = s.factor(K).solve(b), d.factor(K).solve(b)
        assert np.linalg.norm(x - xd) <= 1e-6 * np.linalg.norm(xd)
    assert s.factorizations == 1 and s.krylov_iterations > 0


def test_newton_picks_the_method(slab3d):
    from tactileskin.fe.solver import SolverOptions, linear_method

    _, model = slab3d
    n = len(model.free)
    auto = SolverOptions()
    assert linear_method(model, n, auto) == "direct"  # below reuse_min_dofs
    big = SolverOptions(reuse_min_dofs=n)
    assert linear_method(model, n, big) == ("reuse" if linsolve.pardiso_available() else "direct")
    assert linear_method(model, n, SolverOptions(reuse_min_dofs=n, linear_solver="superlu")) == "direct"
    assert linear_method(model, n, SolverOptions(linear_method="reuse")) == "reuse"
    assert linear_method(model, 10 ** 9, SolverOptions(linear_method="direct")) == "direct"
    with pytest.raises(ParameterError, match="linear_method"):
        linear_method(model, n, SolverOptions(linear_method="amg"))
    model.m, m = 2, model.m
    try:
        assert linear_method(model, 10 ** 9, auto) == "direct"  # 2D keeps direct solves
    finally:
        model.m = m


def test_3d_solve_with_reuse_matches_direct(slab3d):
    """The whole Newton path with a reused factorisation: same answer to the Newton tolerance,
    and at most 10 % more Newton iterations (the Krylov solves stop at 0.1 |R|, an inexact
    Newton step; the contact multipliers are updated inside Newton once the residual falls
    below a threshold, which an inexact step can reach one iteration later: 31 against 30
    here, where the exact-step path used to tie)."""
    from tactileskin.fe import model_for_scene, run
    from tactileskin.fe.solver import SolverOptions
    from tactileskin.mesh.slab3d import build_slab_mesh

    sc, _ = slab3d
    mesh = build_slab_mesh(sc, length=2.0)
    out = {}
    for method in ("direct", "reuse"):
        model = model_for_scene(sc, mesh)[0]
        ev, st = run(model, sc.duration, SolverOptions(linear_method=method))
        out[method] = (model.u.copy(), st.newton_iterations, model._linsolve)
    (ud, nd, ld), (ur, nr, lr) = out["direct"], out["reuse"]
    assert lr.method == "reuse" and lr.krylov_iterations > 0 and lr.factorizations < ld.factorizations
    # the reused factorisation is single precision (PARDISO): it only preconditions
    assert lr.precision == ("single" if lr.backend == "pardiso" else "double") and ld.precision == "double"
    assert nr <= 1.1 * nd
    assert np.linalg.norm(ur - ud) <= 1e-6 * np.linalg.norm(ud)


def test_looser_krylov_tolerance_takes_fewer_iterations_and_is_met():
    """The Newton-aware tolerance (solve(b, rtol)): looser stops earlier and still meets it;
    direct solves ignore it."""
    rng = np.random.default_rng(9)
    A = _spd(900, rng)
    B = _shifted(A, 1.0)
    b = rng.standard_normal(900)
    its = {}
    for rtol in (None, 1e-4):
        s = linsolve.SymmetricSolver(A, "superlu", "reuse", factor_cost=40)
        s.factor(A).solve(b)
        x = s.factor(B).solve(b, rtol=rtol)
        its[rtol] = s.krylov_iterations
        assert np.linalg.norm(B @ x - b) <= 10 * (rtol or linsolve.KRYLOV_RTOL) * np.linalg.norm(b)
    assert 0 < its[1e-4] < its[None]
    d = linsolve.SymmetricSolver(B, "superlu", "direct")
    x = d.factor(B).solve(b, rtol=1e-2)
    assert np.linalg.norm(B @ x - b) <= 1e-12 * np.linalg.norm(b)


@pytest.mark.skipif(not linsolve.pardiso_available(), reason="MKL is installed on x86-64 only")
def test_single_precision_factorisation_only_preconditions():
    """precision "single": PARDISO factorises in float32, which alone solves to ~1e-7; every
    solve, the fresh factorisation's own matrix included, is GMRES in double precision to the
    same tolerance as the double-precision solver, so the answers agree to it."""
    rng = np.random.default_rng(21)
    A = _spd(2500, rng)
    b = rng.standard_normal(2500)
    # (the cost rule would refactorise at once on so small a matrix: test the Krylov path)
    s = linsolve.SymmetricSolver(A, "pardiso", "reuse", precision="single", factor_cost=linsolve.KRYLOV_MAX)
    d = linsolve.SymmetricSolver(A, "pardiso", "direct")
    xd = d.factor(A).solve(b)
    x = s.factor(A).solve(b)
    assert s._pardiso.data.dtype == np.float32 and s.describe()["precision"] == "single"
    alone = s._direct(b)
    assert np.linalg.norm(A @ alone - b) > 1e-10 * np.linalg.norm(b)      # float32 alone is not enough
    assert s.krylov_iterations >= 1
    assert np.linalg.norm(A @ x - b) <= 10 * linsolve.KRYLOV_RTOL * np.linalg.norm(b)
    assert np.linalg.norm(x - xd) <= 1e-6 * np.linalg.norm(xd)
    # reused for the next matrix, like the double-precision factorisation
    A2 = _scaled(A, 1e-3, rng)
    x2 = s.factor(A2).solve(b)
    assert s.factorizations == 1 and np.linalg.norm(A2 @ x2 - b) <= 10 * linsolve.KRYLOV_RTOL * np.linalg.norm(b)


@pytest.mark.skipif(not linsolve.pardiso_available(), reason="MKL is installed on x86-64 only")
def test_single_precision_that_does_not_precondition_falls_back_to_double():
    """If GMRES fails with the single-precision factorisation of the very matrix it solves,
    the solver switches to double precision for good and answers directly."""
    rng = np.random.default_rng(22)
    A = _spd(900, rng)
    b = rng.standard_normal(900)
    s = linsolve.SymmetricSolver(A, "pardiso", "reuse", precision="single")
    real = s._gmres
    s._gmres = lambda A_, b_, rtol, limit: ((np.zeros_like(b_), limit, False) if s.precision == "single"
                                             else real(A_, b_, rtol, limit))
    x = s.factor(A).solve(b)
    assert s.precision == "double" and s._pardiso.data.dtype == np.float64
    assert np.linalg.norm(A @ x - b) <= 1e-10 * np.linalg.norm(b)


def test_single_precision_is_for_reuse_only():
    A = sp.eye(3, format="csr")
    with pytest.raises(ParameterError, match="precision"):
        linsolve.SymmetricSolver(A, "superlu", "direct", precision="single")
    with pytest.raises(ParameterError, match="precision"):
        linsolve.SymmetricSolver(A, "superlu", "reuse", precision="half")
    assert linsolve.SymmetricSolver(A, "superlu", "reuse", precision="single").precision == "double"  # SuperLU


def test_factor_precision_option_is_checked(slab3d):
    from tactileskin.fe import model_for_scene, run
    from tactileskin.fe.solver import SolverOptions
    from tactileskin.mesh.slab3d import build_slab_mesh

    sc, _ = slab3d
    model = model_for_scene(sc, build_slab_mesh(sc, length=2.0))[0]
    with pytest.raises(ParameterError, match="factor_precision"):
        run(model, sc.duration, SolverOptions(linear_method="reuse", factor_precision="half"))


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_system_at_which_gmres_failed_last_increment_is_factorised_directly(backend):
    """Each increment: a matrix near the last factorised one, then one far from it (the 3D
    dots' second Newton system after the first step moved the contact set). GMRES fails on the
    far one in the first increment (its budget wasted, then a factorisation); from the second
    increment that system is factorised without a GMRES try, so no budget is wasted again."""
    rng = np.random.default_rng(11)
    A = _spd(900, rng)
    s = linsolve.SymmetricSolver(A, backend, "reuse", factor_cost=15)
    s.factor(A).solve(rng.standard_normal(900))           # the first factorisation
    shift = [0.0]
    for inc in range(3):
        s.begin_increment()
        near = _shifted(A, shift[0] + 1e-6)
        s.factor(near).solve(rng.standard_normal(900))    # near the last factorised: GMRES
        shift[0] -= 3.0
        far = _shifted(A, shift[0])
        x = s.factor(far).solve(b := rng.standard_normal(900))
        assert np.linalg.norm(far @ x - b) <= 10 * linsolve.KRYLOV_RTOL * np.linalg.norm(b)
        if inc == 0:
            assert s.factorizations == 2 and 15 <= s.krylov_iterations <= 19  # one wasted budget
            spent = s.krylov_iterations
    # increments 2 and 3: the far system factorised at once (no budget wasted again); the near
    # one of increment 2 directly too (the back-off after a failure), of increment 3 by GMRES
    assert s.factorizations == 5 and spent < s.krylov_iterations <= spent + 8 and s._failures == 0
