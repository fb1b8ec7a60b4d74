"""Analytic indenter surfaces: exact gaps at hand-computed points, normals, 2D/3D consistency."""

import math

import numpy as np
import pytest

from tactileskin.errors import ParameterError
from tactileskin.geometry import braille
from tactileskin.geometry.indenters import make_indenter, indenter_for_scene
from tactileskin.scene import Scene

Y0 = 7.0
SA = braille.get_standard("standard_american")  # R = 0.78, centre 0.30 above the base plane


def _random_points(rng, n, dim, y0=Y0, spread=3.0):
    p = rng.uniform(-spread, spread, size=(n, dim))
    p[:, 1] = rng.uniform(y0 - 2.0, y0 + 0.3, size=n)
    return p


# --- hand-computed values ------------------------------------------------------------------

def test_flat_exact():
    ind = make_indenter("flat", y0=Y0)
    g, n = ind.gap(np.array([[0.0, 6.5], [12.0, 7.1], [-3.0, 6.9]]), d=0.2)
    np.testing.assert_allclose(g, [0.3, -0.3, -0.1], atol=1e-14)
    np.testing.assert_array_equal(n, [[0, -1]] * 3)


def test_curved_exact():
    ind = make_indenter("curved", y0=Y0)
    # axis at (0, y0 - d + 12); at d = 0 the point (5, y0) is 13 from it (5-12-13) -> g = 1
    g, n = ind.gap(np.array([[5.0, Y0], [0.0, Y0 - 0.5], [0.0, Y0 + 0.5]]), d=0.3)
    assert g[0] == pytest.approx(math.hypot(5.0, 11.7) - 12.0, abs=1e-14)
    np.testing.assert_allclose(g[1:], [0.2, -0.8], atol=1e-14)
    np.testing.assert_allclose(n[0], np.array([5.0, -11.7]) / math.hypot(5.0, 11.7), atol=1e-14)
    g0, n0 = ind.gap(np.array([[5.0, Y0, 4.0]]), d=0.0)          # 3D ignores z
    assert g0[0] == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(n0[0], [5 / 13, -12 / 13, 0.0], atol=1e-14)


def test_braille_single_dot_exact():
    ind = make_indenter("braille", y0=Y0)          # base plane 7.48, sphere centre (0, 7.78)
    pts = np.array([[0.0, 6.5], [2.0, 7.0], [0.8, 7.0], [0.0, 7.2], [0.0, 7.6], [3.0, 7.6]])
    g, n = ind.gap(pts, d=0.0)
    d08 = math.hypot(0.8, 0.78)
    np.testing.assert_allclose(g, [0.5, 0.48, d08 - 0.78, -0.2, -0.6, -0.12], atol=1e-14)
    np.testing.assert_allclose(n[2], [0.8 / d08, -0.78 / d08], atol=1e-14)
    np.testing.assert_array_equal(n[[0, 1, 3, 4, 5]], [[0, -1]] * 5)
    # with travel d everything moves down by d
    g_d, _ = ind.gap(pts - [0.0, 0.25], d=0.25)
    np.testing.assert_allclose(g_d, g, atol=1e-13)


def test_braille_multi_dot_3d_exact():
    ind = make_indenter("braille", y0=Y0, braille_text="⠿", dim=3)   # 2 x 3 dots
    p = SA.dot_pitch / 2
    g, n = ind.gap(np.array([[p, 6.0, 2 * p], [-p, 6.9, -2 * p]]), d=0.0)
    np.testing.assert_allclose(g, [1.0, 0.1], atol=1e-13)             # right under dots 6 and 1
    np.testing.assert_allclose(n, [[0, -1, 0], [0, -1, 0]], atol=1e-14)


# --- properties ---------------------------------------------------------------------------

KINDS = [("flat", ""), ("curved", ""), ("braille", ""), ("braille", "⠿"), ("braille", "ab")]


@pytest.mark.parametrize("kind, text", KINDS)
@pytest.mark.parametrize("dim", [2, 3])
def test_normals_unit_and_gradient(kind, text, dim):
    ind = make_indenter(kind, y0=Y0, braille_text=text, dim=dim)
    rng = np.random.default_rng(1)
    p = _random_points(rng, 400, dim)
    d = 0.3
    g, n = ind.gap(p, d)
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-14)
    # n = grad g wherever one part is active (skip points near a crease of the union).
    # Central differences with h = 1e-6: truncation ~ h^2 / R ~ 1e-12, round-off ~ 1e-16 / h = 1e-10.
    h = 1e-6
    grad = np.empty_like(p)
    for k in range(dim):
        e = np.zeros(dim)
        e[k] = h
        grad[:, k] = (ind.gap(p + e, d)[0] - ind.gap(p - e, d)[0]) / (2 * h)
    ok = _single_active_part(ind, p, d, margin=1e-3)
    assert ok.sum() > 200
    np.testing.assert_allclose(grad[ok], n[ok], atol=1e-7)


