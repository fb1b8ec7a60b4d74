"""2D section meshes: named boundaries, curved geometry, refinement, validity, errors, export."""

from __future__ import annotations

import collections
import threading

import meshio
import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from tactileskin.errors import ParameterError
from tactileskin.mesh import BOUNDARIES_2D, build_mesh
from tactileskin.scene import Scene

COARSE = 0.5  # mm: fast meshes for the structural tests


@pytest.fixture(scope="module")
def default_t3():
    return build_mesh(Scene(thickness=3.0))  # the default size (0.25 mm, refinement 3)


@pytest.fixture(scope="module")
def coarse_t1():
    return build_mesh(Scene(thickness=1.0), mesh_size=COARSE)


def test_boundaries_present_and_disjoint(default_t3):
    sm = default_t3
    assert set(sm.boundaries) == set(BOUNDARIES_2D)
    bnd = set(sm.mesh.boundary_facets().tolist())
    seen = set()
    for name, f in sm.boundaries.items():
        assert len(f) > 0, name
        assert set(f.tolist()) <= bnd, name
        assert not (seen & set(f.tolist())), name  # each boundary facet in one group only
        seen |= set(f.tolist())
    assert seen == bnd  # the four groups close the boundary
    assert set(sm.mesh.boundaries) == set(BOUNDARIES_2D)  # also attached to the skfem mesh


def test_lengths_and_area_match_cad_at_default_size(default_t3):
    sm, sec = default_t3, default_t3.section
    assert type(sm.mesh).__name__ == "MeshTri2"
    # requirement: |L_mesh - L_cad| / L_cad < 1e-3; quadratic edges on the true curve give
    # ~1e-8, so a tight 1e-6 bound still leaves room for the CAD tables' own 1e-8 error.
    for name, exact in (("bone_interface", sec.interface_length), ("outer_surface", sec.outer_length),
                        ("symmetry", sec.thickness)):
        assert abs(sm.boundary_measure(name) - exact) / exact < 1e-6, name
    # Section.area() is a shoelace sum on a 4000-point polygon: chord error ~ 1e-7 relative
    assert abs(sm.measure() - sec.area()) / sec.area() < 1e-6
    nail = np.linalg.norm(sec.outer_end - sec.interface_end)
    assert sm.boundary_measure("nail_edge") == pytest.approx(nail, rel=1e-12)


def _distance_to_interface(sec, p):
    """Exact distance from p to the interface curve by a bounded 1D minimisation in u."""
    u0 = np.linspace(0.0, sec.u_interface_end, 2001)
    k = np.argmin(np.linalg.norm(sec.interface(u0) - p, axis=1))
    lo, hi = u0[max(k - 1, 0)], u0[min(k + 1, len(u0) - 1)]
    r = minimize_scalar(lambda u: np.sum((sec.interface(u) - p) ** 2), bounds=(lo, hi),
                        method="bounded", options={"xatol": 1e-12})
    return np.sqrt(r.fun)


def test_mid_nodes_lie_on_true_curves(coarse_t1):
    sm, sec = coarse_t1, coarse_t1.section
    m, ft = sm.mesh, sec.fingertip
    # outer contour: exactly the ellipse (x/a)^2 + (y/b)^2 = 1
    f = sm.boundaries["outer_surface"]
    mid = m.doflocs[:, m.dofs.facet_dofs[0, f]].T
    chord = m.doflocs[:, m.facets[:, f]].mean(axis=1).T
    ell = lambda p: np.abs(np.hypot(p[:, 0] / ft.half_width, p[:, 1] / ft.height) - 1.0)  # noqa: E731
    # spline interpolation through 240 samples: error ~ 1e-7 mm; straight chords sag ~ h^2 k/8 ~ 1e-3
    assert ell(mid).max() * ft.height < 1e-6
    assert ell(chord).max() * ft.height > 1e-4  # the check above can fail: chords are off the curve
    # bone interface: distance to the offset curve
    f = sm.boundaries["bone_interface"]
    mid = m.doflocs[:, m.dofs.facet_dofs[0, f]].T
    d = [_distance_to_interface(sec, p) for p in mid[::3]]
    assert max(d) < 1e-6


