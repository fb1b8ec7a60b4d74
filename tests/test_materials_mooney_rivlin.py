"""Mooney-Rivlin closed forms: simple shear is linear, uniaxial, and the neo-Hookean limit."""

from __future__ import annotations

import numpy as np
import pytest

from tactileskin.materials.mooney_rivlin import MooneyRivlin
from tactileskin.materials.neo_hookean import NeoHookean


@pytest.mark.parametrize("g", [0.01, 0.3, 1.0, 2.5])
def test_simple_shear_is_linear(g):
    """F = I + g e1 e2 (J = 1): sigma_12 = 2 (c10 + c01) g exactly, for any g (a classic
    property of the Mooney-Rivlin solid); rounding only."""
    law = MooneyRivlin(0.03, 0.012, 5.0)
    F = np.eye(3)
    F[0, 1] = g
    S = law.pk2(F.T @ F)[0]
    sigma = F @ S @ F.T
    assert sigma[0, 1] == pytest.approx(2 * (0.03 + 0.012) * g, rel=1e-12)


@pytest.mark.parametrize("lam", [0.7, 1.3, 2.0])
def test_isochoric_uniaxial(lam):
    """sigma_1 - sigma_3 = 2 (l^2 - 1/l)(c10 + c01 / l) (incompressible uniaxial)."""
    law = MooneyRivlin(0.03, -0.005, 5.0)
    C = np.diag([lam**2, 1 / lam, 1 / lam])
    s = np.diag(C) * np.diag(law.pk2(C)[0])
    assert s[0] - s[2] == pytest.approx(2 * (lam**2 - 1 / lam) * (0.03 - 0.005 / lam), rel=1e-12)


def test_c01_zero_is_neo_hookean():
    """c01 = 0 is the neo-Hookean law with mu = 2 c10, at any (compressible) state."""
    rng = np.random.default_rng(2)
    F = np.eye(3) + 0.2 * rng.standard_normal((5, 3, 3))
    C = F.transpose(0, 2, 1) @ F
    S1, D1, _ = MooneyRivlin(0.04, 0.0, 3.0).pk2_tangent(C)
    S2, D2, _ = NeoHookean(0.08, 3.0).pk2_tangent(C)
    assert np.abs(S1 - S2).max() <= 1e-14 * 3.0 and np.abs(D1 - D2).max() <= 1e-13 * 3.0
