"""A profile with NaN gets no verdict: before, the NaN distance read 'not distinguishable'."""

import numpy as np
import pytest

from tactileskin.discrimination import discriminate, profile_distance
from tactileskin.errors import ParameterError

S = np.linspace(0, 5, 51)
P = np.exp(-S**2)


def test_non_finite_profiles_are_refused():
    q = P.copy()
    q[3] = np.nan
    with pytest.raises(ParameterError, match="profile 'b' P=.*non-finite"):  # names the record
        discriminate({"a": (S, P), "b": (S, q)})
    with pytest.raises(ParameterError):
        profile_distance(S, P, S[:-1], P)


def test_halved_and_whole_profiles_of_one_shape_are_the_same():
    s2 = np.linspace(-5, 5, 101)
    assert profile_distance(S, P, s2, np.exp(-s2**2)) == pytest.approx(0.0, abs=1e-9)
    assert profile_distance(S, P, S, 0.7 * P) == pytest.approx(0.3)
