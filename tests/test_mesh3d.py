"""3D slab meshes: named boundaries, curved faces on the true surfaces, symmetry, validity."""

from __future__ import annotations

import logging

import meshio
import numpy as np
import pytest

from tactileskin.mesh import BOUNDARIES_3D, build_mesh
from tactileskin.mesh.skinmesh import facet_nodes
from tactileskin.scene import Scene
from mesh_probe import edges_near

COARSE = {"mesh_size": 1.5, "refinement": 1.5}  # a few thousand P2 tetrahedra: ~1 s


@pytest.fixture(scope="module")
def slab_t3():
    return build_mesh(Scene(thickness=3.0, dim=3), **COARSE)


def test_boundaries_present_disjoint_and_closed(slab_t3):
    sm = slab_t3
    assert type(sm.mesh).__name__ == "MeshTet2"
    assert set(sm.boundaries) == set(BOUNDARIES_3D)
    bnd = set(sm.mesh.boundary_facets().tolist())
    seen = set()
    for name, f in sm.boundaries.items():
        assert len(f) > 0, name
        assert not (seen & set(f.tolist())), name
        seen |= set(f.tolist())
    assert seen == bnd


def test_flat_indenter_uses_z_symmetry_and_planes_are_where_documented(slab_t3):
    sm, m = slab_t3, slab_t3.mesh
    assert sm.z_symmetric and sm.length == sm.section.fingertip.sample_length
    z = lambda name: m.p[2, m.facets[:, sm.boundaries[name]]]  # noqa: E731
    assert np.all(z("end_back") == 0.0) and np.allclose(z("end_front"), 0.5 * sm.length)
    assert np.all(m.p[0, m.facets[:, sm.boundaries["symmetry"]]] == 0.0)


def test_areas_and_volume_match_cad(slab_t3):
    sm, sec = slab_t3, slab_t3.section
    lz = 0.5 * sm.length
    # P2 faces on the exact cylinder over the curve: the error is the z-independent
    # interpolation error of the curve, ~1e-7 relative at this size; 1e-5 leaves margin and is
    # still far tighter than the 1e-3 requirement.
    assert sm.boundary_measure("bone_interface") / lz == pytest.approx(sec.interface_length, rel=1e-5)
    assert sm.boundary_measure("outer_surface") / lz == pytest.approx(sec.outer_length, rel=1e-5)
    assert sm.boundary_measure("symmetry") == pytest.approx(sec.thickness * lz, rel=1e-12)
    assert sm.boundary_measure("end_front") == pytest.approx(sec.area(), rel=1e-5)
    assert sm.measure() / lz == pytest.approx(sec.area(), rel=1e-5)


def test_curved_face_nodes_on_true_surfaces(slab_t3):
    sm, m = slab_t3, slab_t3.mesh
    ft = sm.section.fingertip
    f = sm.boundaries["outer_surface"]
    nodes = np.unique(facet_nodes(m, f, 3, 2))
    p = m.doflocs[:, nodes]
    assert np.abs(np.hypot(p[0] / ft.half_width, p[1] / ft.height) - 1.0).max() < 1e-9
    # interface: the node minus t times the outward normal at the curve parameter is on the
    # ellipse, i.e. its distance to the ellipse is t; check with the curve-parameter solve
    from tactileskin.mesh.snap import curve_parameter

    sec = sm.section
    nodes = np.unique(facet_nodes(m, sm.boundaries["bone_interface"], 3, 2))
    q = m.doflocs[:2, nodes].T
    u = curve_parameter(sec.interface, q, sec.u_interface_end)
    assert np.linalg.norm(sec.interface(u) - q, axis=1).max() < 1e-9


