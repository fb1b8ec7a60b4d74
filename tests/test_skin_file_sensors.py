"""Sensor layouts inside a user's file skin (skins.file.FileCoordinates): s = x - x_top and z of
the contact surface's point, depth along its inward normal there, height along that line from
the bonded surface, the sensor plane along the contact surface there. The pad's own mesh read back as
a file skin reads what the pad reads; the coordinates follow a skin that is not a flat layer; a
sensor outside the skin is refused."""

import numpy as np
import pytest
from test_skin_file import PAD, _gmsh_polygon

from tactileskin import sensors
from tactileskin.errors import ParameterError
from tactileskin.fe import solve
from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene

LAYOUTS = [{"name": "mid", "kind": "line", "s": [-4.0, 4.0], "pitch": [0.5], "depth": 1.0},
           {"name": "bone", "kind": "points", "s": [0.0, 1.0, 3.9], "height": 0.0, "taxel": 0.2},
           {"name": "chip", "kind": "points", "s": [-1.0, 2.5], "height": 0.5, "taxel": 1.0}]


def test_the_pads_mesh_as_a_file_skin_reads_the_pads_sensors(tmp_path):
    """Same mesh, same layouts -> the same sites (exactly: the file's top y = 2 and its facets
    are the pad's) and the same readings to 1e-9 of the largest (the solves agree to 1e-10,
    test_msh_of_the_pad_mesh_solves_like_the_pad; measured 1e-15), in the same sensors.csv
    columns; s < 0 is the mirror half of both (a `symmetry` group)."""
    pad = Scene(**PAD, sensors=LAYOUTS)
    sm = build_mesh(pad)
    path = sm.write(tmp_path / "pad.msh")
    user = Scene(skin="file", skin_file=str(path), indenter="flat", depth_fraction=0.03, viscoelastic=False,
                 sensors=LAYOUTS)
    a, b = sensors.sites_for(pad), sensors.sites_for(user)
    assert b.ids == a.ids and np.array_equal(b.s, a.s)
    for name in ("xyz", "depth", "normal", "t1", "t2", "samples", "weights"):
        assert np.allclose(getattr(b, name), getattr(a, name), rtol=0, atol=1e-12), name
    ra, rb = solve(pad, mesh=sm).sensors, solve(user, mesh=build_mesh(user)).sensors
    assert rb.to_csv().splitlines()[0] == ra.to_csv().splitlines()[0]
    for name in ("pressure", "sigma_nn", "tau_1", "tau_2"):
        va, vb = getattr(ra, name), getattr(rb, name)
        assert np.allclose(vb, va, rtol=0, atol=1e-9 * np.abs(va).max() + 1e-15), name
    assert ra.pressure.max() > 0.01 and np.abs(ra.tau_1).max() > 1e-3  # a press was read


def _tent(tmp_path):
    """A whole 2D skin: its top rises from y = 1.6 at x = +-4 to 2 on the axis; its bonded base
    is y = 0 for x < 0 and y = 0.5 for 0 < x < 3, with a free lip under 3 < x < 4."""
    pts = [(-4, 0), (0, 0), (0, 0.5), (3, 0.5), (4, 0.5), (4, 1.6), (0, 2), (-4, 1.6)]
    return _gmsh_polygon(tmp_path / "tent.msh", pts, {"bonded": [0, 2], "step": [1], "lip": [3],
                                                      "sides": [4, 7], "outer_surface": [5, 6]}, h=0.5)


def test_depth_and_height_follow_the_skin_at_each_x(tmp_path):
    """Depth is measured from the contact surface over the sensor, height from the bonded
    surface, not from the top point's thickness (1.5 here): at s = 2 the top is at y = 1.8 and
    the base at 0.5, at s = -2 at 1.8 and 0; both along the surface's inward normal there (the
    slope is 0.1: it was straight down, 0.5 / sqrt(1.01) = 0.4975 mm from the surface along it);
    a taxel's points follow the surface."""
    path = str(_tent(tmp_path))
    lays = [{"name": "d", "kind": "points", "s": [2.0, -2.0, 3.5], "depth": 0.5},
            {"name": "h", "kind": "points", "s": [2.0, -2.0], "height": 0.25},
            {"name": "deep", "kind": "points", "s": [-2.0], "depth": 1.7},  # deeper than t = 1.5
            {"name": "tx", "kind": "points", "s": [2.0], "depth": 0.5, "taxel": 2.0, "taxel_points": 3}]
    sc = Scene(skin="file", skin_file=path, indenter="flat", sensors=lays)
    assert sc.thickness == pytest.approx(1.5)
    st = sensors.sites_for(sc)
    c = 1.0 / np.sqrt(1.01)  # the normal's y part; its x part is 0.1 c (the slope 0.4 / 4)
    xy = dict(zip(st.ids, st.xyz[:, :2]))
    assert np.allclose([xy["d-0"], xy["d-1"], xy["d-2"]],
                       [[2.0 - 0.05 * c, 1.8 - 0.5 * c], [-2.0 + 0.05 * c, 1.8 - 0.5 * c], [3.5 - 0.05 * c, 1.65 - 0.5 * c]],
                       rtol=0, atol=1e-6)
    # the normal line meets the base y = 0.5 (y = 0) 1.3 / c (1.8 / c) under the surface
    assert np.allclose([xy["h-0"][1], xy["h-1"][1]], [0.5 + 0.25 * c, 0.25 * c], rtol=0, atol=1e-6)
    assert xy["deep-0"][1] == pytest.approx(1.8 - 1.7 * c)
    depth = dict(zip(st.ids, st.depth))
    assert (depth["h-0"], depth["h-1"]) == (pytest.approx(1.3 / c - 0.25), pytest.approx(1.8 / c - 0.25))
    # the sensor plane lies along the contact surface over it (slope 0.4 / 4 down from the axis)
    sign = np.sign(st.s)[:, None]
    assert np.allclose(st.normal, np.column_stack([0.1 * sign, np.ones((7, 1)), np.zeros((7, 1))]) / np.sqrt(1.01),
                       rtol=0, atol=1e-9)
    assert np.allclose(st.t1, np.column_stack([np.ones((7, 1)), -0.1 * sign, np.zeros((7, 1))]) / np.sqrt(1.01),
                       rtol=0, atol=1e-9)
    g = np.polynomial.legendre.leggauss(3)[0]
    i = st.ids.index("tx-0")
    assert np.allclose(st.samples[i, :3, 0], 2.0 + g - 0.05 * c)  # the side along x, then 0.5 along -n
    assert np.allclose(st.samples[i, :3, 1], 2.0 - 0.1 * (2.0 + g) - 0.5 * c)  # 0.5 under the slope


