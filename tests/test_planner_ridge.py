"""Planner: the measured 2D-ridge vs 3D-dots table, looked up by thickness, material and dot pattern."""

from tactileskin import planner
from tactileskin.planner import dot_pattern, measured_ridge_vs_dots, plan
from tactileskin.scene import Scene


def test_dot_pattern_identifies_single_dot_and_full_cell():
    assert dot_pattern("") == dot_pattern("a") == planner.SINGLE_DOT
    assert dot_pattern("\u283f") == "\u283f" != dot_pattern("a")


def test_lookup_by_pattern_and_signed_difference_costs_its_magnitude(monkeypatch):
    table = {(3.0, "silicone", "\u2801"): {"peak": -0.004, "span": 0.1},
             (3.0, "silicone", "\u283f"): {"peak": 0.3, "span": -0.2}}
    monkeypatch.setattr(planner, "MEASURED_RIDGE_VS_DOTS", table)
    dot, cell = (Scene(thickness=3.0, indenter="braille", braille_text=t) for t in ("a", "\u283f"))
    assert measured_ridge_vs_dots(dot)["peak"] == -0.004
    assert measured_ridge_vs_dots(cell)["peak"] == 0.3
    assert measured_ridge_vs_dots(dot.replace(thickness=1.0)) is None
    # a 2D ridge 0.4 % below 3D costs 0.4 %: accepted at 1 %, refused at 0.3 %
    assert plan(dot, tolerance=0.01).choice("dimension").cost == 0.004
    assert plan(dot, tolerance=0.003).scene.dim == 3
    # the full cell's 30 % difference keeps it 3D, and the ridge model states that cost
    assert plan(cell, tolerance=0.01).scene.dim == 3
    assert plan(cell, braille="ridge").choice("dimension").cost == 0.3
