"""fe.linsolve: both backends solve symmetric (indefinite) systems of a fixed structure,
refactorise with new values, and fail with a typed error on singular input."""

import os

import numpy as np
import pytest
import scipy.sparse as sp

from tactileskin.errors import ParameterError
from tactileskin.fe import linsolve

BACKENDS = ["superlu"] + (["pardiso"] if linsolve.pardiso_available() else [])


def _laplacian_like(n: int, shift: float, rng) -> sp.csr_matrix:
    """Symmetric 2D 5-point matrix with random symmetric off-diagonals, diagonal shifted:
    indefinite for a shift inside the spectrum (the fingertip tangent is nearly SPD, but the
    contact-curvature term can make it indefinite)."""
    k = int(np.sqrt(n))
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(k, k))
    A = sp.kronsum(T, T).tocsr()
    R = sp.random(k * k, k * k, density=2.0 / (k * k), random_state=rng.integers(1 << 31))
    R = R + R.T
    A = (A + 0.1 * R.multiply(A != 0) - shift * sp.eye(k * k)).tocsr()
    A.sort_indices()
    return A


@pytest.mark.parametrize("backend", BACKENDS)
def test_solves_indefinite_symmetric_systems_and_refactorises(backend):
    rng = np.random.default_rng(1)
    A1 = _laplacian_like(900, 0.0, rng)
    A2 = A1.copy()
    A2.data = A1.data - 0.5 * (A1.indices == np.repeat(np.arange(900), np.diff(A1.indptr)))  # shift: indefinite
    assert np.linalg.eigvalsh(A2.toarray()).min() < 0  # the second matrix really is indefinite
    s = linsolve.SymmetricSolver(A1, backend)
    for A in (A1, A2, A1):
        b = rng.standard_normal(900)
        x = s.factor(A).solve(b)
        # backward-stable direct solve: residual ~ cond * eps; cond < 1e5 here
        assert np.linalg.norm(A @ x - b) <= 1e-9 * np.linalg.norm(b)
    assert s.factorizations == 3
    s.close()


@pytest.mark.skipif("pardiso" not in BACKENDS, reason="MKL is installed on x86-64 only")
def test_pardiso_matches_superlu():
    rng = np.random.default_rng(2)
    A = _laplacian_like(400, 0.3, rng)
    b = rng.standard_normal(400)
    xs = linsolve.SymmetricSolver(A, "superlu").factor(A).solve(b)
    xp = linsolve.SymmetricSolver(A, "pardiso").factor(A).solve(b)
    assert np.allclose(xs, xp, rtol=1e-9, atol=1e-12 * np.abs(xs).max())


@pytest.mark.parametrize("backend", BACKENDS)
def test_singular_matrix_raises_typed_error(backend):
    A = sp.csr_matrix((np.array([1.0, 2.0, 0.0, 3.0]), np.arange(4), np.arange(5)), shape=(4, 4))
    s = linsolve.SymmetricSolver(A, backend)
    with pytest.raises(RuntimeError):  # SingularMatrix (pardiso) or SuperLU's RuntimeError
        x = s.factor(A).solve(np.ones(4))
        # pardiso may perturb the zero pivot instead of failing: then the solve is not finite
        # or does not satisfy the system; either way the caller sees it
        if not np.all(np.isfinite(x)) or np.linalg.norm(A @ x - np.ones(4)) > 1e-6:
            raise linsolve.SingularMatrix("perturbed")


def test_unknown_backend_is_a_parameter_error():
    A = sp.eye(3, format="csr")
    with pytest.raises(ParameterError, match="linear solver backend"):
        linsolve.SymmetricSolver(A, "umfpack")


@pytest.mark.skipif("pardiso" not in BACKENDS, reason="MKL is installed on x86-64 only")
def test_fingertip_solve_is_backend_independent():
    """Same Newton path with either backend: the peak agrees to the Newton tolerance (1e-8
    relative residual gives ~1e-8 relative in the state; allow 1e-7)."""
    from tactileskin import fe
    from tactileskin.fe.solver import SolverOptions
    from tactileskin.scene import Scene

    sc = Scene(thickness=1, material="silicone", indenter="curved", mesh_size=1.0, refinement=2)
    peaks = [fe.solve(sc, options=SolverOptions(linear_solver=b)).peak for b in ("superlu", "pardiso")]
    assert peaks[1] == pytest.approx(peaks[0], rel=1e-7)