@pytest.mark.parametrize("layout,match", [
    # along the normal (slope 0.1) the skin is 1.3 sqrt(1.01) = 1.30648 mm thick at s = 2 (1.3 vertically)
    ({"s": [2.0], "depth": 1.4}, r"'x' depth=1.4 .*\[0, 1.30648\] mm at s = 2 mm.*sensor x-0"),
    ({"s": [-2.0], "depth": -0.1}, r"'x' depth=-0.1 .*\[0, 1.80898\] mm at s = -2 mm"),      # above the surface
    ({"s": [0.0, 2.0], "height": 1.4}, r"'x' height=1.4 .*\[0, 1.30648\] mm at s = 2 mm.*sensor x-1"),
    ({"s": [-2.0], "height": -0.2}, r"'x' height=-0.2 .*\[0, 1.80898\] mm"),                 # below the bonded face
    ({"s": [3.5], "height": 0.2}, r"'x' height=0.2 .*a depth instead.*sensor x-0: at s = 3.5 mm.*not bonded"),
    ({"s": [1.0, 4.5], "depth": 0.5}, r"'x' s=4.5 .*s in \[-4, 4\] mm.*sensor x-1: no skin under it"),
    ({"s": [3.8], "depth": 0.5, "taxel": 1.0}, r"'x' s \+- taxel/2=4.3 .*sensor x-0 \(taxel edge at s = 4.3 mm\)"),
])
def test_a_sensor_outside_a_file_skin_names_the_layout_and_the_sensor(tmp_path, layout, match):
    with pytest.raises(ParameterError, match=match):
        Scene(skin="file", skin_file=str(_tent(tmp_path)), indenter="flat", sensors=[{"name": "x", **layout}])


def test_a_file_skins_sensors_enter_the_cache_key_and_its_path_does_not(tmp_path):
    import shutil

    from tactileskin.cache import cache_key

    path = _tent(tmp_path)
    lay = {"name": "d", "kind": "points", "s": [2.0], "depth": 0.5}
    keys = {cache_key(Scene(skin="file", skin_file=str(path), indenter="flat", sensors=s))
            for s in ([], [lay], [{**lay, "depth": 0.6}], [{**lay, "height": 0.5, "depth": None}])}
    assert len(keys) == 4
    moved = shutil.copy(path, tmp_path / "moved.msh")
    assert (cache_key(Scene(skin="file", skin_file=str(moved), indenter="flat", sensors=[lay]))
            == cache_key(Scene(skin="file", skin_file=str(path), indenter="flat", sensors=[lay])))


