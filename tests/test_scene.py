"""Scene: validation, TOML round trip, stable content hash."""

import pytest

from tactileskin.errors import ParameterError
from tactileskin.scene import IndenterKind, Scene


def test_defaults_follow_the_paper():
    s = Scene(thickness=5.0)
    assert s.indentation == pytest.approx(1.0)   # 20 % of 5 mm
    assert s.duration == pytest.approx(1.0)      # at 1 mm/s
    assert s.indenter is IndenterKind.FLAT


def test_toml_round_trip_and_hash(tmp_path):
    s = Scene(thickness=1.0, material="polyurethane", indenter="curved", mesh_size=0.3)
    p = tmp_path / "s.toml"
    s.to_toml(p)
    s2 = Scene.from_toml(p)
    assert s2 == s and s2.key() == s.key()


def test_hash_changes_with_any_field():
    base = Scene()
    keys = {base.key()}
    for change in [dict(thickness=1.0), dict(material="polyurethane"), dict(indenter="curved"),
                   dict(depth=0.5), dict(rate=2.0), dict(mesh_size=0.2), dict(formulation="displacement"),
                   dict(viscoelastic=False), dict(fingertip={"height": 6.8})]:
        keys.add(base.replace(**change).key())
    assert len(keys) == 10


def test_hash_is_stable_across_sessions():
    # A literal guard: the cache key must not change unless SCHEMA_VERSION is bumped.
    assert Scene().key() == Scene(thickness=3.0, indenter="flat").key()
    assert len(Scene().key()) == 20


@pytest.mark.parametrize("field, value, needle", [
    ("thickness", 9.0, "thickness"),
    ("indenter", "pyramid", "flat, curved, braille"),
    ("rate", 0.0, "rate"),
    ("dim", 4, "2 or 3"),
    ("mesh_size", -1.0, "mesh_size"),
    ("depth", 5.0, "depth"),
    ("order", 1, "2 with the mixed formulation"),
])
def test_invalid_fields(field, value, needle):
    with pytest.raises(ParameterError, match=needle):
        Scene(**{field: value})