def test_thread_count_from_the_environment_or_the_cpus(monkeypatch):
    monkeypatch.delenv("TACTILESKIN_THREADS", raising=False)
    monkeypatch.setenv("MKL_NUM_THREADS", "3")
    assert linsolve.default_threads(large=False) == 3 and linsolve.default_threads(large=True) == 3
    monkeypatch.setenv("TACTILESKIN_THREADS", "2")  # a sweep worker's share: large systems only
    assert linsolve.default_threads(large=True) == 2 and linsolve.default_threads(large=False) == 3
    monkeypatch.delenv("TACTILESKIN_THREADS")
    monkeypatch.setenv("MKL_NUM_THREADS", "many")
    assert linsolve.default_threads(large=True) == 1
    monkeypatch.delenv("MKL_NUM_THREADS")
    assert linsolve.default_threads(large=False) == 1
    n = linsolve.default_threads(large=True)
    assert 1 <= n <= linsolve.MAX_THREADS and n <= (os.cpu_count() or 1)


@pytest.mark.skipif("pardiso" not in BACKENDS, reason="MKL is installed on x86-64 only")
def test_pardiso_with_two_threads_solves_the_same_system():
    """The threaded factorisation sums in another order: same solution to rounding (cond < 1e5)."""
    rng = np.random.default_rng(3)
    A = _laplacian_like(2500, 0.3, rng)
    b = rng.standard_normal(2500)
    x1 = linsolve.SymmetricSolver(A, "pardiso", threads=1).factor(A).solve(b)
    s2 = linsolve.SymmetricSolver(A, "pardiso", threads=2)
    lib = s2._pardiso.lib
    before = lib.MKL_Get_Max_Threads()
    during = []
    inner = s2._pardiso._pardiso

    def spy(*args):  # MKL's thread count in effect inside each PARDISO call
        during.append(lib.MKL_Get_Max_Threads())
        return inner(*args)

    s2._pardiso._pardiso = spy
    x2 = s2.factor(A).solve(b)
    assert during and set(during) == {2}
    assert lib.MKL_Get_Max_Threads() == before  # the thread-local setting is undone after
    assert np.linalg.norm(A @ x2 - b) <= 1e-9 * np.linalg.norm(b)
    assert np.allclose(x1, x2, rtol=1e-8, atol=1e-10 * np.abs(x1).max())


def test_sweep_workers_share_the_cpus(monkeypatch):
    from tactileskin.sweep import worker_threads

    for v in ("TACTILESKIN_THREADS", "MKL_NUM_THREADS"):
        monkeypatch.delenv(v, raising=False)
    from tactileskin.threads import available_cpus

    cpus = available_cpus()
    assert 1 <= cpus <= (os.cpu_count() or 1)
    assert worker_threads(cpus) == "1"
    assert worker_threads(1) == str(cpus)
    monkeypatch.setenv("MKL_NUM_THREADS", "1")
    assert worker_threads(1) == "1"


@pytest.mark.skipif("pardiso" not in BACKENDS, reason="MKL is installed on x86-64 only")
def test_a_failed_factorisation_is_not_kept_as_the_preconditioner():
    """Method "reuse": after a factorisation fails, the next factor() refactorises instead of
    preconditioning GMRES with what the failed call left."""
    rng = np.random.default_rng(4)
    A = _laplacian_like(400, 0.0, rng)
    s = linsolve.SymmetricSolver(A, "pardiso", method="reuse")
    s.factor(A)
    real = s._pardiso.factor

    def fail(data):
        raise linsolve.SingularMatrix("made to fail")

    s._pardiso.factor, s._stale = fail, True
    with pytest.raises(linsolve.SingularMatrix):
        s.factor(A)
    s._pardiso.factor = real
    n = s.factorizations
    b = rng.standard_normal(400)
    x = s.factor(A).solve(b)
    assert s.factorizations == n + 1
    assert np.linalg.norm(A @ x - b) <= 1e-9 * np.linalg.norm(b)


