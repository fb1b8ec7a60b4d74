"""The flat pad skin (skins.pad): Scene fields, meshes, and verification against closed forms
(homogeneous plane-strain compression, the bonded-layer bounds, Hertz line contact, the 3D
block against its 2D section) and the sensor frame."""

import numpy as np
import pytest
from scipy.optimize import brentq

from tactileskin.errors import ParameterError
from tactileskin.fe import Contact, Dirichlet, Model, material_law, reaction, run
from tactileskin.fe.output import make_result
from tactileskin.geometry.indenters import indenter_for_scene
from tactileskin.materials import get_material
from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene

LAW = get_material("silicone").law


def _pad(**kw):
    base = dict(skin="pad", pad_width=8.0, pad_length=8.0, thickness=2.0, indenter="flat",
                depth_fraction=0.03, viscoelastic=False, mesh_size=0.5, refinement=1.0)
    return Scene(**{**base, **kw})


def _solve(scene, bcs, mesh=None):
    sm = build_mesh(scene) if mesh is None else mesh
    model = Model(sm.mesh, sm.boundaries, material_law(LAW), bcs,
                  contact=Contact(indenter_for_scene(scene), boundary="outer_surface", rate=scene.rate),
                  order=2, stiffness=max(LAW.K0, LAW.mu0))
    ev, stats = run(model, scene.duration)
    return model, ev, stats


def _top_stretch(model, t):
    X, u = model.basis.doflocs.T, model.u.reshape(-1, model.m)
    top = np.abs(X[:, 1] - t) < 1e-9
    return 1.0 + u[top, 1].mean() / t, np.ptp(u[top, 1])


def _S(lx, ly):
    return LAW.pk2(np.diag([lx ** 2, ly ** 2, 1.0]))[0]


def test_scene_fields_and_errors():
    sc = _pad()
    assert sc.section().top == 2.0 and sc.sample_length == 8.0
    assert sc.label().startswith("pad8x8-t2-")
    assert "skin" not in Scene().to_dict()  # the default skin leaves the paper's keys unchanged
    assert Scene(skin="fingertip").key() == Scene().key()
    assert Scene(skin="pad").pad_width == 20.0  # defaults filled in, so they enter the key
    with pytest.raises(ParameterError, match="pad_width"):
        Scene(skin="pad", pad_width=0.5)
    with pytest.raises(ParameterError, match="pad_width.*only with skin = pad"):
        Scene(pad_width=10.0)
    with pytest.raises(ParameterError, match="skin.*fingertip, pad"):
        Scene(skin="padd")
    with pytest.raises(ParameterError, match="thickness"):
        Scene(skin="pad", thickness=60.0)
    assert sc.replace(skin="fingertip").pad_width is None


def test_mesh_boundaries_2d_and_3d():
    sm = build_mesh(_pad())
    assert set(sm.boundaries) == {"bone_interface", "outer_surface", "symmetry", "side"}
    assert sm.boundary_measure("bone_interface") == pytest.approx(4.0, rel=1e-12)
    assert sm.boundary_measure("side") == pytest.approx(2.0, rel=1e-12)
    assert sm.measure() == pytest.approx(8.0, rel=1e-12)
    s3 = build_mesh(_pad(dim=3, pad_length=2.0))
    assert s3.z_symmetric  # a plate is symmetric about z = 0: the quarter block
    assert s3.measure() == pytest.approx(4.0 * 2.0 * 1.0, rel=1e-12)
    assert s3.boundary_measure("end_front") == pytest.approx(8.0, rel=1e-12)


