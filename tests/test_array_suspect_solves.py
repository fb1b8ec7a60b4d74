"""A chart built on a solve that tactileskin.quality flags says so (chart notes: the report's
Suspect list and exit status 3); before, only failed solves stopped it."""

from types import SimpleNamespace

from tactileskin.array.chart import suspect_solves
from tactileskin.scene import Scene


def test_flagged_solves_become_notes_ok_ones_do_not():
    a = Scene(thickness=1.0, indenter="flat")
    b = Scene(thickness=1.0, indenter="curved")
    recs = {a: SimpleNamespace(summary={"status": "ok"}),
            b: SimpleNamespace(summary={"status": "suspect: peak at the bonded skin's edge"})}
    notes = suspect_solves(recs)
    assert len(notes) == 1 and "curved" in notes[0] and "peak at the bonded skin's edge" in notes[0]
    assert suspect_solves({a: SimpleNamespace(summary={})}) == []


def test_the_csv_marks_the_rows_of_a_suspect_thickness():
    from tactileskin.array.chart import Chart, ChartConfig

    ch = Chart(ChartConfig(thicknesses=(1.0, 3.0), sets=("paper",)))
    for t in (1.0, 3.0):
        ch.rows.append(dict(material="silicone", thickness_mm=t, set="paper", pitch_mm=1.0, taxel_mm=0.8,
                            noise_fs=0.01, noise_mpa=0.001, full_scale_mpa=0.3, bits=12, method="template",
                            accuracy=1.0, chance=1 / 3, n_test=16))
    ch.suspect[("silicone", 3.0)] = "the solve x is suspect: no contact"
    lines = ch.to_csv().splitlines()
    assert lines[1].endswith(",ok")
    assert lines[2].endswith('"suspect: the solve x is suspect: no contact"')