def test_unknown_field_in_toml(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text("thicknes = 2.0\n")
    with pytest.raises(ParameterError, match="scene field"):
        Scene.from_toml(p)


def test_mesh_defaults_follow_dimension():
    from tactileskin.scene import DEFAULT_MESH

    assert (Scene().mesh_size, Scene().refinement) == DEFAULT_MESH[2]
    assert (Scene(dim=3).mesh_size, Scene(dim=3).refinement) == DEFAULT_MESH[3]
    assert Scene().replace(dim=3) == Scene(dim=3)            # defaults re-derived
    assert Scene(mesh_size=0.4).replace(dim=3).mesh_size == 0.4  # explicit choices kept


def test_braille_2d_default_mesh_is_finer():
    from tactileskin.scene import DEFAULT_MESH, DEFAULT_MESH_BRAILLE_2D

    b = Scene(indenter="braille")
    assert (b.mesh_size, b.refinement) == DEFAULT_MESH_BRAILLE_2D
    assert DEFAULT_MESH_BRAILLE_2D[0] / DEFAULT_MESH_BRAILLE_2D[1] < DEFAULT_MESH[2][0] / DEFAULT_MESH[2][1]
    assert Scene().replace(indenter="braille") == b              # defaults re-derived
    assert b.replace(indenter="flat") == Scene()
    assert Scene(mesh_size=0.4).replace(indenter="braille").mesh_size == 0.4
    from tactileskin.scene import DEFAULT_MESH_BRAILLE_3D

    b3 = Scene(indenter="braille", dim=3, thickness=1.0)
    assert (b3.mesh_size, b3.refinement) == DEFAULT_MESH_BRAILLE_3D  # the local plan's sizes
    assert b3.replace(indenter="flat") == Scene(dim=3, thickness=1.0)
    # thick skins take the preset's thick-skin sizes (presets.json braille_mesh_by_thickness),
    # re-derived when the thickness changes; sizes the user gave are kept
    from tactileskin import presets

    b5 = b3.replace(thickness=5.0)
    assert (b5.mesh_size, b5.refinement) == presets.mesh(3, "default", braille=True, thickness=5.0) \
        != DEFAULT_MESH_BRAILLE_3D
    assert b5 == Scene(indenter="braille", dim=3, thickness=5.0) and b5.replace(thickness=1.0) == b3
    assert b3.replace(mesh_size=1.0).replace(thickness=5.0).mesh_size == 1.0


def test_a_depth_and_a_depth_fraction_are_not_both_taken(tmp_path, capsys):
    """Both given: refused (the run used the depth, the record showed the fraction too, e.g.
    depth 0.4 mm with depth_fraction 0.3 at t = 2). With a depth the fraction is not in effect
    and not recorded; --depth over a scene file's depth_fraction is the option winning."""
    from tactileskin.cli import main

    with pytest.raises(ParameterError, match="depth_fraction=0.3 is invalid; valid: not given with depth = 0.4 mm"):
        Scene(thickness=2.0, depth=0.4, depth_fraction=0.3)
    s = Scene(thickness=2.0, depth=0.4)
    assert "depth_fraction" not in s.to_dict() and Scene.from_dict(s.to_dict()) == s
    assert Scene(thickness=2.0, depth_fraction=0.3).to_dict()["depth_fraction"] == 0.3
    # a depth given later (replace: the API's overrides, a sweep's depths) replaces the fraction
    later = Scene(thickness=2.0, depth_fraction=0.3).replace(depth=0.4)
    assert (later.depth, later.depth_fraction) == (0.4, 0.2)
    f = tmp_path / "s.toml"
    f.write_text("thickness = 2\ndepth = 0.4\ndepth_fraction = 0.3\n")
    assert main(["mesh", "--scene", str(f), "--quality", "preview", "--out", str(tmp_path / "m.vtu")]) == 2
    assert "depth_fraction" in capsys.readouterr().err
    f.write_text("thickness = 2\ndepth_fraction = 0.3\n")
    assert main(["mesh", "--scene", str(f), "--depth", "0.4", "--quality", "preview",
                 "--out", str(tmp_path / "m.vtu")]) == 0


def test_an_unknown_material_name_is_refused_when_the_scene_is_made():
    """'SILICONE' made a scene (labelled t3-SILICONE-flat-2d) and failed only at the solve."""
    with pytest.raises(ParameterError, match=r"material='SILICONE' is invalid.*did you mean 'silicone'"):
        Scene(material="SILICONE")
    assert Scene(material="polyurethane").material == "polyurethane"
    assert Scene(material="my_gel.toml").material == "my_gel.toml"  # a file: read at the solve


def test_a_braille_text_is_only_taken_by_the_braille_indenter():
    """A text on a flat indenter was accepted and only changed the cache key (the other fields
    an indenter does not read are refused); switching a Braille scene to another kind drops it."""
    with pytest.raises(ParameterError, match="braille_text='a' is invalid; valid: only with indenter = braille"):
        Scene(indenter="flat", braille_text="a")
    s = Scene(indenter="braille", braille_text="a").replace(indenter="flat")
    assert s.braille_text == "" and s.key() == Scene(indenter="flat").key()


def test_a_field_given_twice_in_a_scene_file_is_named_with_its_value(tmp_path):
    """A field given both at the top level and in [scene], or beside its [sweep] list, read
    "scene field thickness='s.toml' is invalid": the file's name as the field's value."""
    from tactileskin import scenefile

    p = tmp_path / "s.toml"
    p.write_text("[scene]\nthickness = 1.0\n[sweep]\nthicknesses = [1, 3]\n")
    with pytest.raises(ParameterError, match=r"^thickness=1\.0 is invalid; valid: either thickness or "
                                             r"sweep\.thicknesses, not both \(.*s\.toml gives both\)"):
        scenefile.read(p)
    p.write_text("thickness = 2.0\n[scene]\nthickness = 3.0\n")
    with pytest.raises(ParameterError, match=r"^thickness=2\.0 is invalid; valid: given once .*gives it twice"):
        scenefile.read(p)


@pytest.mark.parametrize("dim", [[3], {}, [2, 3]])
def test_replace_refuses_an_unhashable_dim_as_the_constructor_does(dim):
    """Scene().replace(dim=[3]) (ts.sweep({"dim": [3], ...}): dim is a Scene field there, not
    an axis) raised TypeError: unhashable type: 'list' from the mesh-default lookup."""
    with pytest.raises(ParameterError, match="dim"):
        Scene().replace(dim=dim)