def test_the_cli_refuses_a_sensor_outside_a_file_skin_in_one_line(tmp_path, capsys):
    from tactileskin.cli import main

    (tmp_path / "s.toml").write_text('[[sensors]]\nname = "deep"\ns = [2.0]\ndepth = 1.4\n')
    rc = main(["solve", "--skin-file", str(_tent(tmp_path)), "-i", "flat", "--sensors", str(tmp_path / "s.toml"),
               "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "Traceback" not in err and len(err.splitlines()) == 1, err
    assert "sensor layout 'deep' depth=1.4" in err and "deep-0" in err
    assert not (tmp_path / "o").exists()


LAYOUTS_3D = [{"name": "mid", "kind": "line", "s": [-1.0, 1.0], "pitch": [0.5], "depth": 0.5},
              {"name": "g", "kind": "grid", "s": [-1.0, 1.0], "z": [-1.0, 1.0], "pitch": [1.0], "height": 0.5,
               "taxel": 0.5, "taxel_points": 3},
              {"name": "p", "kind": "points", "s": [0.0, 0.5], "z": [-0.5, 1.0], "height": 0.0}]


def test_the_3d_quarter_pads_mesh_as_a_file_skin_reads_the_pads_sensors(tmp_path):
    """The z-symmetric quarter of the 3D pad written as .msh: the same sites (z < 0 and s < 0
    read by reflection in both) and the same readings to 1e-9 of the largest (the solves
    agree to 1e-8 of the reaction, test_3d_quarter_pad_written_as_msh_solves_like_the_pad;
    measured 1e-13)."""
    kw = dict(indenter="sphere", indenter_radius=2.5, depth=0.2, viscoelastic=False, sensors=LAYOUTS_3D)
    pad = Scene(skin="pad", pad_width=6.0, pad_length=6.0, thickness=2.0, dim=3, mesh_size=1.0, refinement=3.0, **kw)
    sm = build_mesh(pad)
    user = Scene(skin="file", skin_file=str(sm.write(tmp_path / "quarter.msh")), **kw)
    a, b = sensors.sites_for(pad), sensors.sites_for(user)
    for name in ("xyz", "depth", "normal", "t1", "t2", "samples", "weights"):
        assert np.allclose(getattr(b, name), getattr(a, name), rtol=0, atol=1e-12), name
    ra, rb = solve(pad, mesh=sm).sensors, solve(user, mesh=build_mesh(user)).sensors
    for name in ("pressure", "sigma_nn", "tau_1", "tau_2"):
        va, vb = getattr(ra, name), getattr(rb, name)
        assert np.allclose(vb, va, rtol=0, atol=1e-9 * np.abs(va).max()), name
    assert np.abs(ra.tau_2).max() > 1e-3  # off the plane z = 0 the shear along z is read


def test_a_step_block_reads_the_sensors_of_the_3d_pad(tmp_path):
    """A STEP block 4 x 2 x 4 mm (a full model: its analysis mesh's facets give the heights)
    has the pad's sites exactly, and under a flat plate reads what the built-in pad of that
    size (its quarter) reads, to 5 % of the largest |sigma_nn|: different tetrahedral meshes
    (h = 0.5: reactions 3.5e-4 apart), whose point stresses carry the element's O(h^2) error
    (measured up to 2.7 %, at the bonded point 1 mm from the base's edge; the largest pressure
    difference on an 8 mm block was 11.4 % at h = 1 and 2.7 % at h = 0.5)."""
    import build123d as bd

    path = tmp_path / "block.step"
    bd.export_step(bd.Box(4.0, 2.0, 4.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER)), str(path))
    kw = dict(indenter="flat", depth_fraction=0.03, viscoelastic=False, mesh_size=0.5, refinement=1.0,
              sensors=LAYOUTS_3D)
    user = Scene(skin="file", skin_file=str(path), **kw)
    pad = Scene(skin="pad", pad_width=4.0, pad_length=4.0, thickness=2.0, dim=3, **kw)
    a, b = sensors.sites_for(pad), sensors.sites_for(user)
    for name in ("xyz", "depth", "normal", "t1", "t2", "samples", "weights"):
        assert np.allclose(getattr(b, name), getattr(a, name), rtol=0, atol=1e-9), name
    ra, rb = solve(pad).sensors, solve(user).sensors
    assert rb.to_csv().splitlines()[0] == ra.to_csv().splitlines()[0]
    tol = 0.05 * np.abs(ra.sigma_nn).max()
    for name in ("pressure", "sigma_nn", "tau_1", "tau_2"):
        assert np.allclose(getattr(rb, name), getattr(ra, name), rtol=0, atol=tol), name
    assert np.ptp(ra.pressure) > 2 * tol  # the readings vary by more than the tolerance


def _cap(tmp_path):
    """A sphere cap (R 6, 2 mm over a flat base 8 x 8 mm) as STEP, and its top y(x, z)."""
    import build123d as bd

    path = tmp_path / "cap.step"
    base = bd.Box(8.0, 2.0, 8.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    bd.export_step(bd.Pos(0, -4.0, 0) * bd.Sphere(6.0) & base, str(path))
    return path, lambda x, z: -4.0 + np.sqrt(36.0 - np.square(x) - np.square(z))


def test_a_curved_step_skins_sensors_follow_its_surface(tmp_path):
    """On a sphere cap a grid at depth 0 lies on the cap's CAD surface (within 1e-8 mm); it lay
    on the coarse analysis mesh's chords, 0.006-0.039 mm under it (size / 8 = 1 mm facets)."""
    path, top = _cap(tmp_path)
    lay = {"name": "c", "kind": "grid", "s": [-3.0, 3.0], "z": [-3.0, 3.0], "pitch": [1.0], "depth": 0.0}
    x, y, z = sensors.sites_for(Scene(skin="file", skin_file=str(path), sensors=[lay])).xyz.T
    assert np.abs(top(x, z) - y).max() < 1e-8


def test_a_step_skins_sensors_are_checked_on_its_cad_faces(tmp_path):
    """The scene checks a STEP skin's sensors on its CAD faces, not on the coarse analysis
    mesh's chords. Under the sphere cap's top the chords lay 0.0285 mm low at (1.3, 1.7): a
    sensor 0.002 mm under the surface (then height 1.6034 mm, vertical) was refused ("valid:
    [0, 1.57683] mm"). Over the half tube's R 6 bonded face the chords lay low (t 2.2258 for
    2.2200 mm vertically at s = 3): a sensor 0.005 mm under the bone was held and refused only
    after meshing. Both along the surface's normal now (the tube's radial: t = 2)."""
    import build123d as bd

    path, top = _cap(tmp_path)
    ny = (top(1.3, 1.7) + 4.0) / 6.0  # the cap's normal there (its centre is (0, -4, 0)): y part
    h = top(1.3, 1.7) / ny - 0.002  # the normal line meets the flat bonded face y = 0 top / ny in
    lay = {"name": "hi", "kind": "points", "s": [1.3], "z": [1.7], "height": h}
    y = sensors.sites_for(Scene(skin="file", skin_file=str(path), sensors=[lay])).xyz[0, 1]
    # 0.002 along the normal under the surface (the line's direction is the central difference's,
    # to ~1e-9 on the CAD: y to 1e-8, not the 1e-9 of a vertical line that had no direction to err)
    assert abs(y - (top(1.3, 1.7) - 0.002 * ny)) < 1e-8

    tube = bd.Cylinder(8, 8) - bd.Cylinder(6, 8)
    shell = tmp_path / "shell.step"
    bd.export_step(tube - bd.Box(20, 10, 20, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER)), str(shell))
    t = 2.0  # along the normal (radial); 2.22005 mm vertically at s = 3
    kw = dict(skin="file", skin_file=str(shell), skin_bonded="normal:-y:89.99")
    for d, ok in ((t, True), (t + 0.005, False)):
        lay = {"name": "deep", "kind": "points", "s": [3.0], "z": [0.5], "depth": d}
        if ok:
            xy = sensors.sites_for(Scene(sensors=[lay], **kw)).xyz[0, :2]
            # on R 6, 2 mm along the normal, whose central difference over 1.6e-3 mm errs by
            # ~(1.6e-3 / 8)^2 / 6 = 7e-9 (the vertical line's 1e-8 had no direction to err)
            assert np.abs(xy - np.array([3.0, np.sqrt(55.0)]) * 6.0 / 8.0).max() < 5e-8
        else:
            with pytest.raises(ParameterError, match=r"depth=2\.005.*valid: \[0, 2\] mm at s = 3, z = 0\.5"):
                Scene(sensors=[lay], **kw)


def _distance_to_polyline(points, poly):
    a, b = poly[:-1], poly[1:]
    ab = b - a
    out = []
    for p in points:
        u = np.clip(np.sum((p - a) * ab, axis=1) / np.sum(ab * ab, axis=1), 0.0, 1.0)
        out.append(np.min(np.linalg.norm(a + u[:, None] * ab - p, axis=1)))
    return np.array(out)


def test_sensors_on_a_curved_p2_msh_lie_on_its_curved_faces(tmp_path):
    """The fingertip's own P2 mesh (curved faces) read back as a file skin: sensors on its bone
    (height 0) and its surface (depth 0) lie on the mesh's quadratic faces, within 3e-5 mm of the
    fingertip's analytic curves. On the straight chords between the nodes they were 4.8e-3 and
    9.5e-3 mm off, the bone's inside the bone: the solve ran and then failed reading them
    ("sample point ... inside the meshed skin")."""
    ft = Scene(skin="fingertip", thickness=3.0, indenter="flat", depth_fraction=0.05, viscoelastic=False,
               mesh_size=0.8, refinement=2.0)
    lays = [{"name": "bone", "kind": "line", "s": [-4.5, 4.5], "pitch": [0.25], "height": 0.0},
            {"name": "top", "kind": "line", "s": [-7.0, 7.0], "pitch": [0.25], "depth": 0.0}]
    user = Scene(skin="file", skin_file=str(build_mesh(ft).write(tmp_path / "ft.msh")), indenter="flat",
                 depth_fraction=0.05, viscoelastic=False, sensors=lays)
    st = sensors.sites_for(user)
    sec = ft.section()
    xy = np.abs(st.xyz[:, :2])  # the analytic half x >= 0
    on_bone = np.array([n == "bone" for n in st.layout])
    assert _distance_to_polyline(xy[on_bone], sec.point_at_s(np.linspace(0, sec.interface_length, 20001))).max() < 3e-5
    assert _distance_to_polyline(xy[~on_bone], sec.outer_points(20001)).max() < 3e-5
    res = solve(user)
    assert res.sensors.pressure.size == on_bone.size and np.abs(res.sensors.sigma_nn).max() > 0


def test_sensors_on_a_curved_3d_p2_msh_lie_on_its_curved_faces(tmp_path):
    """The dome's P2 mesh (an elliptic cylinder a = 8, b = 7 over its bone a = 6, b = 5 for
    z < 0) as a file skin: grids on its surface (depth 0) and bone (height 0) lie on the mesh's
    quadratic faces, 2.0e-4 / 4.8e-4 mm off the analytic ellipses on these h = 2 cells (their
    quadratic interpolation). On the straight chords they were 0.063 / 0.051 mm off and the
    solve failed reading them ("sample point ... inside the meshed skin")."""
    dome = Scene(skin="dome", thickness=2.0, mesh_size=2.0, refinement=1.0, indenter="flat", depth_fraction=0.05,
                 viscoelastic=False)
    lays = [{"name": "top", "kind": "grid", "s": [0.0, 4.0], "z": [-6.0, -1.0], "pitch": [1.0], "depth": 0.0},
            {"name": "bone", "kind": "grid", "s": [0.0, 3.0], "z": [-6.0, -1.0], "pitch": [1.0], "height": 0.0}]
    user = Scene(skin="file", skin_file=str(build_mesh(dome).write(tmp_path / "dome.msh")), indenter="flat",
                 depth_fraction=0.05, viscoelastic=False, sensors=lays)
    st = sensors.sites_for(user)
    th = np.linspace(0.0, np.pi / 2, 20001)
    on_bone = np.array([n == "bone" for n in st.layout])
    for pick, (a, b) in ((~on_bone, (8.0, 7.0)), (on_bone, (6.0, 5.0))):
        ellipse = np.column_stack([a * np.cos(th), b * np.sin(th)])
        assert _distance_to_polyline(st.xyz[pick, :2], ellipse).max() < 1e-3
    assert solve(user).sensors.pressure.size == on_bone.size


def test_a_step_skins_sensors_are_read_on_its_solved_curved_faces(tmp_path):
    """A half tube (outer R 8, inner R 6, bonded on the inner face) from STEP: its scene's sites
    lie on the coarse analysis mesh's chords, a bone line (height 0) 0.011-0.077 mm inside the
    bone; the solve ran and then failed reading it ("sample point ... inside the meshed skin").
    The sensors are now placed on the solved mesh's faces, curved onto the CAD (within 2e-4 mm
    of R 6 and R 8 on these h = 2 cells) and checked before the solve."""
    import build123d as bd

    tube = bd.Cylinder(8, 8) - bd.Cylinder(6, 8)
    path = tmp_path / "shell.step"
    bd.export_step(tube - bd.Box(20, 10, 20, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER)), str(path))
    lays = [{"name": "bone", "kind": "line", "s": [-4.0, 4.0], "pitch": [0.5], "z": [0.0], "height": 0.0},
            {"name": "top", "kind": "line", "s": [-5.0, 5.0], "pitch": [0.5], "z": [1.0], "depth": 0.0}]
    sc = Scene(skin="file", skin_file=str(path), skin_bonded="normal:-y:89.99", sensors=lays, indenter="sphere",
               indenter_radius=3.0, depth=0.1, viscoelastic=False, mesh_size=2.0, refinement=1.0)
    on_bone = np.array([n == "bone" for n in sensors.sites_for(sc).layout])
    read = solve(sc).sensors
    r = np.hypot(read.xyz[:, 0], read.xyz[:, 1])
    assert np.abs(r[on_bone] - 6.0).max() < 2e-4 and np.abs(r[~on_bone] - 8.0).max() < 2e-4
    assert np.abs(read.sigma_nn).max() > 0
    # each sensor's plane lies along the R 8 surface over s, the tube's along z (2.6e-4 off it
    # on these h = 2 quadratic faces; it was horizontal, 30 degrees off at s = 4): its normal is
    # radial, through the sensor, which lies on that normal line
    n = np.column_stack([read.xyz[:, :2] / r[:, None], np.zeros_like(r)])
    assert np.abs(read.normal - n).max() < 1e-3


