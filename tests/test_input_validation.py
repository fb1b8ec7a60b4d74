"""Inputs are checked once, with one clear ParameterError (issue #12): scene, material and
sweep TOML files, the CLI's sweep options, the printed ranges at a bound, rich markup in
user text, and the resource caps (Braille text length, mesh size, material terms)."""

from __future__ import annotations

import logging
import socket
import time

import pytest

from tactileskin import sweep
from tactileskin.cli import main
from tactileskin.errors import ParameterError, check_range
from tactileskin.geometry import braille
from tactileskin.materials import get_material
from tactileskin.materials.hyperfoam import MAX_TERMS as HF_MAX, Hyperfoam
from tactileskin.materials.presets import Material
from tactileskin.materials.prony import MAX_TERMS as PRONY_MAX, Prony
from tactileskin.mesh import sizing
from tactileskin.params import MAX_TOML_BYTES, read_toml
from tactileskin.scene import Scene


def _write(tmp_path, text, name="f.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


# --- scene files ----------------------------------------------------------------------------

@pytest.mark.parametrize("text,name", [
    ('viscoelastic = "no"', "viscoelastic"),        # ran viscoelastic
    ("thickness = true", "thickness"),              # became 1 mm
    ('thickness = "3"', "thickness"),
    ("dim = 2.0", "dim"),                           # crashed later
    ("order = true", "order"),
    ("depth = [1.0]", "depth"),
    ('material = ["silicone"]', "material"),
    ("braille_text = 5", "braille_text"),
    ("[fingertip]\nhieght = 7.0", "fingertip key"),  # was a traceback
    ('[fingertip]\nheight = "7"', "fingertip.height"),
    ("fingertip = 3", "fingertip"),
    ("thikness = 3.0", "scene field"),
    ("[solver]\ntol = 1e-6", "scene field"),        # unknown top-level table
])
def test_scene_file_types_and_keys(tmp_path, text, name):
    with pytest.raises(ParameterError) as e:
        Scene.from_toml(_write(tmp_path, text))
    assert str(e.value).startswith(name + "=")


def test_unknown_fingertip_key_suggests_the_known_one():
    with pytest.raises(ParameterError, match="did you mean 'height'"):
        Scene(fingertip={"hieght": 7.0})


def test_fingertip_override_is_used_and_normalised():
    sc = Scene(fingertip={"height": 7})
    assert sc.fingertip == (("height", 7.0),) and sc.key() == Scene(fingertip={"height": 7.0}).key()
    assert sc.fingertip_model().height == 7.0


def test_value_at_a_computed_bound_is_accepted_and_the_message_is_consistent():
    # 0.6 * 3 = 1.7999999999999998: 1.8 was refused with "valid: (0, 1.8]"
    assert Scene(thickness=3.0, depth=1.8).depth == 1.8
    with pytest.raises(ParameterError, match=r"valid: \(0, 1\.8\] mm"):
        Scene(thickness=3.0, depth=1.81)
    # a bound with more than 6 significant digits is printed in full, so a value above it
    # never reads as inside the printed range
    t = 1.2345678
    with pytest.raises(ParameterError) as e:
        Scene(thickness=t, depth=0.740741)
    printed = float(str(e.value).split(", ")[1].split("]")[0])
    assert printed < 0.740741 and Scene(thickness=t, depth=printed).depth == printed


@pytest.mark.parametrize("value", [True, "1", float("inf"), float("-inf"), float("nan"), None, [1.0]])
def test_check_range_refuses_non_numbers(value):
    with pytest.raises(ParameterError):
        check_range("x", value)


# --- file reading ---------------------------------------------------------------------------

def test_non_utf8_file_is_a_parameter_error(tmp_path):
    p = tmp_path / "s.toml"
    p.write_bytes(b'material = "sil\xe9cone"\n')
    with pytest.raises(ParameterError, match="UTF-8"):
        Scene.from_toml(p)


def test_oversized_file_is_refused_without_reading_it_whole(tmp_path):
    p = tmp_path / "big.toml"
    p.write_bytes(b"# " + b"x" * MAX_TOML_BYTES + b"\n")
    with pytest.raises(ParameterError, match="at most 1024 KiB"):
        read_toml(p, "scene file")
    with pytest.raises(ParameterError, match="readable"):
        read_toml(tmp_path, "scene file")  # a folder


# --- material files -------------------------------------------------------------------------

_HF = "[hyperfoam]\nmu = [0.08, 0.01]\nalpha = [0.001, 15.5]\nnu = 0.49\n"


def test_material_prony_typo_is_refused_not_elastic(tmp_path):
    with pytest.raises(ParameterError, match="did you mean 'prony'"):
        Material.from_toml(_write(tmp_path, _HF + "[prnoy]\ng = [0.1]\ntau = [1.0]\n"))
    m = Material.from_toml(_write(tmp_path, _HF + "[prony]\ng = [0.1]\ntau = [1.0]\n"))
    assert m.prony.g == (0.1,) and m.hyperfoam.mu == (0.08, 0.01)


@pytest.mark.parametrize("body,name", [
    ("[hyperfoam]\nmu = 0.08\nalpha = [2.0]\nnu = 0.3\n", "mu"),             # not a list
    ('[hyperfoam]\nmu = ["0.08"]\nalpha = [2.0]\nnu = 0.3\n', "mu[0]"),
    ("[hyperfoam]\nmu = [true]\nalpha = [2.0]\nnu = 0.3\n", "mu[0]"),
    ("[hyperfoam]\nmu = [0.08]\nalpha = [2.0]\nnu = true\n", "nu"),
    ("[hyperfoam]\nmu = [0.08]\nalpha = [2.0, 3.0]\nnu = 0.3\n", "alpha"),  # unequal lengths
    ("[hyperfoam]\nmu = [0.08, 0.0]\nalpha = [2.0, 3.0]\nnu = 0.3\n", "mu[1]"),
    ("[hyperfoam]\nmu = [0.08]\nalpha = [2.0]\nnu = 0.5\n", "nu"),
    ("[hyperfoam]\nmu = [0.08]\nalpha = [2.0]\nnu = 0.3\nbeta = 1.0\n", "material 'f' hyperfoam key"),
    (_HF + "[prony]\ng = [0.6, 0.5]\ntau = [1.0, 2.0]\n", "g"),              # sum g >= 1
    (_HF + "[prony]\ng = [0.1]\ntau = [0.0]\n", "tau[0]"),
    (_HF + "[prony]\ng = [0.1, 0.1]\ntau = [1.0]\n", "tau"),
    (_HF + "[prony]\ng = [0.1]\n", "material 'f' prony"),
    (_HF + "[prony]\ng = [0.1]\ntau = [1.0]\nG = 2\n", "material 'f' prony key"),
    ("colour = 'red'\n" + _HF, "material 'f' key"),
    ("hyperfoam = 3\n", "material 'f' hyperfoam"),
    ("stray = 1\n[a]\n" + _HF.replace("[hyperfoam]", "[a.hyperfoam]"), "material file"),
])
def test_material_file_is_checked(tmp_path, body, name):
    with pytest.raises(ParameterError) as e:
        Material.from_toml(_write(tmp_path, body))
    assert str(e.value).startswith(name + "="), str(e.value)


def test_material_term_counts_are_capped():
    Hyperfoam((0.01,) * HF_MAX, (2.0,) * HF_MAX, 0.3)
    with pytest.raises(ParameterError, match=f"at most {HF_MAX} terms"):
        Hyperfoam((0.01,) * (HF_MAX + 1), (2.0,) * (HF_MAX + 1), 0.3)
    Prony((0.01,) * PRONY_MAX, (1.0,) * PRONY_MAX)
    with pytest.raises(ParameterError, match=f"at most {PRONY_MAX} terms"):
        Prony((0.01,) * (PRONY_MAX + 1), (1.0,) * (PRONY_MAX + 1))
    with pytest.raises(ParameterError, match=f"at most {PRONY_MAX} numbers"):
        Material.from_dict("m", {"hyperfoam": {"mu": [0.1], "alpha": [2.0], "nu": 0.3},
                                 "prony": {"g": [0.001] * 10_000, "tau": [1.0] * 10_000}})


# --- sweep files and options ------------------------------------------------------------------

@pytest.mark.parametrize("text,name", [
    ("[sweeep]\nthicknesses = [1.0]", "sweep file table key"),   # ran the default sweep
    ('[sweep]\nmaterials = "silicone"', "sweep.materials"),      # became 8 one-letter materials
    ('[sweep]\nthicknesses = ["1"]', "sweep.thicknesses[0]"),
    ("[sweep]\nthicknesses = []", "sweep.thicknesses"),
    ("[sweep]\ndepths = 1.0", "sweep.depths"),
    ("[sweep]\nmaterial = ['silicone']", "sweep key"),
    ("sweep = 3", "[sweep]"),
    ("[scene]\nviscoelastic = 0", "viscoelastic"),
])
def test_sweep_file_is_checked(tmp_path, text, name):
    with pytest.raises(ParameterError) as e:
        sweep.load_spec(_write(tmp_path, text))
    assert str(e.value).startswith(name + "="), str(e.value)


def test_sweep_file_loads_typed_lists(tmp_path):
    spec = sweep.load_spec(_write(tmp_path, '[sweep]\nthicknesses = [1, 3.5]\nmaterials = ["silicone"]\n'
                                            '[scene]\nrate = 2.0\n'))
    assert spec["thicknesses"] == (1.0, 3.5) and spec["materials"] == ("silicone",)
    assert spec["base"].rate == 2.0


@pytest.mark.parametrize("text", ["1:inf:1", "inf", "nan", "1,nan", "-inf:1:1", "1:2:nan"])
def test_parse_values_refuses_non_finite(text):
    with pytest.raises(ParameterError, match="finite"):
        sweep.parse_values(text, "thickness")


@pytest.mark.parametrize("text, says", [("", "none of them empty"), ("1,,2", "none of them empty"),
                                         ("2,", "none of them empty"), ("0.5:5:1e-6", "at most 1000 values"),
                                         ("5:1:1", "start <= stop")])  # said only "step > 0"
def test_parse_values_names_what_is_wrong(text, says):
    with pytest.raises(ParameterError, match=says):  # a tiny positive step is not "step > 0"
        sweep.parse_values(text, "thickness")


def test_sweep_options_given_empty_are_refused_not_the_default_axes(tmp_path, capsys):
    from tactileskin.cli import main

    for opt in (["-t", ""], ["-m", ""], ["-i", "flat,,curved"]):
        assert main(["sweep", *opt, "--no-render", "--out", str(tmp_path / "o")]) == 2
        assert "none of them empty" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_grid_resolves_every_material_before_any_work():
    t0 = time.process_time()
    with pytest.raises(ParameterError, match="material='bogus'"):
        sweep.expand_grid(thicknesses=(1.0, 3.0), materials=("silicone", "bogus"), indenters=("flat",))
    assert time.process_time() - t0 < 1.0
    with pytest.raises(ParameterError, match="not a string"):
        sweep.expand_grid(materials="silicone")
    t0 = time.process_time()
    with pytest.raises(ParameterError, match="at most 10000 cases"):
        sweep.expand_grid(thicknesses=sweep.parse_values("1:5:0.005", "t"), depths=(0.1, 0.2, 0.3, 0.4, 0.5))
    assert time.process_time() - t0 < 1.0


@pytest.mark.parametrize("args,needle", [
    (["-m", "silicone,bogus"], "material='bogus'"),
    (["-t", "1:inf:1"], "thickness='1:inf:1'"),
    (["-i", "braille", "--braille-text", "a" * 41], "at most 40 braille cells"),
    (["--scheduler", "localhost"], "--scheduler='localhost'"),
    (["--scheduler", "http://h:8786"], "--scheduler="),
    (["--workers", "0"], "--workers"),
])
def test_sweep_cli_refuses_bad_input_before_starting(tmp_path, capsys, monkeypatch, args, needle):
    def started(*a, **kw):
        raise AssertionError("the sweep started")

    monkeypatch.setattr(sweep, "run_sweep", started)
    out = tmp_path / "out"
    t0 = time.process_time()  # CPU seconds: a loaded machine's wall clock says nothing of the work done
    assert main(["sweep", "--serial", "--no-render", "--out", str(out), *args]) == 2
    assert time.process_time() - t0 < 1.0
    cap = capsys.readouterr()
    text = (cap.err + cap.out).replace("\n", "")
    assert needle in text and "Traceback" not in text
    assert not out.exists()


def test_scheduler_address_forms():
    for ok in ("tcp://127.0.0.1:8786", "10.0.0.2:8786", "tls://sched.example.org:8786/", "tcp://[::1]:8786"):
        assert sweep.check_scheduler(ok) == ok
    for bad in ("", "tcp://h", "tcp://h:0", "tcp://h:70000", "http://h:8786", "tcp://h:8786 x"):
        with pytest.raises(ParameterError):
            sweep.check_scheduler(bad)


def test_unreachable_scheduler_is_a_parameter_error(monkeypatch):
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    monkeypatch.setattr(sweep, "SCHEDULER_TIMEOUT_S", 0.5)
    import dask.distributed  # noqa: F401 (its first import, seconds on a loaded machine, is not what is timed)

    t0 = time.perf_counter()
    with pytest.raises(ParameterError, match="no connection within 0.5 s"):
        sweep.connect(f"tcp://127.0.0.1:{port}")
    assert time.perf_counter() - t0 < 5.0


# --- user text printed as text ----------------------------------------------------------------

@pytest.mark.parametrize("name", ["[bold]x[/bold]", "[/]", "a[red]b"])
def test_markup_in_a_material_name_is_printed_verbatim(tmp_path, capsys, name):
    assert main(["solve", "-t", "1", "-m", name, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.replace("\n", "")
    assert f"material={name!r}" in err and "Traceback" not in err


def test_sweep_lines_print_labels_verbatim(tmp_path, capsys, monkeypatch):
    # the case line of a Braille case: its label carries the text in brackets
    scene = Scene(thickness=1.0, indenter="braille", braille_text="ab")
    assert scene.label() == "t1-silicone-braille[ab]-2d"

    def fake_run(scenes, cache, *, on_event=None, **kw):
        oc = sweep.CaseOutcome(scene, "failed", 0.0, "boom [/] [bold]x")
        on_event(oc)
        return [oc]

    import tactileskin.report.outputs as outputs

    monkeypatch.setattr(sweep, "run_sweep", fake_run)
    monkeypatch.setattr(outputs, "write_outputs",
                        lambda out, oc, cache, wall, render: {"failures": [1], "report": out / "report.md"})
    rc = main(["sweep", "-t", "1", "-m", "silicone", "-i", "braille", "--braille-text", "ab",
               "--serial", "--out", str(tmp_path / "o")])
    assert rc == 1
    out = capsys.readouterr().out
    assert "t1-silicone-braille[ab]-2d: boom [/] [bold]x" in out


# --- resources --------------------------------------------------------------------------------

def test_braille_text_is_capped():
    ok = "a" * braille.MAX_CELLS   # on a pad wide enough to hold it (the skin's top is checked too)
    assert Scene(indenter="braille", skin="pad", pad_width=250, braille_text=ok).braille_text == ok
    for text in ("a" * (braille.MAX_CELLS + 1), "A" * (braille.MAX_CELLS // 2 + 1), "x" * 1_000_000):
        t0 = time.process_time()
        with pytest.raises(ParameterError, match="at most 40 braille cells"):
            Scene(indenter="braille", braille_text=text)
        assert time.process_time() - t0 < 1.0
    with pytest.raises(ParameterError):
        braille.dot_centres("b" * 200)


def test_dof_estimate_counts_order_and_dimension():
    assert sizing.estimate_dofs(1000, 2, 2) == 4000       # P2 triangles: ~2 nodes per cell
    assert sizing.estimate_dofs(1000, 2, 1) == 1000
    assert sizing.estimate_dofs(1000, 3, 2) > 7 * sizing.estimate_dofs(1000, 3, 1)  # P2 tets: ~7 nodes per vertex


def _plan(scene, **kw):
    return sizing.plan(scene, scene.section(), dim=scene.dim, length=20.0, z_symmetric=True, **kw)


def test_mesh_estimate_refuses_with_sizes_and_counts():
    sc = Scene(thickness=3.0, dim=3)
    with pytest.raises(ParameterError) as e:
        _plan(sc, mesh_size=0.3, refinement=3.0)
    msg = str(e.value)
    assert all(s in msg for s in ("mesh_size=0.3", "refinement=3", "cells", "dofs", "at most 4e+05"))
    # the suggested size fits, 5 % below it does not
    hint = float(msg.split("at or above ")[1].split(" mm")[0])
    _plan(sc, mesh_size=hint, refinement=3.0)
    with pytest.raises(ParameterError):
        _plan(sc, mesh_size=0.95 * hint, refinement=3.0)
    # the estimate grows with the refinement: a size that fits at 1 is refused at 20
    _plan(sc, mesh_size=0.5, refinement=1.0)
    with pytest.raises(ParameterError):
        _plan(sc, mesh_size=0.5, refinement=20.0)
    # the default meshes are allowed without a warning, in 2D and 3D
    for dim in (2, 3):
        for t in (0.5, 5.0):
            p = _plan(Scene(thickness=t, dim=dim))
            assert sizing.estimate_dofs(p.estimate, dim) < sizing.WARN_DOFS[dim]


def test_large_allowed_mesh_is_announced(caplog):
    with caplog.at_level(logging.WARNING, logger="tactileskin.mesh.sizing"):
        _plan(Scene(thickness=5.0), mesh_size=0.05, refinement=20.0)
    assert "a large mesh" in caplog.text


def test_mesh_cli_refuses_before_gmsh(tmp_path, capsys):
    import tactileskin.mesh.slab3d  # noqa: F401 (imports are not what is timed)

    out = tmp_path / "m.vtu"
    t0 = time.process_time()
    assert main(["mesh", "--dim", "3", "-t", "3", "--mesh-size", "0.3", "--refinement", "3",
                 "--out", str(out)]) == 2
    assert time.process_time() - t0 < 1.0
    err = capsys.readouterr().err.replace("\n", "")
    assert "mesh_size=0.3" in err and "dofs" in err and "Traceback" not in err
    assert not out.exists()


def test_presets_still_load():
    assert get_material("silicone").prony.n_terms == 3
