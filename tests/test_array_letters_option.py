"""--letters takes 'abl' and, like the other list options, 'a,b,l' (refused before with a message
that did not name the comma)."""

import pytest

from tactileskin.array.chart import ChartConfig
from tactileskin.errors import ParameterError


def test_letters_with_separators_are_the_same_set():
    assert ChartConfig(letters="a,b,l").letters == ChartConfig(letters="a b l").letters == "abl"
    with pytest.raises(ParameterError, match="not characters of the set: A"):
        ChartConfig(letters="a,A")


def test_a_window_the_lattice_cannot_cover_is_refused_not_cut():
    # 20 mm at 0.05 mm is 401 taxels a side: the array was cut to 200 (a 10 mm window) silently
    with pytest.raises(ParameterError, match="window"):
        ChartConfig(window=20.0, pitches=(0.05, 1.0))
    cfg = ChartConfig(window=4.0, pitches=(0.05, 1.0))
    assert cfg.spec(0.05).n == 81