def test_tet10_node_ordering(slab_t3):
    # interior edges are straight: their mid-node is exactly the midpoint of the end vertices;
    # a wrong gmsh -> scikit-fem permutation puts it on another edge of the cell.
    m = slab_t3.mesh
    mid = m.doflocs[:, m.dofs.edge_dofs[0]]
    chord = m.doflocs[:, m.edges].mean(axis=1)
    err = np.linalg.norm(mid - chord, axis=0)
    on_curve = np.zeros(m.nedges, bool)
    for name in ("outer_surface", "bone_interface"):
        on_curve[np.unique(m.f2e[:, slab_t3.boundaries[name]])] = True
    assert err[~on_curve].max() < 1e-12
    assert 0 < err[on_curve].max() < 0.05  # curved edges sag by h^2 kappa / 8 < 1.5^2 / 8 / 6


def test_facet_export_ordering(slab_t3):
    # triangle6 facets for export: mid-node k belongs to the edge (0,1), (1,2), (0,2)
    m = slab_t3.mesh
    fn = facet_nodes(m, slab_t3.boundaries["bone_interface"], 3, 2)
    x = m.doflocs[:, fn]
    for k, (a, b) in enumerate([(0, 1), (1, 2), (0, 2)]):
        d = np.linalg.norm(x[:, :, 3 + k] - 0.5 * (x[:, :, a] + x[:, :, b]), axis=0)
        assert d.max() < 0.05


@pytest.mark.parametrize("t", [1.0, 3.0, 5.0])
def test_no_inverted_cells(t):
    sm = build_mesh(Scene(thickness=t, dim=3), **COARSE)
    assert sm.min_jacobian() > 0.0
    # min over quadrature points and the cell's lattice points (vertices included, where a
    # P2 cell's det J is often smallest): t = 5 gives 0.254 here, 0.425 at the quadrature
    # points alone; the refusal threshold (skinmesh.MIN_SCALED_JACOBIAN) is 0.05
    assert sm.quality["min_scaled_jacobian"] > 0.25
    assert sm.quality["min_sicn"] > 0.1


def test_braille_text_without_z_symmetry_meshes_full_length(caplog):
    # "e" = dots 1 and 5: diagonal, mirror-symmetric about neither x = 0 nor z = 0
    with caplog.at_level(logging.WARNING, logger="tactileskin.mesh.slab3d"):
        sm = build_mesh(Scene(thickness=3.0, dim=3, indenter="braille", braille_text="e"), **COARSE)
    assert not sm.z_symmetric
    z = sm.mesh.p[2]
    assert z.min() == pytest.approx(-0.5 * sm.length) and z.max() == pytest.approx(0.5 * sm.length)
    assert "not symmetric about x = 0" in caplog.text


def test_export_round_trip_3d(slab_t3, tmp_path):
    sm = slab_t3
    for suffix in (".msh", ".vtu", ".inp"):
        back = meshio.read(sm.write(tmp_path / f"slab{suffix}"))
        np.testing.assert_allclose(back.points, sm.mesh.doflocs.T, atol=1e-9)
        np.testing.assert_array_equal(back.get_cells_type("tetra10"), sm.mesh.dofs.element_dofs.T)


def test_absurd_3d_request_is_refused_before_gmsh():
    from tactileskin.errors import ParameterError

    # refined size 0.02 mm over a 10 mm slab: ~1e9 tetrahedra; must fail fast, naming the knob
    with pytest.raises(ParameterError, match=r"mesh_size=0.1 .*dofs in 3D.*refinement=5"):
        build_mesh(Scene(thickness=5.0, dim=3), mesh_size=0.1, refinement=5.0)


def test_cell_estimate_is_upper_side_3d(slab_t3):
    # the slab uses the same graded plan; its estimate (checked before gmsh) must not fall
    # below the actual count nor exceed it 2x (measured 1.0-1.5x for sizes <= the thickness)
    r = slab_t3.sizes["estimate"] / slab_t3.mesh.nelements
    assert 1.0 <= r <= 2.0, r


# --- local refinement of 3D Braille slabs (sizing.local_plan) ---------------------------------

