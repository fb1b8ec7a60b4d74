"""A large taxel's area mean does not depend on where a narrow peak falls between its Gauss points."""

import numpy as np
import pytest
from scipy.special import erf

from tactileskin.array import maps
from tactileskin.array.sampler import ArraySpec, sample

S = np.linspace(-10, 10, 801)
Z = np.linspace(-10, 10, 801)


def test_default_rule_reads_a_narrow_peak_under_a_large_taxel_at_every_offset():
    # a single dot's bone map at t = 1 mm is about this wide (sd 0.4 mm); a 4 mm pitch's 3.2 mm
    # taxel with a fixed 4 x 4 rule read it 15 % off its mean where it fell between the points
    sig, a = 0.4, 3.2
    m = maps.on_grid(lambda s, z: np.exp(-(s * s + z * z) / (2 * sig**2)), S, Z)
    spec = ArraySpec(pitch=4.0, taxel=a, n=1)
    one = lambda x: sig * np.sqrt(2 * np.pi) / a * 0.5 * (erf((a / 2 - x) / (np.sqrt(2) * sig))  # noqa: E731
                                                          + erf((a / 2 + x) / (np.sqrt(2) * sig)))
    for off in np.linspace(0, 1.6, 9):
        expect = one(off) * one(0.3 * off)
        assert sample(m, spec, (off, 0.3 * off))[0] == pytest.approx(expect, abs=0.01 * one(0) ** 2)
    assert spec.quad == 13


def test_default_rule_by_size():
    from tactileskin.array.sampler import default_quad

    assert default_quad(3.2) == 13
    assert ArraySpec(pitch=0.5, taxel=0.4).quad == 4        # small taxels keep 4 x 4
    assert ArraySpec(pitch=1.0, taxel=0.8).quad == 4
    assert ArraySpec(pitch=2.0, taxel=1.6).quad == 7
    assert ArraySpec(pitch=20.0, taxel=16.0).quad == 64
    assert ArraySpec(pitch=1.0, taxel=0.0).quad == 4        # point taxels: one point (unused rule)
    assert ArraySpec(pitch=1.0, taxel=0.9, quad=12).quad == 12