def _single_active_part(ind, p, d, margin):
    """Points whose nearest part of a Braille union wins by more than `margin` (all points otherwise)."""
    if ind.kind != "braille":
        return np.ones(len(p), bool)
    std = ind.standard
    yb = ind.base_plane(d)
    parts = [yb - p[:, 1]]
    centres = [(x, 0.0) for x in ind.section_x] if p.shape[1] == 2 else list(ind.dots)
    for cx, cz in centres:
        c = np.array([cx, yb + std.centre_offset, cz][: p.shape[1]])
        parts.append(np.linalg.norm(p - c, axis=1) - std.sphere_radius)
    s = np.sort(np.array(parts), axis=0)
    return s[1] - s[0] > margin


@pytest.mark.parametrize("kind, text", KINDS)
@pytest.mark.parametrize("dim", [2, 3])
def test_closest_point_projection_lies_on_surface(kind, text, dim):
    # For a true signed distance, p - g n is on the surface (g = 0 there) and on the face.
    ind = make_indenter(kind, y0=Y0, braille_text=text, dim=dim)
    rng = np.random.default_rng(2)
    p = _random_points(rng, 300, dim)
    g, n = ind.gap(p, 0.1)
    # inside a Braille union the projection onto one part may land inside another part (the
    # documented penetration bound), so check points outside; flat and curved: all points.
    keep = g >= 0 if kind == "braille" else np.ones(len(p), bool)
    assert keep.sum() > 150
    p, g, n = p[keep], g[keep], n[keep]
    q = p - g[:, None] * n
    gq, _ = ind.gap(q, 0.1)
    np.testing.assert_allclose(gq, 0.0, atol=1e-12)
    # the closest point is on the working face (the lowest point of the solid at its x, z)
    ys = ind.surface_y(q[:, 0], d=0.1) if dim == 2 else ind.surface_y(q[:, 0], q[:, 2], d=0.1)
    outside = g > 0
    np.testing.assert_allclose(q[outside, 1], ys[outside], atol=1e-12)


def test_braille_2d_gap_against_brute_force():
    # Independent check of "min over parts is exact outside the union": distance to a dense
    # sampling of the union's lower boundary (plane segments + cap arcs). Sampling at 2e-4 mm
    # spacing bounds the brute-force error by spacing^2/(8R) + spacing/2 ~ 1e-4 mm.
    ind = make_indenter("braille", y0=Y0, braille_text="c")           # two dots on the row, x = +-1.17
    xs = np.arange(-4.0, 4.0, 2e-4)
    ys = ind.surface_y(xs)
    boundary = np.column_stack([xs, ys])
    # the caps meet the plane on the base circle, so the graph y(x) is the whole lower boundary
    rng = np.random.default_rng(3)
    p = np.column_stack([rng.uniform(-2.5, 2.5, 60), rng.uniform(Y0 - 1.0, Y0 - 0.01, 60)])
    g, _ = ind.gap(p, 0.0)
    brute = np.min(np.linalg.norm(p[:, None, :] - boundary[None], axis=2), axis=1)
    assert np.all(g > 0)
    np.testing.assert_allclose(g, brute, atol=2e-4)


@pytest.mark.parametrize("kind, text", KINDS)
def test_2d_equals_3d_on_section_plane(kind, text):
    ind2 = make_indenter(kind, y0=Y0, braille_text=text, dim=2)
    ind3 = make_indenter(kind, y0=Y0, braille_text=text, dim=3)
    rng = np.random.default_rng(4)
    p2 = _random_points(rng, 500, 2)
    zs = ind2.section_z if kind == "braille" else rng.uniform(-5, 5, len(p2))
    p3 = np.column_stack([p2, np.broadcast_to(zs, len(p2))])
    g2, n2 = ind2.gap(p2, 0.2)
    g3, n3 = ind3.gap(p3, 0.2)
    # Dots of other rows are >= dot_pitch - R = 1.56 mm away from the section plane, so
    # below that gap the 3D and 2D distances coincide exactly (round-off only).
    near = g2 < 1.5
    assert near.sum() > 300
    np.testing.assert_allclose(g3[near], g2[near], atol=1e-13)
    np.testing.assert_allclose(n3[near, :2], n2[near], atol=1e-13)
    np.testing.assert_allclose(n3[near, 2], 0.0, atol=1e-13)


