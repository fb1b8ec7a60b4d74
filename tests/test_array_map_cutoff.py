"""The chart's measured cut-off of a single-dot map is its 2D spectrum's along k_s: a point load
on a half-space must read the closed form (1 + kd) e^-kd = 0.1, not its section row's 4.46 / d."""

import numpy as np
import pytest

from tactileskin.array import halfspace as hs
from tactileskin.array.chart import map_cutoff
from tactileskin.results import BoneMap


def test_boussinesq_map_reads_the_half_space_cutoff():
    d = 1.0
    s = np.arange(-20, 20.001, 0.05)
    z = np.arange(-20, 20.001, 0.05)
    S, Z = np.meshgrid(s, z)
    m = BoneMap(s, z, hs.boussinesq_szz(np.hypot(S, Z), d))
    assert map_cutoff(m) == pytest.approx(hs.cutoff(d), rel=0.01)  # the section row: 4.46, 15 % high


def test_an_extruded_profile_reads_its_own_cutoff():
    d = 0.8
    s = np.arange(-20, 20.001, 0.02)
    z = np.linspace(-10, 10, 41)
    m = BoneMap(s, z, np.tile(hs.flamant_szz(s, d), (z.size, 1)))
    assert map_cutoff(m) == pytest.approx(hs.cutoff(d), rel=0.01)
