"""`tactileskin build`, run in-process through tactileskin.cli.main."""

from __future__ import annotations

import json

import pytest

from tactileskin import params
from tactileskin.cli import main
from tactileskin.geometry import braille
from tactileskin.geometry.fingertip import Fingertip

_FT = Fingertip.from_params()


def test_default_build_makes_every_part(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["build", "--out", str(out)]) == 0
    m = json.loads((out / "manifest.json").read_text())
    names = [e["name"] for e in m["parts"]]
    assert names == ["skin", "rigid_base", "mold_lower", "mold_upper",
                     "indenter_flat", "indenter_curved", "indenter_braille"]
    assert m["parameters"]["thickness"] == params.load("fingertip")["thickness"]["default"]
    for e in m["parts"]:
        assert e["watertight"] and e["is_volume"] and e["volume_mm3"] > 0
        assert (out / e["stl"]).is_file() and (out / e["step"]).is_file()
    text = capsys.readouterr().out
    assert all(n in text for n in names)  # the table lists what was made
    # a rebuild replaces the previous build in place
    assert main(["build", "--out", str(out), "--thickness", "2", "--indenter", "none", "--no-molds"]) == 0
    m2 = json.loads((out / "manifest.json").read_text())
    assert [e["name"] for e in m2["parts"]] == ["skin", "rigid_base"]
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "manifest.json", "rigid_base.step", "rigid_base.stl", "skin.step", "skin.stl"]


def test_braille_word_option(tmp_path):
    out = tmp_path / "w"
    assert main(["build", "-t", "1", "--out", str(out), "--indenter", "braille", "--braille-text", "Hi",
                 "--braille-standard", "ada_2010", "--no-molds"]) == 0
    m = json.loads((out / "manifest.json").read_text())
    e = {p["name"]: p for p in m["parts"]}["indenter_braille"]
    assert e["parameters"]["standard"] == "ada_2010"
    assert e["parameters"]["dots"] == len(braille.dot_centres("Hi", "ada_2010"))
    # the dots protrude the ADA height below the base plane; the lowest point is the skin top
    assert e["bbox_min"][1] == pytest.approx(Fingertip.from_params().height, abs=0.005)


@pytest.mark.parametrize("argv, words", [
    (["--thickness", "9"], ["thickness=9", f"[{_FT.thickness_min:g}, {_FT.thickness_bounds[1]:g}] mm"]),
    (["--thickness", "0.1"], ["thickness=0.1", "valid"]),
    (["--indenter", "braille", "--braille-text", "a\u00e9"], ["braille_text", "U+00E9"]),
    (["--indenter", "braille", "--braille-standard", "klingon"], ["braille_standard", "standard_american"]),
])
def test_invalid_input_is_a_clear_error_with_exit_code_2(tmp_path, capsys, argv, words):
    out = tmp_path / "out"
    assert main(["build", "--out", str(out), *argv]) == 2
    cap = capsys.readouterr()
    err = " ".join(cap.err.split())  # rich wraps long lines
    assert "error:" in err and all(w in err for w in words), err
    assert "Traceback" not in cap.err + cap.out
    assert list(tmp_path.iterdir()) == []  # nothing written


