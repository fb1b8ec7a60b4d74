"""A material given as a file is named by its stem in tables and figures: results.csv,
report.md and every sweep figure (titles, legends) named it by its full path, long and
showing the user's home folder. Two files of one stem, or a file named as a preset, keep
distinct labels (scene.material_labels)."""

from __future__ import annotations

import csv

import pytest

from tactileskin.scene import material_labels


def test_a_file_is_named_by_its_stem_and_presets_by_their_name():
    assert material_labels(["silicone", "/home/alice/mats/gel.toml"]) == {
        "silicone": "silicone", "/home/alice/mats/gel.toml": "gel"}


def test_two_files_of_one_stem_keep_distinct_labels():
    got = material_labels(["/home/alice/a/gel.toml", "/home/alice/b/gel.toml", "/srv/gel2.toml"])
    assert got == {"/home/alice/a/gel.toml": "a/gel.toml", "/home/alice/b/gel.toml": "b/gel.toml",
                   "/srv/gel2.toml": "gel2"}
    deeper = material_labels(["/x/a/m/gel.toml", "/y/a/m/gel.toml"])
    assert deeper == {"/x/a/m/gel.toml": "x/a/m/gel.toml", "/y/a/m/gel.toml": "y/a/m/gel.toml"}


def test_labels_are_unique_and_carry_no_root_slash():
    # a path that is the tail of another ('/x/soft.toml' in '/y/x/soft.toml') was labelled
    # '//x/soft.toml' (the root joined as a part), and two spellings of one relative path
    # ('soft.toml', './soft.toml') shared 'soft.toml' in the legends and results.csv
    assert material_labels(["/x/soft.toml", "/y/x/soft.toml"]) == {
        "/x/soft.toml": "x/soft.toml", "/y/x/soft.toml": "y/x/soft.toml"}
    assert material_labels(["/a/soft.toml", "a/soft.toml"]) == {
        "/a/soft.toml": "/a/soft.toml", "a/soft.toml": "a/soft.toml"}
    got = material_labels(["soft.toml", "./soft.toml", "a/soft.toml", "b/soft.toml"])
    assert len(set(got.values())) == 4 and got["a/soft.toml"] == "a/soft.toml"


def test_a_file_named_as_a_preset_is_not_labelled_as_the_preset():
    # the paper checks key on the preset names: a user's silicone.toml is not the paper's silicone
    assert material_labels(["/home/alice/silicone.toml"]) == {"/home/alice/silicone.toml": "silicone.toml"}
    assert material_labels(["silicone", "/h/silicone.toml"]) == {"silicone": "silicone",
                                                                "/h/silicone.toml": "silicone.toml"}


@pytest.fixture(scope="module")
def gel(tmp_path_factory):
    from tactileskin.materials import get_material

    si = get_material("silicone")
    d = tmp_path_factory.mktemp("home") / "alice" / "mats"
    d.mkdir(parents=True)
    p = d / "nh_gel.toml"
    p.write_text(f'law = "neo_hookean"\nsource = "gel"\n[neo_hookean]\nmu = {si.law.mu0!r}\nkappa = {si.law.K0!r}\n')
    return p


@pytest.mark.usefixtures("close_figures")
def test_sweep_tables_and_figures_name_a_material_file_by_its_stem(tmp_path, gel):
    from tactileskin.cli import main

    out = tmp_path / "out"
    assert main(["sweep", "-t", "1", "-m", f"silicone,{gel}", "-i", "flat,curved", "--quality", "preview",
                 "--serial", "--no-render", "--out", str(out)]) == 0
    with open(out / "results.csv", newline="") as fh:
        assert sorted({r["material"] for r in csv.DictReader(fh)}) == ["nh_gel", "silicone"]
    report = (out / "report.md").read_text()
    assert "| nh_gel | flat |" in report and "- `nh_gel` (nh_gel.toml):" in report
    files = [out / "report.md", out / "results.csv", out / "profiles.csv"] + sorted(out.glob("*.svg"))
    for f in files:
        assert str(gel.parent) not in f.read_text(), f.name
    for stem in ("fig10_profiles", "fig11_peak", "metrics_vs_thickness"):
        assert "nh_gel" in (out / f"{stem}.svg").read_text(), stem


@pytest.mark.usefixtures("close_figures")
def test_result_plot_names_a_material_file_by_its_stem(gel):
    from tactileskin.fe import solve
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    res = solve(with_quality(Scene(thickness=1.0, material=str(gel)), "preview"))
    fig, ax = res.plot()
    assert ax.get_title(loc="left").startswith("t = 1 mm, nh_gel, flat (2D)")


def test_result_plot_does_not_name_a_file_as_the_preset_of_its_stem():
    # a user's silicone.toml is not the paper's silicone: the sweep tables say 'silicone.toml'
    # (material_labels), Result.plot's title said 'silicone'
    from types import SimpleNamespace

    from tactileskin.report.result_plot import _label

    res = SimpleNamespace(scene={"thickness": 1.0, "material": "/home/alice/silicone.toml", "indenter": "flat"})
    assert _label(res) == "t = 1 mm, silicone.toml, flat (2D)"
    res.scene["material"] = "/home/alice/gel.toml"
    assert _label(res) == "t = 1 mm, gel, flat (2D)"
