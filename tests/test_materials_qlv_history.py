"""The viscoelastic state of a material (Prony.history -> QLVHistory) wraps any law's stress."""

from __future__ import annotations

import numpy as np
import pytest

from tactileskin.errors import ParameterError
from tactileskin.materials import get_material
from tactileskin.materials.neo_hookean import NeoHookean
from tactileskin.materials.prony import Prony


def test_order_one_is_the_prony_update():
    """History order 1 (the chord) reproduces Prony.update step by step, to rounding."""
    p = get_material("polyurethane").prony
    rng = np.random.default_rng(0)
    S0s = np.cumsum(rng.standard_normal((6, 4, 3, 3)), axis=0)
    dts = [0.01, 0.05, 0.2, 1.0, 0.003, 3.0]
    h = p.history((4, 3, 3), order=1)
    H = p.initial_state((4, 3, 3))
    S0_old = np.zeros((4, 3, 3))
    for S0, dt in zip(S0s, dts):
        S_ref, H = p.update(H, S0_old, S0, dt)
        S, gamma = h.stress(S0, dt)
        assert np.abs(S - S_ref).max() <= 1e-13 * np.abs(S_ref).max()
        assert gamma == pytest.approx(p.tangent_factor(dt), rel=1e-15)
        h.commit(S0, dt)
        S0_old = S0


def test_relaxation_of_a_neo_hookean_ramp_and_hold():
    """A neo-Hookean stress ramped linearly over t_r, then held: the closed-form convolution
    S(t) = S_end [g_inf + sum_i g_i (tau_i/t_r)(1 - e^(-t_r/tau_i)) e^(-(t - t_r)/tau_i)]
    (the chord update is exact for S0 linear in time; rounding only)."""
    law, p = NeoHookean(0.05, 2.5), Prony((0.3, 0.2), (0.1, 2.0))
    S_end = law.pk2(np.diag([0.9**2, 1.05**2, 1.0]))[0]
    t_r, n = 0.5, 10
    h = p.history((3, 3), order=1)
    t = 0.0
    for k in range(1, n + 1):                      # ramp: S0 linear in time
        h.commit(S_end * k / n, t_r / n)
    t = t_r
    for dt in (0.05, 0.3, 1.0, 4.0):               # hold
        S, _ = h.stress(S_end, dt)
        h.commit(S_end, dt)
        t += dt
        g = p.g_inf + sum(gi * ti / t_r * -np.expm1(-t_r / ti) * np.exp(-(t - t_r) / ti)
                          for gi, ti in zip(p.g, p.tau))
        assert np.abs(S - g * S_end).max() <= 1e-13 * np.abs(S_end).max()


def test_elastic_history_passes_the_stress_through():
    h = Prony.elastic().history((2, 3, 3))
    S0 = np.random.default_rng(1).standard_normal((2, 3, 3))
    S, gamma = h.stress(S0, 0.1)
    assert gamma == 1.0 and np.array_equal(S, S0)
    with pytest.raises(ParameterError, match="qlv_order"):
        Prony.elastic().history((3, 3), order=3)


@pytest.mark.parametrize("material", ["silicone", "polyurethane", None])
def test_trial_stress_is_the_term_by_term_numpy_update_bit_for_bit(material):
    """QLVHistory.stress (a compiled loop) gives the bits of the numpy expression it replaces,
    S = gamma S0 + sum_i (decay_i H_i - gain_i S0_old - back_i (S0_old - S0_prev)) term by
    term, on the chord's first step, the parabola's later steps, and with no terms (elastic)."""
    p = Prony.elastic() if material is None else get_material(material).prony
    rng = np.random.default_rng(3)
    shape = (7, 3, 3, 3)
    h = p.history(shape, order=2)
    for step, dt in enumerate((0.02, 0.05, 0.011, 0.3)):
        S0 = rng.standard_normal(shape) * 10.0 ** rng.uniform(-3, 1, shape)
        gamma, decay, gain, back = h.factors(dt)
        ref = gamma * S0
        for i in range(len(decay)):
            ref = ref + decay[i] * h.H[i] - gain[i] * h.S0_old
            if back[i]:
                ref = ref - back[i] * (h.S0_old - h.S0_prev)
        S, g = h.stress(S0, dt)
        assert g == gamma and S.shape == shape
        assert np.array_equal(S, ref), f"step {step}: max |diff| {np.abs(S - ref).max():.3g}"
        assert step < 2 or material is None or np.any(back)   # the parabola's term exercised
        h.commit(S0, dt)
