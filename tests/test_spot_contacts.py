"""3D indenters that touch in spots (a ball, a file's low pieces, Braille dots) are meshed by the
local plan at those spots (Indenter.contact_patches, mesh.sizing.local_plan)."""

import math

import numpy as np
import pytest

from tactileskin.geometry.indenters import indenter_symmetry, make_indenter
from tactileskin.mesh import sizing
from tactileskin.scene import Scene, default_mesh

Y0 = 7.0
trimesh = pytest.importorskip("trimesh")


def _stl(tmp_path, name, *meshes):
    f = tmp_path / name
    trimesh.util.concatenate(list(meshes)).export(f)
    return str(f)


def test_the_sphere_spot_is_its_chord_at_the_depth():
    ind = make_indenter("sphere", y0=Y0, dim=3, indenter_radius=2.5)
    assert ind.contact_patches(0.0) == ((0.0, 0.0, 0.0),)
    (x, z, a), = ind.contact_patches(0.2)
    assert (x, z) == (0.0, 0.0) and a == pytest.approx(math.sqrt(2 * 2.5 * 0.2 - 0.04))
    assert ind.contact_patches(9.0)[0][2] == 2.5  # past the equator: the ball's radius


def test_a_file_ball_has_the_analytic_spot_and_two_balls_have_two(tmp_path):
    ball = trimesh.creation.icosphere(subdivisions=5, radius=2.5)
    one = make_indenter("file", y0=Y0, dim=3, indenter_file=_stl(tmp_path, "b.stl", ball))
    (x, z, a), = one.contact_patches(0.2)
    # the cut through the facets is within the chordal deviation (~1e-3 mm at 10k faces)
    assert abs(x) < 0.01 and abs(z) < 0.01 and a == pytest.approx(math.sqrt(2 * 2.5 * 0.2 - 0.04), abs=0.01)
    other = ball.copy()
    other.apply_translation((0.0, 0.0, 6.0))
    two = make_indenter("file", y0=Y0, dim=3, indenter_file=_stl(tmp_path, "b2.stl", ball, other))
    got = sorted(two.contact_patches(0.2), key=lambda s: s[1])
    assert [round(s[1], 2) for s in got] == [0.0, 6.0]
    # a ball raised 0.1 mm is not reached by 0.05 mm of travel, and is by 0.2 mm
    other.apply_translation((0.0, 0.1, 0.0))
    step = make_indenter("file", y0=Y0, dim=3, indenter_file=_stl(tmp_path, "b3.stl", ball, other))
    assert len(step.contact_patches(0.05)) == 1 and len(step.contact_patches(0.2)) == 2


def test_a_file_is_symmetric_where_it_can_touch(tmp_path):
    # a ball with an off-centre block 10 mm above it: the block never reaches the skin
    ball = trimesh.creation.icosphere(subdivisions=3, radius=2.5)
    block = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    block.apply_translation((1.5, 10.0, 0.8))
    f = _stl(tmp_path, "stem.stl", ball, block)
    ind = make_indenter("file", y0=Y0, dim=3, indenter_file=f)
    assert ind.symmetry() == (False, False) and ind.symmetry(0.2) == (True, True)
    assert indenter_symmetry(Scene(thickness=1.0, dim=3, indenter="file", indenter_file=f)) == (True, True)


def test_a_sphere_gets_the_local_plan_and_its_preset():
    kw = {"indenter": "sphere", "indenter_radius": 2.5}
    sc = Scene(thickness=1.0, dim=3, **kw)
    assert (sc.mesh_size, sc.refinement) == default_mesh(3, "braille", 1.0)
    sec = sc.section()
    p = sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True)
    (x, y, z, r, h), = p.patches
    a = math.sqrt(2 * 2.5 * sc.indentation - sc.indentation ** 2)
    # the spot is wider than a dot (base radius 0.72 mm): its size grows as the square root
    assert (x, z) == (0.0, 0.0) and r == pytest.approx(sizing.PATCH_RADIUS * a)
    assert h == pytest.approx(p.fine * math.sqrt(a / 0.72)) and p.strip == 0.0
    (xb, yb, zb, rb, hb), = p.bone_patches
    assert yb == pytest.approx(y - 1.0) and rb == pytest.approx(a + 1.0)
    # a skin without the local plan keeps the strip preset, also when a scene moves to it
    dome = Scene(thickness=2.0, dim=3, skin="dome", **kw)
    assert (dome.mesh_size, dome.refinement) == default_mesh(3, "flat")
    moved = Scene(thickness=2.0, dim=3, **kw).replace(skin="dome")
    assert (moved.mesh_size, moved.refinement) == default_mesh(3, "flat")