def test_node_ordering_interior_mid_nodes_at_edge_midpoints(coarse_t1):
    # gmsh keeps interior edges straight; a wrong node permutation would put a mid-node of
    # one edge on another edge, far from this edge's midpoint.
    m = coarse_t1.mesh
    interior = np.setdiff1d(np.arange(m.nfacets), m.boundary_facets())
    mid = m.doflocs[:, m.dofs.facet_dofs[0, interior]]
    chord = m.doflocs[:, m.facets[:, interior]].mean(axis=1)
    assert np.abs(mid - chord).max() < 1e-12


@pytest.mark.parametrize("t", [1.0, 3.0, 5.0])
def test_no_inverted_cells(t):
    sm = build_mesh(Scene(thickness=t), mesh_size=COARSE)
    assert sm.min_jacobian() > 0.0  # at every quadrature point of the curved cells
    assert sm.quality["min_scaled_jacobian"] > 0.3  # gmsh minSJ: well-shaped, not just valid
    assert sm.quality["elements"] == sm.mesh.nelements > 100


def test_outer_normals_point_outwards(coarse_t1):
    from skfem import FacetBasis

    sm = coarse_t1
    fb = FacetBasis(sm.mesh, sm.mesh.elem(), facets=sm.boundaries["outer_surface"])
    x, n = np.asarray(fb.global_coordinates()), np.asarray(fb.normals)
    ft = sm.section.fingertip
    grad = np.stack([x[0] / ft.half_width ** 2, x[1] / ft.height ** 2])  # outward ellipse normal
    grad /= np.linalg.norm(grad, axis=0)
    assert np.min(np.sum(n * grad, axis=0)) > 0.999


def _cell_size(m):
    p = m.doflocs[:, m.t]  # vertices (2, 3, n)
    a = 0.5 * np.abs((p[0, 1] - p[0, 0]) * (p[1, 2] - p[1, 0]) - (p[0, 2] - p[0, 0]) * (p[1, 1] - p[1, 0]))
    return np.sqrt(a), p.mean(axis=1).T


def test_refinement_is_finer_where_requested():
    sc = Scene(thickness=1.0, refinement=4.0)
    sm = build_mesh(sc, mesh_size=0.4)
    sec = sm.section
    h, c = _cell_size(sm.mesh)
    s = sec.s_of_point(c)
    near_bone = (s < 5.0) & (np.linalg.norm(c - sec.point_at_s(s), axis=1) < 0.1)
    far_bone = (s > 10.0) & (np.linalg.norm(c - sec.point_at_s(s), axis=1) < 0.2)
    # refined zone vs coarse zone: the ratio of mean sizes should be near refinement = 4
    ratio = h[far_bone].mean() / h[near_bone].mean()
    assert 2.5 < ratio < 6.0, ratio
    # contact zone at the top (x ~ 0) finer than the outer surface near the nail
    top = np.hypot(c[:, 0], c[:, 1] - sec.top) < 0.5
    nail = np.linalg.norm(c - sec.outer_end, axis=1) < 1.0
    assert h[nail].mean() / h[top].mean() > 2.5


@pytest.fixture(scope="module")
def default_t5():
    # the graded mesh at 0.25 / 3 (the 2D default until the boundary fit of the pressure let
    # flat and curved scenes go to 0.5 / 3; still the Braille default): ~3.8k cells, 0.5 s
    return build_mesh(Scene(thickness=5.0, mesh_size=0.25, refinement=3.0))


def _edge_length(m):
    """Mean edge length of each cell (gmsh's size field targets edge lengths) and its centroid."""
    p = m.p[:, m.t]
    e = np.mean([np.linalg.norm(p[:, i] - p[:, (i + 1) % 3], axis=0) for i in range(3)], axis=0)
    return e, p.mean(axis=1).T


def _facet_length(sm, name):
    p = sm.mesh.p[:, sm.mesh.facets[:, sm.boundaries[name]]]
    return np.linalg.norm(p[:, 1] - p[:, 0], axis=0), p.mean(axis=1).T


