"""fe.solve runs its solve on one BLAS thread unless the user set a thread count."""

import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import tactileskin.fe as fe
from tactileskin.scene import Scene

COARSE = Scene(thickness=1.0, material="polyurethane", indenter="flat", mesh_size=1.0, refinement=2.0,
               viscoelastic=False)


def _blas_threads_seen_by_run(monkeypatch):
    seen = []
    real = fe.run

    def spy(*a, **k):
        seen.extend(p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas")
        return real(*a, **k)

    monkeypatch.setattr(fe, "run", spy)
    with threadpool_limits(limits=2, user_api="blas"):  # a caller whose BLAS runs 2 threads
        fe.solve(COARSE)
    return seen


def test_library_solve_limits_blas_to_one_thread(monkeypatch):
    for v in fe.THREAD_VARS:
        monkeypatch.delenv(v, raising=False)
    seen = _blas_threads_seen_by_run(monkeypatch)
    assert seen and set(seen) == {1}


def test_a_thread_count_set_by_the_user_is_respected(monkeypatch):
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
    seen = _blas_threads_seen_by_run(monkeypatch)
    if not seen or max(seen) < 2:
        pytest.skip("this BLAS cannot run 2 threads here")
    assert max(seen) == 2


def _numba_threads_seen_by_tangent(monkeypatch, scene, options):
    import numba

    from tactileskin.fe import kernels

    seen = []
    real = kernels.tangent

    def spy(*a, **k):
        seen.append(numba.get_num_threads())
        return real(*a, **k)

    monkeypatch.setattr(kernels, "tangent", spy)
    before = numba.get_num_threads()
    fe.solve(scene, options=options)
    assert numba.get_num_threads() == before     # the solve's setting is undone after
    return seen


def test_compiled_loops_take_the_solves_thread_count(monkeypatch):
    """The element and material loops run on the solve's threads (SolverOptions.threads, else
    linsolve.default_threads: 1 for a 2D model), not numba's default of every CPU."""
    import numba

    from tactileskin.fe.solver import SolverOptions

    monkeypatch.delenv("MKL_NUM_THREADS", raising=False)
    seen = _numba_threads_seen_by_tangent(monkeypatch, COARSE, SolverOptions())
    assert seen and set(seen) == {1}
    seen = _numba_threads_seen_by_tangent(monkeypatch, COARSE, SolverOptions(threads=2))
    assert seen and set(seen) == {min(2, numba.config.NUMBA_NUM_THREADS)}
