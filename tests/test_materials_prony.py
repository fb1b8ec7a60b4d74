"""Prony-series QLV: recursive update against closed-form hereditary integrals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from tactileskin.errors import ParameterError
from tactileskin.materials import Prony, get_material, pk2, pk2_tangent

PRONY = {n: get_material(n).prony for n in ("silicone", "polyurethane")}


@pytest.mark.parametrize("g, tau", [
    ((-0.1,), (1.0,)),
    ((0.5, 0.5), (1.0, 2.0)),       # sum = 1: no long-term modulus
    ((0.1,), (0.0,)),
    ((0.1,), (-1.0,)),
    ((0.1, 0.2), (1.0,)),
    ((float("nan"),), (1.0,)),
])
def test_invalid_prony_raises(g, tau):
    with pytest.raises(ParameterError):
        Prony(g, tau)


def test_long_term_factors_table_i():
    # design.md: g_inf = 0.912 (silicone), 0.562 (polyurethane); exact sums of Table I
    assert PRONY["silicone"].g_inf == pytest.approx(0.912, abs=1e-12)
    assert PRONY["polyurethane"].g_inf == pytest.approx(0.562, abs=1e-12)


def test_step_factors_small_and_zero_steps():
    p = PRONY["polyurethane"]
    decay, gain = p.step_factors(0.0)
    assert np.all(decay == 1.0) and np.allclose(gain, p.g, rtol=0, atol=0)
    # h = 1e-10: gain = g (1 - h/2 + h^2/6); the naive (1 - e^-h)/h would be off by ~1e-7
    dt = 1e-10
    h = dt / np.array(p.tau)
    decay, gain = p.step_factors(dt)
    assert np.allclose(gain, np.array(p.g) * (1 - h / 2 + h * h / 6), rtol=1e-15, atol=0)
    assert np.allclose(decay, 1 - h + h * h / 2, rtol=1e-15, atol=0)
    with pytest.raises(ParameterError):
        p.step_factors(-1.0)


def _ramp_hold_exact(p: Prony, t, T):
    """S/S_ref for S0 = S_ref min(t, T)/T: (1/T) int_0^min(t,T) g(t - u) du."""
    tr = np.minimum(t, T)
    out = p.g_inf * tr
    for gi, ti in zip(p.g, p.tau):
        out = out + gi * ti * (np.exp(-(t - tr) / ti) - np.exp(-t / ti))
    return out / T


def _run(p, times, S0_of_t):
    """March the recursive update over `times` (t0 = 0, S0(0) = 0); stresses at each time."""
    S0_old = S0_of_t(0.0)
    H = p.initial_state(S0_old.shape)
    out = [p.g_inf * S0_old]
    for t0, t1 in zip(times[:-1], times[1:]):
        S0_new = S0_of_t(t1)
        S, H = p.update(H, S0_old, S0_new, t1 - t0)
        S0_old = S0_new
        out.append(S)
    return np.array(out)


@pytest.mark.parametrize("name", PRONY)
def test_ramp_and_hold_matches_closed_form(name):
    """Stress linear in time over each increment: the update is exact (1e-12, rounding only)."""
    p = PRONY[name]
    T = 0.2                                          # the paper's 0.2 mm at 1 mm/s
    t_end = T + 50 * max(p.tau)                      # long hold: reaches g_inf to e^-50
    S_ref, _ = pk2(get_material(name).hyperfoam, np.diag([0.9**2, 1.02**2, 1.0]))
    S0 = lambda t: S_ref * min(t, T) / T  # noqa: E731
    rng = np.random.default_rng(0)
    for n_ramp, n_hold in [(4, 5), (37, 60)]:        # two unrelated, non-uniform partitions
        ramp = np.sort(np.concatenate([[0.0, T], rng.uniform(0, T, n_ramp - 1)]))
        hold = np.sort(np.concatenate([[t_end], T + (t_end - T) * rng.uniform(0, 1, n_hold - 1) ** 3]))
        times = np.concatenate([ramp, hold])
        S = _run(p, times, S0)
        exact = _ramp_hold_exact(p, times, T)[:, None, None] * S_ref
        scale = np.abs(S_ref).max()
        assert np.abs(S - exact).max() <= 1e-12 * scale
        # long-term limit: g_inf S0 (the remaining transient is e^-50 ~ 2e-22)
        assert np.abs(S[-1] - p.g_inf * S_ref).max() <= 1e-12 * scale


def test_step_response_is_relaxation_function():
    p = PRONY["polyurethane"]
    t = np.array([0.0, 0.05, 0.3, 2.0, 30.0, 300.0])
    eps = 1e-9                       # ramp time: the step response differs by O(eps / tau_min) = 1e-8
    times = np.concatenate([[0.0], eps + t])
    S = _run(p, times, lambda s: np.array([[min(s, eps) / eps]]))[1:, 0, 0]
    assert np.allclose(S, p.relaxation(t), rtol=2e-8, atol=0)
    assert p.relaxation(0.0) == pytest.approx(1.0, abs=1e-15)
    assert p.relaxation(1e6) == pytest.approx(p.g_inf, abs=1e-15)


def test_nonlinear_history_converges_at_second_order():
    """Strain ramp (confined compression, silicone): S0(t) is curved, the update interpolates it
    linearly per increment, so the error must fall as dt^2."""
    mat = get_material("silicone")
    p, hf = mat.prony, mat.hyperfoam
    T, strain = 0.2, 0.02
    lam = lambda t: 1.0 - strain * min(t, T) / T  # noqa: E731
    S0 = lambda t: pk2(hf, np.diag([lam(t) ** 2, 1.0, 1.0]))[0]  # noqa: E731

    def dS11(s):  # dS0_11/ds = 1/2 D_11kl dC_kl/ds, dC_11/ds = -2 lam strain / T
        D = pk2_tangent(hf, np.diag([lam(s) ** 2, 1.0, 1.0]))[1]
        return 0.5 * D[0, 0, 0, 0] * (-2.0 * lam(s) * strain / T)

    ref = integrate.quad(lambda s: p.relaxation(T - s) * dS11(s), 0.0, T, epsabs=0, epsrel=1e-13, limit=200)[0]
    errs = []
    for n in (5, 10, 20, 40):
        S = _run(p, np.linspace(0.0, T, n + 1), S0)
        errs.append(abs(S[-1, 0, 0] - ref) / abs(ref))
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    # second order: observed rates within 0.2 of 2 on this smooth history
    assert np.all(np.abs(rates - 2.0) < 0.2), (errs, rates)


def test_tangent_factor_is_exact_derivative():
    p = PRONY["silicone"]
    rng = np.random.default_rng(3)
    H = rng.standard_normal((p.n_terms, 4, 3, 3))
    S0_old, S0_new, dS = rng.standard_normal((3, 4, 3, 3))
    dt = 0.013
    S1, _ = p.update(H, S0_old, S0_new, dt)
    S2, _ = p.update(H, S0_old, S0_new + 1e-3 * dS, dt)
    # the update is affine in S0_new: the difference quotient is exact up to rounding
    assert np.allclose((S2 - S1) / 1e-3, p.tangent_factor(dt) * dS, rtol=1e-9, atol=1e-12)
    assert p.tangent_factor(0.0) == pytest.approx(1.0, abs=1e-15)
    assert p.tangent_factor(1e9) == pytest.approx(p.g_inf, abs=1e-9)


def test_update_is_pure_and_checks_shapes():
    p = PRONY["silicone"]
    H = np.zeros((p.n_terms, 2, 3, 3))
    H0 = H.copy()
    p.update(H, np.zeros((2, 3, 3)), np.ones((2, 3, 3)), 0.1)
    assert np.array_equal(H, H0)
    with pytest.raises(ParameterError):
        p.update(np.zeros((2, 2, 3, 3)), np.zeros((2, 3, 3)), np.ones((2, 3, 3)), 0.1)


def test_elastic_prony_is_identity():
    p = Prony.elastic()
    assert p.g_inf == 1.0 and p.tangent_factor(0.5) == 1.0
    S, H = p.update(p.initial_state((3, 3)), np.zeros((3, 3)), np.eye(3), 0.5)
    assert np.array_equal(S, np.eye(3)) and H.shape == (0, 3, 3)
    assert math.isclose(p.relaxation(3.0), 1.0)


@pytest.mark.parametrize("dt,dt_prev", [(1e-4, 2e-4), (0.01, 0.01), (0.1, 0.05), (0.3, 0.2), (5.0, 1.0)])
def test_quadratic_step_factors_match_quadrature(dt, dt_prev):
    """gain/back of the parabola update against adaptive quadrature of
    int_0^dt sum_i g_i exp(-(dt - x)/tau_i) p'(x) dx, p the parabola through
    (-dt_prev, S_{n-1}), (0, S_n), (dt, S_{n+1}); covers the series branch (dt/tau < 0.02)
    and dt >> tau. quad's error is ~1e-14 here: 1e-9 relative is a wide margin."""
    from scipy.integrate import quad

    pr = Prony((0.167, 0.158, 0.113), (0.100, 1.380, 25.472))
    decay, gain, back = pr.step_factors_quadratic(dt, dt_prev)
    Sm, S0, S1 = 0.3, 1.0, 2.2
    c2 = ((S1 - S0) / dt - (S0 - Sm) / dt_prev) / (dt + dt_prev)
    c1 = (S1 - S0) / dt - c2 * dt
    for i, (g, tau) in enumerate(zip(pr.g, pr.tau)):
        ref = g * quad(lambda x: np.exp(-(dt - x) / tau) * (c1 + 2 * c2 * x), 0.0, dt, epsabs=0, epsrel=1e-13)[0]
        got = gain[i] * (S1 - S0) - back[i] * (S0 - Sm)
        assert got == pytest.approx(ref, rel=1e-9, abs=1e-15)
    assert np.allclose(decay, np.exp(-dt / np.asarray(pr.tau)))