def _half_tube(path, R=8.0, r=6.0, h=0.5):
    """A whole 2D half tube (outer R, inner r, y >= 0) bonded on its inner arc, P2 (curved)."""
    import gmsh

    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        c = occ.addPoint(0, 0, 0)
        p = [occ.addPoint(x, 0, 0) for x in (R, r, -r, -R)]
        top, mid = occ.addPoint(0, R, 0), occ.addPoint(0, r, 0)
        ends = [occ.addLine(p[1], p[0]), occ.addLine(p[3], p[2])]
        outer = [occ.addCircleArc(p[0], c, top), occ.addCircleArc(top, c, p[3])]
        inner = [occ.addCircleArc(p[2], c, mid), occ.addCircleArc(mid, c, p[1])]
        occ.addPlaneSurface([occ.addCurveLoop([ends[0], *outer, ends[1], *inner])])
        occ.synchronize()
        for name, lines in (("bonded", inner), ("outer_surface", outer), ("ends", ends)):
            gmsh.model.addPhysicalGroup(1, lines, name=name)
        gmsh.model.addPhysicalGroup(2, [1], name="skin")
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(2)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def test_sensors_under_a_slope_lie_along_the_surface_and_read_across_it(tmp_path):
    """A sensor lies on the contact surface's normal line and its plane lies along that surface
    (normal: the surface's over s, t1 along it in the x-y plane), as a chip
    embedded under a slope does. On a half tube (R 8, t 2) under a flat plate the sensors 0.5 mm
    under the 30 and 45 degree slopes, on the free surface beside the contact, read the traction
    across that plane: ~0 (measured 0.5 and 0.06 % of the peak sigma_nn, -0.37 MPa at the top).
    With the plane horizontal (normal +y) they read sigma_yy, -0.011 and -0.014 MPa, 3.1 and 3.8 %
    of that peak, a pressure where none acts (at 10 degrees, under the contact, 3.8 % of the
    reading). The normals are the circle's to 1.6e-6 on these P2 faces (h = 0.5)."""
    path = _half_tube(tmp_path / "tube.msh")
    ang = np.radians([0.0, 10.0, 20.0, 30.0, 45.0])
    lays = [{"name": "s", "kind": "points", "s": (8.0 * np.sin(ang)).tolist(), "depth": 0.5},
            {"name": "b", "kind": "points", "s": [-3.0, 2.0], "height": 0.0}]
    sc = Scene(skin="file", skin_file=str(path), indenter="flat", depth=0.5, viscoelastic=False, sensors=lays)
    st = sensors.sites_for(sc)
    x = st.s  # the surface point's x: the sensor lies on its normal line
    n = np.column_stack([x, np.sqrt(64.0 - x ** 2), np.zeros_like(x)]) / 8.0  # the circle's over x
    assert np.allclose(st.normal, n, rtol=0, atol=1e-5)
    assert np.allclose(st.t1, np.column_stack([n[:, 1], -n[:, 0], np.zeros_like(x)]), rtol=0, atol=1e-5)
    assert np.allclose(st.t2, [0.0, 0.0, 1.0])
    read = solve(sc).sensors.select("s")
    peak = np.abs(read.sigma_nn).max()
    assert peak > 0.1 and np.abs(read.sigma_nn[3:]).max() < 0.01 * peak


def test_a_taxel_under_a_slope_is_warned_of(tmp_path, caplog):
    """A taxel keeps its side along x while its plane follows the surface: under the half
    tube's 38.7 degree slope (x = 5) it averages side / cos = 1.28 sides of the surface, said
    once (in whole degrees, and 1 / cos of them); under 7 degrees (x = 1, +0.8 %) nothing is said."""
    import logging

    path = str(_half_tube(tmp_path / "tube.msh"))
    lay = {"name": "tx", "kind": "points", "s": [1.0, 5.0], "depth": 0.5, "taxel": 1.0}
    with caplog.at_level(logging.WARNING, logger="tactileskin.sensors"):
        Scene(skin="file", skin_file=path, indenter="flat", sensors=[lay])
        Scene(skin="file", skin_file=path, indenter="flat", sensors=[lay])
        Scene(skin="file", skin_file=path, indenter="flat", sensors=[{**lay, "name": "flat", "s": [1.0]}])
    said = [r.getMessage() for r in caplog.records if "slope" in r.getMessage()]
    assert said == ["sensor layout 'tx': sensor tx-1 lies under a 39 degree slope; its taxel's side is along x, "
                    "so it averages 29 % more of the surface than its side"]


