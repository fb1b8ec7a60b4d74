"""`tactileskin build --indenter sphere|cylinder`: the printable sphere and cylinder indenters
are closed STL volumes whose volume matches their closed form (solids.sphere_indenter,
solids.cylinder_indenter: working body + mounting stem + stem-root fillet)."""

from __future__ import annotations

import json
import math

import pytest
import trimesh

from tactileskin import params
from tactileskin.cli import main
from tactileskin.geometry.export import STL_TOLERANCE
from tactileskin.geometry.fingertip import Fingertip
from tactileskin.geometry.indenters import make_indenter


def _stem_volume(ind) -> float:
    """Stem cylinder plus the fillet ring at its root (Pappus: the corner region between the
    square rf x rf and the fillet's quarter circle, revolved about the stem axis)."""
    rf = float(params.load("indenters")["stem"]["fillet"])
    r = 0.5 * ind.stem_diameter
    area = rf * rf * (1.0 - math.pi / 4.0)
    xbar = rf * (5.0 / 6.0 - math.pi / 4.0) / (1.0 - math.pi / 4.0)  # centroid off the stem wall
    return math.pi * r * r * ind.stem_length + 2.0 * math.pi * (r + xbar) * area


def _mount_volume(ind, half_x: float, half_z: float) -> float:
    """The block under the stem where the back face (half-widths half_x, half_z) leaves less
    than the fillet's room twice around the stem: (stem + 2 x 2 fillets)^2 x mount thickness."""
    q = params.load("indenters")["stem"]
    r, rf = 0.5 * ind.stem_diameter, float(q["fillet"])
    if min(half_x, half_z) - r >= 2.0 * rf:
        return 0.0
    return (2.0 * (r + 2.0 * rf)) ** 2 * float(q["mount_thickness"])


def _sphere_volume(ind) -> float:
    """Plate (2.4 R square, from 0.95 R to 2.2 R above the lowest point) plus the ball's cap of
    height h = 0.95 R under it: pi h^2 (3R - h) / 3."""
    R = ind.radius
    h = 0.95 * R
    return ((2.4 * R) ** 2 * 1.25 * R + math.pi * h * h * (3 * R - h) / 3.0
            + _mount_volume(ind, 1.2 * R, 1.2 * R) + _stem_volume(ind))


def _cylinder_volume(ind) -> float:
    """(chord x back thickness + the circular segment of that chord) x the length along the axis."""
    R, w = ind.radius, ind.chord
    theta = 2.0 * math.asin(w / (2.0 * R))
    segment = 0.5 * R * R * (theta - math.sin(theta))
    along = ind.length if ind.axis == "z" else ind.width
    return (w * ind.back_thickness + segment) * along + _mount_volume(ind, 0.5 * w, 0.5 * along) + _stem_volume(ind)


@pytest.mark.parametrize("argv, kind, opts", [
    (["--indenter", "sphere", "--indenter-radius", "5"], "sphere", dict(indenter_radius=5.0)),
    # small balls: the plate (half-width 1.2 R) is narrower than the stem and its fillet; the
    # stem stands on a mount block (R = 2.5, the README's example, once failed in the kernel)
    (["--indenter", "sphere", "--indenter-radius", "2.5"], "sphere", dict(indenter_radius=2.5)),
    (["--indenter", "sphere", "--indenter-radius", "0.5"], "sphere", dict(indenter_radius=0.5)),
    (["--indenter", "cylinder", "--indenter-radius", "8", "--indenter-axis", "x"], "cylinder",
     dict(indenter_radius=8.0, indenter_axis="x")),
    (["--indenter", "cylinder", "--indenter-radius", "20"], "cylinder", dict(indenter_radius=20.0)),
    (["--indenter", "cylinder", "--indenter-radius", "1"], "cylinder", dict(indenter_radius=1.0)),
])
def test_sphere_and_cylinder_parts_are_closed_with_the_closed_form_volume(tmp_path, argv, kind, opts):
    """Chordal bound: vertices on the exact CAD surfaces, no facet more than STL_TOLERANCE off
    them, so |V_stl - V| <= tol * area (measured well inside it)."""
    out = tmp_path / "out"
    assert main(["build", "--out", str(out), "--no-molds", *argv]) == 0
    man = json.loads((out / "manifest.json").read_text())
    e = {p["name"]: p for p in man["parts"]}[f"indenter_{kind}"]
    assert e["parameters"]["radius"] == opts["indenter_radius"]
    ft = Fingertip.from_params()
    ind = make_indenter(kind, y0=ft.section(2.0).top, dim=3, sample_length=ft.sample_length, **opts)
    exact = _sphere_volume(ind) if kind == "sphere" else _cylinder_volume(ind)
    m = trimesh.load(str(out / e["stl"]), force="mesh")
    assert m.is_watertight and m.is_winding_consistent and m.is_volume
    assert abs(m.volume - exact) <= STL_TOLERANCE * m.area, (m.volume, exact, STL_TOLERANCE * m.area)
    assert _precise_volume(ind.solid()) == pytest.approx(exact, rel=1e-7)  # the CAD solid is exact


def _precise_volume(shape) -> float:
    """OCC's volume integral to 1e-9 (build123d's `.volume` uses the default precision, which
    is off by up to ~6e-4 on a spherical cap)."""
    from tactileskin.geometry.export import cad_volume

    return cad_volume(shape)


