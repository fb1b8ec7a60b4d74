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
