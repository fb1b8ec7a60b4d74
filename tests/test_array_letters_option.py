"""--letters takes 'abl' and, like the other list options, 'a,b,l' (refused before with a message
that did not name the comma)."""

import pytest

from tactileskin.array.chart import ChartConfig
from tactileskin.errors import ParameterError


def test_letters_with_separators_are_the_same_set():
    assert ChartConfig(letters="a,b,l").letters == ChartConfig(letters="a b l").letters == "abl"
    with pytest.raises(ParameterError, match="not characters of the set: A"):
        ChartConfig(letters="a,A")