def test_graded_mesh_is_fine_on_the_contact_surface_and_the_roi(default_t5):
    sm, sec, z = default_t5, default_t5.section, default_t5.sizes
    fine, coarse = z["fine"], z["coarse"]
    # boundary edges where the fields ask for `fine` (Threshold below DistMin): gmsh meets a
    # size field to a few % on a curve; the transition (coarse - fine) / growth away from
    # the zone ends is excluded
    h, c = _facet_length(sm, "outer_surface")
    zone = c[:, 0] <= z["contact_x"]
    assert zone.sum() > 50 and np.all(np.abs(h[zone] / fine - 1) < 0.1)
    assert np.all(h[c[:, 0] > z["contact_x"] + z["transition"]] > 2.5 * fine)  # coarse away from it
    h, c = _facet_length(sm, "bone_interface")
    roi = sec.s_of_point(c) <= z["roi_s"]
    assert roi.sum() > 50 and np.all(np.abs(h[roi] / fine - 1) < 0.1)


def test_graded_mesh_is_coarse_far_from_both(default_t5):
    # issue #7: the former default was fine through the whole skin under the contact zone;
    # cells farther than layer + transition from the contact surface and from the bone must be
    # at the coarse size (gmsh's Frontal-Delaunay meets it to ~10-20 % in the mean)
    sm, sec, z = default_t5, default_t5.section, default_t5.sizes
    h, c = _edge_length(sm.mesh)
    ft = sec.fingertip
    # depth below the ellipse: (1 - normalised radius) * b bounds the distance from below
    # for points inside (the ellipse's min radius of curvature b^2/a < b)
    d_out = (1.0 - np.hypot(c[:, 0] / ft.half_width, c[:, 1] / ft.height)) * ft.height
    d_bone = np.linalg.norm(c - sec.point_at_s(sec.s_of_point(c)), axis=1)
    margin = 0.25  # mm: a cell's own extent
    far = (d_out > z["outer_layer"] + z["transition"] + margin) & (d_bone > z["roi_layer"] + z["transition"] + margin)
    under = far & (c[:, 0] < z["contact_x"])  # below the contact: fine in the former default
    assert under.sum() > 100
    assert h[under].mean() > 0.8 * z["coarse"] and h[under].min() > 2.0 * z["fine"]


def test_graded_default_cuts_cells_and_keeps_quality(default_t5):
    sm = default_t5
    # the former box-refined default had 14,046 cells at t = 5 (1,903 / 6,688 at t = 1 / 3);
    # the grading measured 3,823 (benchmarks/results/mesh_grading.md): assert a factor >= 3.5
    assert sm.mesh.nelements < 14046 / 3.5
    assert set(sm.boundaries) == set(BOUNDARIES_2D)
    assert sm.quality["min_scaled_jacobian"] > 0.3 and sm.min_jacobian() > 0.0
    sec = sm.section
    assert abs(sm.boundary_measure("bone_interface") - sec.interface_length) / sec.interface_length < 1e-6


@pytest.mark.parametrize("t,ind,size,ratio", [(1.0, "curved", 0.5, 3.0), (3.0, "braille", 0.5, 3.0),
                                              (5.0, "flat", 1.0, 2.0), (3.0, "flat", 0.25, 1.0)])
def test_cell_estimate_is_upper_side(t, ind, size, ratio):
    # the plan's estimate guards against absurd requests before gmsh runs: it must not fall
    # below the actual count, nor be so loose that it refuses feasible meshes (<= 2x;
    # measured 1.1-1.5x over t = 1-5, sizes 0.125-1 mm, refinement 1-4)
    sm = build_mesh(Scene(thickness=t, indenter=ind), mesh_size=size, refinement=ratio)
    r = sm.sizes["estimate"] / sm.mesh.nelements
    assert 1.0 <= r <= 2.0, r


def test_cell_estimate_of_default_t5(default_t5):
    r = default_t5.sizes["estimate"] / default_t5.mesh.nelements
    assert 1.0 <= r <= 2.0, r