def test_sliding_pad_is_homogeneous_plane_strain_compression():
    """On a frictionless base under a frictionless plate wider than the pad, the pad deforms
    homogeneously: lambda_z = 1, sigma_x = 0 fixes lambda_x for the measured lambda_y, and the
    force is the law's nominal stress. P2 elements represent the field exactly, so the only
    error is the solver's stopping tests (measured 1e-10 relative)."""
    sc = _pad()
    model, ev, _ = _solve(sc, [Dirichlet("bone_interface", (1,)), Dirichlet("symmetry", (0,))])
    ly, spread = _top_stretch(model, sc.thickness)
    assert spread < 1e-9
    lx = brentq(lambda v: _S(v, ly)[0, 0], 0.9, 1.2)
    force = -_S(lx, ly)[1, 1] * ly * 4.0  # nominal stress x reference half width (N/mm)
    assert float(reaction(model, ev)[1]) == pytest.approx(force, rel=1e-6)
    X, u = model.basis.doflocs.T, model.u.reshape(-1, 2)
    side = np.abs(X[:, 0] - 4.0) < 1e-9
    assert 1.0 + u[side, 0].mean() / 4.0 == pytest.approx(lx, rel=1e-8)


def test_sliding_3d_pad_reports_contact_pressure_per_current_area():
    """The 3D sliding pad compressed 10 % is homogeneous uniaxial compression: the plate's
    pressure per current area is the force over the top face's current area (4 lx x 4 lz on
    the quarter), whatever the contact law. contact.csv read the multiplier per reference area
    in 3D, 10.9 % above it here (lx = lz = 1.053: the top face spreads), while 2D converted it."""
    sc = _pad(dim=3, depth_fraction=0.1, mesh_size=1.0)
    model, ev, stats = _solve(sc, [Dirichlet("bone_interface", (1,)), Dirichlet("symmetry", (0,)),
                                   Dirichlet("end_back", (2,))])
    res = make_result(model, ev, stats, s_of_point=lambda X: X[:, 0])
    X, u = model.basis.doflocs.T, model.u.reshape(-1, 3)
    lx = 1.0 + u[np.abs(X[:, 0] - 4.0) < 1e-9, 0].mean() / 4.0
    lz = 1.0 + u[np.abs(X[:, 2] - 4.0) < 1e-9, 2].mean() / 4.0
    assert lx * lz > 1.09  # the current area is 10.9 % larger than the reference one
    expected = float(reaction(model, ev)[1]) / (4.0 * lx * 4.0 * lz)
    assert len(res.contact_pressure) > 10
    assert np.allclose(res.contact_pressure, expected, rtol=1e-6)


def test_bonded_pad_lies_between_unconfined_and_confined_compression():
    """Bonded to the board, the pad is stiffer than the laterally free layer (sigma_x = 0)
    and softer than the laterally confined one (lambda_x = 1) at the same plate travel: both
    closed forms of the law, strict bounds for any mesh."""
    sc = _pad()
    model, ev, _ = _solve(sc, [Dirichlet("bone_interface", (0, 1)), Dirichlet("symmetry", (0,))])
    ly = 1.0 - sc.indentation / sc.thickness
    lx = brentq(lambda v: _S(v, ly)[0, 0], 0.9, 1.2)
    free, confined = (-_S(v, ly)[1, 1] * ly * 4.0 for v in (lx, 1.0))
    f = float(reaction(model, ev)[1])
    assert 1.5 * free < f < confined  # width / thickness 4: shape-factor stiffening (measured 1.86x)


def test_cylinder_on_thick_pad_matches_hertz_line_contact():
    """R = 5 mm cylinder, 0.05 mm into a 10 mm pad bonded to its board: a/R = 0.075,
    a/t = 0.04, so the half-space Hertz solution (plane strain, E* = E/(1-nu^2) at the law's
    small-strain mu0, K0) holds to ~1 %; with 9 fine cells per half contact (h = 0.04 mm) the
    fit of p^2 gives a -0.2 % and p0 +0.2 %, the largest point pressure +1.4 %. Asserted with
    the 2D block's tolerances (tests/test_fe_contact.py)."""
    R = 5.0
    sc = _pad(pad_width=60.0, thickness=10.0, indenter="cylinder", indenter_radius=R, depth=0.05,
              depth_fraction=0.2, mesh_size=0.8, refinement=20.0)
    from tactileskin.fe import solve

    res = solve(sc)
    mu, K = LAW.mu0, LAW.K0
    nu = (3 * K - 2 * mu) / (2 * (3 * K + mu))
    estar = 2 * mu * (1 + nu) / (1 - nu ** 2)
    P = 2.0 * res.reaction  # the half model carries half the load per mm
    a_h = np.sqrt(4 * R * P / (np.pi * estar))
    p0_h = 2 * P / (np.pi * a_h)
    xc, pc = res.contact_x, res.contact_pressure
    sel = pc > 0.2 * pc.max()
    c0, c1 = np.linalg.lstsq(np.column_stack([np.ones(sel.sum()), xc[sel] ** 2]), pc[sel] ** 2, rcond=None)[0]
    assert np.sqrt(-c0 / c1) == pytest.approx(a_h, rel=0.03)
    assert np.sqrt(c0) == pytest.approx(p0_h, rel=0.03)
    assert pc.max() == pytest.approx(p0_h, rel=0.05)


