"""A sweep file's [scene] fields of an indenter kind it lists in [sweep] indenters."""

import pytest

SWEEP = """
[sweep]
thicknesses = [1.0]
materials = ["silicone"]
indenters = {indenters}
[scene]
indenter_radius = 2.5
dim = 3
"""


@pytest.mark.parametrize("indenters", ['["sphere"]', '["sphere", "flat"]'])
def test_a_listed_kinds_own_field_in_scene_is_taken(tmp_path, indenters):
    """[scene] indenter_radius with indenters = ["sphere"] was refused against the default flat
    plate ('only with indenter = cylinder or sphere'), by the CLI and by sweep.load_spec."""
    from tactileskin.cli.sweep import scenes_from_options
    from tactileskin.sweep import load_spec

    f = tmp_path / "s.toml"
    f.write_text(SWEEP.format(indenters=indenters))
    scenes = scenes_from_options({"scene_file": str(f), "quality": "preview"})
    spheres = [s for s in scenes if s.indenter.value == "sphere"]
    assert len(scenes) == len(eval(indenters)) and [s.indenter_radius for s in spheres] == [2.5]
    assert all(s.indenter_radius is None for s in scenes if s.indenter.value == "flat")
    spec = load_spec(f)
    assert spec["base"].indenter.value == "sphere" and spec["base"].indenter_radius == 2.5


def test_a_field_no_listed_kind_takes_is_still_refused(tmp_path):
    from tactileskin.cli.sweep import scenes_from_options
    from tactileskin.errors import ParameterError

    f = tmp_path / "s.toml"
    f.write_text(SWEEP.format(indenters='["flat", "curved"]'))
    with pytest.raises(ParameterError, match="indenter_radius"):
        scenes_from_options({"scene_file": str(f), "quality": "preview"})


def test_a_later_listed_kinds_own_field_is_taken(tmp_path):
    """indenters = ["flat", "sphere"] with [scene] indenter_radius was refused ('the flat
    indenter does not take it') while ["sphere", "flat"] ran: the base took the first listed
    kind, not the first that takes the field."""
    from tactileskin import scenefile
    from tactileskin.cli.sweep import scenes_from_options
    from tactileskin.sweep import load_spec

    f = tmp_path / "s.toml"
    f.write_text(SWEEP.format(indenters='["flat", "curved", "sphere"]'))
    scenefile.read(f)
    scenes = scenes_from_options({"scene_file": str(f), "quality": "preview"})
    assert [(s.indenter.value, s.indenter_radius) for s in scenes] == [("flat", None), ("curved", None),
                                                                       ("sphere", 2.5)]
    assert load_spec(f)["base"].indenter_radius == 2.5


def test_the_indenter_option_takes_its_radius_with_a_later_kind(tmp_path):
    from tactileskin.cli.sweep import scenes_from_options

    scenes = scenes_from_options({"indenter": "flat,sphere", "indenter_radius": 2.5, "dim": 3,
                                  "thickness": "1", "material": "silicone", "quality": "preview"})
    assert [(s.indenter.value, s.indenter_radius) for s in scenes] == [("flat", None), ("sphere", 2.5)]


@pytest.mark.parametrize("grid", ["file", "dict"])
def test_the_python_api_takes_a_listed_kinds_own_field(tmp_path, grid):
    """tactileskin.scenes / tactileskin.sweep built the base on the default flat plate: a
    sweep file (or a dict grid) with indenters = ["flat", "sphere"] and indenter_radius was
    refused there after the CLI took it."""
    from tactileskin import api

    f = tmp_path / "s.toml"
    f.write_text(SWEEP.format(indenters='["flat", "sphere"]'))
    g = str(f) if grid == "file" else dict(indenter=["flat", "sphere"], indenter_radius=2.5, thickness=[1.0],
                                           material=["silicone"], dim=3)
    scenes = api.scenes(g, quality="preview")
    assert [(s.indenter.value, s.indenter_radius) for s in scenes] == [("flat", None), ("sphere", 2.5)]
