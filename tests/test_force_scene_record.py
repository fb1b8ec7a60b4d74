"""Under force control the depth is an output (the travel found), not an input: the scene's
record (to_dict, the `scene` of summary.json) listed depth_fraction = 0.2 all the same, as
if the case were pressed to 20 % of t. It is now refused with a force (as with a depth) and
not recorded; the expected travel that sizes the contact zone is the default 20 % of t."""

from __future__ import annotations

import json

import pytest

from tactileskin.errors import ParameterError
from tactileskin.scene import Scene


def test_a_force_scene_records_no_depth_fraction():
    s = Scene(thickness=1.0, force=0.03)
    assert "depth_fraction" not in s.to_dict() and s.to_dict()["force"] == 0.03
    assert Scene.from_dict(s.to_dict()) == s
    assert Scene(thickness=1.0).to_dict()["depth_fraction"] == 0.2  # depth control: still recorded
    # the load time (no force_rate, no load_time) is still the depth ramp's: 0.2 t / rate
    assert s.duration == pytest.approx(0.2)


def test_a_depth_fraction_with_a_force_is_refused_and_a_later_force_replaces_it():
    with pytest.raises(ParameterError, match="depth_fraction=0.3 is invalid; valid: not with force"):
        Scene(thickness=1.0, force=0.03, depth_fraction=0.3)
    later = Scene(thickness=1.0, depth_fraction=0.3).replace(force=0.03)
    assert (later.force, later.depth_fraction) == (0.03, 0.2)


def test_the_solve_summary_of_a_force_case_lists_no_depth_fraction(tmp_path):
    from tactileskin.cli import main

    out = tmp_path / "o"
    assert main(["solve", "-t", "1", "-i", "curved", "--quality", "preview", "--force", "0.03",
                 "-o", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert "depth_fraction" not in summary["scene"] and summary["scene"]["force"] == 0.03
    assert summary["loading"]["control"] == "force" and summary["loading"]["reached_travel_mm"] > 0


def test_a_failed_force_case_has_no_depth_in_results_csv():
    """A force-controlled case's depth is the travel its solve reached: one that failed has none
    (results.csv read 0.2 t, the default depth ramp's travel, as if pressed that far)."""
    from tactileskin import sweep
    from tactileskin.report import outputs

    force = Scene(thickness=1.0, indenter="flat", force=0.03)
    depth = Scene(thickness=1.0, indenter="curved")
    ocs = [sweep.CaseOutcome(sc, "failed", 0.0, "no convergence", key=f"k{i}") for i, sc in enumerate((force, depth))]
    _, rows, failures = outputs.collect(ocs, cache=None)
    assert len(failures) == 2
    assert rows[0]["depth_mm"] is None and rows[0]["target_force_n_per_mm"] == 0.03
    assert rows[1]["depth_mm"] == depth.indentation  # a depth case's depth is its input