def test_a_taxel_layout_reads_each_point_of_its_lines_once(tmp_path, monkeypatch):
    """Placing a layout on its normal lines read each surface point twice (depths, then frame)
    and its top once more per slope direction, and a flat top's vertical line its one column 16
    times: each read a few CAD queries on a STEP (the half tube's 273-sensor grid with taxels
    0.4: 0.43 s before the normal lines, 3.1 s after). Two taxels (3 points each, 2D) under the
    half tube's slope and a sensor on its flat top took 284 + 25 reads; now each line reads its
    top, its 2 slope points and its EXIT_SAMPLES samples (the flat top's: one column), and every
    point lies where it did: 0.5 along the radial of R 8 from the surface point over its s."""
    from tactileskin.skins.file_coordinates import EXIT_SAMPLES, FileCoordinates

    path = _half_tube(tmp_path / "tube.msh")
    lays = [{"name": "tx", "kind": "points", "s": [1.0, 5.0], "depth": 0.5, "taxel": 1.0, "taxel_points": 3},
            {"name": "top", "kind": "points", "s": [0.0], "depth": 0.5}]
    scenes = [Scene(skin="file", skin_file=str(path), indenter="flat", sensors=[lay]) for lay in lays]
    sensors.coordinates_for(scenes[0]).__dict__.pop("_surface_memo", None)  # the scenes' checks' answer
    reads, column = [], FileCoordinates.column
    monkeypatch.setattr(FileCoordinates, "column", lambda self, s, z=None: reads.append(np.size(s)) or column(self, s, z))
    st = sensors.sites_for(scenes[0])
    lines = 2 * (2 + 1 + 3)  # each taxel's edges, centre and Gauss points
    assert sum(reads) == lines * (3 + EXIT_SAMPLES)
    reads.clear()
    top = sensors.sites_for(scenes[1]).xyz[0]
    assert sum(reads) == 3 + 1
    g = np.polynomial.legendre.leggauss(3)[0]
    s = np.concatenate([[1.0, 5.0], (np.array([1.0, 5.0])[:, None] + 0.5 * g).ravel()])
    xy = np.concatenate([st.xyz[:2, :2], st.samples[:2, :3, :2].reshape(-1, 2)])
    # on the P2 faces (R 8 to ~1e-6 at h = 0.5): r = 7.5 on the ray through (s, top(s))
    assert np.abs(np.hypot(*xy.T) - 7.5).max() < 2e-6 and np.abs(xy[:, 0] * 8.0 / 7.5 - s).max() < 1e-5
    assert top[0] == 0.0 and abs(top[1] - 7.5) < 2e-6


def test_the_solve_places_in_its_mesh_what_the_scene_held(tmp_path):
    """The solve places the sensors the scene held on the STEP's CAD in the mesh solved, moved
    at most as far as that mesh's faces lie off the CAD, and refuses what the scene refuses in
    the scene's words. A sensor 0.002 mm under the cap passed the scene and was refused on a P1
    mesh (h = 1: its chords 0.0168 mm low there, "valid: [0, 1.58851] mm", vertically) after
    meshing. Heights are along the cap's normal (1.71838 mm to the base there)."""
    path, top = _cap(tmp_path)
    sc = Scene(skin="file", skin_file=str(path), order=1, formulation="displacement", mesh_size=1.0,
               refinement=1.0, indenter="flat", depth_fraction=0.03, viscoelastic=False)
    coords = sc.skin_kind.mesh_coordinates(sc, build_mesh(sc))
    chord = coords.column([1.3], [1.7])["top"][0]
    assert 0.01 < top(1.3, 1.7) - chord < 0.05  # the P1 mesh's chords under the cap there
    reach = top(1.3, 1.7) * 6.0 / (top(1.3, 1.7) + 4.0)  # along the cap's normal to the face y = 0
    lay = {"name": "hi", "kind": "points", "s": [1.3], "z": [1.7], "height": reach - 0.002}
    y = sensors.resolve(sensors.layouts([lay]), coords, 3).xyz[0, 1]
    assert y == pytest.approx(chord, abs=1e-9)  # on the mesh's top face: 0.0148 mm down
    out = {**lay, "height": reach + 0.001}
    with pytest.raises(ParameterError) as scene:
        Scene(skin="file", skin_file=str(path), sensors=[out])
    with pytest.raises(ParameterError) as solve_time:
        sensors.resolve(sensors.layouts([out]), coords, 3)
    assert str(solve_time.value) == str(scene.value) and "valid: [0, 1.71838] mm" in str(scene.value)


