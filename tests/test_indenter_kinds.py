"""Indenter kinds as objects: gap functions against closed forms, the STL kind against the
analytic sphere, symmetry flags, the registry, Scene validation and cache keys."""

import numpy as np
import pytest

from tactileskin.cache import cache_key
from tactileskin.errors import ParameterError
from tactileskin.geometry.indenters import KINDS, get_kind, indenter_for_scene, indenter_symmetry, make_indenter
from tactileskin.scene import Scene

Y0 = 7.0
RNG = np.random.default_rng(3)


def _points(n=400, spread=4.0):
    return RNG.normal(size=(n, 3)) * spread + np.array([0.0, Y0 + 1.0, 0.0])


def _fd_gradient(ind, p, d, h=1e-6):
    """Central differences of g: the normal must be its gradient (exact up to O(h^2) and
    round-off ~1e-16/h = 1e-10; 1e-6 tolerance leaves room for points near a kink)."""
    grad = np.zeros_like(p)
    for k in range(p.shape[1]):
        e = np.zeros(p.shape[1])
        e[k] = h
        grad[:, k] = (ind.gap(p + e, d)[0] - ind.gap(p - e, d)[0]) / (2 * h)
    return grad


def test_sphere_gap_closed_form_sign_and_normal():
    R, d = 2.5, 0.3
    ind = make_indenter("sphere", y0=Y0, dim=3, indenter_radius=R)
    p = _points()
    c = np.array([0.0, Y0 + R - d, 0.0])
    g, n = ind.gap(p, d)
    np.testing.assert_allclose(g, np.linalg.norm(p - c, axis=1) - R, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(n, _fd_gradient(ind, p, d), atol=1e-6)
    # the lowest point is at y0 - d; just below it separated, just above penetrating
    g2, n2 = ind.gap(np.array([[0.0, Y0 - d - 0.1, 0.0], [0.0, Y0 - d + 0.1, 0.0]]), d)
    np.testing.assert_allclose(g2, [0.1, -0.1], atol=1e-12)
    np.testing.assert_allclose(n2, [[0, -1, 0], [0, -1, 0]], atol=1e-12)


@pytest.mark.parametrize("axis", ["z", "x"])
def test_cylinder_gap_closed_form(axis):
    R, d = 4.0, 0.2
    ind = make_indenter("cylinder", y0=Y0, dim=3, indenter_radius=R, indenter_axis=axis)
    p = _points()
    across = 0 if axis == "z" else 2
    g, n = ind.gap(p, d)
    dist = np.hypot(p[:, across], p[:, 1] - (Y0 + R - d))
    np.testing.assert_allclose(g, dist - R, atol=1e-12)
    np.testing.assert_allclose(n[:, 2 - across], 0.0, atol=1e-15)  # no component along the axis
    np.testing.assert_allclose(n, _fd_gradient(ind, p, d), atol=1e-6)


def test_cylinder_along_z_is_the_papers_curved_indenter():
    curved = make_indenter("curved", y0=Y0, dim=2)
    cyl = make_indenter("cylinder", y0=Y0, dim=2, indenter_radius=12.0, indenter_axis="z")
    p = _points()[:, :2]
    for a, b in zip(curved.gap(p, 0.4), cyl.gap(p, 0.4)):
        np.testing.assert_array_equal(a, b)


def test_sphere_section_in_2d_is_the_plane_z0():
    ind = make_indenter("sphere", y0=Y0, dim=3, indenter_radius=2.0)
    p3 = _points()
    p3[:, 2] = 0.0
    g3, n3 = ind.gap(p3, 0.1)
    g2, n2 = ind.gap(p3[:, :2], 0.1)
    np.testing.assert_allclose(g2, g3, atol=1e-14)
    np.testing.assert_allclose(n2, n3[:, :2], atol=1e-14)


def test_stl_sphere_matches_the_analytic_sphere_within_tessellation(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    R = 2.5
    mesh = trimesh.creation.icosphere(subdivisions=4, radius=R)
    f = tmp_path / "ball.stl"
    mesh.export(f)
    stl = make_indenter("file", y0=Y0, dim=3, indenter_file=str(f))
    ana = make_indenter("sphere", y0=Y0, dim=3, indenter_radius=R)
    # the icosphere's vertices are on the sphere; its flat faces lie inside it by at most the
    # sagitta of a face, R (1 - cos(theta)) with theta the largest vertex-to-centroid angle
    tri = mesh.vertices[mesh.faces]
    cen = tri.mean(axis=1)
    cos = np.einsum("ijk,ik->ij", tri, cen) / (R * np.linalg.norm(cen, axis=1))[:, None]
    sag = R * (1 - cos.min())
    # stl's lowest vertex sits at y0; the analytic sphere's lowest point too, so their centres
    # differ by R - (lowest vertex depth), at most sag: allow 2 sag
    p = _points(600, 3.0)
    g_s, n_s = stl.gap(p, 0.2)
    g_a, n_a = ana.gap(p, 0.2)
    assert sag < 0.01
    np.testing.assert_allclose(g_s, g_a, atol=2 * sag)
    assert np.all(np.sign(g_s) == np.sign(g_a)) or np.all(np.abs(g_a[np.sign(g_s) != np.sign(g_a)]) < 2 * sag)
    far = np.abs(g_a) > 0.2  # away from the surface the normals agree to ~ the facet angle
    assert np.max(np.linalg.norm(n_s[far] - n_a[far], axis=1)) < 0.1
    np.testing.assert_allclose(np.linalg.norm(n_s, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(n_s[far], _fd_gradient(stl, p[far], 0.2), atol=1e-5)
    assert stl.symmetry() == (True, True)


def test_stl_errors_name_the_file_and_what_is_wrong(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    open_box = trimesh.Trimesh(box.vertices, box.faces[:-1])
    f = tmp_path / "open.stl"
    open_box.export(f)
    with pytest.raises(ParameterError, match="indenter_file.*watertight"):
        make_indenter("file", y0=Y0, dim=3, indenter_file=str(f))
    m = tmp_path / "metres.stl"
    trimesh.creation.box(extents=(0.002, 0.002, 0.002)).export(m)
    with pytest.raises(ParameterError, match="metres"):
        Scene(dim=3, indenter="file", indenter_file=str(m))
    with pytest.raises(ParameterError, match="indenter_file"):
        Scene(dim=3, indenter="file", indenter_file=str(tmp_path / "missing.stl"))


def test_symmetry_flags():
    assert indenter_symmetry(Scene(indenter="flat")) == (True, True)
    assert indenter_symmetry(Scene(dim=3, indenter="sphere", indenter_radius=2.0)) == (True, True)
    assert indenter_symmetry(Scene(dim=3, indenter="cylinder", indenter_radius=3.0, indenter_axis="x")) == (True, True)
    # the layout is centred on its dots: one dot is symmetric; 'd' (dots 1, 4, 5) is not
    assert indenter_symmetry(Scene(dim=3, indenter="braille", braille_text="a")) == (True, True)
    assert indenter_symmetry(Scene(dim=3, indenter="braille", braille_text="d")) == (False, False)


def test_stl_symmetry_detects_an_off_centre_file(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    ball = trimesh.creation.icosphere(subdivisions=2, radius=2.0)
    ball.apply_translation((0.7, 0.0, 0.0))
    f = tmp_path / "off.stl"
    ball.export(f)
    assert make_indenter("file", y0=Y0, dim=3, indenter_file=str(f)).symmetry() == (False, True)


def test_registry_lists_valid_kinds_on_unknown_name():
    assert KINDS[:3] == ("flat", "curved", "braille")
    assert {"sphere", "cylinder", "file"} <= set(KINDS)
    with pytest.raises(ParameterError, match="one of flat, curved, braille, cylinder, sphere, file"):
        get_kind("cone")
    with pytest.raises(ParameterError, match="one of flat, curved, braille"):
        Scene(indenter="cone")


def test_scene_validates_kind_parameters():
    with pytest.raises(ParameterError, match=r"indenter_radius.*\(0.1, 100\] mm"):
        Scene(dim=3, indenter="sphere")
    with pytest.raises(ParameterError, match=r"indenter_radius=-1.*\(0.1, 100\] mm"):
        Scene(dim=3, indenter="sphere", indenter_radius=-1)
    with pytest.raises(ParameterError, match="indenter_axis"):
        Scene(indenter="cylinder", indenter_radius=3.0, indenter_axis="y")
    with pytest.raises(ParameterError, match="indenter_radius.*only with indenter = cylinder or sphere"):
        Scene(indenter="flat", indenter_radius=3.0)
    # a sphere has no plane-strain model: 2D is refused, pointing at the cylinder section
    with pytest.raises(ParameterError, match="dim=2.*cylinder"):
        Scene(dim=2, indenter="sphere", indenter_radius=2.0)
    with pytest.raises(ParameterError, match="dim=2"):
        Scene(dim=2, indenter="cylinder", indenter_radius=2.0, indenter_axis="x")
    # changing the kind drops the parameters the new kind does not read
    s = Scene(dim=3, indenter="sphere", indenter_radius=2.0).replace(indenter="flat")
    assert s.indenter_radius is None


def test_cache_key_changes_with_kind_parameters_and_file_bytes(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    a = Scene(indenter="cylinder", indenter_radius=12.0)
    assert cache_key(a) != cache_key(a.replace(indenter_radius=10.0))
    s = Scene(dim=3, indenter="sphere", indenter_radius=2.0)
    assert cache_key(s) != cache_key(s.replace(indenter_radius=2.5))
    assert cache_key(a) != cache_key(Scene(indenter="curved"))  # different scenes, same answer
    f = tmp_path / "ind.stl"
    trimesh.creation.icosphere(subdivisions=2, radius=2.0).export(f)
    sf = Scene(dim=3, indenter="file", indenter_file=str(f))
    k1 = cache_key(sf)
    g = tmp_path / "moved.stl"
    g.write_bytes(f.read_bytes())
    assert cache_key(sf.replace(indenter_file=str(g))) == k1  # the bytes count, not the path
    trimesh.creation.icosphere(subdivisions=2, radius=2.1).export(f)
    assert cache_key(sf) != k1


def test_contact_extent_for_mesh_sizing():
    from tactileskin.mesh import sizing

    s = Scene(dim=3, thickness=2.0, indenter="sphere", indenter_radius=2.5)
    z0, z1 = sizing.contact_zrange(s, 20.0, True)
    a = 1.5 * np.sqrt(2 * 2.5 * s.indentation)  # Hertz-like half-length along the straight slab
    assert (z0, z1) == (0.0, pytest.approx(a))
    c = Scene(dim=3, thickness=2.0, indenter="curved")
    assert sizing.contact_zrange(c, 20.0, True) == (0.0, 10.0)  # the whole slab
    assert sizing.contact_halfwidth(c, c.section()) == sizing.contact_halfwidth(s, s.section())


def test_cylinder_in_2d_answers_as_curved():
    """A 2D solve with the cylinder kind (R 12, axis z) is the paper's curved solve: same
    gap, same mesh sizing, so the same numbers (coarse mesh: a cross-check, not accuracy)."""
    from tactileskin.fe import solve

    kw = dict(thickness=1.0, mesh_size=1.0, refinement=2.0, viscoelastic=False)
    a = solve(Scene(indenter="curved", **kw))
    b = solve(Scene(indenter="cylinder", indenter_radius=12.0, **kw))
    np.testing.assert_allclose(b.pressure, a.pressure, rtol=1e-10, atol=1e-12)
    assert b.reaction == pytest.approx(a.reaction, rel=1e-10)


def test_sphere_3d_coarse_solve():
    """A coarse 3D sphere press: the pressure map peaks under the ball (z near 0) and the
    reaction is positive; the section profile is the plane z = 0."""
    from tactileskin.fe import solve

    s = Scene(dim=3, thickness=1.0, indenter="sphere", indenter_radius=2.5, mesh_size=1.2, refinement=2,
              viscoelastic=False)
    r = solve(s)
    assert r.reaction > 0
    p_max, _, z_at = r.bone_map.peak()
    assert p_max > 0
    assert abs(z_at) < 1.5  # under the ball, within ~ the contact half-length 1.5 sqrt(2 R d) = 1.5 mm
    assert indenter_for_scene(s).section_z == 0.0


def test_a_file_indenters_long_triangles_are_split_and_the_gap_is_the_same(tmp_path):
    # a built indenter's mounting stem has triangles 13 mm long against 0.3 mm at the ball: one
    # global candidate radius made every point test nearly every triangle (a solve ran minutes)
    trimesh = pytest.importorskip("trimesh")
    from tactileskin.geometry.indenters.file import _split_long

    ball = trimesh.creation.icosphere(subdivisions=3, radius=2.5)
    stem = trimesh.creation.cylinder(radius=1.0, height=13.0, sections=8)
    stem.apply_translation([0.0, 0.0, 8.0])
    part = trimesh.util.concatenate([ball, stem])
    f = tmp_path / "part.stl"
    part.export(f)
    ind = make_indenter("file", y0=Y0, dim=3, indenter_file=str(f))
    tri = ind.vertices[ind.faces]
    split = _split_long(tri)
    reach = np.max(np.linalg.norm(split - split.mean(axis=1)[:, None, :], axis=2), axis=1)
    assert reach.max() <= 4.0 * np.median(np.max(np.linalg.norm(tri - tri.mean(axis=1)[:, None, :], axis=2), axis=1)) + 1e-12
    assert np.isclose(np.sum(np.linalg.norm(np.cross(split[:, 1] - split[:, 0], split[:, 2] - split[:, 0]), axis=1)),
                      np.sum(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)))  # same area
    # the gap against brute force over the original triangles
    from trimesh.triangles import closest_point

    p = _points(200, 4.0)
    g, _ = ind.gap(p, 0.1)
    q = p + np.array([0.0, 0.1, 0.0])
    brute = np.array([np.min(np.linalg.norm(closest_point(tri, np.repeat(x[None], len(tri), 0)) - x, axis=1))
                      for x in q])
    np.testing.assert_allclose(np.abs(g), brute, atol=1e-9)


def test_a_sphere_is_pressed_within_its_printed_cap():
    # the printed ball is a cap 0.95 R high on a plate (geometry.solids.sphere_indenter): a
    # deeper press would push the plate into the skin (and wrap the model's skin round the ball)
    from tactileskin.array.chart import ChartConfig
    from tactileskin.geometry.indenters.sphere import CAP

    assert CAP == 0.95
    with pytest.raises(ParameterError, match=r"depth=1\.0 .*<= 0\.95 x indenter_radius = 0\.475 mm"):
        Scene(dim=3, indenter="sphere", indenter_radius=0.5, thickness=2.0, depth=1.0)
    with pytest.raises(ParameterError, match="depth"):  # the default 20 % of t = 1 mm
        Scene(dim=3, indenter="sphere", indenter_radius=1.0, thickness=5.0)
    Scene(dim=3, indenter="sphere", indenter_radius=0.5, thickness=2.0, depth=0.47)
    Scene(dim=3, indenter="sphere", indenter_radius=0.5, thickness=2.0, force=0.1)  # the travel is found
    with pytest.raises(ParameterError, match=r"sphere_radius=0\.5 .*>= 1\.05 mm"):
        ChartConfig(thicknesses=(5.0,), sets=("shapes",), sphere_radius=0.5)
    ChartConfig(thicknesses=(5.0,), sets=("shapes",), sphere_radius=0.5, max_depth=0.4)


def test_a_cylinder_pressed_past_its_printed_face_is_flagged():
    # the printed cylinder is a strip one chord wide (min(18, 1.8 R)) under a flat back and, for a
    # small R, a 14 mm mount block, all from the sagitta above its lowest line up
    # (solids.cylinder_indenter); the model's cylinder goes on round. R 2.5 on t = 5 at 3 mm was
    # solved "ok": the face's edges cut 1.3 mm and the mount's flat (1.96 mm up) 0.76 mm into the skin
    s = 2.5 - np.sqrt(2.5 ** 2 - 2.25 ** 2)                 # 1.410: the face's edges at |x| = 2.25
    cap = s + 7.0 - 7.0 * np.sqrt(1.0 - (2.25 / 8.0) ** 2)  # + where the fingertip's top has fallen there
    ind = indenter_for_scene(Scene(indenter="cylinder", indenter_radius=2.5, thickness=5.0))
    assert ind.working_travel(Scene(thickness=5.0).section(), 20.0) == pytest.approx(cap, abs=1e-6)
    # across the finger the chord runs along z, where the top is straight: the sagitta itself
    x = indenter_for_scene(Scene(dim=3, indenter="cylinder", indenter_radius=2.5, indenter_axis="x", thickness=5.0))
    assert x.working_travel(Scene(thickness=5.0).section(), 20.0) == pytest.approx(s, abs=1e-9)
    # a skin that ends within the face never meets its edges: the 16 mm fingertip under an 18 mm
    # face (R 100), an 18 mm pad under the curved; the curved on a 40 mm pad: its sagitta 4.06 mm
    big = indenter_for_scene(Scene(indenter="cylinder", indenter_radius=100.0, thickness=5.0))
    assert big.working_travel(Scene(thickness=5.0).section(), 20.0) == np.inf
    pad18 = Scene(skin="pad", pad_width=18.0, thickness=25.0, indenter="curved")
    assert indenter_for_scene(pad18).working_travel(pad18.section(), pad18.sample_length) == np.inf
    pad40 = Scene(skin="pad", pad_width=40.0, thickness=25.0, indenter="curved")
    assert indenter_for_scene(pad40).working_travel(pad40.section(), pad40.sample_length) == pytest.approx(4.06, abs=0.01)
    # flagged, not refused: a soft skin sinks away from the edges, so a depth past the bound is solved
    # and marked (R 0.5 on a 2 mm pad: sagitta 0.282 mm)
    from tactileskin.api import solve

    deep = solve(Scene(skin="pad", pad_width=10.0, thickness=2.0, indenter="cylinder", indenter_radius=0.5, depth=0.4))
    assert deep.stats["indenter_cap"]["cap_mm"] == pytest.approx(0.5 - np.sqrt(0.25 - 0.45 ** 2), rel=1e-9)
    assert deep.status.startswith("suspect") and "sagitta" in deep.status
    shallow = solve(Scene(skin="pad", pad_width=10.0, thickness=2.0, indenter="cylinder", indenter_radius=0.5,
                          depth=0.25))
    assert "indenter_cap" not in shallow.stats


def test_a_force_past_the_cylinders_face_is_flagged():
    # a force finds its travel in the solve: R 0.5 (0.9 mm face, sagitta 0.282 mm) on a 10 mm pad
    # went 0.61 mm at 0.3 N/mm and read "ok"
    from tactileskin.api import solve

    r = solve(Scene(skin="pad", pad_width=10.0, thickness=2.0, indenter="cylinder", indenter_radius=0.5,
                    force=0.3))
    cap = r.stats["indenter_cap"]
    assert cap["cap_mm"] == pytest.approx(0.5 - np.sqrt(0.25 - 0.45 ** 2), rel=1e-9)
    assert cap["travel_mm"] > 2.0 * cap["cap_mm"]
    assert r.status.startswith("suspect") and "sagitta" in r.status


def test_a_force_past_the_spheres_cap_is_flagged():
    # force control finds the travel only in the solve (measured: R 0.5 on 1 mm silicone at 6x
    # the 0.25 mm reaction went to 0.521 mm, past the 0.475 mm cap, and read "ok")
    from tactileskin import quality

    ball = indenter_for_scene(Scene(dim=3, indenter="sphere", indenter_radius=0.5, thickness=1.0, depth=0.1))
    assert ball.working_depth == pytest.approx(0.475)
    assert indenter_for_scene(Scene(indenter="flat")).working_depth == float("inf")
    normal = {"peak_mpa": 0.1, "reaction_n": 0.3, "contact_points": 10}
    assert quality.flags(normal) == []
    found = quality.flags({**normal, "indenter_cap": {"travel_mm": 0.521, "cap_mm": 0.475}})
    assert [f.code for f in found] == ["indenter_cap"] and "0.521 mm" in found[0].reason


def test_a_contact_past_the_printed_face_is_flagged():
    # the printed cylinder is the arc of chord 1.8 R under a flat back; the model's gap is the
    # whole circle. Measured (preview, elastic polyurethane): R 0.5 on 1 mm at 0.6 mm touched out
    # to x = 0.470 mm (the face ends at 0.45), status ok before 2026-11-27. Plates need no bound:
    # the printed plate covers the skin's width (geometry.parts._covering)
    from tactileskin.fe import solve

    assert indenter_for_scene(Scene(indenter="cylinder", indenter_radius=0.5)).face_halfwidths() == (
        pytest.approx(0.45), float("inf"))
    assert indenter_for_scene(Scene(indenter="flat")).face_halfwidths() == (float("inf"),) * 2
    assert indenter_for_scene(Scene(dim=3, indenter="sphere", indenter_radius=0.5, thickness=1.0,
                                    depth=0.1)).face_halfwidths() == (float("inf"),) * 2
    kw = dict(material="polyurethane", mesh_size=1.0, refinement=5.0, viscoelastic=False)
    deep = solve(Scene(thickness=1, indenter="cylinder", indenter_radius=0.5, depth=0.6, **kw)).summary()
    assert [f["code"] for f in deep["flags"]] == ["indenter_cap"]
    assert deep["indenter_cap"]["contact_mm"] > deep["indenter_cap"]["face_half_mm"] == pytest.approx(0.45)
    assert "0.45 mm" in deep["status"]
    # at 0.4 mm the contact stays on the arc (x <= 0.413 mm), but the travel is past where the face's
    # edges meet the undeformed top (0.28 mm + the fall of the fingertip's top there): flagged by the travel
    mid = solve(Scene(thickness=1, indenter="cylinder", indenter_radius=0.5, depth=0.4, **kw)).summary()
    assert "contact_mm" not in mid["indenter_cap"] and mid["indenter_cap"]["cap_mm"] < 0.4
    assert solve(Scene(thickness=1, indenter="cylinder", indenter_radius=0.5, depth=0.25, **kw)).status == "ok"
    assert solve(Scene(skin="pad", pad_width=40, thickness=2, indenter="flat", depth=0.1, **kw)).status == "ok"


@pytest.mark.parametrize("name", ["tips.stl", "tips"])
def test_an_indenter_file_that_is_a_folder_is_named_a_folder(tmp_path, capsys, name):
    """A folder given as --indenter-file was 'no such file' (named like a file) or 'unsupported
    suffix' (any other name): it exists, it is a folder; the message says so and what to give."""
    from tactileskin.cli import main

    d = tmp_path / name
    d.mkdir()
    with pytest.raises(ParameterError, match=r"indenter_file=.*it is a folder: give the indenter's STL, OBJ, "
                                             r"PLY, OFF or STEP file itself"):
        Scene(dim=3, indenter="file", indenter_file=str(d))
    capsys.readouterr()
    assert main(["solve", "--dim", "3", "--indenter", "file", "--indenter-file", str(d), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "is a folder" in err and "no such file" not in err and "suffix" not in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("name", ["skin.step", "skin"])
def test_a_skin_file_that_is_a_folder_is_named_a_folder(tmp_path, capsys, name):
    from tactileskin.cli import main

    d = tmp_path / name
    d.mkdir()
    assert main(["mesh", "--skin", "file", "--skin-file", str(d)]) == 2
    err = capsys.readouterr().err
    assert "skin_file" in err and "it is a folder: give the skin's .msh or STEP file itself" in err, err


def test_the_sphere_radius_is_bounded_by_its_printed_part(tmp_path, capsys):
    """build -i sphere --indenter-radius 1000 (then inside the (0.1, 1000] mm range) took 327 s and
    wrote a 46 MB STL of a part 2.4 m across: the ball cannot be cut to a strip as the cylinder is
    (its contact grows as sqrt(2 R d) along the finger too), so its radius is bounded by the part
    a printer makes. The cylinder keeps its range."""
    import time

    from tactileskin.cli import main
    with pytest.raises(ParameterError, match=r"indenter_radius=1000.*\(0.1, 100\] mm.*printed"):
        Scene(dim=3, indenter="sphere", indenter_radius=1000.0)
    Scene(dim=3, indenter="sphere", indenter_radius=100.0)
    Scene(dim=3, indenter="cylinder", indenter_radius=1000.0)
    out = tmp_path / "b"
    t0 = time.process_time()  # CPU seconds: the 327 s build, not a loaded machine's wall clock
    assert main(["build", "-i", "sphere", "--indenter-radius", "1000", "-o", str(out)]) == 2
    assert time.process_time() - t0 < 20.0
    err = " ".join(capsys.readouterr().err.split())
    assert "(0.1, 100] mm" in err and "Traceback" not in err, err
    assert not list(out.glob("*.stl")) if out.exists() else True
    from tactileskin.array.chart import ChartConfig

    with pytest.raises(ParameterError, match=r"sphere_radius.*\(0.1, 100\] mm"):
        ChartConfig(sphere_radius=1000.0)
    from tactileskin.geometry.indenters.sphere import MAX_RADIUS

    assert MAX_RADIUS == 100.0


def test_a_file_edited_while_it_is_read_is_not_kept_as_the_old_bytes(tmp_path, monkeypatch):
    """The loaded surface is memoised by (path, SHA-256 of the bytes hashed first), but the
    file was read again to load it: an edit landing between the two (a script rewriting the
    STL while a sweep runs) kept the new surface under the old bytes' digest, so once the file
    was back to those bytes every solve in the process took the other surface, under the key
    of the first."""
    trimesh = pytest.importorskip("trimesh")
    from tactileskin.geometry.indenters import file as file_mod

    f = tmp_path / "ind.stl"
    trimesh.creation.icosphere(subdivisions=2, radius=2.0).export(f)
    old = f.read_bytes()
    trimesh.creation.icosphere(subdivisions=2, radius=2.5).export(tmp_path / "other.stl")
    real, calls = file_mod._read, []

    def edited_meanwhile(path, *a):
        if not calls:
            path.write_bytes((tmp_path / "other.stl").read_bytes())
        calls.append(path)
        return real(path, *a)

    monkeypatch.setattr(file_mod, "_read", edited_meanwhile)
    file_mod._load.cache_clear()
    with pytest.raises(ParameterError, match="indenter_file.*changed while it was read"):
        file_mod.load_surface(f)
    f.write_bytes(old)
    v, _ = file_mod.load_surface(f)
    assert np.ptp(v[:, 0]) == pytest.approx(4.0, rel=0.02)  # the 2 mm ball's, not the 2.5 mm one's
    file_mod._load.cache_clear()


def test_a_half_written_indenter_file_is_called_changed_not_unreadable(tmp_path, monkeypatch):
    """A file being written while it is read fails to parse (truncated) before the digest is
    checked again: the error said 'cannot read it', as for a damaged file, though the file had
    changed meanwhile (its full form reads). It now says it changed while it was read."""
    trimesh = pytest.importorskip("trimesh")
    from tactileskin.geometry.indenters import file as file_mod

    f = tmp_path / "ind.stl"
    trimesh.creation.icosphere(subdivisions=2, radius=2.0).export(f)
    full = f.read_bytes()
    real = file_mod._read

    def half_written(path, *a):
        path.write_bytes(full[: len(full) // 2])  # the writer is half way
        try:
            return real(path, *a)
        finally:
            path.write_bytes(full[: len(full) // 2 + 100])  # and goes on

    monkeypatch.setattr(file_mod, "_read", half_written)
    file_mod._load.cache_clear()
    with pytest.raises(ParameterError, match="indenter_file.*changed while it was read") as e:
        file_mod.load_surface(f)
    assert "cannot read" not in str(e.value)
    monkeypatch.setattr(file_mod, "_read", real)
    f.write_bytes(full)
    assert len(file_mod.load_surface(f)[0]) > 0