def test_3d_pad_slice_equals_2d_section():
    """A 3D block with u_z = 0 on both ends is in plane strain: its bonded-surface pressure on
    any z plane and its force per mm equal the 2D section's, on the same in-plane sizes (the
    3D mesh's tetrahedra differ from the 2D triangles, so to the discretisation error)."""
    sc2 = _pad(pad_width=6.0, depth_fraction=0.05, mesh_size=0.4)
    sc3 = sc2.replace(dim=3, pad_length=1.6)
    m2, ev2, st2 = _solve(sc2, [Dirichlet("bone_interface", (0, 1)), Dirichlet("symmetry", (0,))])
    sm3 = build_mesh(sc3)
    m3, ev3, st3 = _solve(sc3, [Dirichlet("bone_interface", (0, 1, 2)), Dirichlet("symmetry", (0,)),
                                Dirichlet("end_back", (2,)), Dirichlet("end_front", (2,))], sm3)
    f2 = float(reaction(m2, ev2)[1])
    f3 = float(reaction(m3, ev3)[1]) / (0.5 * sc3.pad_length)
    # measured +1.4 %: coarse tetrahedra (element-constant pressure) are stiffer than the
    # triangles on this confined layer; the fingertip slab's plate check is within 1-3 % too
    assert f3 == pytest.approx(f2, rel=0.03)
    sec = sc2.section()
    r2 = make_result(m2, ev2, st2, s_of_point=sec.s_of_point)
    r3 = make_result(m3, ev3, st3, s_of_point=sec.s_of_point, plane_z=0.4)
    p3 = np.interp(r2.s, r3.s, r3.pressure)
    inner = r2.s < 2.0  # a thickness away from the free side's corner singularity (x = 3)
    # measured: at most 1.7 % of the peak there (the same tetrahedra-vs-triangles difference)
    assert np.max(np.abs(p3[inner] - r2.pressure[inner])) < 0.03 * np.max(np.abs(r2.pressure))