def test_surface_profile_and_cap_dimensions():
    ind = make_indenter("braille", y0=Y0, braille_text="⠿", dim=3)
    std, d = ind.standard, 0.15
    yb = ind.base_plane(d)
    c = ind.dots
    np.testing.assert_allclose(ind.surface_y(c[:, 0], c[:, 1], d=d), yb - std.height, atol=1e-14)
    # at the base radius the cap meets the plane; outside it the surface is the plane
    np.testing.assert_allclose(ind.surface_y(c[:, 0] + std.base_radius, c[:, 1], d=d), yb, atol=1e-12)
    np.testing.assert_allclose(ind.surface_y(np.array([3.0]), np.array([0.0]), d=d), yb, atol=1e-14)
    cur = make_indenter("curved", y0=Y0)
    x = np.array([0.0, 4.0, 9.0])
    np.testing.assert_allclose(cur.surface_y(x), Y0 + 12 - np.sqrt(144 - x**2), atol=1e-14)
    assert cur.sagitta == pytest.approx(12 - math.sqrt(144 - 81), abs=1e-14)
    with pytest.raises(ParameterError, match="x"):
        cur.surface_y(np.array([9.5]))


def test_rows_and_section():
    ind = make_indenter("braille", y0=Y0, braille_text="ab")     # rows z = +1.17 (a1, b1), -1.17 (b2)
    np.testing.assert_allclose(ind.rows, [-1.17, 1.17], atol=1e-12)
    assert ind.row == 1 and ind.section_z == pytest.approx(1.17)  # the text's upper row
    np.testing.assert_allclose(ind.section_x, [-3.1, 3.1], atol=1e-12)
    assert ind.section_symmetric
    other = make_indenter("braille", y0=Y0, braille_text="ab", row=0)
    np.testing.assert_allclose(other.section_x, [3.1], atol=1e-12)
    assert not other.section_symmetric
    mid = make_indenter("braille", y0=Y0, braille_text="⠿")
    assert mid.section_z == 0.0                                       # the row nearest z = 0
    with pytest.raises(ParameterError, match="row"):
        make_indenter("braille", y0=Y0, braille_text="ab", row=2)


def test_plate_sizes_from_toml():
    flat = make_indenter("flat", y0=Y0)
    assert flat.face_box() == (-15.0, 15.0, -10.0, 10.0)              # width 30, sample length 20
    long = make_indenter("braille", y0=Y0, braille_text="braille text")
    xmin, xmax, _, _ = braille.footprint("braille text", SA)
    assert long.width == pytest.approx(2 * (max(-xmin, xmax) + long.margin))
    assert make_indenter("braille", y0=Y0).width == 20.0


def test_scene_indenters_touch_skin_top():
    for kind in ("flat", "curved", "braille"):
        scene = Scene(indenter=kind, thickness=1.0)
        ind = indenter_for_scene(scene)
        assert ind is not None and make_indenter(scene).y0 == ind.y0 == scene.section().top
        g, n = ind.gap(np.array([[0.0, scene.section().top]]), 0.0)
        assert g[0] == pytest.approx(0.0, abs=1e-14) and n[0].tolist() == [0.0, -1.0]


def test_bad_inputs():
    ind = make_indenter("flat", y0=Y0)
    with pytest.raises(ParameterError, match="points"):
        ind.gap(np.zeros((3, 4)), 0.0)
    with pytest.raises(ParameterError, match="points"):
        ind.gap(np.array([[0.0, np.nan]]), 0.0)
    with pytest.raises(ParameterError, match="d="):
        ind.gap(np.zeros((3, 2)), -0.1)
    with pytest.raises(ParameterError, match="indenter"):
        make_indenter("sphere", y0=Y0)
    with pytest.raises(ParameterError, match="braille_standard"):
        make_indenter("braille", y0=Y0, braille_standard="nope")


def test_gap_shapes_vectorised():
    ind = make_indenter("braille", y0=Y0, braille_text="ab", dim=3)
    p = np.zeros((4, 5, 3))
    g, n = ind.gap(p, 0.0)
    assert g.shape == (4, 5) and n.shape == (4, 5, 3)


@pytest.mark.parametrize("text", ["b", "\u2812", "\u283f", "", "e"])
def test_the_3d_section_plane_lies_in_the_modelled_slab(text):
    """The profile plane of a 3D Braille scene must be inside the meshed z range: the quarter
    model (z >= 0) when the dot pattern is mirror-symmetric in z ('b': rows at -+1.17 mm once
    picked z = -1.17 and the solve failed after it had run), the full length otherwise."""
    from tactileskin.mesh.slab3d import z_symmetric
    from tactileskin.scene import Scene

    scene = Scene(dim=3, indenter="braille", braille_text=text)
    ind = make_indenter(scene)
    half = 0.5 * scene.section().fingertip.sample_length
    lo = 0.0 if z_symmetric(scene) else -half
    assert lo <= ind.section_z <= half
    # rows -+z of a z-symmetric pattern cut the same section: the 2D answer cannot change
    two = make_indenter(scene.replace(dim=2))
    assert abs(two.section_z) == min(abs(ind.rows))
