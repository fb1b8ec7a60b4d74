"""Case ids are unique within a sweep and name the fields that tell cases apart; two depths in
one sweep are two rows, two profiles and two bars."""

import csv

import pytest

from tactileskin.cli import main
from tactileskin.report import figures
from tactileskin.scene import Scene
from tactileskin.sweep import case_ids, case_variants, expand_grid


# the `_save` stubs here keep each figure to look at, so _save's close never runs (conftest.py)
pytestmark = pytest.mark.usefixtures("close_figures")


def test_paper_grid_ids_are_the_plain_labels():
    scenes = expand_grid()
    assert case_ids(scenes) == [s.label() for s in scenes]
    assert set(case_variants(scenes)) == {""}


def test_two_depths_get_depth_suffixes():
    scenes = expand_grid(thicknesses=[1.0, 3.0], materials=["silicone"], indenters=["flat", "curved"],
                         depths=[0.1, 0.2])
    ids = case_ids(scenes)
    assert len(set(ids)) == len(scenes) == 8
    for sc, cid in zip(scenes, ids):
        assert cid == f"{sc.label()}-d{sc.indentation:g}"


@pytest.mark.parametrize("changes, suffixes", [
    ([dict(rate=1.0), dict(rate=2.0)], ["r1", "r2"]),
    ([dict(mesh_size=0.5), dict(mesh_size=0.25)], ["h0.5", "h0.25"]),
    ([dict(refinement=2.0), dict(refinement=4.0)], ["ref2", "ref4"]),
    ([dict(viscoelastic=True), dict(viscoelastic=False)], ["visco", "elastic"]),
    ([dict(formulation="mixed"), dict(formulation="displacement")], ["mixed", "displacement"]),
    ([dict(depth=0.2, rate=1.0), dict(depth=0.2, rate=3.0), dict(depth=0.4, rate=1.0)],
     ["d0.2-r1", "d0.2-r3", "d0.4-r1"]),
])
def test_only_the_differing_fields_are_named(changes, suffixes):
    scenes = [Scene(thickness=1.0, **c) for c in changes]
    assert case_variants(scenes) == suffixes
    assert case_ids(scenes) == [f"{s.label()}-{x}" for s, x in zip(scenes, suffixes)]


def test_braille_texts_and_standards_are_told_apart():
    base = Scene(thickness=1.0, indenter="braille")
    scenes = [base, base.replace(braille_text="ab"), base.replace(braille_standard="marburg_medium")]
    ids = case_ids(scenes)
    assert len(set(ids)) == 3 and "[ab]" in ids[1] and ids[2].endswith("marburg_medium")


def test_material_files_are_named_by_their_file(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    scenes = [Scene(material=str(tmp_path / d / "soft.toml")) for d in ("a", "b")]
    ids = case_ids(scenes)
    assert ids == ["t3-soft-flat-2d-@a", "t3-soft-flat-2d-@b"]
    # `solve` (its title, the Result's repr) names the case as the sweep does: it read
    # 't3-/tmp/.../a/soft.toml-flat-2d' for the sweep's 't3-soft-flat-2d'
    assert case_ids(scenes[:1]) == [scenes[0].label()] == ["t3-soft-flat-2d"]


def test_a_pad_sweeps_ids_name_the_pad_as_solve_does():
    """A sweep of a 2D pad named its cases 't2-silicone-braille-2d', as the fingertip's, while
    `solve` of the same scene says 'pad20x20-t2-silicone-braille-2d'; results.csv and the report
    (neither has a skin column) then did not say the cases were a pad's."""
    scenes = [Scene(skin="pad", pad_width=20.0, thickness=t, indenter="braille") for t in (1.5, 2.0)]
    assert case_ids(scenes) == [s.label() for s in scenes] == ["pad20x20-t1.5-silicone-braille-2d",
                                                               "pad20x20-t2-silicone-braille-2d"]
    two = [Scene(skin="pad", pad_width=w, thickness=2.0) for w in (20.0, 30.0)]
    assert case_ids(two) == ["pad20x20-t2-silicone-flat-2d", "pad30x20-t2-silicone-flat-2d"]


def test_two_depth_sweep_writes_two_rows_profiles_and_bars(tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    args = ["sweep", "--out", str(out), "--thickness", "1", "--material", "polyurethane",
            "--indenter", "flat", "--mesh-size", "1", "--refinement", "5", "--depth", "0.1,0.2", "--serial", "--no-render"]
    captured = []
    monkeypatch.setattr(figures, "_save", lambda fig, o, stem: captured.append((stem, fig)) or [])
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "t1-polyurethane-flat-2d-d0.1" in text and "t1-polyurethane-flat-2d-d0.2" in text

    with open(out / "results.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["case"] for r in rows] == ["t1-polyurethane-flat-2d-d0.1", "t1-polyurethane-flat-2d-d0.2"]
    assert [float(r["depth_mm"]) for r in rows] == [0.1, 0.2]
    peaks = [float(r["peak_mpa"]) for r in rows]
    assert peaks[1] > peaks[0] > 0

    with open(out / "profiles.csv") as fh:
        prof = list(csv.DictReader(fh))
    for r in rows:
        s = [float(p["s_mm"]) for p in prof if p["case"] == r["case"]]
        assert len(s) >= 2 and all(a < b for a, b in zip(s, s[1:]))   # one profile each, not two glued
    assert {p["case"] for p in prof} == {r["case"] for r in rows}

    fig = dict(captured)["fig11_peak"]
    heights = sorted(b.get_height() for c in fig.axes[0].containers for b in c)
    assert heights == pytest.approx(sorted(peaks))

    report = (out / "report.md").read_text()
    assert all(f"| {r['case']} |" in report for r in rows)
    # the paper's claim at 1 mm uses the paper's 20 % indentation (0.2 mm), not 0.1 mm
    claim = next(line for line in report.splitlines() if line.startswith("| peak, 1 mm polyurethane, flat"))
    assert f"| {peaks[1]:.3g} MPa |" in claim
    assert "paper's conditions" in report


def test_profiles_csv_quotes_a_case_id_with_a_comma(tmp_path, monkeypatch):
    """A Braille text with a comma (',a,') puts one in the case id: profiles.csv wrote it
    unquoted, so every row read as 4 fields under 3 columns (case 't2-silicone-braille[', s_mm
    'a', pressure_mpa ']-2d'); results.csv and sensors.csv quote it. A lone comma: the commas of
    ',a,' lie at x = +-6.2 mm, where the fingertip falls away past any depth at t = 2 (refused)."""
    out = tmp_path / "out"
    monkeypatch.setattr(figures, "_save", lambda fig, o, stem: [])
    assert main(["sweep", "--out", str(out), "-t", "2", "-m", "silicone", "-i", "braille", "--braille-text", ",",
                 "--quality", "preview", "--serial", "--no-render"]) == 0
    with open(out / "results.csv", newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    assert row["case"] == "t2-silicone-braille[,]-2d"
    with open(out / "profiles.csv", newline="") as fh:
        prof = list(csv.DictReader(fh))
    assert len(prof) >= 2 and all(None not in p and p["case"] == row["case"] for p in prof)
    assert max(float(p["pressure_mpa"]) for p in prof) == pytest.approx(float(row["peak_mpa"]), rel=1e-5)
