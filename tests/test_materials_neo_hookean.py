"""Neo-Hookean closed forms: isochoric uniaxial stress, Young's modulus, pure dilatation."""

from __future__ import annotations

import numpy as np
import pytest

from tactileskin.materials.fit import uniaxial_nominal
from tactileskin.materials.neo_hookean import NeoHookean


def cauchy(law, C, J=1.0):
    """Cauchy stress of a diagonal C: sigma_a = c_a S_a / J."""
    S = law.pk2(C)[0]
    return np.diag(C) * np.diag(S) / J


@pytest.mark.parametrize("lam", [0.6, 0.9, 1.0, 1.5, 3.0])
def test_isochoric_uniaxial(lam):
    """F = diag(l, l^-1/2, l^-1/2): sigma_1 - sigma_3 = mu (l^2 - 1/l) exactly (J = 1, so the
    volumetric term does not enter); rounding only, hence 1e-12."""
    law = NeoHookean(0.05, 2.0)
    s = cauchy(law, np.diag([lam**2, 1 / lam, 1 / lam]))
    assert s[0] - s[2] == pytest.approx(0.05 * (lam**2 - 1 / lam), rel=1e-12, abs=1e-15)


def test_young_modulus_small_strain():
    """Uniaxial stress with free lateral faces at strain 1e-6: slope E = 9 K mu/(3 K + mu),
    -> 3 mu as K/mu -> infinity (the incompressible limit). The secant over 1e-6 differs
    from the tangent by O(1e-6) relative, so rel=1e-5."""
    for kappa in (0.5, 50.0, 5e4):
        law = NeoHookean(0.1, kappa)
        nu = (3 * kappa - 2 * 0.1) / (2 * (3 * kappa + 0.1))
        P, ok = uniaxial_nominal(law, np.array([1.0 + 1e-6]), nu)
        assert ok.all()
        assert P[0] / 1e-6 == pytest.approx(9 * kappa * 0.1 / (3 * kappa + 0.1), rel=1e-5)
    assert 9 * 5e4 * 0.1 / (3 * 5e4 + 0.1) == pytest.approx(3 * 0.1, rel=1e-6)


@pytest.mark.parametrize("J", [0.8, 0.97, 1.0, 1.2])
def test_pure_dilatation(J):
    """C = J^(2/3) I: the isochoric part vanishes, Cauchy stress = kappa (J - 1) I."""
    law = NeoHookean(0.05, 3.0)
    s = cauchy(law, np.eye(3) * J ** (2 / 3), J)
    assert s == pytest.approx(np.full(3, 3.0 * (J - 1.0)), rel=1e-12, abs=1e-15)
