"""Yeoh closed forms: simple shear and uniaxial; one term is neo-Hookean."""

from __future__ import annotations

import numpy as np
import pytest

from tactileskin.materials.neo_hookean import NeoHookean
from tactileskin.materials.yeoh import Yeoh

C3 = (0.045, -0.004, 0.0008)


def dW(x):
    return sum(i * c * x ** (i - 1) for i, c in enumerate(C3, start=1))


@pytest.mark.parametrize("g", [0.01, 0.5, 1.5])
def test_simple_shear(g):
    """F = I + g e1 e2: I1 = 3 + g^2, J = 1, sigma_12 = 2 W'(g^2) g."""
    F = np.eye(3)
    F[0, 1] = g
    S = Yeoh(C3, 5.0).pk2(F.T @ F)[0]
    assert (F @ S @ F.T)[0, 1] == pytest.approx(2 * dW(g * g) * g, rel=1e-12)


@pytest.mark.parametrize("lam", [0.7, 1.3, 2.5])
def test_isochoric_uniaxial(lam):
    """sigma_1 - sigma_3 = 2 W'(I1 - 3) (l^2 - 1/l), I1 = l^2 + 2/l."""
    C = np.diag([lam**2, 1 / lam, 1 / lam])
    s = np.diag(C) * np.diag(Yeoh(C3, 5.0).pk2(C)[0])
    assert s[0] - s[2] == pytest.approx(2 * dW(lam**2 + 2 / lam - 3) * (lam**2 - 1 / lam), rel=1e-12)


def test_one_term_is_neo_hookean():
    rng = np.random.default_rng(4)
    F = np.eye(3) + 0.2 * rng.standard_normal((5, 3, 3))
    C = F.transpose(0, 2, 1) @ F
    S1, D1, _ = Yeoh((0.04,), 3.0).pk2_tangent(C)
    S2, D2, _ = NeoHookean(0.08, 3.0).pk2_tangent(C)
    assert np.abs(S1 - S2).max() <= 1e-14 * 3.0 and np.abs(D1 - D2).max() <= 1e-13 * 3.0