def test_a_line_inside_a_curved_rim_reads_the_top_and_the_bonded_face_not_the_wall(tmp_path, capsys):
    """A disc (R 5, 2 mm thick, y in [-2, 0], bonded on its bottom): inside its rim the coarse
    analysis mesh's wall chords lean (|n_y| 0.02-0.03) and a vertical line crossed them where it
    missed the top and bottom chords. At r = 4.99 the scene read 27 of the 28 lines it held
    0.05-0.59 mm thick, not bonded (one 0.308: top -0.731, floor -1.040), and placed a depth-0.2
    sensor there at y = -0.93, inside the CAD's skin but not 0.2 under its top. Now such a line is read on the CAD faces beside the wall: 2 mm, as the CAD says,
    or no skin (refused) where no face is crossed; a sensor outside the disc is one line."""
    import build123d as bd

    from tactileskin.cli import main

    path = tmp_path / "disc.step"
    bd.export_step(bd.Cylinder(5.0, 2.0, rotation=(90, 0, 0), align=(bd.Align.CENTER, bd.Align.CENTER,
                                                                      bd.Align.MIN)), str(path))
    coords = sensors.coordinates_for(Scene(skin="file", skin_file=str(path), indenter="flat"))
    ang = np.linspace(0.0, 0.5 * np.pi, 31)
    col = coords.column(4.99 * np.cos(ang), 4.99 * np.sin(ang))
    held = np.isfinite(col["top"])
    assert held.sum() >= 20  # 28: the lines crossing a chord (the coarse mesh's; a line in no chord is refused)
    assert np.allclose(col["top"][held], 0.0, atol=1e-9) and np.allclose(col["floor"][held], -2.0, atol=1e-9)
    assert col["bonded"][held].all()
    at = {"s": [4.92856], "z": [0.780608]}  # r = 4.99: crossed two wall chords only
    for key, y in (("depth", -0.2), ("height", -1.8)):
        lay = {"name": "rim", "kind": "points", **at, key: 0.2}
        xyz = sensors.sites_for(Scene(skin="file", skin_file=str(path), indenter="flat", sensors=[lay])).xyz
        assert xyz[0, 1] == pytest.approx(y, abs=1e-9)
    (tmp_path / "s.toml").write_text('[[sensors]]\nname = "out"\ns = [4.97]\nz = [0.79]\ndepth = 0.2\n')  # r 5.03
    rc = main(["solve", "--skin-file", str(path), "-i", "flat", "--sensors", str(tmp_path / "s.toml"),
               "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "Traceback" not in err and len(err.splitlines()) == 1, err
    assert "sensor layout 'out'" in err and "no skin under it" in err and not (tmp_path / "o").exists()


def _disc(tmp_path):
    """A disc (R 5, 2 mm thick, y in [-2, 0], bonded on its bottom) as STEP."""
    import build123d as bd

    path = tmp_path / "disc.step"
    bd.export_step(bd.Cylinder(5.0, 2.0, rotation=(90, 0, 0), align=(bd.Align.CENTER, bd.Align.CENTER,
                                                                      bd.Align.MIN)), str(path))
    return path


def test_a_coarse_p1_solve_places_the_rim_sensors_the_scene_held(tmp_path):
    """On a P1 solve mesh (h = 2) of the disc the rim's straight wall chords lean: at r = 4.95 a
    vertical line crossed them under the top face, and a depth-0.2 sensor the scene placed at y =
    -0.2 (the CAD's) was put up to 0.48 mm deeper (128 of 181 such lines; 4 of these 7, 0.37 mm);
    at r = 4.98 a line crossed no face at all and the sensor the scene held was refused ("no skin
    under it"). The walls' chords are no top now, and a sensor past the mesh's rim moves onto it
    (0.036-0.065 mm here, at most a quarter of the rim's edge): each reads 0.2 under the top, near
    where it was put."""
    path = _disc(tmp_path)
    ang = np.linspace(0.0, 0.5 * np.pi, 7)
    lays = [{"name": f"r{k}", "kind": "points", "s": (r * np.cos(ang)).tolist(), "z": (r * np.sin(ang)).tolist(),
             "depth": 0.2} for k, r in enumerate((4.95, 4.98))]
    sc = Scene(skin="file", skin_file=str(path), indenter="flat", order=1, formulation="displacement",
               mesh_size=2.0, refinement=1.0, sensors=lays)
    held = sensors.sites_for(sc)  # the scene's check on the CAD
    assert np.allclose(held.xyz[:, 1], -0.2, rtol=0, atol=1e-9)
    st = sensors.sites_for(sc, coords=sc.skin_kind.mesh_coordinates(sc, build_mesh(sc)))
    assert np.allclose(st.xyz[:, 1], -0.2, rtol=0, atol=1e-9)
    assert np.allclose(st.normal, [0.0, 1.0, 0.0], rtol=0, atol=1e-9)
    moved = np.hypot(*(st.xyz - held.xyz)[:, [0, 2]].T)
    assert 0.0 < moved.max() < 0.1  # the rim's sagitta on these 2 mm chords is 0.1 mm


def test_a_sensor_just_past_the_meshed_rim_is_refused_with_the_remedy(tmp_path, capsys):
    """The scene reads a STEP's heights on the CAD faces its analysis mesh's chords find: a line
    at r = 4.999 of the disc's R 5 crosses none of them (it ends 0.01 mm inside the rim there) and
    was refused as "no skin under it", nothing said of how far the skin is. The one line now
    says where the nearest skin is and how far."""
    from tactileskin.cli import main

    (tmp_path / "s.toml").write_text(f'[[sensors]]\nname = "rim"\ns = [{4.999 * np.cos(0.3)}]\n'
                                     f'z = [{4.999 * np.sin(0.3)}]\ndepth = 0.2\n')
    rc = main(["solve", "--skin-file", str(_disc(tmp_path)), "-i", "flat", "--sensors", str(tmp_path / "s.toml"),
               "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "Traceback" not in err and len(err.splitlines()) == 1, err
    assert "no skin under it; the nearest skin is 0.00" in err and "mm away (at s = 4.76" in err, err
    assert "move the sensor in by that" in err and not (tmp_path / "o").exists()


def test_a_depth_under_a_slope_is_along_the_surface_normal(tmp_path):
    """A file skin's depth was vertical, the fingertip's along the surface normal: a depth-0.5
    sensor under the half tube's 45 degree slope lay 0.354 mm from the surface along its normal
    (0.346 from the R 8 circle), and sensors.csv's normal_depth_mm said so. The sensor now lies
    0.5 mm along the inward normal from the surface point over s, on the P2 .msh (its faces are
    R 8 to ~1e-6 mm at h = 0.5) and on a STEP's CAD faces (to 1e-6), in the scene's sites and on
    the solved (P2, h = 2) mesh's; normal_depth_mm = depth_mm."""
    import build123d as bd

    s45 = 8.0 * np.sin(np.pi / 4)
    path = _half_tube(tmp_path / "tube.msh")
    lay = {"name": "s", "kind": "points", "s": [0.0, s45], "depth": 0.5}
    st = sensors.sites_for(Scene(skin="file", skin_file=str(path), indenter="flat", sensors=[lay]))
    assert np.abs(8.0 - np.hypot(*st.xyz[:, :2].T) - 0.5).max() < 2e-6
    assert abs(st.xyz[1, 0] - st.xyz[1, 1]) < 1e-6  # on the 45 degree ray: along the normal
    rows = [r.split(",") for r in sensors.readings_from_stress(st, np.zeros((2, 3, 3))).to_csv().splitlines()]
    assert rows[0][-1] == "normal_depth_mm" and [float(r[-1]) for r in rows[1:]] == [0.5, 0.5]

    tube = bd.Cylinder(8, 8) - bd.Cylinder(6, 8)
    shell = tmp_path / "shell.step"
    bd.export_step(tube - bd.Box(20, 10, 20, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER)), str(shell))
    lays = [{"name": "d", "kind": "points", "s": [0.0, s45, 7.0], "z": [0.5], "depth": 0.5},
            {"name": "h", "kind": "points", "s": [s45], "z": [0.5], "height": 0.5}]
    sc = Scene(skin="file", skin_file=str(shell), skin_bonded="normal:-y:89.99", indenter="sphere",
               indenter_radius=3.0, mesh_size=2.0, refinement=1.0, sensors=lays)
    for st in (sensors.sites_for(sc), sensors.sites_for(sc, coords=sc.skin_kind.mesh_coordinates(sc, build_mesh(sc)))):
        r = np.hypot(*st.xyz[:, :2].T)
        # 0.5 under R 8 (the height 0.5 over the R 6 bone on the same normal line: 1.5 deep)
        assert np.abs(r - [7.5, 7.5, 7.5, 6.5]).max() < 1e-4
        assert np.abs(st.xyz[:, 0] / r - st.normal[:, 0]).max() < 1e-4 and np.abs(st.xyz[:, 2] - 0.5).max() < 1e-4
    assert np.abs(np.hypot(*sensors.sites_for(sc).xyz[:, :2].T) - [7.5, 7.5, 7.5, 6.5]).max() < 1e-6


def test_a_too_deep_sensor_under_a_slope_is_refused_in_one_line(tmp_path, capsys):
    """Under the half tube's 45 degree slope the skin is 2 mm thick along the normal but 3.66
    mm vertically: a depth 2.1 was held (vertical, 1.49 mm from the surface). Along the normal it is refused
    in one line naming the layout, the sensor and the largest depth there (2 mm)."""
    from tactileskin.cli import main

    path = _half_tube(tmp_path / "tube.msh")
    s45 = 8.0 * np.sin(np.pi / 4)
    st = sensors.sites_for(Scene(skin="file", skin_file=str(path), indenter="flat",
                                 sensors=[{"name": "ok", "s": [s45], "depth": 1.9}]))
    assert 8.0 - np.hypot(*st.xyz[0, :2]) == pytest.approx(1.9, abs=2e-6)
    (tmp_path / "s.toml").write_text(f'[[sensors]]\nname = "deep"\ns = [{s45}]\ndepth = 2.1\n')
    rc = main(["solve", "--skin-file", str(path), "-i", "flat", "--sensors", str(tmp_path / "s.toml"),
               "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "Traceback" not in err and len(err.splitlines()) == 1, err
    assert "sensor layout 'deep' depth=2.1" in err and "[0, 2] mm at s = 5.65685 mm" in err, err
    assert "(sensor deep-0)" in err and not (tmp_path / "o").exists()


def test_a_flat_file_skins_sensors_are_unchanged_to_the_bit(tmp_path):
    """On a flat top (normal +y) a depth along the normal is the vertical one: the pad's 3D
    block as STEP places a grid at depth 0.7 and a height-0.3 line exactly where the vertical
    columns did (x_top + s, top - depth, z), bit for bit."""
    import build123d as bd

    path = tmp_path / "block.step"
    bd.export_step(bd.Box(4.0, 2.0, 4.0, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER)), str(path))
    lays = [{"name": "g", "kind": "grid", "s": [-1.5, 1.5], "z": [-1.3, 1.3], "pitch": [0.5, 0.65], "depth": 0.7},
            {"name": "h", "kind": "line", "s": [-1.0, 1.0], "pitch": [0.25], "z": [0.4], "height": 0.3}]
    st = sensors.sites_for(Scene(skin="file", skin_file=str(path), indenter="flat", sensors=lays))
    g = np.array([n == "g" for n in st.layout])
    S, Z = np.meshgrid(-1.5 + 0.5 * np.arange(7), -1.3 + 0.65 * np.arange(5))
    assert np.array_equal(st.xyz[g], np.column_stack([S.ravel(), np.full(35, 0.0 - 0.7), Z.ravel()]))
    assert np.array_equal(st.xyz[~g], np.column_stack([-1.0 + 0.25 * np.arange(9), np.full(9, 0.0 - (2.0 - 0.3)),
                                                       np.full(9, 0.4)]))
    assert np.array_equal(st.normal, np.tile([0.0, 1.0, 0.0], (44, 1))) and np.array_equal(st.normal_depth, st.depth)


def test_a_sensor_at_a_step_between_two_top_faces_hangs_from_the_face_not_the_wall(tmp_path):
    """A top of two faces (y = 2 for x < 1, y = 1.5 past a vertical step at x = 1): the surface
    normal's central difference over 1e-4 of the size straddled the step within 8e-4 mm of it
    and read the wall's jump as a slope of 312 (normal (1, 0.0032)), so a depth-0.5 sensor at s
    = 1 (a round grid point) went 0.5 mm sideways under the upper face, 0.0016 mm below the
    surface, and a height 1e-4 mm past it was refused ('leaves the skin through a face that is
    not bonded'; at s = 1 itself the line is the higher face's: test_a_sensor_on_a_steps_edge_...).
    A one-sided difference steeper than a wall is the step, not the surface: the
    other side's is taken, and the sensor hangs straight down from the face it is on."""
    pts = [(-4, 0), (4, 0), (4, 1.5), (1, 1.5), (1, 2.0), (-4, 2.0)]
    path = _gmsh_polygon(tmp_path / "step.msh", pts, {"bonded": [0], "sides": [1, 5], "outer_surface": [2, 3, 4]})
    lays = [{"name": "d", "kind": "points", "s": [1.0, 1.0001, 0.9999], "depth": 0.5},
            {"name": "h", "kind": "points", "s": [0.9999, 1.0001], "height": 0.5}]
    st = sensors.sites_for(Scene(skin="file", skin_file=str(path), indenter="flat", sensors=lays))
    assert np.allclose(st.normal, [0.0, 1.0, 0.0], rtol=0, atol=1e-12)
    assert np.allclose(st.xyz[:, :2], [[1.0, 1.5], [1.0001, 1.0], [0.9999, 1.5], [0.9999, 0.5], [1.0001, 0.5]],
                       rtol=0, atol=1e-9)
    assert np.allclose(st.depth, [0.5, 0.5, 0.5, 1.5, 1.0], rtol=0, atol=1e-9)


def _shell_step(tmp_path):
    """The half tube (outer R 8, inner R 6, 8 mm long along z, y >= 0) as STEP."""
    import build123d as bd

    tube = bd.Cylinder(8, 8) - bd.Cylinder(6, 8)
    path = tmp_path / "shell.step"
    bd.export_step(tube - bd.Box(20, 10, 20, align=(bd.Align.CENTER, bd.Align.MAX, bd.Align.CENTER)), str(path))
    return path


def test_a_step_taxel_layout_imports_the_step_once_a_pass_and_asks_gmsh_only_near_a_faces_edge(tmp_path,
                                                                                                   monkeypatch):
    """Placing taxels on the half tube's STEP read each column batch on a fresh import of the
    STEP (~10-20 ms each: 44 for the 273-taxel grid at a height) and asked gmsh's isInside
    (~30 us a point) of every CAD point found, 74 % of the time. Now one import serves each
    depths() pass (3: centres, taxel points, edges) and a point well inside the polygon of its
    face's boundary in (u, v) is inside without asking; the sensors lie where they did: 0.5 over
    the R 6 bone on its radial."""
    import gmsh

    from tactileskin.mesh import skinfile

    coords = sensors.coordinates_for(Scene(skin="file", skin_file=str(_shell_step(tmp_path)),
                                           skin_bonded="normal:-y:89.99"))
    lay = {"name": "tx", "kind": "points", "s": [1.0, 5.0], "z": [0.5], "height": 0.5, "taxel": 0.4}
    imports, asked = [], []
    real_import, real_inside = skinfile._import_step, gmsh.model.isInside
    monkeypatch.setattr(skinfile, "_import_step", lambda g, p: imports.append(p) or real_import(g, p))
    monkeypatch.setattr(gmsh.model, "isInside", lambda dim, tag, coord, parametric=False:
                        asked.append(len(coord) // 2) or real_inside(dim, tag, coord, parametric=parametric))
    st = sensors.resolve(sensors.layouts([lay]), coords, 3)
    assert len(imports) == 3 and sum(asked) == 0, (len(imports), sum(asked))
    r = np.hypot(*st.xyz[:, :2].T)
    # (z: the normal's central difference has a ~1e-9 z part, 1.5 mm along it)
    assert np.abs(r - 6.5).max() < 1e-6 and np.abs(st.xyz[:, 2] - 0.5).max() < 1e-8
    assert np.abs(st.normal[:, :2] - st.xyz[:, :2] / r[:, None]).max() < 1e-6


def test_a_point_surely_inside_a_faces_domain_is_inside_for_gmsh(tmp_path):
    """The shortcut for gmsh's isInside (mesh.skinfile._surely_inside) never says inside where
    gmsh says out: 500 random (u, v) over each face's parameter box of the half tube (straight
    boundaries in (u, v)), the sphere cap (its curved ones: the sagittas' margin) and the disc
    (a cylinder face whose seam is not among its boundary curves: no polygon, every point asked);
    and it answers for most of the points inside."""
    from tactileskin.mesh import _gmsh, skinfile

    rng = np.random.default_rng(0)
    sure_in = 0
    for path in (_shell_step(tmp_path), _cap(tmp_path)[0], _disc(tmp_path)):
        with _gmsh.session("test", {}) as g:
            skinfile._import_step(g, path)
            for _, f in g.model.getEntities(2):
                lo, hi = g.model.getParametrizationBounds(2, f)
                uv = rng.uniform(lo, hi, (500, 2))
                sure = skinfile._surely_inside(skinfile._face_domain(g, f), uv)
                gm = np.array([g.model.isInside(2, f, p, parametric=True) > 0 for p in uv])
                assert not np.any(sure & ~gm), (path.name, f)
                sure_in += sure.sum()
                if path.name == "shell.step" and g.model.getType(2, f) == "Cylinder":
                    assert sure.mean() > 0.99  # the (u, v) box is the face
    assert sure_in > 4000  # of the 7500 points (5116)


def test_a_sensor_on_a_steps_edge_hangs_from_the_higher_face(tmp_path):
    """On the edge of a step between two top faces (y = 2 for x < 1, 1.5 past the wall at x = 1)
    the vertical line slides down the wall from the higher face's edge and touches the lower
    face's edge (y = 1.5) while still in the skin; that edge was read as the line's floor: a
    height 0.5 at s = 1 was refused ("leaves the skin through a face that is not bonded") and a
    depth 1 held to 0.5 ("valid: [0, 0.5] mm"), while the depth layout hangs it from the higher
    face (its top is y = 2 there). It is the higher face's line now, as 1e-4 mm on that side:
    height 0.5 at y = 0.5 (depth 1.5), depth 1 at y = 1; in 2D (.msh) and 3D (STEP, the same
    step 4 mm along z)."""
    import build123d as bd

    pts = [(-4, 0), (4, 0), (4, 1.5), (1, 1.5), (1, 2.0), (-4, 2.0)]
    msh = _gmsh_polygon(tmp_path / "step.msh", pts, {"bonded": [0], "sides": [1, 5], "outer_surface": [2, 3, 4]})
    step = tmp_path / "step.step"
    box = lambda x, w, h: bd.Pos(x, 0, 0) * bd.Box(w, h, 4, align=(bd.Align.CENTER, bd.Align.MIN,  # noqa: E731
                                                                    bd.Align.CENTER))
    bd.export_step(box(-1.5, 5, 2) + box(2.5, 3, 1.5), str(step))
    for path, z in ((msh, {}), (step, {"z": [0.3]})):
        lays = [{"name": "h", "kind": "points", "s": [1.0, 0.9999], "height": 0.5, **z},
                {"name": "d", "kind": "points", "s": [1.0], "depth": 1.0, **z}]
        st = sensors.sites_for(Scene(skin="file", skin_file=str(path), indenter="flat", sensors=lays))
        assert np.allclose(st.xyz[:, :2], [[1.0, 0.5], [0.9999, 0.5], [1.0, 1.0]], rtol=0, atol=1e-9), path.name
        assert np.allclose(st.depth, [1.5, 1.5, 1.0], rtol=0, atol=1e-9)
        assert np.allclose(st.normal[:, :2], [0.0, 1.0], rtol=0, atol=1e-12)


def test_the_inside_shortcut_is_not_taken_on_a_face_bounded_by_a_spline(tmp_path):
    """_face_domain samples each boundary curve at 33 parameters and takes the polygon through
    them, 4 x its chords' sagitta inside, as surely inside the trimmed face. A B-spline edge can
    hide its shape between those samples: a wavy edge y = 1 + 0.1 sin(2 pi 16 x / 10) (its
    samples all on y = 1: read as a straight line, margin 1e-5) or a notch narrower than their
    spacing; points in its troughs, outside the face for gmsh, were said inside (a sensor on a
    surface that is not there). Only analytic curves (lines, circles, ellipses) on analytic
    faces, whose (u, v) curves the samples follow, make the polygon; a face bounded by any
    other is asked of gmsh, as before."""
    import build123d as bd

    from tactileskin.mesh import _gmsh, skinfile

    wave = lambda x: 1.0 + 0.1 * np.sin(2 * np.pi * 16 * x / 10)  # noqa: E731
    sp = bd.Spline(*[bd.Vector(x, wave(x)) for x in np.linspace(0, 10, 321)])
    face = bd.make_face([sp, bd.Line(sp @ 1, (10, -2)), bd.Line((10, -2), (0, -2)), bd.Line((0, -2), sp @ 0)])
    path = tmp_path / "wavy.step"
    bd.export_step(bd.extrude(face, 2), str(path))
    x = np.linspace(0.0, 10.0, 2001)
    x = x[wave(x) < 0.95]  # the troughs, at y = 0.96: outside the face
    xyz = np.column_stack([x, np.full(len(x), 0.96), np.zeros(len(x))])
    with _gmsh.session("test", {}) as g:
        skinfile._import_step(g, path)
        f = next(f for _, f in g.model.getEntities(2) if np.allclose(np.array(g.model.getBoundingBox(2, f))[[2, 5]], 0))
        uv = np.array(g.model.getParametrization(2, f, xyz.ravel())).reshape(-1, 2)
        out = np.array([g.model.isInside(2, f, p, parametric=True) <= 0 for p in uv])
        assert out.all()  # the premise: gmsh says they are off the face
        sure = skinfile._surely_inside(skinfile._face_domain(g, f), uv)
    assert not np.any(sure & out), int(np.sum(sure & out))


def test_an_error_inside_an_open_step_import_is_not_called_gmsh_s(tmp_path):
    """A placement pass holds its STEP import open in one gmsh session (skinfile.step_open): an
    error of the block's own (a bug, a MemoryError) came out as 'MeshError: gmsh failed to mesh
    skinstep-columns'; it is raised as it is now, and gmsh's own errors still become MeshError."""
    from tactileskin.errors import MeshError
    from tactileskin.geometry.occ import bd
    from tactileskin.mesh import skinfile

    path = tmp_path / "block.step"
    bd.export_step(bd.Box(4, 2, 4), str(path))
    with pytest.raises(KeyError, match="x"):
        with skinfile.step_open(path):
            raise KeyError("x")
    with pytest.raises(MeshError, match="skinstep-columns"):
        with skinfile.step_open(path):
            raise Exception("as gmsh's API raises")  # noqa: TRY002
    with skinfile.step_open(path):  # the import is closed after each: a new one opens
        pass


def test_a_sensor_just_inside_a_curved_rim_hangs_from_the_face_it_is_under(tmp_path):
    """A 12 x 12 x 2 mm pad with an R 3 cap 0.8 mm high (its rim r = 2.04 mm) as STEP. Within
    ~0.1 mm inside the rim the vertical line crossed the coarse mesh's flat-top chords (their
    polygon lies inside the rim), missed that face's trimmed CAD and kept the chord's height:
    the top read 2.0 for the cap's 2.036-2.080 and the normal +y for a 40-43 degree slope, so a
    sensor at depth 1 and s = 2 lay at x = 2 where the normal puts it at x = 1.33. Points now
    read the cap's CAD there, as elsewhere on it."""
    import build123d as bd

    pad = bd.Box(12.0, 2.0, 12.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    cap = bd.Pos(0, -0.2, 0) * bd.Sphere(3.0) & bd.Pos(0, 2.0, 0) * bd.Box(
        20.0, 20.0, 20.0, align=(bd.Align.CENTER, bd.Align.MIN, bd.Align.CENTER))
    path = tmp_path / "domepad.step"
    bd.export_step(pad + cap, str(path))
    r = np.array([1.95, 2.0, 2.03])
    a = np.radians([0.0, 20.0, 30.0])
    x, z = (np.outer(r, np.cos(a)).ravel(), np.outer(r, np.sin(a)).ravel())
    for depth in (0.0, 1.0):
        lays = [{"name": f"p{i}", "kind": "points", "s": [float(xi)], "z": [float(zi)], "depth": depth}
                for i, (xi, zi) in enumerate(zip(x, z))]
        xyz = sensors.sites_for(Scene(skin="file", skin_file=str(path), sensors=lays)).xyz
        surf = np.column_stack([x, -0.2 + np.sqrt(9.0 - x**2 - z**2), z])
        n = (surf - np.array([0.0, -0.2, 0.0])) / 3.0  # the cap's outward normal
        assert np.abs(xyz - (surf - depth * n)).max() < 1e-6