LOCAL = {"mesh_size": 1.2, "refinement": 4.0}  # fine 0.3 mm at the dot: ~10k dofs, ~1-2 s


@pytest.fixture(scope="module")
def dot_t1():
    return build_mesh(Scene(thickness=1.0, dim=3, indenter="braille", braille_text=""), **LOCAL)


def test_local_plan_is_fine_under_the_dot_and_coarse_far_away(dot_t1):
    sizes, t = dot_t1.sizes, 1.0
    fine, coarse = sizes["fine"], sizes["coarse"]
    assert fine == pytest.approx(LOCAL["mesh_size"] / LOCAL["refinement"])
    assert sizes["patches"] and sizes["bone_patches"] and sizes["strip"] == 0.0  # depth 0.2 < dot height
    (x, y, z, r, h), = sizes["patches"]
    assert (x, z, h) == (0.0, 0.0, fine)
    # the ball centres are the dot's contact point on the outer surface and the bone point under it
    out = dot_t1.mesh.p[:, np.unique(dot_t1.mesh.facets[:, dot_t1.boundaries["outer_surface"]])]
    assert np.min(np.linalg.norm(out - np.array([[x], [y], [z]]), axis=0)) < 0.5 * fine
    xb, yb, zb, rb, hb = sizes["bone_patches"][0]
    assert yb == pytest.approx(y - t)
    # gmsh meets the field to ~20 % (edges of a Delaunay mesh scatter around the target size);
    # far from the dot (z = 5 mm, 3.5 mm beyond the ball) the size is the coarse one, capped
    # by gmsh at about the skin thickness
    near_out, n_out = edges_near(dot_t1, "outer_surface", (0, y, 0), 0.6)
    near_bone, n_bone = edges_near(dot_t1, "bone_interface", (0, yb, 0), 1.0)
    far_out, _ = edges_near(dot_t1, "outer_surface", (0, y, 5.0), 1.0)
    far_bone, _ = edges_near(dot_t1, "bone_interface", (0, yb, 5.0), 1.0)
    assert near_out < 1.2 * fine and near_bone < 1.2 * hb and n_out > 5 and n_bone > 10
    assert far_out > 0.75 * min(coarse, 2 * t) and far_bone > 0.75 * min(coarse, 2 * t)


def test_local_plan_has_fewer_dofs_than_the_strip_plan_at_equal_fine_size(dot_t1):
    strip = build_mesh(Scene(thickness=1.0, dim=3, indenter="braille", braille_text=""), local=False, **LOCAL)
    assert strip.sizes["fine"] == dot_t1.sizes["fine"] and not strip.sizes["patches"]
    # the strip plan refines the whole contact strip and 6 mm of bone along the 10 mm half slab
    assert dot_t1.mesh.nelements < 0.6 * strip.mesh.nelements
    r = dot_t1.sizes["estimate"] / dot_t1.mesh.nelements
    assert 1.0 <= r <= 2.0, r  # the local plan's estimate is upper-side too


@pytest.mark.parametrize("t", [3.0, 5.0])
def test_the_local_plan_estimate_counts_overlapping_balls_once(t):
    # a full cell's bone balls (radius base radius + t) overlap: summed, they read the
    # t = 5 cell at 0.8 / 8 as 465k dofs (past the 400k cap) where gmsh makes 176k
    m = build_mesh(Scene(thickness=t, dim=3, indenter="braille", braille_text="\u283f"), **LOCAL)
    r = m.sizes["estimate"] / m.mesh.nelements
    assert 1.0 <= r <= 2.0, r


