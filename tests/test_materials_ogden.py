"""Ogden closed forms: uniaxial, and alpha = (2, -2) is Mooney-Rivlin at every state."""

from __future__ import annotations

import numpy as np
import pytest

from tactileskin.materials.mooney_rivlin import MooneyRivlin
from tactileskin.materials.ogden import Ogden


@pytest.mark.parametrize("lam", [0.6, 1.0, 1.4, 2.5])
def test_isochoric_uniaxial(lam):
    """sigma_1 - sigma_3 = sum_p (2 mu_p / alpha_p)(l^alpha_p - l^(-alpha_p/2))."""
    mu, al = (0.06, 0.002), (1.8, 7.0)
    C = np.diag([lam**2, 1 / lam, 1 / lam])
    s = np.diag(C) * np.diag(Ogden(mu, al, 5.0).pk2(C)[0])
    ref = sum(2 * m / a * (lam**a - lam ** (-a / 2)) for m, a in zip(mu, al))
    assert s[0] - s[2] == pytest.approx(ref, rel=1e-12, abs=1e-16)


def test_alpha_2_minus_2_is_mooney_rivlin():
    """Ogden((2 c10, 2 c01), (2, -2)) = Mooney-Rivlin(c10, c01) for every C, compressible
    too (sum lb^2 = I1b, sum lb^-2 = I2b): an independent check of the spectral
    (Daleckii-Krein) tangent against the invariant one, including repeated stretches."""
    rng = np.random.default_rng(7)
    F = np.eye(3) + 0.25 * rng.standard_normal((6, 3, 3))
    C = np.concatenate([F.transpose(0, 2, 1) @ F, [np.eye(3), np.diag([1.2, 0.9, 0.9])]])
    S1, D1, ok1 = Ogden((0.06, 0.02), (2.0, -2.0), 4.0).pk2_tangent(C)
    S2, D2, ok2 = MooneyRivlin(0.03, 0.01, 4.0).pk2_tangent(C)
    assert ok1.all() and ok2.all()
    assert np.abs(S1 - S2).max() <= 1e-12 * 4.0 and np.abs(D1 - D2).max() <= 1e-12 * 4.0


def test_nearly_equal_stretches_are_smooth():
    """Stretch gaps from 1e-3 down to 0: D varies smoothly (no divided-difference blow-up)."""
    law = Ogden((0.05,), (5.0,), 3.0)
    Ds = [law.pk2_tangent(np.diag([1.1**2, (1.1 + d) ** 2, 0.9]))[1] for d in (1e-3, 1e-6, 1e-9, 1e-13, 0.0)]
    for Da in Ds[1:]:
        assert np.abs(Da - Ds[-1]).max() <= 1e-2 * np.abs(Ds[-1]).max()
    assert np.abs(Ds[-2] - Ds[-1]).max() <= 1e-8 * np.abs(Ds[-1]).max()