@pytest.mark.parametrize("tau", [1e200, 1e13, 1e-320, 1e-16])
def test_a_relaxation_time_past_the_solvable_range_is_refused_naming_it(tmp_path, capsys, tau):
    """tau = 1e200 s (or 1e-320 s) was accepted and every solve failed with 'no convergence ...
    non-finite residual' (tau**2 overflows in the quadratic update), naming neither tau nor a range."""
    from tactileskin.cli import main

    mat = tmp_path / "gel.toml"
    mat.write_text(f"[hyperfoam]\nmu = [0.08, 0.01]\nalpha = [0.001, 15.5]\nnu = 0.49\n"
                   f"[prony]\ng = [0.015, 0.044]\ntau = [{tau!r}, 0.15]\n")
    assert main(["solve", "--quality", "preview", "-t", "1", "-m", str(mat), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "tau[0]" in err and "[1e-15, 1e+12] s" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("tau", [1e-15, 1e12])
def test_the_update_stays_finite_at_the_ends_of_the_relaxation_time_range(tau):
    p = Prony((0.3,), (tau,))
    for dt in (1e-12, 1e-6, 1.0, 3e7):
        for dt_prev in (1e-12, 1.0, 3e7):
            assert all(np.all(np.isfinite(f)) for f in p.step_factors_quadratic(dt, dt_prev))
        assert np.all(np.isfinite(p.step_factors(dt)))


@pytest.mark.parametrize("tau", [1e-10, 1e-12, 1e-15])
def test_a_master_curves_glassy_relaxation_times_are_accepted(tau):
    """A Prony series fitted to a DMA master curve carries terms far below 1 ns (an elastomer's
    glassy relaxation at room temperature): they relax within any step and solve (checked: a
    ramp and a 10 s hold of the gel with tau = 1e-15 s and 1e-12 s, status ok); a lower bound
    of 1e-9 s refused such a file as a units slip."""
    p = Prony((0.015, 0.044), (tau, 0.15))
    assert p.tau[0] == tau
    decay, gain = p.step_factors(1e-3)
    assert decay[0] == 0.0 and gain[0] == pytest.approx(0.015 * tau / 1e-3, rel=1e-9)