def test_local_plan_covers_every_dot_of_a_cell_and_the_plate_strip_when_it_touches():
    from tactileskin.geometry import braille
    from tactileskin.mesh import sizing

    sc = Scene(thickness=3.0, dim=3, indenter="braille", braille_text="\u283f")
    sec = sc.section()
    p = sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True, **LOCAL)
    xz = braille.dot_centres("\u283f", "standard_american")
    # quarter slab x >= 0, z >= 0: the dots inside it plus the mirror dots whose balls reach it
    inside = {(round(x, 6), round(z, 6)) for x, z in xz if x >= 0 and z >= 0}
    got = {(round(b[0], 6), round(b[2], 6)) for b in p.patches}
    assert inside <= got and len(inside) == 2
    assert all(x < 0 or z < 0 for x, z in got - inside)
    # t = 3: depth 0.6 mm > dot height 0.48 mm: the base plate touches along the slab
    assert sc.indentation > braille.get_standard("standard_american").height
    assert p.strip == pytest.approx(np.sqrt(p.fine * p.coarse)) and p.contact_x > 0
    # the bone size grows with t / dot diameter (the bone imprint's length scale)
    assert p.bone_patches[0][4] == pytest.approx(p.fine * 3.0 / 1.44)


@pytest.mark.parametrize("t, scale", [(1.0, 1.0), (3.0, 3.0 / 1.44), (5.0, 2.3)])
def test_the_bone_patch_size_grows_with_thickness_up_to_its_cap(t, scale):
    from tactileskin.mesh import sizing

    sc = Scene(thickness=t, dim=3, indenter="braille", braille_text="")
    sec = sc.section()
    p = sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True, **LOCAL)
    # dot base diameter 1.44 mm: 1 below it, t / 1.44 above, capped at t = 5 (3.47 -> 2.3)
    assert p.bone_patches[0][4] == pytest.approx(min(p.coarse, p.fine * scale))
    assert sizing.BONE_SCALE_MAX == 2.3


@pytest.mark.parametrize("indenter", ["flat", "curved"])
def test_flat_and_curved_keep_the_strip_plan(indenter):
    from tactileskin.mesh import sizing

    sc = Scene(thickness=3.0, dim=3, indenter=indenter)
    sec = sc.section()
    kw = dict(dim=3, length=sec.fingertip.sample_length, z_symmetric=True, **LOCAL)
    assert sizing.plan(sc, sec, **kw) == sizing.plan(sc, sec, local=False, **kw)
    assert not sizing.plan(sc, sec, **kw).patches


def test_a_cell_folded_by_its_snapped_mid_nodes_gets_straight_edges(slab_t3):
    # fold one boundary cell by pushing the mid-node of one of its outer-surface edges through
    # the cell (what snapping a sliver on the curved surface can do: the t = 5 sphere at
    # 1.6 / 8 had one cell at -0.16 and was refused): _unfold straightens that cell's edges
    import dataclasses

    from tactileskin.mesh.skinmesh import MIN_SCALED_JACOBIAN, cell_jacobian_ratios
    from tactileskin.mesh.slab3d import _unfold

    m = slab_t3.mesh
    facet = slab_t3.boundaries["outer_surface"][0]
    cell = int(m.f2t[0, facet])
    edge = int(m.f2e[0, facet])
    mid = m.dofs.edge_dofs[0, edge]
    inner = m.p[:, m.t[:, cell]].mean(axis=1)
    p = m.doflocs.copy()
    p[:, mid] += 3.0 * (inner - p[:, mid])           # far past the cell's centre
    folded = dataclasses.replace(m, doflocs=p)
    assert cell_jacobian_ratios(folded)[cell] < MIN_SCALED_JACOBIAN
    fixed, n = _unfold(folded)
    assert n >= 1 and cell_jacobian_ratios(fixed).min() >= MIN_SCALED_JACOBIAN
    assert np.allclose(fixed.doflocs[:, mid], m.p[:, m.edges[:, edge]].mean(axis=1))
    # an unfolded mesh is returned as it is
    same, n0 = _unfold(m)
    assert same is m and n0 == 0