@pytest.mark.slow
def test_3d_pad_free_ends_cost_a_fixed_force_along_a_z_cylinder():
    """A cylinder along the pad (z) loads it uniformly along its length, so the 2D section is
    the long pad's limit but not a finite block's: its free ends z = +-L/2 carry less. Through
    the solver's own quarter model (fe.solve / model_for_scene: the whole indenter's force),
    with u_z = 0 on the end too the force per mm is the 2D section's (force factor, symmetry
    planes and force integration right); with free ends each end costs a fixed force, so F(L)
    grows by the plane-strain force per mm of added length (benchmarks/results/pad_length.md:
    t = 2, L = 10..80 mm, an end costs 0.71 t of plane-strain pad on two meshes). ~20 s."""
    from tactileskin.fe import indenter_force, model_for_scene, solve

    sc2 = _pad(thickness=1.0, pad_width=6.0, pad_length=6.0, indenter="cylinder", indenter_radius=3.0,
               indenter_axis="z", depth_fraction=0.1, mesh_size=0.6, refinement=2.0)
    f2 = 2.0 * solve(sc2).reaction  # N/mm of the whole section (2D reports the half x >= 0)
    sc3 = sc2.replace(dim=3)
    base, sm = model_for_scene(sc3)
    assert sm.z_symmetric and sm.halved and base.force_factor == 4.0
    m = Model(base.mesh, base.boundaries, base.law, list(base.dirichlet) + [Dirichlet("end_front", (2,))],
              formulation=base.formulation, contact=base.contact, order=sc3.order, stiffness=base.stiffness)
    m.force_factor = base.force_factor
    ev, _ = run(m, sc3.duration)
    f_ps = indenter_force(m, ev) / sc3.pad_length
    # measured +1.4 % (coarse tetrahedra against triangles, as in the slice test above)
    assert f_ps == pytest.approx(f2, rel=0.03)
    F = {L: solve(sc3.replace(pad_length=L)).reaction for L in (6.0, 12.0)}
    # measured 0.764: the free ends matter (each costs 0.71 mm = 0.71 t of plane-strain pad)
    assert F[6.0] / (f_ps * 6.0) < 0.85
    # measured -1.0 % (the ends of the 6 mm pad still see each other a little)
    assert (F[12.0] - F[6.0]) / 6.0 == pytest.approx(f_ps, rel=0.02)


def test_sensors_on_pad_read_depth_along_y_and_the_homogeneous_stress():
    """Sensors at depth d sit at y = t - d with normal +y; in the homogeneous sliding state they
    read the closed-form stress (sigma_nn = sigma_yy, P = -tr/3, no shear) at every depth."""
    from tactileskin import sensors
    from tactileskin.fe import read_sensors

    sc = _pad(sensors=[{"name": "row", "kind": "line", "s": [-3.0, 3.0], "pitch": 1.5, "depth": 0.5},
                       {"name": "deep", "kind": "points", "s": [0.5, 2.0], "height": 0.25, "taxel": 1.0}])
    sites = sensors.sites_for(sc)
    np.testing.assert_allclose(sites.xyz[:5, 1], 1.5)
    np.testing.assert_allclose(sites.xyz[:5, 0], [-3.0, -1.5, 0.0, 1.5, 3.0])
    np.testing.assert_allclose(sites.xyz[5:, 1], 0.25)
    np.testing.assert_allclose(sites.normal, np.tile([0.0, 1.0, 0.0], (7, 1)))
    with pytest.raises(ParameterError, match="s"):
        sc.replace(sensors=[{"name": "x", "kind": "points", "s": [4.5], "depth": 0.5}])
    model, ev, st = _solve(sc, [Dirichlet("bone_interface", (1,)), Dirichlet("symmetry", (0,))])
    res = make_result(model, ev, st, s_of_point=sc.section().s_of_point)
    rd = read_sensors(sc, model, res)
    ly, _ = _top_stretch(model, sc.thickness)
    lx = brentq(lambda v: _S(v, ly)[0, 0], 0.9, 1.2)
    J = lx * ly
    sig = np.array([lx * lx, ly * ly, 1.0]) * np.diag(_S(lx, ly)) / J  # Cauchy, diagonal
    np.testing.assert_allclose(rd.sigma_nn, sig[1], rtol=1e-6)
    np.testing.assert_allclose(rd.pressure, -sig.sum() / 3.0, rtol=1e-6)
    np.testing.assert_allclose(rd.tau_1, 0.0, atol=1e-8 * abs(sig[1]))


