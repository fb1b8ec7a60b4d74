"""`build` of a user's STEP skin (skins.file, geometry.file_parts): the skin and a two-part mold
cast face down, as the pad's, for a skin bonded on one flat face; refusals for the rest."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("build123d")

import build123d as bd  # noqa: E402
import manifold3d  # noqa: E402
import trimesh  # noqa: E402

from tactileskin.errors import ParameterError  # noqa: E402
from tactileskin.geometry.export import export_parts  # noqa: E402
from tactileskin.geometry.molds import MoldParams  # noqa: E402
from tactileskin.geometry.solids import check_solid  # noqa: E402
from tactileskin.skins import get  # noqa: E402

W, H, L, R = 12.0, 4.0, 16.0, 16.0  # block x, y, z (mm) and the dome's sphere radius


def _base():
    return bd.Box(W, H, L, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))


def _dome_step(path, shape=None):
    """A block x in [-6, 6], y in [0, 4], z in [-8, 8] under a sphere of radius 16 whose top is
    the block's top centre (4 mm there, 0.49 mm at the corners), bonded on y = 0."""
    bd.export_step((shape if shape is not None else _base()) & bd.Pos(0, H - R, 0) * bd.Sphere(R), str(path))
    return path


def _solid(mesh: trimesh.Trimesh) -> manifold3d.Manifold:
    m = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=np.asarray(mesh.vertices, np.float64),
                                              tri_verts=np.asarray(mesh.faces, np.uint64)))
    assert m.status() == manifold3d.Error.NoError
    return m


def test_a_domed_step_skins_mold_is_closed_and_its_cavity_is_the_skin(tmp_path):
    path = _dome_step(tmp_path / "dome.step")
    parts = get("file").build_parts(H, skin_file=str(path))
    out = tmp_path / "out"
    manifest = export_parts(parts, out)
    assert [e["name"] for e in manifest["parts"]] == ["skin", "mold_lower", "mold_upper"]
    for e in manifest["parts"]:
        assert e["watertight"] and e["is_volume"], e["name"]
        step = check_solid(bd.import_step(str(out / e["step"])), e["name"])  # the STEP re-reads as the part
        assert step.volume == pytest.approx(e["cad_volume_mm3"], rel=1e-6)
    assert manifest["parts"][1]["parameters"]["bonded_y"] == pytest.approx(0.0, abs=1e-9)
    mesh = {e["name"]: trimesh.load(str(out / e["stl"]), force="mesh") for e in manifest["parts"]}
    skin, lower, upper = (_solid(mesh[n]) for n in ("skin", "mold_lower", "mold_upper"))
    # the assembled mold's void over the skin's footprint (the sprue and vents end at the split
    # plane, the box's face) is the skin: same volume and same shape, to 0.5 % as the built-in molds
    box = _solid(trimesh.creation.box(bounds=[[-W / 2, 0.0, -L / 2], [W / 2, H, L / 2]]))
    cavity = box - lower - upper
    assert cavity.volume() == pytest.approx(skin.volume(), rel=5e-3)
    assert (cavity - skin).volume() + (skin - cavity).volume() < 5e-3 * skin.volume()
    # the lid: its plate minus four blind pin holes and three separate through holes, the vents
    # 2 mm from the bonded face's ends (z = -6, 6) and the sprue 1 mm of mold beyond the z < 0
    # one (z = -2.25): off the middle
    mp = MoldParams.from_params()
    lid = parts[2].shape
    b = lid.bounding_box().size
    pins = 4 * math.pi * (0.5 * (mp.pin_diameter + mp.pin_clearance)) ** 2 * (mp.pin_height + mp.pin_depth_clearance)
    holes = b.Y * math.pi * 0.25 * (mp.pour_diameter ** 2 + 2 * mp.vent_diameter ** 2)
    assert lid.volume == pytest.approx(b.X * b.Y * b.Z - pins - holes, rel=1e-6)
    for z, d in ((-2.25, mp.pour_diameter), (-6.0, mp.vent_diameter), (6.0, mp.vent_diameter)):
        assert not lid.is_inside(bd.Vector(0.0, -1.0, z))  # a hole there
        assert lid.is_inside(bd.Vector(0.0, -1.0, z + 0.5 * d + 0.1))  # and mold beside it
    assert lid.is_inside(bd.Vector(0.0, -1.0, 0.0))  # none under the middle


