"""discrimination.profile_distance: whole-model profiles against halved ones."""

import numpy as np
import pytest

from tactileskin.discrimination import profile_distance


def test_a_whole_models_profile_is_folded_against_a_halved_one():
    """A profile across the centre (a whole model) and the same field from the symmetry line
    (a halved model) are no distance apart; unfolded, the missing half counted as a difference."""
    s = np.linspace(-4.0, 4.0, 161)
    p = np.exp(-s ** 2)
    half = s >= 0
    assert profile_distance(s, p, s[half], p[half]) == pytest.approx(0.0, abs=1e-6)
    assert profile_distance(s[half], p[half], s, p) == pytest.approx(0.0, abs=1e-6)
    shifted = np.exp(-(s - 0.5) ** 2)           # an asymmetric whole profile: its fold differs
    assert profile_distance(s, shifted, s[half], p[half]) > 0.05
    assert profile_distance(s, p, s, shifted) > 0.2   # two whole profiles: compared as they are
