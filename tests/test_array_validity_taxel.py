"""The letters' surrogate is judged by rows read with taxels no larger than the chart's smallest:
point sensors (or finer pitches) see the ripple a 0.4 mm box average hid."""

from tactileskin.array.chart import ChartConfig, surrogate_trust
from tactileskin.array.validity import measured


def test_point_sensors_are_not_covered_by_rows_read_with_04_mm_taxels():
    assert surrogate_trust(ChartConfig(thicknesses=(1.0,)), "silicone", 1.0, "interaction")["status"] == "within"
    # before: 'within 5 %' from the 0.4 mm rows, for point taxels and a 0.08 mm smallest taxel
    assert surrogate_trust(ChartConfig(thicknesses=(1.0,), taxel_fraction=0.0), "silicone", 1.0,
                           "interaction")["status"] == "not validated"
    assert surrogate_trust(ChartConfig(thicknesses=(1.0,), pitches=(0.1, 0.75)), "silicone", 1.0,
                           "interaction")["status"] == "not validated"
    # coarser smallest taxels read smoother maps: the 0.4 mm rows answer for them
    assert surrogate_trust(ChartConfig(thicknesses=(1.0,), pitches=(1.0, 2.0)), "silicone", 1.0,
                           "interaction")["status"] != "not validated"


def test_this_runs_pointwise_rows_judge_a_point_sensor_chart():
    row = {"material": "silicone", "thickness_mm": 1.0, "depth_mm": 0.2, "text": "l", "model": "interaction",
           "taxel_mm": 0.0, "max_abs_over_peak": 0.11, "reference_mesh": [0.8, 8.0]}
    m = measured("silicone", "pad", (0.8, 8.0), 1.0, 0.2, [row], model="interaction", taxel=0.0)
    assert m["status"] == "exceeds" and m["error"] == 0.11
    # a row read with 0.4 mm taxels does not answer for point sensors
    row4 = {**row, "taxel_mm": 0.4, "max_abs_over_peak_taxel": 0.03}
    assert measured("silicone", "pad", (0.8, 8.0), 1.0, 0.2, [row4], model="interaction",
                    taxel=0.0)["source"] != "this run's validation"