def test_a_bonded_face_split_in_several_faces_gets_its_mold(tmp_path):
    """A block whose bonded face is two coplanar faces (a CAD export's split face; here split at
    z = -2.25, through the sprue): the z = -6 vent's disc misses the z > -2.25 face, which
    was a traceback ("'NoneType' object has no attribute 'faces'"); the sprue's straddles both
    and lies wholly on the bonded plane."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse

    a = bd.Pos(0, 0, -2.25) * bd.Box(W, H, L / 2 - 2.25, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.MAX))
    b = bd.Pos(0, 0, -2.25) * bd.Box(W, H, L / 2 + 2.25, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.MIN))
    op = BRepAlgoAPI_Fuse(a.wrapped, b.wrapped)
    op.Build()  # OCP's fuse keeps the two bottom faces (build123d's would merge them)
    skin = bd.Shape.cast(op.Shape()).solids()[0]
    assert len([f for f in skin.faces() if f.bounding_box().max.Y < 1e-9]) == 2
    path = tmp_path / "split.step"
    bd.export_step(skin, str(path))
    parts = get("file").build_parts(H, skin_file=str(path))
    assert [p.name for p in parts] == ["skin", "mold_lower", "mold_upper"]
    lid = parts[2].shape
    for z in (-2.25, -6.0, 6.0):
        assert not lid.is_inside(bd.Vector(0.0, -1.0, z))  # the sprue and the vents
    assert lid.is_inside(bd.Vector(0.0, -1.0, 0.0))


def _tube_shell(length=L):
    """A fingertip-like half tube (outer R 8, inner R 6) on y >= 0: its inner face is curved."""
    tube = bd.Cylinder(8, length) - bd.Cylinder(6, length)
    return tube - bd.Box(20, 10, 2 * length, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER))


@pytest.mark.parametrize("case, bonded, words", [
    ("curved", "normal:-y:89.99", ["skin_bonded", "one plane", "span y in [0, 6]", "curved or stepped", "needs a core"]),
    ("stepped", None, ["skin_bonded", "one plane", "span y in [0, 1]"]),
    ("stepped", "plane:y=1", ["skin_file", "reaches y = 0", "below its bonded faces at y = 1"]),
    ("recess", "plane:y=0", ["skin_file", "encloses 1 room", "loose core"]),
    ("short", None, ["skin_file", ">= 11.5 mm along z", "10 mm long there", "--no-molds"]),
    ("overhang", "plane:y=0", ["skin_file", "undercut <= 1 mm", "undercut 4 mm deep at (x, y, z) = (", "--no-molds"]),
    ("msh", None, ["skin_file", "STEP", "a .msh is a mesh, not CAD"]),
])
def test_a_skin_the_mold_cannot_cast_is_refused(tmp_path, case, bonded, words):
    path = tmp_path / ("skin.msh" if case == "msh" else f"{case}.step")
    if case == "msh":
        path.write_text("not read", encoding="utf-8")
    elif case == "curved":
        bd.export_step(_tube_shell(), str(path))
    elif case == "stepped":  # bottom faces at y = 0 (x < 0) and y = 1 (x > 0)
        _dome_step(path, _base() - bd.Box(W / 2, 1.0, L, align=(bd.Align.MIN, bd.Align.MIN, bd.Align.CENTER)))
    elif case == "overhang":  # a T: 4 mm wide neck under a 12 mm wide cap, which the pocket holds
        bd.export_step(_tee(), str(path))
    elif case == "recess":  # a pocket in the bottom: the block would fill it, loose
        _dome_step(path, _base() - bd.Box(6.0, 2.0, 10.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER)))
    else:
        _dome_step(path, bd.Box(W, H, 10.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER)))
    with pytest.raises(ParameterError) as e:
        get("file").build_parts(H, skin_file=str(path), skin_bonded=bonded)
    msg = " ".join(str(e.value).split())
    assert all(w in msg for w in words), msg
    if case != "msh":  # without the mold, the skin alone is printed
        assert [p.name for p in get("file").build_parts(H, skin_file=str(path), skin_bonded=bonded,
                                                        molds=False)] == ["skin"]


def _tee():
    """A T along z: a neck x in [-2, 2], y in [0, 2] under a cap x in [-6, 6], y in [2, 4]."""
    a = (bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER)
    return (bd.Box(4, 2, L, align=a) + bd.Pos(0, 2, 0) * bd.Box(W, 2, L, align=a)).solids()[0]


def test_an_undercut_is_measured_warned_of_and_written_down(tmp_path, caplog):
    """The pocket was never checked for undercuts: a T-shaped skin (its 4 mm wings held by the
    pocket) got a mold that cannot be opened, silently. The depth is how far the cast must
    squeeze sideways to come out along -y: none for the block and the domed block, 0.5 mm for
    a dovetail groove (2 mm wide at the top, 3 mm at its floor), which builds with a warning
    naming it, 4 mm for the T (refused: test_a_skin_the_mold_cannot_cast_is_refused)."""
    import logging

    from tactileskin.geometry.file_parts import undercut

    dovetail = _base() - bd.extrude(bd.Polygon((-1, H), (-1.5, 2), (1.5, 2), (1, H), align=None), amount=L / 2,
                                    both=True)
    assert undercut(_base().solids()[0], 0.0) == (0.0, None)
    assert undercut((_base() & bd.Pos(0, H - R, 0) * bd.Sphere(R)).solids()[0], 0.0) == (0.0, None)
    depth, at = undercut(_tee(), 0.0)
    assert depth == pytest.approx(4.0, abs=0.01) and abs(at[0]) == pytest.approx(6.0, abs=0.01)
    assert at[1] == pytest.approx(2.0, abs=0.01)  # just above the wings' undersides
    depth, at = undercut(dovetail.solids()[0], 0.0)
    assert depth == pytest.approx(0.5, abs=0.01) and abs(at[0]) == pytest.approx(1.0, abs=0.01)
    assert at[1] == pytest.approx(H, abs=0.01)  # at the groove's lips
    # the dovetail's mold is written, its record and the log say so; the block's says nothing
    for name, shape, mm in (("dovetail", dovetail, 0.5), ("block", _base(), 0.0)):
        path = tmp_path / f"{name}.step"
        bd.export_step(shape, str(path))
        caplog.clear()
        with caplog.at_level(logging.WARNING, logger="tactileskin"):
            manifest = export_parts(get("file").build_parts(H, skin_file=str(path)), tmp_path / name)
        assert all(e["is_volume"] and e["watertight"] for e in manifest["parts"])
        lower, upper = manifest["parts"][1:]
        assert lower["parameters"]["undercut_mm"] == upper["parameters"]["undercut_mm"] == pytest.approx(mm, abs=0.01)
        warned = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
        if mm:
            assert "UNDERCUT 0.5 mm" in lower["description"]
            assert len(warned) == 1 and "undercut 0.5 mm deep at (x, y, z) = (" in warned[0], warned
            assert "air may stay" in warned[0]
        else:
            assert warned == [] and "UNDERCUT" not in lower["description"]


def _manifest(out):
    import json

    return json.loads((out / "manifest.json").read_text())


def test_build_skin_file_writes_the_skin_its_mold_and_indenters_for_it(tmp_path, capsys):
    from tactileskin.cli import main

    path = _dome_step(tmp_path / "dome.step")
    out = tmp_path / "out"
    assert main(["build", "--skin-file", str(path), "--indenter", "flat", "--out", str(out)]) == 0
    m = _manifest(out)
    parts = {e["name"]: e for e in m["parts"]}
    assert list(parts) == ["skin", "mold_lower", "mold_upper", "indenter_flat"]
    assert all(e["is_volume"] and (out / e["stl"]).is_file() and (out / e["step"]).is_file() for e in m["parts"])
    assert m["parameters"]["skin"] == "file" and m["parameters"]["skin_bonded"] == "normal:-y"
    assert m["parameters"]["thickness"] == pytest.approx(H, abs=1e-9)  # measured from the file
    flat = parts["indenter_flat"]  # on the skin's top, as wide and as long as the skin
    assert flat["bbox_min"][1] == pytest.approx(H, abs=1e-6)
    assert flat["bbox_max"][0] - flat["bbox_min"][0] >= W - 1e-6
    assert flat["bbox_max"][2] - flat["bbox_min"][2] == pytest.approx(L, abs=1e-6)
    # its own output as the skin: the rebuild replaced its input, and the manifest named bytes gone
    before = (out / "skin.step").read_bytes()
    capsys.readouterr()
    assert main(["build", "--skin-file", str(out / "skin.step"), "--out", str(out)]) == 2
    assert "--skin-file" in capsys.readouterr().err and (out / "skin.step").read_bytes() == before
    # a scene file names the skin and its bonded-face rule; the rebuild replaces the build in place
    scene = tmp_path / "scene.toml"
    scene.write_text('skin_file = "dome.step"\nskin_bonded = "plane:y=0"\nindenter = "flat"\n', encoding="utf-8")
    assert main(["build", "--scene", str(scene), "--indenter", "none", "--out", str(out)]) == 2  # one or the other
    assert main(["build", "--scene", str(scene), "--no-molds", "--out", str(out)]) == 0
    m = _manifest(out)
    assert [e["name"] for e in m["parts"]] == ["skin", "indenter_flat"]
    assert m["parameters"]["skin_bonded"] == "plane:y=0"
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "indenter_flat.step", "indenter_flat.stl", "manifest.json", "skin.step", "skin.stl"]
    assert "Traceback" not in capsys.readouterr().err


@pytest.mark.parametrize("case, argv, words", [
    ("curved", [], ["skin_bonded='normal:-y:89.99'", "one plane y = const", "curved or stepped"]),
    ("msh", [], ["skin_file=", "a .msh is a mesh, not CAD"]),
    ("scene-msh", [], ["skin_file=", "a .msh is a mesh, not CAD"]),
    ("dome", ["-t", "3.5"], ["thickness=3.5", "4 mm (measured from"]),
    ("dome", ["--skin", "pad"], ["--skin-file is the skin"]),
])
def test_build_refuses_a_skin_file_it_cannot_mold_in_one_line(tmp_path, capsys, case, argv, words):
    from tactileskin.cli import main

    if case == "curved":  # its bonded rule comes from a scene file
        bd.export_step(_tube_shell(), str(tmp_path / "shell.step"))
        scene = tmp_path / "scene.toml"
        scene.write_text('skin_file = "shell.step"\nskin_bonded = "normal:-y:89.99"\n', encoding="utf-8")
        source = ["--scene", str(scene)]
    elif case == "msh":
        (tmp_path / "skin.msh").write_text("not read", encoding="utf-8")
        source = ["--skin-file", str(tmp_path / "skin.msh")]
    elif case == "scene-msh":  # a valid one (a scene file's skin is read as the scene is checked)
        from tactileskin.mesh import build_mesh
        from tactileskin.scene import Scene

        build_mesh(Scene(skin="pad", pad_width=4.0, pad_length=4.0, thickness=1.0, mesh_size=1.0,
                         refinement=1.0)).write(tmp_path / "pad.msh")
        scene = tmp_path / "scene.toml"
        scene.write_text('skin_file = "pad.msh"\n', encoding="utf-8")
        source = ["--scene", str(scene)]
    else:
        source = ["--skin-file", str(_dome_step(tmp_path / "dome.step"))]
    out = tmp_path / "out"
    assert main(["build", *source, *argv, "--out", str(out)]) == 2
    cap = capsys.readouterr()
    err = " ".join(cap.err.split())
    assert "error" in err.lower() and all(w in err for w in words), err
    assert "Traceback" not in cap.err + cap.out
    assert not out.exists()  # nothing written


def test_a_skin_whose_undercut_cannot_be_measured_is_refused_naming_no_molds(tmp_path, capsys, monkeypatch):
    """file_parts.undercut refuses a skin whose tessellation is no closed volume (a CadError):
    its message alone of the mold's refusals did not say the skin builds without molds. Now it
    does, and the CLI prints it as one line, exit 2, nothing written; --no-molds builds."""
    from tactileskin.cli import main

    class Open:  # manifold3d's answer for a tessellation with a hole
        def __init__(self, mesh):
            pass

        def status(self):
            return manifold3d.Error.NotManifold

    monkeypatch.setattr(manifold3d, "Manifold", Open)
    path, out = _dome_step(tmp_path / "dome.step"), tmp_path / "out"
    assert main(["build", "--skin-file", str(path), "--indenter", "none", "--out", str(out)]) == 2
    cap = capsys.readouterr()
    assert len(cap.err.strip().splitlines()) == 1 and "Traceback" not in cap.err + cap.out, cap.err
    err = " ".join(cap.err.split())
    assert "tessellation is no closed volume" in err and "--no-molds" in err, err
    assert not out.exists()  # nothing written
    assert main(["build", "--skin-file", str(path), "--indenter", "none", "--no-molds", "--out", str(out)]) == 0
    assert [e["name"] for e in _manifest(out)["parts"]] == ["skin"]


def test_the_bonded_face_rule_is_an_option_of_the_commands(tmp_path, capsys):
    """The STEP's bonded-face rule could only be set in a scene file: a new user's half tube,
    bonded on its curved inner face, was meshed bonded on its two end strips (64 mm^2, t = 10).
    `--skin-bonded` now sets it on mesh / solve / sweep / export and on build: normal:-y:89.9
    bonds the inner face (366 mm^2, t = 2); a rule without a skin file, or a bad rule, is one line."""
    from tactileskin.cli import main

    bd.export_step(_tube_shell(), str(tmp_path / "tube.step"))
    step = str(tmp_path / "tube.step")
    area = {}
    for rule in (None, "normal:-y:89.9"):
        argv = ["mesh", "--skin-file", step, "--mesh-size", "2", "--out", str(tmp_path / f"m{len(area)}.msh")]
        assert main(argv + (["--skin-bonded", rule] if rule else [])) == 0
        out = capsys.readouterr().out
        area[rule] = float(out.split("bonded boundary measure (mm^2)")[1].split("│")[1])
    # (the tube is symmetric about x = 0 and z = 0: meshed as its quarter, whose area is printed)
    assert area[None] == pytest.approx(64.0 / 4, rel=1e-3)
    assert area["normal:-y:89.9"] == pytest.approx(365.6 / 4, rel=1e-2)
    assert main(["solve", "--skin-bonded", "bonded", "-t", "1", "--out", str(tmp_path / "o")]) == 2
    assert main(["mesh", "--skin-file", step, "--skin-bonded", "normal:-q", "--out", str(tmp_path / "x.msh")]) == 2
    err = capsys.readouterr().err
    assert "skin_bonded='bonded'" in err and "only with skin = file" in err and "skin_bonded='normal:-q'" in err
    assert "Traceback" not in err and not (tmp_path / "o").exists()
    assert main(["build", "--skin-bonded", "plane:y=0", "--out", str(tmp_path / "b")]) == 2
    # build takes it too: the inner face is curved, so the mold is refused naming the rule given
    assert main(["build", "--skin-file", step, "--skin-bonded", "normal:-y:89.9", "--out", str(tmp_path / "b")]) == 2
    assert "skin_bonded='normal:-y:89.9'" in capsys.readouterr().err and not (tmp_path / "b").exists()


def test_the_declared_manifold3d_has_the_64_bit_mesh_undercut_uses():
    """file_parts.undercut builds its solid with manifold3d.Mesh64, which manifold3d 3.0.0 first
    ships (2.5.1's module has no Mesh64): pyproject's 'manifold3d>=2.4' let pip keep a 2.x, where
    every `build --skin-file` with molds stopped in an AttributeError traceback."""
    import re
    import tomllib
    from pathlib import Path

    from packaging.version import Version

    project = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())["project"]
    floor = [re.search(r">=\s*([0-9.]+)", r).group(1) for r in project["dependencies"] if r.startswith("manifold3d")]
    assert floor and Version(floor[0]) >= Version("3.0"), floor
