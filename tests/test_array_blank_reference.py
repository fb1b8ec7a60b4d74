"""The blank Braille plate's measured error (data/blank_plate.json) was taken against a 0.6 / 2
reference whose own error was assumed a third of its last step (<= 0.6 %); against 0.42 / 2 (the
finest the 3D dofs cap allows at t = 3) the 0.6 / 2 maps move up to 1.1 %, and the chart's 1.2 / 1
polyurethane map 1 mm above the bone reads 5.05 % (4.72 % against 0.6 / 2). A row covers the
blank's coarse_mesh flag only where its error plus its reference's own last step (reference_shift)
is within the tolerance."""

from tactileskin.array import chart
from tactileskin.array.chart import blank_measured, blank_scene, dot_scene
from tactileskin.array.config import ChartConfig
from tactileskin.array.surrogate import TOLERANCE

CFG = ChartConfig(thicknesses=(3.0,))


def _blank(t=3.0, material="silicone"):
    return blank_scene(dot_scene(t, material, CFG))


def _row(b, max_error, shift=None):
    r = {"material": b.material, "skin": "pad", "thickness_mm": b.thickness, "depth_mm": float(b.indentation),
         "mesh": [b.mesh_size, b.refinement], "pad_mm": [b.pad_width, b.pad_length], "rate": b.rate,
         "extent_mm": CFG.read_extent, "sensor_height_mm": None, "max_error": max_error, "l2_error": 0.01,
         "reference_mesh": [0.42, 2.0]}
    if shift is not None:
        r["reference_shift"], r["shift_mesh"] = shift, [0.6, 2.0]
    return r


def test_a_row_covers_only_with_its_reference_own_error_within_the_tolerance(monkeypatch):
    b = _blank()
    for row, covered in ((_row(b, 0.04, 0.005), True), (_row(b, 0.04, TOLERANCE - 0.04 + 0.002), False),
                         (_row(b, 0.04), False)):  # no reference_shift: the reference's own error unknown
        monkeypatch.setattr(chart, "_blank_data", lambda: {"cases": [row]})
        assert (blank_measured(b, CFG.read_extent) is not None) == covered, row


def test_the_t3_rows_are_measured_against_the_finer_reference():
    for material in ("silicone", "polyurethane"):
        b = _blank(3.0, material)
        rows = [r for r in chart._blank_data()["cases"] if r["material"] == material and r["thickness_mm"] == 3.0]
        assert len(rows) == 3
        for r in rows:
            assert r["reference_mesh"][0] / r["reference_mesh"][1] < 0.3 - 1e-9  # finer than 0.6 / 2
            assert 0 < r["reference_shift"] < 0.02
        assert blank_measured(b, CFG.read_extent) is not None  # the bone map is shown within 5 %


def test_polyurethane_1mm_above_the_bone_is_not_shown_within_the_tolerance():
    assert blank_measured(_blank(3.0, "polyurethane"), CFG.read_extent, 3.0 - 1.0) is None


def test_the_reference_s_own_error_is_its_last_step_at_the_measured_order():
    """reference_shift (0.6 / 2 against 0.42 / 2) was added as the reference's own error, which holds at order 2
    (0.96 x the step at a 1.43 size ratio); this max norm was measured converging at order ~1.5
    (benchmarks/results/blank_plate.md: 1.2 -> 0.8 -> 0.6 / 1, 4.30 / 2.39 / 1.59 %), where the error is 1.41 x
    the step: silicone's map 0.4 mm above the bone, 3.85 % + 1.41 x 1.05 % = 5.3 %, is not shown within 5 %
    (it was covered at 3.85 + 1.05 = 4.90 %); the bone maps (4.2 / 3.3 %) still are."""
    assert blank_measured(_blank(3.0, "silicone"), CFG.read_extent, 3.0 - 0.4) is None
    for material in ("silicone", "polyurethane"):
        assert blank_measured(_blank(3.0, material), CFG.read_extent) is not None