def test_a_sphere_reads_the_same_on_the_quarter_and_the_whole_slab():
    """The strip plan read the t = 1 R 2.5 sphere 0.0689 MPa on the quarter and 0.0613 on the
    whole slab at `preview` (12 %: a one-sided bone fit at z = 0 against a smoothing two-sided
    one, both on 0.43 mm cells), so a file indenter that is not mirror-symmetric read 12 % low.
    On the local plan the two read 0.0701 / 0.0681 at this level, 0.0708 / 0.0703 at 0.8 / 8
    (the whole slab converges from below to the quarter's limit, 0.0707): 4 % holds the
    recovery's coarse-level difference and catches the strip plan's."""
    from tactileskin.fe import solve
    from tactileskin.mesh.slab3d import build_slab_mesh

    sc = Scene(thickness=1.0, dim=3, indenter="sphere", indenter_radius=2.5, mesh_size=1.6, refinement=8.0)
    quarter = solve(sc, build_slab_mesh(sc))
    whole = solve(sc, build_slab_mesh(sc, use_z_symmetry=False))
    assert quarter.stats["dofs"] < 0.7 * whole.stats["dofs"]
    assert quarter.peak == pytest.approx(whole.peak, rel=0.04)


def test_a_flat_file_face_is_one_wide_spot_at_half_the_far_size(tmp_path):
    # a 20 x 20 mm plate: one spot as wide as its face; scaled as a dot it would be coarser than
    # the far size, so it keeps the strip plan's ratio 2 (solved: 0.2987 MPa at t = 1 against the
    # analytic flat plate's 0.3015)
    f = _stl(tmp_path, "plate.stl", trimesh.creation.box(extents=(20.0, 2.0, 20.0)))
    sc = Scene(thickness=1.0, dim=3, indenter="file", indenter_file=f)
    sec = sc.section()
    p = sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True)
    (x, y, z, r, h), = p.patches
    assert r == pytest.approx(sizing.PATCH_RADIUS * 10.0 * math.sqrt(2.0), rel=1e-6)
    assert h == pytest.approx(0.5 * sc.mesh_size)
    # a user's refinement below 2 is kept, not overridden
    q = sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True,
                    mesh_size=1.0, refinement=1.5)
    assert q.patches[0][4] == pytest.approx(1.0 / 1.5)


def test_a_file_ball_moved_along_the_finger_reads_its_own_plane_and_the_same_force(tmp_path):
    """A ball moved 2 mm along z is the same physics on the straight-along-z finger. The
    profile was read on z = 0, beside the contact (0.00048 MPa against 0.0673 at z = 2, status
    ok), and the force was the modelled part's (quarter 0.0418 N, half 0.0834 N): now the
    profile runs through the map's peak and the force is the whole indenter's. The whole slab
    reads the peak lower than the quarter at this level (2.9 %, the test above): 4 %."""
    from tactileskin.fe import solve

    ball = trimesh.creation.icosphere(subdivisions=4, radius=2.5)
    centred = _stl(tmp_path, "c.stl", ball)
    ball.apply_translation((0.0, 0.0, 2.0))
    moved = _stl(tmp_path, "m.stl", ball)
    kw = dict(thickness=1.0, dim=3, indenter="file", mesh_size=1.6, refinement=8.0)
    a = solve(Scene(indenter_file=centred, **kw))
    b = solve(Scene(indenter_file=moved, **kw))
    assert b.stats["dofs"] > 1.5 * a.stats["dofs"]                    # a half, not a quarter
    assert a.stats["profile_plane_z"] == 0.0 and b.stats["profile_plane_z"] == pytest.approx(2.0, abs=0.1)
    assert b.reaction == pytest.approx(a.reaction, rel=0.01)
    assert b.peak == pytest.approx(a.peak, rel=0.04)
    assert a.status == b.status == "ok"


def test_an_x_asymmetric_file_is_flagged_and_a_ball_past_the_slab_end_refused(tmp_path):
    from tactileskin import quality
    from tactileskin.errors import ParameterError
    from tactileskin.geometry.indenters import mirrored_x

    ball = trimesh.creation.icosphere(subdivisions=3, radius=2.5)
    ball.apply_translation((0.3, 0.0, 0.0))
    off = Scene(thickness=1.0, dim=3, indenter="file", indenter_file=_stl(tmp_path, "x.stl", ball))
    assert mirrored_x(off) and not mirrored_x(Scene(thickness=1.0, dim=3, indenter="sphere", indenter_radius=2.5))
    found = quality.flags({"peak_mpa": 0.08, "reaction_n": 0.1, "mirrored_x": True})
    assert [f.code for f in found] == ["mirrored_x"] and quality.status_of(found).startswith("suspect")
    from tactileskin.fe import solve

    r = solve(off.replace(mesh_size=1.6, refinement=8.0))
    assert r.summary()["mirrored_x"] and [f["code"] for f in r.summary()["flags"]] == ["mirrored_x"]
    # the ball at z = 12 lies past the 20 mm slab's end (z = 10): refused before meshing (it
    # was meshed at 570k dofs and solved for 110 s to "no contact")
    ball.apply_translation((-0.3, 0.0, 12.0))
    far = Scene(thickness=1.0, dim=3, indenter="file", indenter_file=_stl(tmp_path, "z.stl", ball))
    from tactileskin.geometry.indenters import require_contact

    with pytest.raises(ParameterError, match="no contact"):
        require_contact(far)