@pytest.mark.skipif("pardiso" not in BACKENDS, reason="MKL is installed on x86-64 only")
def test_pardiso_orderings_solve_the_same_system():
    """Minimum degree (AMD) and METIS nested dissection: each is the one PARDISO analyses with,
    and both solve the system to rounding (cond < 1e5)."""
    rng = np.random.default_rng(5)
    A = _laplacian_like(1600, 0.3, rng)
    b = rng.standard_normal(1600)
    xs = {}
    for ordering, code in (("metis", 2), ("amd", 0)):
        s = linsolve.SymmetricSolver(A, "pardiso", ordering=ordering)
        assert s._pardiso.iparm[1] == code and s.describe()["ordering"] == ordering
        xs[ordering] = s.factor(A).solve(b)
        assert np.linalg.norm(A @ xs[ordering] - b) <= 1e-9 * np.linalg.norm(b)
        s.close()
    assert np.allclose(xs["amd"], xs["metis"], rtol=1e-8, atol=1e-10 * np.abs(xs["metis"]).max())


def test_unknown_ordering_is_a_parameter_error():
    A = sp.eye(3, format="csr")
    with pytest.raises(ParameterError, match="linear solver ordering"):
        linsolve.SymmetricSolver(A, "superlu", ordering="rcm")


def test_ordering_by_dimension():
    """2D tangents (2-11k free dofs): minimum degree, measured 7-12 % less factorisation CPU
    than METIS and 37-47 % less analysis; 3D keeps nested dissection."""
    assert linsolve.default_ordering(2) == "amd"
    assert linsolve.default_ordering(3) == "metis"


@pytest.mark.skipif("pardiso" not in BACKENDS, reason="MKL is installed on x86-64 only")
def test_a_2d_solve_uses_the_2d_ordering():
    from tactileskin import fe
    from tactileskin.scene import Scene

    r = fe.solve(Scene(thickness=1, material="silicone", indenter="flat", mesh_size=1.0, refinement=2))
    assert r.stats["linear_solver"]["ordering"] == linsolve.default_ordering(2) == "amd"


def _laplacian_3d(k: int, shift: float) -> sp.csr_matrix:
    """7-point 3D Laplacian (k^3 unknowns), diagonal shifted: a small 3D-like sparsity with
    nested-dissection separators."""
    T = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(k, k))
    A = sp.kronsum(sp.kronsum(T, T), T).tocsr()
    A = (A - shift * sp.eye(k ** 3)).tocsr()
    A.sort_indices()
    return A


@pytest.mark.skipif("pardiso" not in BACKENDS, reason="MKL is installed on x86-64 only")
@pytest.mark.parametrize("extra", [{24: 1}, {24: 2}, {23: 1}, {1: 3}])
def test_pardiso_iparm_overrides_are_set_and_solve_the_same_system(extra):
    """_Pardiso's iparm overrides (benchmarks/pardiso_options3d.py) are what PARDISO runs with,
    and each solves a small 3D system (2 threads) as the plain settings do, to rounding
    (cond < 1e3: relative difference < 1e-10)."""
    A = _laplacian_3d(14, 0.05)
    n = A.shape[0]
    b = np.random.default_rng(6).standard_normal(n)
    up = sp.triu(A, format="csr")
    xs = []
    for kw in ({}, extra):
        p = linsolve._Pardiso(n, up.indptr, up.indices, threads=2, iparm=kw)
        for k, v in kw.items():
            assert p.iparm[k] == v
        p.factor(up.data)
        xs.append(p.solve(b))
        p.close()
        assert np.linalg.norm(A @ xs[-1] - b) <= 1e-10 * np.linalg.norm(b)
    assert np.max(np.abs(xs[1] - xs[0])) <= 1e-10 * np.max(np.abs(xs[0]))