@pytest.mark.parametrize("argv", [
    ["--indenter", "flat", "--braille-text", "zz"],
    ["--indenter", "none", "--braille-standard", "klingon"],
])
def test_braille_options_without_a_braille_indenter_are_refused(tmp_path, capsys, argv):
    # they were ignored, and manifest.json recorded them as if a Braille indenter had been built
    out = tmp_path / "out"
    assert main(["build", "--out", str(out), "--no-molds", *argv]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert argv[2] in err and "--indenter braille" in err, err
    assert not out.exists()


def test_out_folder_with_other_files_is_refused(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("keep me")
    assert main(["build", "--out", str(tmp_path), "--indenter", "none", "--no-molds"]) == 2
    assert "out=" in " ".join(capsys.readouterr().err.split())
    assert [p.name for p in tmp_path.iterdir()] == ["notes.txt"]


def test_a_symlinked_out_folder_is_refused_as_a_link(tmp_path, capsys):
    """A link to a folder was refused as "it exists and is not a folder", which it is."""
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    assert main(["build", "--out", str(tmp_path / "link"), "--indenter", "none", "--no-molds"]) == 2
    err = capsys.readouterr().err
    assert "not a symbolic link" in err and "is not a folder" not in err
    assert list((tmp_path / "real").iterdir()) == []


@pytest.mark.parametrize("skin", ["pad", "dome"])
@pytest.mark.parametrize("edit, words", [
    # holes 3.5 mm for 4 mm pins: the pad's and the dome's molds were written, exit 0
    (("clearance = 0.2         # hole", "clearance = -0.5         # hole"), ["molds.pin_clearance=-0.5", ">= 0 mm"]),
    (("wall = 4.0", 'wall = "abc"'), ["molds.wall='abc'", "a number"]),  # a ValueError traceback
])
def test_molds_toml_values_are_checked_for_every_skin(tmp_path, monkeypatch, capsys, skin, edit, words):
    import shutil

    from tactileskin.cli import main
    from tactileskin.params import geometry_dir

    geo = tmp_path / "geo"
    shutil.copytree(geometry_dir(), geo)
    text = (geo / "molds.toml").read_text()
    assert edit[0] in text
    (geo / "molds.toml").write_text(text.replace(edit[0], edit[1], 1))
    monkeypatch.setenv("TACTILESKIN_GEOMETRY", str(geo))
    out = tmp_path / "b"
    assert main(["build", "--skin", skin, "-t", "2", "-i", "none", "-o", str(out)]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert all(w in err for w in words) and "Traceback" not in err, err
    assert not out.exists()


def _scene_file(tmp_path, text):
    p = tmp_path / "scene.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_build_scene_prints_the_skin_the_scene_solves(tmp_path):
    # a scene with fingertip overrides was solved as a 30 mm, 9 mm finger, but build had no option
    # for them and printed the default 20 mm, 8 mm one
    from tactileskin.scene import Scene

    p = _scene_file(tmp_path, 'dim = 3\nthickness = 2.0\nindenter = "sphere"\nindenter_radius = 3.0\n'
                              '[fingertip]\nsample_length = 30.0\nhalf_width = 9.0\n')
    out = tmp_path / "b"
    assert main(["build", "--scene", str(p), "--out", str(out), "--no-molds"]) == 0
    m = json.loads((out / "manifest.json").read_text())
    parts = {e["name"]: e for e in m["parts"]}
    assert list(parts) == ["skin", "rigid_base", "indenter_sphere"]
    sc = Scene.from_toml(p)
    sec = sc.section()
    skin = parts["skin"]
    size = [hi - lo for lo, hi in zip(skin["bbox_min"], skin["bbox_max"])]
    assert size[0] == pytest.approx(2 * sec.half_width, abs=0.01) and sec.half_width == pytest.approx(9.0)
    assert size[2] == pytest.approx(sc.sample_length, abs=0.01) and sc.sample_length == pytest.approx(30.0)
    assert m["parameters"]["thickness"] == 2.0 and m["parameters"]["indenter_radius"] == 3.0
    assert m["parameters"]["fingertip"] == {"half_width": 9.0, "sample_length": 30.0}


def test_build_scene_with_geometry_options_or_a_skin_file_is_refused(tmp_path, capsys):
    p = _scene_file(tmp_path, "thickness = 2.0\n")
    assert main(["build", "--scene", str(p), "-t", "3", "--out", str(tmp_path / "a")]) == 2
    assert "--thickness" in capsys.readouterr().err
    msh = tmp_path / "skin.msh"
    msh.write_text("not read", encoding="utf-8")
    p2 = _scene_file(tmp_path, f'skin_file = "{msh.name}"\n')
    assert main(["build", "--scene", str(p2), "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert "skin_file" in err and "Traceback" not in err
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


@pytest.mark.parametrize("limit, name, cause", [
    (300_000, "skin.stl", "the CAD kernel could not write it"),   # the STEP (88 kB) fits, the STL (678 kB) not
    (50_000, "skin.step", "File too large"),
])
def test_a_full_disk_names_the_file_and_its_cause(tmp_path, capsys, limit, name, cause):
    """A write that fails (a full disk; here a file size limit, ulimit -f) read "exporting skin
    failed (stl=False, step=True) for thickness=1, ..." or "...: RuntimeError: Failed to write
    STEP file": a CAD failure of those parameters, no file named. It is a write error now."""
    import resource
    import signal

    out = tmp_path / "out"
    old_limit = resource.getrlimit(resource.RLIMIT_FSIZE)
    old_handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write fails with EFBIG instead
    try:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, old_limit[1]))
        rc = main(["build", "-t", "1", "--out", str(out), "--indenter", "none", "--no-molds"])
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, old_limit)
        signal.signal(signal.SIGXFSZ, old_handler)
    err = " ".join(capsys.readouterr().err.split())
    assert rc == 2 and f"cannot write {out / name}: {cause}" in err, err
    assert not out.exists()  # nothing half-written left, not even the new folder