@pytest.mark.parametrize("fields", [
    dict(dim=2, indenter="curved", thickness=3.0),
    dict(dim=3, indenter="braille", braille_text="l", thickness=1.0, mesh_size=1.6, refinement=4),
    dict(dim=3, skin="pad", indenter="sphere", indenter_radius=2.5, thickness=2.0, mesh_size=2.0, refinement=4)])
def test_a_skins_size_plan_is_the_plan_its_mesh_is_made_by(fields):
    # size_plan checks a request against the dofs cap before any solve (array --validate):
    # it must plan exactly what build_mesh then meshes
    from tactileskin.scene import Scene

    sc = Scene(**fields)
    assert sc.skin_kind.size_plan(sc).as_dict() == sc.skin_kind.build_mesh(sc).sizes


def _t5_dot_plan(**kw):
    from tactileskin.mesh import sizing

    sc = Scene(thickness=5.0, dim=3, indenter="braille", braille_text="")
    sec = sc.section()
    return sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True, **kw)


@pytest.mark.parametrize("k, s", [(2.0, 1.0), (3.0, 1.0), (1.0, 1.5), (10.0, 10.0)])
def test_the_spot_and_strip_factors_scale_only_the_contact_sizes(monkeypatch, k, s):
    """benchmarks/spot_scale_t5.py's knobs: the contact spot's size times k (at most half the
    far size; k replaces the thick-spot rule's factor), the plate strip's times s (at most the
    far size); the bone balls and the bone ROI keep theirs."""
    from tactileskin.mesh import sizing

    kw = {"mesh_size": 1.6, "refinement": 8.0}
    assert sizing.SPOT_FACTOR is None and sizing.STRIP_FACTOR == 1.0  # the plan: the thick-spot rule
    monkeypatch.setattr(sizing, "SPOT_FACTOR", 1.0)
    base = _t5_dot_plan(**kw)
    assert base.patches[0][4] == pytest.approx(0.2)
    assert base.strip == base.strip_roi == pytest.approx(np.sqrt(0.2 * 1.6))
    monkeypatch.setattr(sizing, "SPOT_FACTOR", k)
    monkeypatch.setattr(sizing, "STRIP_FACTOR", s)
    p = _t5_dot_plan(**kw)
    assert p.patches[0][4] == pytest.approx(min(0.8, base.patches[0][4] * k))
    assert p.strip == pytest.approx(min(1.6, base.strip * s))
    assert p.bone_patches == base.bone_patches and p.strip_roi == base.strip_roi
    assert p.roi_layer == base.roi_layer
    assert (p.estimate < base.estimate) == (k > 1.0 or s > 1.0)


def _spot_sizes(**fields):
    from tactileskin.mesh import sizing

    sc = Scene(dim=3, **fields)
    sec = sc.section()
    p = sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True)
    return [b[4] for b in p.patches], p


@pytest.mark.parametrize("text", ["", "\u283f"])
def test_the_thick_spot_rule_coarsens_the_default_contact_spot_at_t5_only(monkeypatch, text):
    """At t = 5 mm the `default` (1.6 / 8) meshes a dot's contact spot at 3x its fine size (the
    stored levels with "spot_factor" 3, spot_scale_t5.md); the bone balls and the strip keep
    their sizes, and the mesh has fewer nodes. The `fine` preset (0.8 / 8, the study's
    reference) keeps the spot at its fine size."""
    from tactileskin.mesh import sizing
    from tactileskin.mesh.slab3d import build_slab_mesh
    from tactileskin.planner import with_quality

    sc = with_quality(Scene(dim=3, thickness=5.0, indenter="braille", braille_text=text), "default")
    fine = sc.mesh_size / sc.refinement
    assert fine == pytest.approx(sizing.THICK_SPOT_H)
    now, p = _spot_sizes(**{k: getattr(sc, k) for k in ("thickness", "indenter", "braille_text", "mesh_size",
                                                         "refinement")})
    assert now == pytest.approx([3.0 * fine] * len(now))
    nodes = build_slab_mesh(sc).mesh.p.shape[1]
    monkeypatch.setattr(sizing, "SPOT_FACTOR", 1.0)  # the spot at its fine size
    before, q = _spot_sizes(thickness=5.0, indenter="braille", braille_text=text, mesh_size=1.6, refinement=8.0)
    assert before == pytest.approx([fine] * len(now))
    assert p.bone_patches == q.bone_patches and p.strip == q.strip and p.strip_roi == q.strip_roi
    assert nodes < 0.96 * build_slab_mesh(sc).mesh.p.shape[1]
    monkeypatch.setattr(sizing, "SPOT_FACTOR", None)
    f = with_quality(sc, "fine")
    assert f.mesh_size / f.refinement < sizing.THICK_SPOT_H
    spots, _ = _spot_sizes(thickness=5.0, indenter="braille", braille_text=text, mesh_size=f.mesh_size,
                           refinement=f.refinement)
    assert spots == pytest.approx([f.mesh_size / f.refinement] * len(spots))