def test_a_ring_is_covered_by_spots_of_its_half_width(tmp_path):
    # a torus lying flat (major radius 2, tube 0.8): the surface below 0.2 mm is an annulus
    # 2 +- 0.55 mm; one spot around its centre (radius 2.55, sized as such) read the ring 7.9 %
    # low at preview; spots of the annulus' half-width follow the tube instead
    ring = trimesh.creation.torus(major_radius=2.0, minor_radius=0.8, major_sections=96, minor_sections=32)
    ring.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0]))
    from tactileskin.geometry.indenters.file import _cover

    ind = make_indenter("file", y0=Y0, dim=3, indenter_file=_stl(tmp_path, "ring.stl", ring))
    spots = ind.contact_patches(0.2)
    assert len(spots) > 4
    width = 2 * math.sqrt(2 * 0.8 * 0.2 - 0.04)                     # the annulus, 1.10 mm
    assert all(a <= 0.6 * width for _, _, a in spots)               # the tube's chord
    assert all(abs(math.hypot(x, z) - 2.0) < 0.5 * width for x, z, _ in spots)
    # the spots cover every vertex of the ring below the cut
    p = ind.vertices[ind.vertices[:, 1] <= Y0 + 0.2][:, [0, 2]]
    d = np.min([np.hypot(p[:, 0] - x, p[:, 1] - z) - a for x, z, a in spots], axis=0)
    assert len(p) > 100 and np.all(d <= 1e-9)
    # a filled piece (a plate, whose bottom is two triangles) stays one spot
    sq = np.array([[[-1, -1], [1, -1], [1, 1]], [[-1, -1], [1, 1], [-1, 1]]], float)
    assert len(_cover(np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float), sq)) == 1



def test_a_bump_past_the_slab_end_does_not_hide_one_inside_and_a_point_spot_is_meshed(tmp_path):
    from tactileskin.geometry.indenters import first_contact_travel

    far = trimesh.creation.icosphere(subdivisions=3, radius=2.5)
    far.apply_translation((0.0, 0.0, 12.0))
    near = trimesh.creation.icosphere(subdivisions=3, radius=2.5)
    near.apply_translation((0.0, 0.05, 0.0))
    sc = Scene(thickness=1.0, dim=3, indenter="file", indenter_file=_stl(tmp_path, "two.stl", far, near))
    # the lowest ball lies past the slab's end (z = 10); the one inside touches after 0.05 mm
    assert first_contact_travel(sc) == pytest.approx(0.05, abs=1e-4)
    # a piece whose tip sits exactly at y0 + depth is a spot of radius 0: planned, not a crash
    assert sizing.bone_scale(1.0, 0.0) == sizing.BONE_SCALE_MAX
    sec = sc.section()
    p = sizing.local_plan(sc, sec, 1.6, 8.0, length=20.0, z_symmetric=False,
                          spots=((0.0, 0.0, 0.98), (0.0, 5.0, 0.0)))
    assert len(p.patches) == 2 and p.estimate > 0


def test_under_force_control_symmetry_is_judged_over_the_whole_travel(tmp_path):
    # a ball with a bump 0.45 mm above its tip, off x = 0: within 2 x the expected 0.2 mm it is
    # symmetric, but a force may drive the travel to 0.6 mm, where the bump touches
    from tactileskin.geometry.indenters import indenter_symmetry, mirrored_x

    ball = trimesh.creation.icosphere(subdivisions=3, radius=2.5)
    bump = trimesh.creation.icosphere(subdivisions=2, radius=0.3)
    bump.apply_translation((1.6, -2.5 + 0.45 + 0.3 + 0.1, 0.0))
    f = _stl(tmp_path, "bump.stl", ball, bump)
    by_depth = Scene(thickness=1.0, dim=3, indenter="file", indenter_file=f)
    by_force = Scene(thickness=1.0, dim=3, indenter="file", indenter_file=f, force=0.5)
    assert indenter_symmetry(by_depth)[0] and not mirrored_x(by_depth)
    assert not indenter_symmetry(by_force)[0] and mirrored_x(by_force)


def test_indenters_from_the_same_bytes_share_their_search_trees(tmp_path):
    # the mesher and the planner ask the symmetry several times, each on a new indenter: the
    # trees (0.3 s for a built part) are built once per file content; placement is a shift
    ball = trimesh.creation.icosphere(subdivisions=3, radius=2.5)
    f = _stl(tmp_path, "b.stl", ball)
    a = make_indenter("file", y0=Y0, dim=3, indenter_file=f)
    b = make_indenter("file", y0=Y0 + 1.0, dim=3, indenter_file=f)
    assert a._trees is b._trees
    p = np.array([[0.3, Y0 - 0.1, 0.2], [1.0, Y0 + 0.5, -0.4]])
    ga, _ = a.gap(p, 0.0)
    gb, _ = b.gap(p + np.array([0.0, 1.0, 0.0]), 0.0)
    np.testing.assert_allclose(ga, gb, atol=1e-12)
    c = np.array([0.0, Y0 + 2.5, 0.0])                     # the ball's centre, lowest point at y0
    np.testing.assert_allclose(ga, np.linalg.norm(p - c, axis=1) - 2.5, atol=0.02)  # facets