@pytest.mark.parametrize("kw", [{"mesh_size": 0.0}, {"mesh_size": -1.0}, {"refinement": 0.5},
                                {"mesh_size": 0.005, "refinement": 20.0}])
def test_bad_sizes_raise_parameter_error(kw):
    with pytest.raises(ParameterError) as e:
        build_mesh(Scene(thickness=3.0), **kw)
    assert next(iter(kw)) in str(e.value) and "valid" in str(e.value)


@pytest.mark.parametrize("suffix", [".msh", ".vtu", ".inp"])
def test_export_round_trip(coarse_t1, tmp_path, suffix):
    sm = coarse_t1
    path = sm.write(tmp_path / f"skin{suffix}")
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temp file left behind
    back = meshio.read(path)
    np.testing.assert_allclose(back.points[:, :2], sm.mesh.doflocs.T, atol=1e-9)
    tri = back.get_cells_type("triangle6")
    np.testing.assert_array_equal(tri, sm.mesh.dofs.element_dofs.T)
    if suffix == ".msh":  # named physical groups: field_data name -> (tag, dim)
        phys = np.concatenate([d for c, d in zip(back.cells, back.cell_data["gmsh:physical"])
                               if c.type == "line3"])
        for name, f in sm.boundaries.items():
            assert np.sum(phys == back.field_data[name][0]) == len(f), name
    elif suffix == ".inp":  # plane-strain CPE6 cells in ELSET skin, one NSET per boundary
        assert "skin" in back.cell_sets
        for name, f in sm.boundaries.items():
            assert len(back.point_sets[name]) == 2 * len(f) + 1, name  # an open chain of line3


def test_export_unknown_suffix(coarse_t1, tmp_path):
    with pytest.raises(ParameterError, match=r"\.msh, \.vtu, \.inp"):
        coarse_t1.write(tmp_path / "skin.stl")
    assert list(tmp_path.iterdir()) == []


def test_off_main_thread():
    out = {}

    def work():
        out["m"] = build_mesh(Scene(thickness=5.0), mesh_size=1.0)

    th = threading.Thread(target=work)
    th.start()
    th.join(60)
    assert out["m"].mesh.nelements > 0


def test_meshes_are_reproducible(monkeypatch):
    # the result cache is keyed by the scene: the same scene must give the same mesh (gmsh's,
    # each time: the memo of meshes made in this process, emptied, serves neither)
    from tactileskin.mesh import section2d

    monkeypatch.setattr(section2d, "_MEMO", collections.OrderedDict(), raising=False)
    a = build_mesh(Scene(thickness=3.0), mesh_size=1.0)
    monkeypatch.setattr(section2d, "_MEMO", collections.OrderedDict(), raising=False)
    b = build_mesh(Scene(thickness=3.0), mesh_size=1.0)
    np.testing.assert_array_equal(a.mesh.doflocs, b.mesh.doflocs)
    np.testing.assert_array_equal(a.mesh.t, b.mesh.t)


def test_gmsh_failure_becomes_mesh_error():
    from tactileskin.errors import MeshError
    from tactileskin.mesh import _gmsh

    with pytest.raises(MeshError, match=r"thickness.*3"):
        with _gmsh.session("broken", {"thickness": 3.0}) as gmsh:
            gmsh.model.occ.addCurveLoop([12345])  # no such curve: gmsh raises
    import gmsh

    assert not gmsh.isInitialized()  # finalized after the failure


def test_order_one_gives_straight_triangles():
    sm = build_mesh(Scene(thickness=3.0, order=1, formulation="displacement"), mesh_size=1.0)
    assert type(sm.mesh).__name__ == "MeshTri1" and sm.min_jacobian() > 0
    assert set(sm.boundaries) == set(BOUNDARIES_2D)