def test_the_thick_spot_rule_leaves_thinner_skins_wider_spots_and_finer_meshes_alone(monkeypatch):
    from tactileskin.mesh import sizing

    cases = [dict(thickness=t, indenter="braille", braille_text=x, mesh_size=h, refinement=8.0)
             for t in (1.0, 3.0, 4.9) for x in ("", "\u283f") for h in (0.8, 1.6, 2.4)]
    cases += [dict(thickness=5.0, indenter="braille", braille_text="", mesh_size=1.2, refinement=8.0),
              dict(thickness=5.0, indenter="sphere", indenter_radius=2.5, mesh_size=1.6, refinement=8.0)]
    now = [_spot_sizes(**c)[0] for c in cases]
    monkeypatch.setattr(sizing, "SPOT_FACTOR", 1.0)
    assert now == [_spot_sizes(**c)[0] for c in cases]
    assert sizing.spot_factor(5.0, 0.72, 0.2) == 1.0  # the override
    monkeypatch.setattr(sizing, "SPOT_FACTOR", None)
    assert sizing.spot_factor(5.0, 0.72, 0.2) == sizing.spot_factor(8.0, 0.5, 0.3) == 3.0
    assert sizing.spot_factor(4.9, 0.72, 0.2) == sizing.spot_factor(5.0, 2.0, 0.2) == 1.0
    assert sizing.spot_factor(5.0, 0.72, 0.199) == 1.0


def test_the_thick_spot_rule_leaves_a_skin_with_sensors_inside_at_the_fine_size():
    """The 3x contact spot at t = 5 was measured on the bone map, which does not see the spot's
    detail; sensors inside the skin do: a line 0.4 mm deep under the `default` dot read +34 %
    under the dot at 3x. With such sensors the spot keeps its fine size; on the bonded surface
    (height 0: the bone) the rule holds."""
    line = {"name": "d", "kind": "line", "s": [0.0, 3.0], "pitch": [0.5], "z": [0.0]}
    for text in ("", "\u283f"):
        kw = dict(thickness=5.0, indenter="braille", braille_text=text, mesh_size=1.6, refinement=8.0)
        for where in ({"depth": 0.4}, {"height": 4.0}, {"depth": 4.99}):
            spots, _ = _spot_sizes(**kw, sensors=[line | where])
            assert spots == pytest.approx([0.2] * len(spots)), where
        for where in ({"height": 0.0}, {"depth": 5.0}):
            spots, _ = _spot_sizes(**kw, sensors=[line | where])
            assert spots == pytest.approx([0.6] * len(spots)), where
    pad = Scene(dim=3, skin="pad", thickness=5.0, indenter="braille", mesh_size=1.6, refinement=8.0)
    for sensors, size in (((), 0.6), ([line | {"depth": 1.0}], 0.2)):
        sc = pad.replace(sensors=sensors)
        assert [b[4] for b in sc.skin_kind.size_plan(sc).patches] == pytest.approx([size])