def test_pad_parts_and_mold_are_closed_and_the_cavity_is_the_pad(tmp_path):
    """The pad and both mold parts export as closed volumes (trimesh, export.py), and the
    lower part's pocket is exactly the pad: block - pocket + four pins."""
    pytest.importorskip("build123d")
    from tactileskin.geometry.export import export_parts
    from tactileskin.geometry.molds import MoldParams
    from tactileskin.skins import get

    parts = get("pad").build_parts(2.0, pad_width=20.0, pad_length=15.0)
    manifest = export_parts(parts, tmp_path / "out")
    assert [e["name"] for e in manifest["parts"]] == ["skin", "mold_lower", "mold_upper"]
    assert all(e["is_volume"] for e in manifest["parts"])
    assert manifest["parts"][0]["volume_mm3"] == pytest.approx(600.0, rel=1e-6)
    mp = MoldParams.from_params()
    hole = mp.pin_diameter + mp.pin_clearance
    A = 10.0 + mp.wall + hole + mp.pin_flange
    Z = 7.5 + mp.wall
    pins = 4 * np.pi * (0.5 * mp.pin_diameter) ** 2 * mp.pin_height
    lower = (2 * A) * (2.0 + mp.wall) * (2 * Z) - 600.0 + pins
    assert parts[1].shape.volume == pytest.approx(lower, rel=1e-6)
    with pytest.raises(ParameterError, match="pad_width"):
        get("pad").build_parts(2.0, pad_width=0.2, pad_length=15.0)


def test_a_pad_builds_indenters_for_the_pad_as_its_solver_sees_them(tmp_path):
    """`build --skin pad` prints indenters that stand on the pad's top, as long as the pad and,
    for plate faces, as wide: the solver presses the whole 40 x 40 pad with its flat plane, and
    the printed plate was the fingertip's 30 x 20 at y0 = 7 (37.5 % of the pad)."""
    pytest.importorskip("build123d")
    from tactileskin.cli import main

    out = tmp_path / "b"
    assert main(["build", "--skin", "pad", "--pad-width", "40", "--pad-length", "40", "-t", "2", "-i", "all",
                 "--no-molds", "-o", str(out)]) == 0
    import json

    parts = {p["name"]: p for p in json.loads((out / "manifest.json").read_text())["parts"]}
    sc = Scene(skin="pad", pad_width=40.0, pad_length=40.0, thickness=2.0, dim=3)
    for kind in ("flat", "curved", "braille"):
        p = parts[f"indenter_{kind}"]
        solver = indenter_for_scene(sc.replace(indenter=kind))
        # on the pad's top (a dot's tessellated tip sits 0.5 um above it)
        assert p["bbox_min"][1] == pytest.approx(solver.y0, abs=1e-3) and solver.y0 == 2.0
        assert p["bbox_max"][2] - p["bbox_min"][2] == pytest.approx(40.0, abs=1e-6)          # the pad's length
        if kind != "curved":
            assert p["bbox_max"][0] - p["bbox_min"][0] >= 40.0 - 1e-6                       # the pad's width


def test_a_pad_too_small_for_the_mold_names_its_size_and_no_molds():
    """`build --skin pad --pad-width 1`: the message named molds.pour.pour_diameter, a file
    entry the user never set; it names the pad's size, its minimum and --no-molds."""
    from tactileskin.geometry.pad_parts import build_pad_parts

    with pytest.raises(ParameterError, match=r"pad_width=3\.0 is invalid; valid: > 4 mm .*--no-molds"):
        build_pad_parts(2.0, 3.0, 20.0)
    with pytest.raises(ParameterError, match=r"pad_length=2\.0 is invalid; valid: > 4 mm .*--no-molds"):
        build_pad_parts(2.0, 20.0, 2.0)
    assert [p.name for p in build_pad_parts(2.0, 3.0, 2.0, molds=False)] == ["skin"]


