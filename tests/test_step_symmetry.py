"""A STEP skin that is its own mirror image about x = 0 and z = 0 is cut there and solved as its
quarter (mesh.skinfile.step_symmetry, mesh_step(halve=...)) where the indenter is symmetric the
same way, as a .msh quarter is; an almost symmetric skin or an asymmetric indenter keeps the
whole model."""

import math
from pathlib import Path

import pytest

pytest.importorskip("build123d")

import build123d as bd  # noqa: E402

from tactileskin.fe import solve  # noqa: E402
from tactileskin.mesh import build_mesh  # noqa: E402
from tactileskin.mesh.skinfile import step_symmetry  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402

W, H, R = 8.0, 2.0, 12.0  # block x and z, thickness on the axis, the dome's sphere radius (mm)


def _dome(path, dx=0.0):
    """A block x, z in [-4, 4] (moved dx along x), y in [0, 2] under a sphere of radius 12 whose
    top is on the axis (2 mm there, 0.67 mm at the corners), bonded on y = 0."""
    base = bd.Pos(dx, 0, 0) * bd.Box(W, H, W, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    bd.export_step(base & bd.Pos(0, H - R, 0) * bd.Sphere(R), str(path))
    return str(path)


KW = dict(skin="file", viscoelastic=False, mesh_size=1.0, refinement=2.0)


def test_a_symmetric_domed_step_is_solved_as_its_quarter_like_the_whole(tmp_path):
    """The quarter (cut at x = 0 and z = 0) and the whole block under a sphere agree within their
    meshes' differences: the two meshes differ (the quarter has nodes on the axis planes, where
    the peak and the z = 0 profile are read; the whole model's cells cross them), and the whole
    model alone moves by 3.1 % (reaction), 6.7 % (peak) and 1.3 % (span) between h = 0.9, 1.0 and
    1.1 mm; the quarter reads 2.2 %, 2.8 % and 3.7 % above it at h = 1 (TOL)."""
    sc = Scene(skin_file=_dome(tmp_path / "dome.step"), indenter="sphere", indenter_radius=1.5, depth=0.1, **KW)
    quarter, whole = build_mesh(sc), build_mesh(sc, use_symmetry=False)
    assert quarter.halved and quarter.z_symmetric and not whole.halved and not whole.z_symmetric
    assert {"symmetry", "end_back"} <= set(quarter.boundaries) and "symmetry_z" not in quarter.boundaries
    # the cut faces are the symmetry planes, not bonded or contact faces: a quarter of each
    assert quarter.measure() == pytest.approx(whole.measure() / 4.0, rel=1e-6)
    assert quarter.boundary_measure("bone_interface") == pytest.approx(W * W / 4.0, rel=1e-9)
    # each cut face is the dome's section z in [0, 4] under y = H - R + sqrt(R^2 - z^2), 7.0955 mm^2
    # (the P2 faces curved onto the CAD: 1e-4)
    cut = 0.5 * W / 2 * math.sqrt(R**2 - (W / 2) ** 2) + 0.5 * R**2 * math.asin(W / 2 / R) + (H - R) * W / 2
    assert quarter.boundary_measure("symmetry") == pytest.approx(cut, rel=1e-4)
    assert quarter.boundary_measure("end_back") == pytest.approx(cut, rel=1e-4)
    a, b = solve(sc, mesh=quarter), solve(sc, mesh=whole)
    assert a.stats["dofs"] < 0.4 * b.stats["dofs"]
    assert a.status == b.status == "ok" and a.sides == 1 and b.sides == 2
    TOL = 0.05
    assert a.reaction == pytest.approx(b.reaction, rel=TOL)
    assert a.peak == pytest.approx(b.peak, rel=TOL)
    assert a.span == pytest.approx(b.span, rel=TOL)


def test_an_almost_symmetric_step_stays_whole_on_that_axis(tmp_path):
    """A block moved 0.001 mm along x (its symmetric difference with its mirror image about x = 0
    is 2.4e-4 of its volume, above SYMMETRY_TOL = 1e-6) is halved in z only; a bonded-face rule
    naming an axis bonds one side only: no cut across it."""
    exact, off = _dome(tmp_path / "exact.step"), _dome(tmp_path / "off.step", dx=0.001)
    assert step_symmetry(exact) == (True, True)
    assert step_symmetry(off) == (False, True)
    assert step_symmetry(exact, "normal:-z") == (True, False)
    assert step_symmetry(exact, "plane:x=0") == (False, True)
    sm = build_mesh(Scene(skin_file=off, indenter="sphere", indenter_radius=1.5, depth=0.1, **KW))
    assert not sm.halved and sm.z_symmetric and "symmetry" not in sm.boundaries


def _pad(path, *features, cut=False):
    """A 100 x 100 x 5 mm pad (x, z centred, y in [0, 5]) with `features` added (cut=True: cut)."""
    s = bd.Box(100, 5, 100, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    for f in features:
        s = s - f if cut else s + f
    bd.export_step(s, str(path))
    return str(path)


def test_a_small_feature_on_one_side_of_a_large_step_keeps_it_whole(tmp_path):
    """A 0.25 x 0.3 x 0.25 mm nub or a 1 mm dimple 0.03 mm deep at x = z = 20 on a 100 x 100 x 5
    pad: 7.5e-7 and 9.5e-7 of its volume, under SYMMETRY_TOL, read symmetric and the quarter
    dropped the feature; the difference's piece is 0.1 / 0.028 mm thick (SYMMETRY_LENGTH 1e-4).
    The same features mirrored at (+-20, +-20) keep the pad symmetric."""
    def nub(x, z):
        return bd.Pos(x, 5, z) * bd.Box(0.25, 0.3, 0.25, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))

    def dimple(x, z):
        return bd.Pos(x, 5, z) * bd.Cylinder(0.5, 0.06, rotation=(90, 0, 0))

    assert step_symmetry(_pad(tmp_path / "nub.step", nub(20, 20))) == (False, False)
    assert step_symmetry(_pad(tmp_path / "dimple.step", dimple(20, 20), cut=True)) == (False, False)
    four = [(x, z) for x in (-20, 20) for z in (-20, 20)]
    assert step_symmetry(_pad(tmp_path / "nubs.step", *(nub(x, z) for x, z in four))) == (True, True)
    assert step_symmetry(_pad(tmp_path / "dimples.step", *(dimple(x, z) for x, z in four), cut=True)) == (True, True)


def test_a_cut_that_splits_the_step_falls_back_to_the_whole_model(tmp_path, caplog):
    """A 20 x 20 x 2 mm pad with 2 mm square holes at (+-3, +-3) and a notch 1e-5 mm wide through
    it at z = 3 from the hole at x = -3 to the edge x = 10 is its mirror image within the
    tolerances (difference under 1e-6 of its volume, 1e-5 mm thick), but its quarter x, z >= 0
    falls in two pieces: that raised MeshError; now the whole pad is meshed, saying why."""
    import logging

    pad = bd.Box(20, 2, 20, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    for x, z in ((-3, -3), (-3, 3), (3, -3), (3, 3)):
        pad -= bd.Pos(x, 1, z) * bd.Box(2, 2, 2)
    notch = bd.Pos(-3, 0, 3) * bd.Box(13, 2, 1e-5, align=(bd.Align.MIN, bd.Align.MIN, bd.Align.MIN))
    path = tmp_path / "notched.step"
    bd.export_step(pad - notch, str(path))
    assert step_symmetry(path) == (True, True)
    sc = Scene(skin_file=str(path), indenter="sphere", indenter_radius=1.5, depth=0.1, skin="file",
               viscoelastic=False, mesh_size=2.0, refinement=1.0)
    with caplog.at_level(logging.WARNING, logger="tactileskin.mesh.skinfile"):
        sm = build_mesh(sc)
    assert not sm.halved and not sm.z_symmetric and not {"symmetry", "end_back"} & set(sm.boundaries)
    # the whole bonded face: 400 mm^2 less the holes (16) and the notch's 10 mm outside them
    assert sm.boundary_measure("bone_interface") == pytest.approx(384.0 - 10 * 1e-5, rel=1e-9)
    assert any("left 2 volumes, not one: meshed whole" in r.getMessage() for r in caplog.records)


def test_an_asymmetric_indenter_keeps_the_whole_step(tmp_path):
    """Braille ⠑ (dots at (-1.17, 1.17) and (1.17, -1.17) mm: symmetric about neither plane) on
    the symmetric block: the whole model, as before the cut existed."""
    sc = Scene(skin_file=_dome(tmp_path / "dome.step"), indenter="braille", braille_text="⠑", depth=0.3, **KW)
    sm = build_mesh(sc)
    assert not sm.halved and not sm.z_symmetric
    assert sm.boundary_measure("bone_interface") == pytest.approx(W * W, rel=1e-9)


def test_the_mesh_command_says_a_step_skin_is_modelled_as_its_quarter(tmp_path, capsys):
    """Its bonded measure is the quarter's (16 of the block's 64 mm^2): the table says so."""
    from tactileskin.cli import main

    path = _dome(tmp_path / "dome.step")
    assert main(["mesh", "--skin-file", path, "-i", "sphere", "--indenter-radius", "1.5", "--mesh-size", "1"]) == 0
    out = " ".join(capsys.readouterr().out.split())  # the table wraps at the terminal's width
    assert "model │ quarter (x >= 0, z >= 0) │" in out
    assert "bonded boundary measure (mm^2) │ 16 │" in out


def test_a_step_skin_edited_while_its_symmetry_is_read_is_not_kept_as_the_old_bytes(tmp_path, monkeypatch):
    """The symmetry of a STEP skin is memoised by the SHA-256 of the bytes hashed first, but
    the file was imported again to test it: an edit in between kept the other solid's symmetry
    under the first bytes' digest, so once the file was back to them an asymmetric skin was cut
    at x = 0 (or a symmetric one solved whole) for the life of the process."""
    from tactileskin.errors import ParameterError
    from tactileskin.mesh import skinfile

    f = tmp_path / "skin.step"
    old = Path(_dome(f, dx=0.5)).read_bytes()
    other = Path(_dome(tmp_path / "sym.step")).read_bytes()
    real, calls = skinfile._import_step, []

    def edited_meanwhile(gmsh, path):
        if not calls:
            f.write_bytes(other)
        calls.append(path)
        return real(gmsh, path)

    monkeypatch.setattr(skinfile, "_import_step", edited_meanwhile)
    skinfile._solid_symmetry.cache_clear()
    with pytest.raises(ParameterError, match="skin_file.*changed while it was read"):
        step_symmetry(f)
    f.write_bytes(old)
    assert step_symmetry(f) == (False, True)  # the moved block's, not the symmetric one's
    skinfile._solid_symmetry.cache_clear()