@pytest.mark.parametrize("argv, words", [
    (["--indenter", "sphere"], ["indenter_radius", "required"]),
    (["--indenter", "sphere", "--indenter-radius", "-1"], ["indenter_radius=-1", "mm"]),
    (["--indenter", "flat", "--indenter-radius", "3"], ["--indenter-radius", "sphere or cylinder"]),
    (["--indenter", "sphere", "--indenter-radius", "3", "--indenter-axis", "x"], ["--indenter-axis", "cylinder"]),
])
def test_bad_indenter_options_are_one_line_errors(tmp_path, capsys, argv, words):
    assert main(["build", "--out", str(tmp_path / "out"), "--no-molds", *argv]) == 2
    cap = capsys.readouterr()
    err = " ".join(cap.err.split())
    assert all(w in err for w in words), err
    assert "Traceback" not in cap.err + cap.out
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kind, opts", [("sphere", dict(indenter_radius=0.3)), ("sphere", dict(indenter_radius=2.5)),
                                        ("cylinder", dict(indenter_radius=1.0))])
def test_every_printed_indenter_carries_the_standard_stem(kind, opts):
    """The stem mounts the indenter on the load cell's adapter (indenters.toml [stem]): the
    same for every kind. It shrank with small bodies instead: 0.48 mm across and 20 mm long
    for a ball of R = 0.3 (unprintable), 4 mm for the README's R = 2.5."""
    import build123d as bd

    q = params.load("indenters")["stem"]
    ind = make_indenter(kind, y0=7.0, dim=3, sample_length=20.0, **opts)
    assert ind.stem_diameter == float(q["diameter"])
    solid = ind.solid()
    top = solid.bounding_box().max.Y
    rims = [e for e in solid.edges() if e.geom_type == bd.GeomType.CIRCLE and abs(e.center().Y - top) < 1e-6]
    assert len(rims) == 1 and rims[0].radius == pytest.approx(0.5 * float(q["diameter"]), abs=1e-6)
    # the working face is still the model's: the lowest point at y0, the ball / arc under the mount
    assert solid.bounding_box().min.Y == pytest.approx(7.0, abs=1e-6)


def test_a_geometry_folder_without_the_mount_thickness_is_a_one_line_error(tmp_path, monkeypatch, capsys):
    """A TACTILESKIN_GEOMETRY folder copied before the mount block has no [stem]
    mount_thickness: an indenter that needs the block names the entry (it was a KeyError
    traceback, for every indenter, the flat plate too); one that does not builds as before."""
    import shutil

    geo = tmp_path / "geometry"
    shutil.copytree(params.geometry_dir(), geo)
    text = (geo / "indenters.toml").read_text()
    kept = [ln for ln in text.splitlines() if not ln.startswith("mount_thickness")]
    assert len(kept) == len(text.splitlines()) - 1
    (geo / "indenters.toml").write_text("\n".join(kept) + "\n")
    monkeypatch.setenv("TACTILESKIN_GEOMETRY", str(geo))
    make_indenter("flat", y0=7.0, dim=3, sample_length=20.0).solid()  # no block: not read
    out = tmp_path / "out"
    assert main(["build", "--out", str(out), "--no-molds", "--indenter", "sphere", "--indenter-radius", "0.5"]) == 2
    cap = capsys.readouterr()
    assert "indenters.stem.mount_thickness" in cap.err and "Traceback" not in cap.err + cap.out


def test_a_printed_cylinder_meets_the_skin_off_its_modelled_face_only_past_its_working_travel(tmp_path):
    """The part beyond the model's face (the chord's edges, back and mount) stays out of the
    fingertip until `working_travel`, the depth a scene may ask: R 2.5 at t = 5 was accepted to
    3 mm, where the face's edges lay 1.3 mm and the mount's flat 0.76 mm inside the finger."""
    import numpy as np

    from tactileskin.geometry.export import write_stl
    from tactileskin.geometry.solids import indenter_solid
    from tactileskin.scene import Scene

    sc = Scene(indenter="cylinder", indenter_radius=2.5, thickness=5.0, depth=1.0)
    ft, ind = Fingertip.from_params(), make_indenter(sc)
    cap = ind.working_travel(sc.section(), sc.sample_length)
    write_stl(indenter_solid(ind), tmp_path / "c.stl")
    pts, _ = trimesh.sample.sample_surface_even(trimesh.load(str(tmp_path / "c.stl")), 40000, seed=1)
    off = pts[np.abs(ind.gap(pts, 0.0)[0]) > 0.01]  # printed surface that is not the model's cylinder

    def inside_finger(travel):  # below the fingertip's outer contour, within its sample length
        x, y = off[:, 0], off[:, 1] - travel
        return int(np.sum((np.abs(x) < ft.half_width) & (np.abs(off[:, 2]) < 0.5 * ft.sample_length)
                          & (y < ft.height * np.sqrt(np.clip(1.0 - (x / ft.half_width) ** 2, 0.0, None)))))

    assert cap == pytest.approx(1.693, abs=1e-3)
    assert inside_finger(cap - 0.01) == 0
    assert inside_finger(cap + 0.1) > 0
    assert inside_finger(3.0) > 1000  # the depth once accepted: the mount's flat is in the finger
