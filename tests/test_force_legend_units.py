"""A force-controlled sweep's figure legends name the force with its unit: they read "F0.03"
(the case id's suffix), N/mm in 2D and N in 3D left to the reader. The ids keep their short
suffix (file names); the legends use sweep.case_variant_labels."""

from __future__ import annotations

import pytest

from tactileskin.scene import Scene
from tactileskin.sweep import case_ids, case_variant_labels


def test_variant_labels_name_the_force_with_its_unit():
    two = [Scene(thickness=1.0, force=f) for f in (0.03, 0.06)]
    assert case_ids(two) == ["t1-silicone-flat-2d-F0.03", "t1-silicone-flat-2d-F0.06"]  # ids unchanged
    assert case_variant_labels(two) == ["F = 0.03 N/mm", "F = 0.06 N/mm"]
    three = [Scene(thickness=1.0, indenter="sphere", indenter_radius=2.5, dim=3, force=f) for f in (0.5, 1.0)]
    assert case_variant_labels(three) == ["F = 0.5 N", "F = 1 N"]


def test_variant_labels_give_units_to_depth_and_rate_and_say_depth_control():
    depths = [Scene(thickness=1.0, depth=d) for d in (0.1, 0.2)]
    assert case_variant_labels(depths) == ["d = 0.1 mm", "d = 0.2 mm"]
    rates = [Scene(thickness=1.0, rate=r) for r in (1.0, 2.0)]
    assert case_variant_labels(rates) == ["rate 1 mm/s", "rate 2 mm/s"]
    # a force case beside a depth case: the force case's depth is its travel (an output), not named
    mixed = [Scene(thickness=1.0, force=0.03), Scene(thickness=1.0, depth=0.1)]
    assert case_variant_labels(mixed) == ["F = 0.03 N/mm", "d = 0.1 mm, depth control"]
    assert case_variant_labels([Scene(thickness=1.0)]) == [""]


def _preview_sweep(tmp_path, config: str):
    """The folder of a serial 2D preview sweep of the sweep TOML `config` (no renders)."""
    from tactileskin.cli import main

    cfg = tmp_path / "sweep.toml"
    cfg.write_text(config)
    out = tmp_path / "out"
    assert main(["sweep", "--config", str(cfg), "--quality", "preview", "--serial", "--no-render",
                 "--out", str(out)]) == 0
    return out


@pytest.mark.usefixtures("close_figures")
def test_sweep_figure_legends_carry_the_force_unit(tmp_path):
    out = _preview_sweep(tmp_path, '[sweep]\nthicknesses = [1.0]\nmaterials = ["silicone"]\n'
                         'indenters = ["flat", "curved"]\nforces = [0.03, 0.06]\n[scene]\ndim = 2\n')
    for stem in ("fig10_profiles", "fig11_peak", "metrics_vs_thickness"):
        svg = (out / f"{stem}.svg").read_text()  # text kept as text (figures._plt)
        assert "flat F = 0.03 N/mm" in svg and "curved F = 0.06 N/mm" in svg, stem
        assert "F0.03" not in svg, stem
    # the report's discrimination table names the variant alike
    report = (out / "report.md").read_text()
    assert "| silicone | 1 | F = 0.03 N/mm |" in report
    # the Cases table's depth of a force case is the travel it reached, not a prescribed depth
    assert "Depth of a force-controlled case: the travel the indenter reached (an output" in report


@pytest.mark.usefixtures("close_figures")
def test_each_series_of_the_thickness_figure_has_its_own_style(tmp_path, monkeypatch):
    """Two forces of one indenter and material were drawn alike (marker and line style by
    material only, colour by indenter): at one thickness 'flat F = 0.03 N/mm, gel' and 'flat
    F = 0.06 N/mm, gel' were two identical blue circles, told apart by nothing but position."""
    from tactileskin.report import figures

    rows = [dict(status="ok", material=m, thickness_mm=1.0, indenter=ind, braille_text="", variant=v,
                 variant_label=f"F = {v[1:]} N/mm", dim=2, peak_mpa=p, span_mm=1.0, auc_mpa_mm=0.1)
            for m in ("gel", "silicone") for ind in ("flat", "curved") for v, p in (("F0.03", 0.03), ("F0.06", 0.05))]
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.thickness_figure(rows, tmp_path)
    lines = got["metrics_vs_thickness"].axes[0].get_lines()
    styles = {(ln.get_color(), ln.get_marker(), ln.get_linestyle(), ln.get_fillstyle()) for ln in lines}
    assert len(lines) == 8 and len(styles) == 8, sorted(styles)


def test_a_variant_shared_by_2d_and_3d_cases_names_both_units_in_the_discrimination_tables():
    # one id suffix "F0.5" is 0.5 N/mm on the 2D cases and 0.5 N on the 3D dots: a table row
    # holding both named it with the unit of whichever record came last
    from types import SimpleNamespace

    from tactileskin.report.markdown import discrimination_table_by_model
    from tactileskin.sweep import case_variant_labels, case_variants

    scenes = [Scene(thickness=1.0, indenter=i, dim=d, force=f) for i, d in (("flat", 2), ("braille", 2),
                                                                            ("braille", 3)) for f in (0.5, 1.0)]
    recs = [SimpleNamespace(scene=s, variant=v, variant_label=lab)
            for s, v, lab in zip(scenes, case_variants(scenes), case_variant_labels(scenes))]
    assert {r.variant for r in recs} == {"F0.5", "F1"}
    groups = [dict(group=("silicone", 1.0, "F0.5"), distances={2: "d2", 3: "d3"}, verdict={2: "v2", 3: "v3"},
                   changed=False)]
    row = discrimination_table_by_model(groups, recs)[-1]
    cell = row.split("|")[3]
    assert "0.5 N/mm" in cell and "0.5 N (3D)" in cell, row
    for order in (recs, recs[::-1]):  # not the last record's alone
        assert discrimination_table_by_model(groups, order)[-1] == row


@pytest.mark.usefixtures("close_figures")
def test_the_cases_note_says_which_state_a_force_case_with_later_segments_reports(tmp_path):
    # force 0.03 N/mm, a hold, then 0.06 N/mm: the row's depth and reaction are those of the
    # peak-load state (0.06), not of the target force the note named
    import csv

    out = _preview_sweep(tmp_path, '[sweep]\nthicknesses = [1.0]\nmaterials = ["silicone"]\nindenters = ["flat"]\n'
                         'forces = [0.03]\n[scene]\ndim = 2\n[[scene.loading]]\nhold = 0.1\n'
                         '[[scene.loading]]\nforce = 0.06\ntime = 0.2\n')
    with open(out / "results.csv", newline="") as fh:
        row, = csv.DictReader(fh)
    assert float(row["reaction_n_per_mm"]) == pytest.approx(0.06, rel=0.05)  # the peak load's state
    note = [ln for ln in (out / "report.md").read_text().splitlines() if ln.startswith("Depth of a force-controlled")]
    assert len(note) == 1 and "peak load" in note[0], note
