"""3D verification: Hertz (rigid sphere on a thick block) and the flat plate on an extruded
slab against the 2D plane-strain section."""

import numpy as np
import pytest

from tactileskin.fe.verification import Sphere, fit_hertz_pressure, hertz_sphere


@pytest.fixture(scope="module")
def hertz():
    # the coarsest level of benchmarks/hertz3d.py: h = 0.15 mm, a/h = 3.3, ~11.6k dofs
    return hertz_sphere(h=0.15)


def test_sphere_gap_and_normal():
    s = Sphere(2.0)
    x = np.array([[0.0, -0.1, 0.0], [1.0, 0.5, 1.0], [0.0, 4.0, 0.0]])
    g, n = s.gap(x, 0.1)
    c = np.array([0.0, 1.9, 0.0])
    np.testing.assert_allclose(g, np.linalg.norm(x - c, axis=1) - 2.0)
    np.testing.assert_allclose(g[0], 0.0, atol=1e-15)  # the lowest point after travel 0.1
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    np.testing.assert_allclose(n[0], [0.0, -1.0, 0.0])


def test_fit_recovers_a_semi_ellipse_despite_point_scatter():
    # points on a quarter disc; pressure = Hertz times a zero-mean +-30 % pattern, like the
    # point scatter of 3 contact points per P2 triangle. A fit of p^2 is biased by it (that
    # is what this estimator avoids); the fit of p is not, to the sampling noise.
    rng = np.random.default_rng(0)
    n = 4000
    r = 0.8 * np.sqrt(rng.random(n))
    w = np.full(n, np.pi * 0.8 ** 2 / 4 / n)
    a, p0 = 0.5, 0.02
    exact = p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None))
    af, pf, am = fit_hertz_pressure(r, exact, w)
    assert af == pytest.approx(a, rel=1e-5) and pf == pytest.approx(p0, rel=1e-5)  # 2e-6: the solver's stop
    assert am == pytest.approx(a, rel=0.02)  # the moment estimate from 4000 random points
    noisy = exact * (1 + 0.3 * np.where(np.arange(n) % 2, 1.0, -1.0))
    af, pf, _ = fit_hertz_pressure(r, noisy, w)
    # measured +0.10 % and -0.88 % (seeds 0-3: |a| <= 0.1 %, |p0| <= 0.9 %)
    assert af == pytest.approx(a, rel=0.005) and pf == pytest.approx(p0, rel=0.015)
    sel = noisy > 0.2 * noisy.max()
    c0, c1 = np.linalg.lstsq(np.column_stack([np.ones(sel.sum()), r[sel] ** 2]), noisy[sel] ** 2, rcond=None)[0]
    # a fit of p^2 sees sqrt(mean p^2) = sqrt(1.09) p0: +3.0 % here (seeds 0-3: +2.5 to +5.4 %)
    assert np.sqrt(c0) > 1.02 * p0


def test_hertz_sphere_force_indentation_and_contact_radius(hertz):
    """Measured at this level (benchmarks/results/hertz3d.md, 2026-11-27): P(d) -0.38 %, contact
    radius +1.42 %, peak (fit) -2.92 %. Asserted: the load within 1 % (at most ~1 % on every level
    of the benchmark) and the radius within the issue's 3 %. The peak is not asserted at this
    level: 0.08 points inside 3 %, less than the fit moves with the points' arrangement (the
    benchmark: -1.3 to -1.4 % from a/h ~ 5)."""
    h = hertz
    assert h["a_h"] / h["R"] < 0.06 and h["a_h"] / h["size"] < 0.015  # near Hertz' assumptions
    assert h["P"] == pytest.approx(h["P_h"], rel=0.01)
    assert h["a_fe"] == pytest.approx(h["a_h"], rel=0.03)
    # an independent measure of the radius: the pressure's second moment (measured +1.59 %).
    # (-sigma_yy at the axis node is not asserted: one projected nodal value, -0.02 % here
    # but -4.6 % on the next finer level)
    assert h["a_moment"] == pytest.approx(h["a_h"], rel=0.03)


def test_hertz_sphere_contact_is_consistent(hertz):
    # the contact points carry the whole reaction, and the contact is enforced to tolerance
    m, ev = hertz["model"], hertz["ev"]
    g, lamN, _, n = ev.contact
    carried = 4 * np.sum(m.surface.w * lamN * -n[..., 1])
    assert carried == pytest.approx(hertz["P"], rel=1e-3)
    assert hertz["penetration"] <= m.contact.tol_penetration
    # the load is carried only inside the contact disc (a few elements of smearing)
    x = ev.contact[2]
    r = np.hypot(x[..., 0], x[..., 2])
    assert r[lamN > 0].max() < hertz["a_h"] + hertz["h"]


@pytest.fixture(scope="module")
def flat_plate():
    """t = 3 mm silicone under a flat plate, 0.1 mm travel, elastic: the 2D section and the
    3D slab (1 mm long, quarter model, u_z = 0 on both ends, so the continuum solution is
    the plane-strain one, uniform along z), same nominal mesh (h 1 mm, refinement 2)."""
    from tactileskin.fe import Dirichlet, Model, make_result, model_for_scene, run, solve
    from tactileskin.mesh.slab3d import build_slab_mesh
    from tactileskin.scene import Scene

    sc = Scene(thickness=3, indenter="flat", dim=3, mesh_size=1.0, refinement=2, viscoelastic=False, depth=0.1)
    r2 = solve(sc.replace(dim=2))
    sm = build_slab_mesh(sc, length=1.0)
    assert sm.z_symmetric  # end_back is the plane z = 0, end_front the end z = 0.5
    base, _ = model_for_scene(sc, sm)
    model = Model(base.mesh, base.boundaries, base.law, list(base.dirichlet) + [Dirichlet("end_front", (2,))],
                  formulation=base.formulation, contact=base.contact, order=sc.order, stiffness=base.stiffness)
    # force_factor stays 1 here (a Model made by hand): the reaction is the modelled half-slab
    # x >= 0 of width 0.5 mm, against the 2D half section's per mm, as the test compares them
    assert model.force_factor == 1.0 and base.force_factor == 4.0
    ev, stats = run(model, sc.duration)
    planes = (0.0, 0.25, 0.5)
    r3 = [make_result(model, ev, stats, s_of_point=sc.section().s_of_point, plane_z=z) for z in planes]
    return r2, r3, sm.length / 2


def test_flat_plate_on_extruded_slab_equals_2d_section(flat_plate):
    """The same continuum problem on two different meshes of the same nominal size (about two
    P2 elements through the skin): what differs is discretisation. Measured on this solver
    (3D 6429 dofs, 22 Newton iterations): load per mm -1.7 %; bone-pressure
    peak -1.9 / -2.6 / -3.3 % and relative L2 (s <= 6 mm) 1.2 / 2.2 / 1.1 % on the planes
    z = 0 / 0.25 / 0.5 (the spread between planes of one solve is of the same size as the
    difference to 2D)."""
    from tactileskin.planner import profile_difference

    r2, r3, width = flat_plate
    assert r3[0].reaction / width == pytest.approx(r2.reaction, rel=0.025)
    for r in r3:
        d = profile_difference(r, r2)
        assert d["peak"] < 0.04 and d["l2"] < 0.03
