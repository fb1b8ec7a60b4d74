"""A discrimination verdict decided within 10 % of the threshold says it is borderline (the
paper sweep's 5 mm groups: 0.193 and 0.196 against 0.2 read plainly 'indistinguishable: agrees')."""

import numpy as np

from tactileskin.report.markdown import _discrimination_cells, borderline_note

S = np.linspace(0.0, 5.0, 101)
P = np.exp(-S**2)


def test_near_threshold_distances_are_marked_far_ones_are_not():
    d, verdict = _discrimination_cells({"flat": (S, P), "curved": (S, 0.804 * P)})  # distance 0.196
    assert verdict == "not distinguishable" and "borderline" in d
    d, _ = _discrimination_cells({"flat": (S, P), "curved": (S, 0.5 * P)})  # 0.5
    assert "borderline" not in d
    assert borderline_note(0.21) and borderline_note(0.181) and not borderline_note(0.179)
    assert borderline_note(float("nan")) == ""
