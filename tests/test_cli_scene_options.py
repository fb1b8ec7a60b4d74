"""One set of scene options and one TOML layout for `solve`, `mesh` and `sweep` (no solving)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from tactileskin import presets
from tactileskin.cli import main
from tactileskin.cli._common import PHYSICS_KEYS, SCENE_KEYS, scene_from_options
from tactileskin.cli.build import command as build_cmd
from tactileskin.cli.mesh import command as mesh_cmd
from tactileskin.cli.solve import command as solve_cmd
from tactileskin.cli.sweep import command as sweep_cmd
from tactileskin.cli.sweep import scenes_from_options
from tactileskin.errors import ParameterError
from tactileskin.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def _opts(cmd) -> dict:
    return {p.name: p for p in cmd.params}


def _scene_opts(**kw) -> dict:
    return {k: kw.get(k) for k in SCENE_KEYS + PHYSICS_KEYS}


def test_the_scene_options_are_the_same_on_solve_mesh_and_sweep():
    solve, mesh, sweep = _opts(solve_cmd), _opts(mesh_cmd), _opts(sweep_cmd)
    for name in SCENE_KEYS:
        flags = [tuple(sorted(o[name].opts)) for o in (solve, mesh, sweep)]
        assert len(set(flags)) == 1, (name, flags)
    for name in PHYSICS_KEYS:  # they do not change a mesh, so `mesh` does not offer them
        assert name in solve and name in sweep and name not in mesh


def test_out_has_the_short_form_everywhere():
    for cmd in (solve_cmd, mesh_cmd, sweep_cmd, build_cmd):
        outs = [p for p in cmd.params if "--out" in p.opts]
        assert outs and "-o" in outs[0].opts, cmd.name


def test_quality_on_solve_sets_the_preset_and_mesh_size_overrides_it():
    size, ref = presets.mesh(2, "preview")
    sc = scene_from_options(_scene_opts(thickness=1.0, quality="preview"))
    assert (sc.mesh_size, sc.refinement) == (size, ref)
    sc = scene_from_options(_scene_opts(thickness=1.0, quality="preview", mesh_size=0.77))
    assert (sc.mesh_size, sc.refinement) == (0.77, ref)


def test_a_one_case_sweep_file_is_a_scene_file(tmp_path):
    f = tmp_path / "sweep.toml"
    f.write_text('quality = "preview"\n[scene]\nmaterial = "polyurethane"\n'
                 '[sweep]\nthicknesses = [2.0]\nindenters = ["curved"]\n')
    sc = scene_from_options(_scene_opts(scene_file=str(f)))
    expect = Scene(thickness=2.0, material="polyurethane", indenter="curved")
    size, ref = presets.mesh(2, "preview")
    assert sc == expect.replace(mesh_size=size, refinement=ref)
    # and the same file as a sweep gives that one case
    assert scenes_from_options(_scene_opts(scene_file=str(f))) == [sc]


def test_a_scene_file_is_a_sweep_of_one_case_and_options_override_it(tmp_path):
    f = tmp_path / "scene.toml"
    Scene(thickness=2.0, material="polyurethane", indenter="flat", rate=2.0).to_toml(f)
    scenes = scenes_from_options(_scene_opts(scene_file=str(f)))
    assert len(scenes) == 1 and scenes[0].thickness == 2.0 and scenes[0].rate == 2.0
    scenes = scenes_from_options(_scene_opts(scene_file=str(f), thickness="1,3", elastic=True,
                                             refinement=2.5, dim="3"))
    assert [s.thickness for s in scenes] == [1.0, 3.0]
    assert all(s.dim == 3 and not s.viscoelastic and s.refinement == 2.5 and s.rate == 2.0 for s in scenes)


def test_file_paths_in_a_scene_file_are_relative_to_the_file_not_the_working_folder(tmp_path, monkeypatch):
    from tactileskin import sweep
    from tactileskin.materials import get_material

    gel = "[hyperfoam]\nmu = [{mu}]\nalpha = [8.0]\nnu = 0.45\n"
    (tmp_path / "sw").mkdir()
    (tmp_path / "other").mkdir()
    (tmp_path / "sw" / "gel.toml").write_text(gel.format(mu=0.05))
    (tmp_path / "other" / "gel.toml").write_text(gel.format(mu=0.5))  # same name, another folder
    f = tmp_path / "sw" / "scene.toml"
    f.write_text('material = "gel.toml"\nthickness = 2.0\n')
    monkeypatch.chdir(tmp_path / "other")
    mine = str(tmp_path / "sw" / "gel.toml")
    sc = scene_from_options(_scene_opts(scene_file="../sw/scene.toml"))
    assert sc.material == mine and get_material(sc.material).law.mu0 == pytest.approx(0.05)
    f.write_text('[scene]\nmaterial = "gel.toml"\n[sweep]\nthicknesses = [1.0]\nmaterials = ["gel.toml"]\n')
    spec = sweep.load_spec("../sw/scene.toml")
    assert spec["base"].material == mine and list(spec["materials"]) == [mine]
    # saved and read back from another folder, a scene names the same file
    Scene(thickness=1.0, material=mine).to_toml(tmp_path / "other" / "deep" / "s.toml")
    assert "../../sw/gel.toml" in (tmp_path / "other" / "deep" / "s.toml").read_text()
    assert Scene.from_toml(tmp_path / "other" / "deep" / "s.toml").material == mine


def test_a_sweep_takes_an_indenter_kinds_own_options_from_the_file_and_the_command_line(tmp_path):
    f = tmp_path / "cyl.toml"
    f.write_text('indenter = "cylinder"\nindenter_radius = 2.0\nthickness = 1.0\nmaterial = "silicone"\n')
    (sc,) = scenes_from_options(_scene_opts(scene_file=str(f)))
    assert sc.indenter_kind.name == "cylinder" and sc.indenter_radius == 2.0
    scenes = scenes_from_options(_scene_opts(indenter="cylinder,sphere", indenter_radius=2.0, thickness="1",
                                             material="silicone"))
    assert [(s.indenter_kind.name, s.indenter_radius) for s in scenes] == [("cylinder", 2.0), ("sphere", 2.0)]


def test_solve_refuses_a_sweep_file_of_several_cases_and_says_what_to_run(tmp_path, capsys):
    f = tmp_path / "grid.toml"
    f.write_text("[sweep]\nthicknesses = [1.0, 3.0]\n")
    assert main(["solve", "--scene", str(f), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "sweep.thicknesses" in err and "tactileskin sweep --scene" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_a_field_given_twice_or_a_bad_quality_in_a_file_is_refused(tmp_path):
    f = tmp_path / "both.toml"
    f.write_text("thickness = 2.0\n[sweep]\nthicknesses = [1.0, 3.0]\n")
    with pytest.raises(ParameterError, match="thickness"):
        scenes_from_options(_scene_opts(scene_file=str(f)))
    f.write_text('quality = "ultra"\n')
    with pytest.raises(ParameterError, match="quality"):
        scene_from_options(_scene_opts(scene_file=str(f)))


def test_dev_without_arguments_prints_its_usage_and_succeeds():
    r = subprocess.run([str(ROOT / "dev")], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "./dev run" in r.stdout
    r = subprocess.run([str(ROOT / "dev"), "nonsense"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "nonsense" in r.stderr


@pytest.mark.parametrize("cmd", ["solve", "sweep", "mesh"])
@pytest.mark.parametrize("text", ["", "# nothing yet\n", "[scene]\n", "[sweep]\n"])
def test_an_empty_scene_file_is_refused(tmp_path, capsys, cmd, text):
    """An empty scene file ran the default scene with exit 0: surely a mistake."""
    f = tmp_path / "s.toml"
    f.write_text(text)
    out = tmp_path / ("o.msh" if cmd == "mesh" else "o")
    assert main([cmd, "--scene", str(f), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "scene file=" in err and "at least one setting" in err and "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize("cmd", ["solve", "sweep", "mesh", "export"])
def test_help_states_the_valid_ranges_from_the_validation_constants(cmd):
    """--help gave units but no ranges (-t, --depth, --rate, --mesh-size, --refinement,
    --indenter-radius (each kind's: the next test), --pad-width/--pad-length, --force), no default of --rate/--force-rate,
    no text for --formulation, and `sweep -i` named only three of the six indenters."""
    from click.testing import CliRunner

    from tactileskin import loading, scene
    from tactileskin.cli import cli
    from tactileskin.errors import range_text
    from tactileskin.geometry.fingertip import Fingertip
    from tactileskin.skins import pad

    text = " ".join(CliRunner().invoke(cli, [cmd, "--help"]).output.split())
    wanted = [f"fingertip {range_text(*Fingertip.from_params().thickness_bounds)}", range_text(*pad.THICKNESS),
              f"(0, {scene.MAX_DEPTH_FRACTION:g} t]", range_text(*scene.MESH_SIZE), range_text(*scene.REFINEMENT),
              range_text(*pad.SIZE)]
    if cmd != "mesh":  # the physics options
        wanted += [range_text(*scene.RATE), f"Default {scene.Scene.rate:g}", "--force-rate",
                   range_text(loading.MIN_FORCE, loading.MAX_FORCE, unit="N"), "mixed (locking-free; default)"]
    for w in wanted:
        assert w in text, (w, text)
    assert "[0.5, 5.512]" in text  # the fingertip's, as the QA probe's Scene error stated it
    if cmd == "sweep":
        from tactileskin.scene import IndenterKind

        assert "Indenters: " + ", ".join(k.value for k in IndenterKind) in text and "cylinder" in text


@pytest.mark.parametrize("cmd", ["solve", "mesh"])
def test_help_states_the_default_indenter_and_dim_and_what_a_skin_file_fixes(cmd):
    # `-i` said only "Indenter kind." and `--dim` gave no default, so a user had to guess both; a
    # .msh skin silently ignored --quality / --mesh-size and a STEP's bonded-face rule had no hint
    from click.testing import CliRunner

    from tactileskin.cli import cli

    text = " ".join(CliRunner().invoke(cli, [cmd, "--help"]).output.split())
    assert f"Indenter kind. Default {Scene().indenter.value}." in text
    assert f"3D slab. Default {Scene().dim}" in text
    assert "solved on its own mesh" in text and "--skin-bonded" in text and "'normal:-y'" in text


@pytest.mark.parametrize("cmd", ["solve", "sweep", "mesh", "export", "build"])
def test_help_gives_each_indenter_kinds_radius_range_as_its_check_takes_it(cmd):
    """`solve --help` (and sweep's) gave --indenter-radius as (0.1, 1000] while a sphere above
    100 mm is refused (its printed part): the help now gives each kind's range, the very range
    its check refuses outside of."""
    from click.testing import CliRunner

    from tactileskin.cli import cli

    text = " ".join(CliRunner().invoke(cli, [cmd, "--help"]).output.split())
    assert "sphere (0.1, 100]" in text and "cylinder (0.1, 1000]" in text, text
    for kind, hi in (("sphere", 100.0), ("cylinder", 1000.0)):
        extra = {"dim": 3} if kind == "sphere" else {}
        Scene(indenter=kind, indenter_radius=hi, **extra)                  # the help's upper end is taken
        with pytest.raises(ParameterError, match="indenter_radius"):
            Scene(indenter=kind, indenter_radius=hi * 1.001, **extra)      # and just past it refused
    from tactileskin.scene_doc import FIELDS

    assert "(0.1, 1000] (sphere: (0.1, 100]" in FIELDS["indenter_radius"][1]  # help(Scene) agrees
