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