def test_a_pad_mold_keeps_its_vents_apart_from_the_sprue():
    """The vents stand vent_inset from the pocket's ends, on the sprue's line: an 8 mm pad's
    vents (z = +-2, 1.5 mm across) opened into the 4 mm sprue, a 5 mm pad's lay inside it,
    and the mold was written with one hole. As the dome's mold: 1 mm of mold between them."""
    from tactileskin.geometry.molds import MoldParams
    from tactileskin.geometry.pad_parts import build_pad_parts

    mp = MoldParams.from_params()
    need = 2.0 * (mp.vent_inset + 0.5 * (mp.pour_diameter + mp.vent_diameter) + 1.0)  # 11.5 mm
    for length in (5.0, 8.0, need - 0.1):
        with pytest.raises(ParameterError, match=r"pad_length=.* >= 11\.5 mm .*vents.*--no-molds"):
            build_pad_parts(2.0, 40.0, length)
    lower, lid = (p.shape for p in build_pad_parts(2.0, 40.0, need)[1:])
    pins = 4 * np.pi * (0.5 * (mp.pin_diameter + mp.pin_clearance)) ** 2 * (mp.pin_height + mp.pin_depth_clearance)
    holes = lid.bounding_box().size.Y * np.pi * 0.25 * (mp.pour_diameter ** 2 + 2 * mp.vent_diameter ** 2)
    box = lid.bounding_box().size
    assert lid.volume == pytest.approx(box.X * box.Y * box.Z - pins - holes, rel=1e-6)  # three separate holes


def test_a_full_width_pad_sees_the_dots_at_x_below_zero():
    # 'e' (dots 1, 5) puts its section's one dot at x = -1.17 mm: the pad models its full width
    # for it, and the dot touches the flat top at once; the contact check sampled only the half
    # x >= 0 and refused a 0.4 mm press on 2 mm ("first touches the skin after 0.48 mm of
    # travel ... the half model (x >= 0) does not see the dots at x < 0")
    from tactileskin.fe import solve
    from tactileskin.geometry.indenters import first_contact_travel, require_contact

    sc = Scene(skin="pad", pad_width=10, thickness=2, indenter="braille", braille_text="e", depth=0.1,
               viscoelastic=False, mesh_size=1.0, refinement=5)
    assert "symmetry" not in build_mesh(sc).boundaries                     # the full width
    assert first_contact_travel(sc) == pytest.approx(0.0, abs=1e-6)
    require_contact(sc.replace(depth=0.4))
    r = solve(sc)
    assert r.peak > 0 and r.reaction > 0 and r.status == "ok"
    # the dot presses where it is: the profile's peak lies under it, at x = -1.17
    assert r.s[np.argmax(r.pressure)] == pytest.approx(-1.17, abs=0.3)


def test_a_slender_pad_pressed_past_its_buckling_strain_is_suspect():
    # t = 10 mm, 2 mm wide under the plate at 20 %: the half model (and a symmetric full one)
    # cannot buckle, and read 'ok'; Euler's strain of a column clamped to the board and guided
    # by the plate is pi^2/12 (2/10)^2 = 3.3 %
    import math

    from tactileskin import quality
    from tactileskin.fe import solve

    tall = Scene(dim=2, skin="pad", indenter="flat", thickness=10.0, pad_width=2.0, mesh_size=0.5, refinement=2)
    assert tall.skin_kind.buckling_strain(tall) == pytest.approx(math.pi ** 2 / 12 * 0.04)
    s = solve(tall).summary()
    assert s["buckling"]["strain"] == pytest.approx(0.2) and "buckles" in s["status"]
    assert [f["code"] for f in s["flags"]] == ["buckling"]
    # 3D: the smaller side decides; a stocky pad (Euler strain 0.21 > 0.2) and a sphere are not judged
    block = Scene(dim=3, skin="pad", indenter="flat", thickness=4.0, pad_width=20.0, pad_length=2.0)
    assert block.skin_kind.buckling_strain(block) == pytest.approx(math.pi ** 2 / 12 * 0.25)
    stocky = Scene(dim=2, skin="pad", indenter="flat", thickness=4.0, pad_width=2.0, mesh_size=0.5, refinement=2)
    assert quality.status(solve(stocky).summary()) == "ok"
    ball = Scene(dim=3, skin="pad", indenter="sphere", indenter_radius=2.5, thickness=10.0, pad_width=2.0)
    assert ball.skin_kind.buckling_strain(ball) is None



