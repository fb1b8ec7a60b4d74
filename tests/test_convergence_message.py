"""A solve that does not converge says where (the indenter's travel) and what a user can change."""

import pytest

from tactileskin.errors import ConvergenceError
from tactileskin.fe import solve
from tactileskin.planner import with_quality
from tactileskin.scene import Scene


def test_a_solve_that_gives_out_says_after_how_much_travel_and_what_to_try():
    # a 0.1 mm silicone pad 10 mm wide is laterally confined: the hyperfoam's volume term
    # (alpha beta = 380) locks up after ~3.6 um of travel. The message gave only the time
    # ("no convergence at t = 0.0036 s with dt = 2.4e-07 s: ...")
    sc = with_quality(Scene(skin="pad", pad_width=10.0, pad_length=10.0, thickness=0.1, indenter="flat", depth=0.02),
                      "preview")
    with pytest.raises(ConvergenceError, match=r"after 0\.00[0-9]+ mm of indenter travel .*smaller depth or force") as e:
        solve(sc)
    assert 0.0 < e.value.diagnosis["time"] < 0.02