@pytest.mark.parametrize("t", [1.0, 5.0])
def test_quadrilateral_option(t, tmp_path):
    sm = build_mesh(Scene(thickness=t), mesh_size=COARSE, cell="quad")
    m, sec = sm.mesh, sm.section
    assert type(m).__name__ == "MeshQuad2" and set(sm.boundaries) == set(BOUNDARIES_2D)
    assert sm.min_jacobian() > 0.0
    # same curved-edge accuracy as the triangles (1e-6, see the default-size test)
    assert abs(sm.boundary_measure("bone_interface") / sec.interface_length - 1) < 1e-6
    assert abs(sm.measure() / sec.area() - 1) < 1e-6
    interior = np.setdiff1d(np.arange(m.nfacets), m.boundary_facets())  # quad9 node order
    mid = m.doflocs[:, m.dofs.facet_dofs[0, interior]]
    assert np.abs(mid - m.doflocs[:, m.facets[:, interior]].mean(axis=1)).max() < 1e-12
    back = meshio.read(sm.write(tmp_path / "q.vtu"))
    np.testing.assert_array_equal(back.get_cells_type("quad9"), m.dofs.element_dofs.T)
    # Abaqus has no 9-node plane element: the deck holds CPE8 (corner + edge nodes)
    from tactileskin.mesh.abaqus import read_inp_sets

    pts, etype, cells, sets = read_inp_sets(sm.write(tmp_path / "q.inp").read_text())
    assert etype == "CPE8"
    np.testing.assert_array_equal(cells, m.dofs.element_dofs[:8].T)
    np.testing.assert_allclose(pts, m.doflocs.T, atol=1e-12)
    assert set(sets) == set(BOUNDARIES_2D)


def test_quadrilateral_option_is_2d_only():
    with pytest.raises(ParameterError, match="cell"):
        build_mesh(Scene(thickness=3.0, dim=3), cell="quad")


def test_gmsh_is_silent(capfd, monkeypatch):
    # library code never prints: gmsh's own terminal output is off unless logging is DEBUG
    from tactileskin.mesh import section2d

    monkeypatch.setattr(section2d, "_MEMO", collections.OrderedDict(), raising=False)  # gmsh runs
    build_mesh(Scene(thickness=3.0), mesh_size=1.0)
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_a_mesh_of_the_same_content_is_meshed_once_per_process(monkeypatch):
    """The paper sweep's 18 2D cases have 6 meshes (the material, and the indenter beyond its
    contact zone, do not enter one): each was meshed anew per case. Built once now, the same
    mesh given back, its arrays equal to gmsh's own; another thickness or size is meshed."""
    from tactileskin.mesh import _gmsh, section2d

    monkeypatch.setattr(section2d, "_MEMO", collections.OrderedDict(), raising=False)
    runs = []
    real = _gmsh.session
    monkeypatch.setattr(_gmsh, "session", lambda *a: (runs.append(a[0]), real(*a))[1])
    a = build_mesh(Scene(thickness=1.0, material="silicone", indenter="flat"), mesh_size=1.0)
    a.boundaries["symmetry"] = a.boundaries["symmetry"][:1]  # the caller's copy, not the memo's
    b = build_mesh(Scene(thickness=1.0, material="polyurethane", indenter="curved"), mesh_size=1.0)
    assert len(runs) == 1
    monkeypatch.setattr(section2d, "_MEMO", collections.OrderedDict(), raising=False)
    fresh = build_mesh(Scene(thickness=1.0, material="polyurethane", indenter="curved"), mesh_size=1.0)
    assert len(runs) == 2
    for x in ("p", "t", "doflocs"):
        np.testing.assert_array_equal(getattr(b.mesh, x), getattr(fresh.mesh, x))
    assert b.boundaries.keys() == fresh.boundaries.keys()
    for name in fresh.boundaries:
        np.testing.assert_array_equal(b.boundaries[name], fresh.boundaries[name])
        np.testing.assert_array_equal(b.mesh.boundaries[name], fresh.mesh.boundaries[name])
    assert b.sizes == fresh.sizes and b.section == fresh.section
    build_mesh(Scene(thickness=1.0), mesh_size=1.2)
    build_mesh(Scene(thickness=3.0), mesh_size=1.0)
    assert len(runs) == 4