def test_a_pad_too_wide_for_the_flat_plate_is_refused_at_once_naming_its_range():
    """--skin pad --pad-width 500 under the default flat plate (a plane over the whole top:
    the compression of a 167 t wide bonded layer is confined and locks up at ~0.08 mm) meshed
    22015 cells at the fine size over the whole top and was still cutting back after 300 s
    (200 mm failed in 62 s CPU, 236 s wall; 100 mm in 43 s CPU). Under the plate the width (and in 3D the
    length) is refused past 100 mm at once; real fingertip and robot pads (up to ~100 mm) and
    a local press on a wide pad (a cylinder on 500 mm solves in 3 s) stay valid."""
    from tactileskin.skins import pad

    for name in ("pad_width", "pad_length"):
        with pytest.raises(ParameterError, match=rf"^{name}=500.0 is invalid; valid: \[1, 100\] mm under the flat "
                                                 r"plate.*cylinder"):
            Scene(skin="pad", dim=3, mesh_size=2.0, **{name: 500.0})
        assert getattr(Scene(skin="pad", dim=3, mesh_size=2.0, **{name: 100.0}), name) == 100.0
    with pytest.raises(ParameterError, match=r"^pad_width=500.0 .*\[1, 100\] mm under the flat plate"):
        Scene(skin="pad", pad_width=500.0)
    assert Scene(skin="pad", pad_length=500.0).pad_length == 500.0  # 2D: the length is not modelled
    assert Scene(skin="pad", pad_width=500.0, indenter="cylinder", indenter_radius=5.0).pad_width == 500.0
    assert pad.SIZE == (1.0, 500.0)


def test_a_confined_pad_under_the_flat_plate_fails_fast_naming_its_width_against_t():
    """--skin pad --pad-width 60 --indenter flat -t 1: the bonded layer, 60 t wide, is confined and
    locks up (Newton fails at 0.045-0.051 of 0.2 mm). After an increment of 1.7e-5 s failed,
    increments were capped below it and crawled 390-870 more tiny steps (15-24 s CPU; the count
    differs between CPUs) before failing: the cap left 13 700 increments to go, past
    max_increments (2000), so the run could never finish.
    It now stops there, and the error names pad_width against t and what solved."""
    from tactileskin.errors import ConvergenceError
    from tactileskin.fe import solve

    seen = []
    with pytest.raises(ConvergenceError, match=r"pad_width = 60 mm = 60 t\).*8 t") as err:
        solve(Scene(skin="pad", pad_width=60.0, thickness=1.0, indenter="flat"), progress=seen.append)
    assert "increments" in str(err.value)
    assert seen and seen[-1].increment < 60  # before: 400-900
    # a pad 8 t wide still solves at 20 % (suspect: the law locks up, flagged)
    r = solve(Scene(skin="pad", pad_width=8.0, thickness=1.0, indenter="flat"))
    assert r.status.startswith("suspect")


def test_the_confined_pad_hint_needs_both_sides_wide_in_3d():
    """In 3D a pad bulges out at its free ends too, so its confinement is set by its shorter
    side (as buckling_strain's): a 5 x 60 x 1 mm strip is no more confined than the 2D 5 t
    section that solved, yet a failure of it said 'pad_length = 60 mm = 60 t ... is confined
    ... use a narrower pad' (it is 5 t wide already). Force-controlled scenes get 'force'."""
    def hint(**kw):
        sc = Scene(skin="pad", thickness=1.0, indenter="flat", **kw)
        return sc.skin_kind.convergence_hint(sc)

    assert hint(dim=3, pad_width=5.0, pad_length=60.0) is None
    assert hint(dim=3, pad_width=60.0, pad_length=5.0) is None
    assert hint(dim=3, pad_width=8.0, pad_length=8.0) is None
    both = hint(dim=3, pad_width=20.0, pad_length=30.0)
    assert "pad_width = 20 mm = 20 t and pad_length = 30 mm = 30 t" in both
    assert "pad_width = 60 mm = 60 t)" in hint(dim=2, pad_width=60.0, pad_length=5.0)  # 2D: plane strain
    assert "a smaller force" in hint(dim=2, pad_width=60.0, force=1.0)
    assert "a smaller depth" in hint(dim=2, pad_width=60.0)
