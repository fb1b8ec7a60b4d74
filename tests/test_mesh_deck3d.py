"""The 3D CalculiX deck (mesh.deck3d) and the meshed indenter face (mesh.indenter3d): element
counts, node order (positive isoparametric volumes that add up to the mesh's), sets, surfaces,
supports as the 3D solver applies them, and the indenter face on the kind's exact surface.
No CalculiX needed (benchmarks/calculix_compare3d.py runs ccx), but for one force-control run where ccx is
installed (skipped otherwise)."""

from __future__ import annotations

import os
import shutil
from types import SimpleNamespace

import numpy as np
import pytest

from tactileskin.errors import ParameterError
from tactileskin.geometry.indenters import indenter_for_scene
from tactileskin.mesh import build_mesh
from tactileskin.mesh.deck import FACES, _num, deck_text, parse_deck, undefined_names
from tactileskin.mesh.indenter3d import CHORD_TOL, cap_rise, curved_cap, indenter_face, max_chord_error, wedge_cells
from tactileskin.scene import Scene
from mesh_probe import c3d10_grad


@pytest.fixture(scope="module")
def braille():
    sc = Scene(thickness=1.0, material="polyurethane", indenter="braille", dim=3, viscoelastic=False,
               mesh_size=1.6, refinement=8.0)
    sm = build_mesh(sc)
    return sc, sm, deck_text(sc, sm, "calculix")


def _elements(p, etype):
    ids = sorted(k for k, (t, _) in p["elements"].items() if t == etype)
    X = np.array([[p["nodes"][n] for n in p["elements"][k][1]] for k in ids])
    return ids, X


def test_c3d10_cells_have_positive_volumes_adding_up_to_the_mesh(braille):
    from skfem.quadrature import get_quadrature
    from skfem.refdom import RefTet

    sc, sm, deck = braille
    p = parse_deck(deck.text)
    ids, X = _elements(p, "C3D10")
    assert len(ids) == deck.n_skin_cells == sm.mesh.nelements
    pts, w = get_quadrature(RefTet, 4)  # det J of a P2 tet is cubic: integrated exactly
    dets = np.stack([np.linalg.det(np.einsum("kd,ckD->cDd", c3d10_grad(pts[:, q]), X))
                     for q in range(len(w))], 1)
    assert np.all(dets > 0.0)  # at every point of every element, curved boundary cells too
    assert (dets @ w).sum() == pytest.approx(sm.measure(), rel=1e-10)


def test_wedges_are_positive_and_their_face_s1_is_the_working_face(braille):
    sc, sm, deck = braille
    p = parse_deck(deck.text)
    ids, X = _elements(p, "C3D6")
    assert len(ids) == deck.info["indenter_cells"] > 0
    # C3D6 (Abaqus / ccx): corners 1-2-3 counter-clockwise seen from 4-5-6 = positive volume
    bot, top = X[:, :3], X[:, 3:]
    n = np.cross(bot[:, 1] - bot[:, 0], bot[:, 2] - bot[:, 0])
    assert np.all(np.einsum("ij,ij->i", n, top.mean(1) - bot.mean(1)) > 0.0)
    assert np.all(n[:, 1] > 0.0)  # S1's outward normal (-n) points down, to the skin
    ind = indenter_for_scene(sc)
    x0, x1, z0, z1 = ind.face_box()
    b = bot.reshape(-1, 3)
    inside = (b[:, 0] >= x0) & (b[:, 0] <= x1) & (b[:, 2] >= z0) & (b[:, 2] <= z1)
    assert np.allclose(b[inside, 1], ind.surface_y(b[inside, 0], b[inside, 2]), atol=1e-12, rtol=0)
    faces = p["surfaces"]["indenter_face"][1]
    assert {r[1] for r in faces} == {"S1"} and len(faces) == len(ids)


def test_sets_surfaces_and_supports_are_the_solvers(braille):
    sc, sm, deck = braille
    p = parse_deck(deck.text)
    assert undefined_names(p) == []
    assert len(p["nodes"]) == deck.n_skin_nodes + deck.info["indenter_nodes"]
    for name, facets in sm.boundaries.items():
        faces = p["surfaces"][f"{name}_faces"][1]
        assert len(faces) == len(facets)
        nset = set(p["nsets"][name])
        # all six nodes of each listed face (corners and C3D10 mid-nodes) are the boundary's:
        # a wrong mid-node order would name a node off the face
        mids = {(0, 1, 2): (4, 5, 6), (0, 3, 1): (7, 8, 4), (1, 3, 2): (8, 9, 5), (2, 3, 0): (9, 7, 6)}
        for e, f in faces:
            nodes = p["elements"][int(e)][1]
            loc = FACES["C3D10"][int(f[1:]) - 1]
            assert {nodes[i] for i in loc + mids[loc]} <= nset
    # the quarter model: bonded bone and nail fixed, x = 0 and z = 0 symmetry planes, z = 10 free
    bc = [b for b in p["blocks"] if b[0] == "BOUNDARY" and "AMPLITUDE" not in b[1]]
    rows = {tuple(r) for b in bc for r in b[2]}
    assert rows == {("bone_interface", "1", "3"), ("nail_edge", "1", "3"), ("symmetry", "1", "1"),
                    ("end_back", "3", "3"), ("indenter_nodes", "1", "1"), ("indenter_nodes", "3", "3")}
    assert sm.z_symmetric and sm.halved and deck.info["force_factor"] == 4.0
    X = np.array([p["nodes"][n] for n in p["nsets"]["end_back"]])
    assert np.all(X[:, 2] == 0.0)
    moved = next(b for b in p["blocks"] if b[0] == "BOUNDARY" and b[1].get("AMPLITUDE") == "travel")
    assert moved[2] == [["indenter_nodes", "2", "2", _num(-sc.indentation)]]
    pair = next(b for b in p["blocks"] if b[0] == "CONTACT PAIR")
    assert pair[1]["TYPE"] == "SURFACE TO SURFACE" and pair[2] == [["outer_surface_faces", "indenter_face"]]
    mat = p["materials"]["polyurethane"]
    assert [kw for kw, _, _ in mat] == ["HYPERFOAM"]  # elastic: ccx has no Prony series
    # every number fits CalculiX's 20-character fields
    assert all(len(v) <= 20 for kw, _, rows in p["blocks"] if kw != "HEADING" for r in rows for v in r)


def test_a_flat_plate_deck_has_no_z_symmetry_only_where_the_mesh_has_none():
    sc = Scene(thickness=1.0, material="polyurethane", indenter="flat", dim=3, mesh_size=1.6, refinement=2.0)
    sm = build_mesh(sc, mesh_size=2.5, refinement=2.0)
    deck = deck_text(sc, sm, "calculix")
    p = parse_deck(deck.text)
    assert undefined_names(p) == []
    ids, X = _elements(p, "C3D6")
    assert np.all(X[:, :3, 1] == indenter_for_scene(sc).y0)  # the plane y = y0 at zero travel
    assert deck.info["face_chord_error_mm"] < 1e-12
    # the face covers the skin with 1 mm to spare on every side
    Xs = sm.mesh.doflocs
    assert X[:, :, 0].min() == pytest.approx(Xs[0].min() - 1.0) and X[:, :, 2].max() == pytest.approx(Xs[2].max() + 1.0)
    from tactileskin.mesh.slab3d import build_slab_mesh

    whole = build_slab_mesh(sc, mesh_size=2.5, refinement=2.0, use_z_symmetry=False)
    d2 = deck_text(sc, whole, "calculix")
    assert "end_back, 3, 3" not in d2.text and d2.info["force_factor"] == 2.0
    assert "end_back, 3, 3" in deck.text


def test_braille_face_follows_the_caps_within_microns():
    sc = Scene(thickness=1.0, indenter="braille", dim=3)
    ind = indenter_for_scene(sc)
    face = indenter_face(ind, (-1.0, 8.0, -1.0, 11.0), 1.6)
    err = max_chord_error(face, ind)
    assert 0.0 < err < 1.5e-3  # mm, measured vertically (the rim is steep: slope 2.4)
    coarse = indenter_face(ind, (-1.0, 8.0, -1.0, 11.0), 1.6, h_dot=0.09)
    assert len(coarse.tris) < len(face.tris) and max_chord_error(coarse, ind) > 2.0 * err
    a = 0.5 * ind.standard.base_diameter
    r = np.hypot(face.points[:, 0], face.points[:, 2])
    assert np.sum(np.isclose(r, a, atol=1e-9)) >= 24  # the base circle is a line of nodes (the kink)
    # no facet straddles the rim: each lies on the cap or on the plate
    rt = r[face.tris]
    assert not np.any((rt.min(1) < a - 1e-9) & (rt.max(1) > a + 1e-9))
    n = np.cross(*(face.points[face.tris[:, k]] - face.points[face.tris[:, 0]] for k in (1, 2)))
    assert np.all(n[:, 1] < 0.0)
    pts, cells = wedge_cells(face, 0.5)
    assert cells.shape == (len(face.tris), 6) and np.allclose(pts[len(face.points):, 1] - face.points[:, 1], 0.5)


def test_bad_requests_raise_typed_errors(braille):
    sc, sm, _ = braille
    with pytest.raises(ParameterError, match="dialect"):
        deck_text(sc, sm, "abaqus")
    with pytest.raises(ParameterError, match="penalty"):
        deck_text(sc, sm, "calculix", penalty=-1.0)
    ind = indenter_for_scene(Scene(indenter="sphere", indenter_radius=2.0, dim=3))
    with pytest.raises(ParameterError, match="reach"):  # how far up to mesh it: the travel
        indenter_face(ind, (0, 1, 0, 1), 0.5)
    with pytest.raises(ParameterError, match="indenter"):
        indenter_face(SimpleNamespace(kind="file"), (0, 1, 0, 1), 0.5)
    with pytest.raises(ParameterError, match="box"):
        indenter_face(indenter_for_scene(sc), (1, 0, 0, 1), 0.5)


def test_numbers_fit_calculix_fields():
    for v in (-1.0000245733392007e-14, 1.2345678901234567e-4, -3.5790351206165774, 7.0, 0.0, -1.5e-300):
        s = _num(v)
        assert len(s) <= 20 and float(s) == pytest.approx(v, rel=1e-12, abs=0)
    assert _num(-3.5790351206165774) == repr(-3.5790351206165774)  # exact where it fits


def test_cli_exports_a_3d_calculix_deck(tmp_path, capsys):
    from tactileskin.cli import main

    out = tmp_path / "slab.inp"
    args = ["export", "--dim", "3", "-t", "1", "-m", "polyurethane", "-i", "braille", "--mesh-size", "1.6",
            "--refinement", "8", "--elastic", "-o", str(out)]
    assert main(args) == 0  # the dialect defaults to calculix in 3D
    said = capsys.readouterr().out
    assert "C3D10" in said and "C3D6" in said and "calculix" in said
    p = parse_deck(out.read_text())
    assert undefined_names(p) == [] and "indenter_face" in p["surfaces"]


def _benchmark():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "calculix_compare3d.py"
    spec = importlib.util.spec_from_file_location("calculix_compare3d", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_benchmark_without_ccx_says_so_and_writes_nothing(tmp_path, monkeypatch, capsys):
    bench = _benchmark()
    monkeypatch.setattr(bench.shutil, "which", lambda name: None)
    out = tmp_path / "cmp.md"
    assert bench.main(["--case", "braille:1", "--out", str(out)]) == 2
    assert "calculix-ccx" in capsys.readouterr().err
    assert not out.exists() and not list(tmp_path.iterdir())


def test_benchmark_reads_the_last_integration_point_block(tmp_path):
    dat = tmp_path / "job.dat"
    dat.write_text(
        "\n stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz) for set SKIN and time  0.1\n\n"
        "         1   1  1.0 2.0 3.0 0.0 0.0 0.0\n         1   2  9.0 9.0 9.0 0.0 0.0 0.0\n"
        "\n stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz) for set SKIN and time  0.2\n\n"
        "         1   1 -1.0E-01 -2.0E-01 -3.0E-01 0.0 0.0 0.0\n"
        "         1   2 -4.0E-01 -5.0E-01 -6.0E-01 0.0 0.0 0.0\n"
        "         2   1  1.5 2.5 3.5 0.0 0.0 0.0\n"
        "\n total force (fx,fy,fz) for set INDENTER_NODES and time  0.2\n\n  1.0 2.0 3.0\n")
    ip = _benchmark().read_dat_elstress(dat)
    assert sorted(ip) == [1, 2] and ip[1].shape == (2, 6)
    assert np.allclose(ip[1][:, :3], [[-0.1, -0.2, -0.3], [-0.4, -0.5, -0.6]]) and np.allclose(ip[2][0, :3], [1.5, 2.5, 3.5])


def test_a_dot_cut_by_the_footprint_stays_inside_it():
    """A footprint box that cuts a dot's base circle (a slab narrower than the text) keeps
    the face inside the box, the cut cap included."""
    sc = Scene(thickness=1.0, indenter="braille", dim=3)
    ind = indenter_for_scene(sc)
    face = indenter_face(ind, (0.3, 3.0, -2.0, 2.0), 0.5)  # the dot at x = 0 is cut at x = 0.3
    assert face.points[:, 0].min() == pytest.approx(0.3) and face.points[:, 0].max() == pytest.approx(3.0)
    on_cap = np.hypot(face.points[:, 0], face.points[:, 2]) < 0.5 * ind.standard.base_diameter - 1e-9
    assert on_cap.any() and max_chord_error(face, ind) < 5e-3


def test_default_penalty_is_forty_k0_over_h(braille):
    """At 10 K0/h (the 2D default) ccx let the t = 1 plate penetrate 3.5 % of the travel."""
    from tactileskin.materials import get_material

    sc, sm, deck = braille
    hf = get_material(sc.material).hyperfoam
    assert deck.info["penalty_mpa_per_mm"] == pytest.approx(40.0 * max(hf.K0, hf.mu0) / sm.sizes["fine"])
    p = parse_deck(deck.text)
    slope = next(rows for kw, _, rows in p["blocks"] if kw == "SURFACE BEHAVIOR")
    assert float(slope[0][0]) == pytest.approx(deck.info["penalty_mpa_per_mm"])


def _on_cap(cap, P):
    return np.hypot(P[:, 0], P[:, 2]) < cap.a - 1e-9 if cap.axis is None else \
        np.abs(P[:, 0 if cap.axis == "z" else 2]) < cap.a - 1e-9


@pytest.mark.parametrize("kw", [dict(indenter="sphere", indenter_radius=2.5),
                                dict(indenter="curved"),
                                dict(indenter="cylinder", indenter_radius=3.0, indenter_axis="x")])
def test_sphere_and_cylinder_faces_lie_on_the_exact_surface(kw):
    """Nodes on the exact surface; facets within CHORD_TOL x the travel of it by the solver's
    own gap (chords lie inside a convex indenter: g in [-tol, 0]); the rim a line of nodes
    and no facet across it; past it the flat flange, twice the travel above the lowest point."""
    sc = Scene(thickness=1.0, skin="pad", depth=0.2, dim=3, **kw)
    ind = indenter_for_scene(sc)
    box = (-1.0, 8.0, -1.0, 11.0)  # a quarter pad's footprint
    face = indenter_face(ind, box, 1.6, reach=sc.reach)
    cap, tol = curved_cap(ind, sc.reach), CHORD_TOL * sc.reach
    assert cap_rise(ind, sc.reach) == pytest.approx(0.4) and tol == pytest.approx(1e-3)
    X = face.points
    on = _on_cap(cap, X)
    assert on.sum() > 100
    z0, z1 = ind.face_box()[2:]  # a cylinder along z is uniform past its printed ends
    assert np.allclose(X[on, 1], ind.surface_y(X[on, 0], np.clip(X[on, 2], z0, z1)), atol=1e-12, rtol=0)
    assert np.allclose(X[~on, 1], ind.y0 + 0.4, atol=1e-12, rtol=0)  # the flange
    assert X[:, 1].min() == pytest.approx(ind.y0, abs=1e-12)  # a node (a line) where it first touches
    W = np.array([(1, 1, 1), (2, 1, 1), (1, 2, 1), (1, 1, 2)], float) / np.array([[3.0], [4], [4], [4]])
    P = np.einsum("wk,tkd->twd", W, X[face.tris]).reshape(-1, 3)
    g, _ = ind.gap(P[_on_cap(cap, P)])
    assert g.max() <= 1e-12 and -tol <= g.min() < -0.1 * tol
    assert 0.1 * tol < max_chord_error(face, ind) <= tol
    across = np.hypot(X[:, 0], X[:, 2]) if cap.axis is None else np.abs(X[:, 0 if cap.axis == "z" else 2])
    assert np.sum(np.isclose(across, cap.a, atol=1e-9)) >= 24  # the rim (the kink) is a line of nodes
    at = across[face.tris]
    assert not np.any((at.min(1) < cap.a - 1e-9) & (at.max(1) > cap.a + 1e-9))
    n = np.cross(*(X[face.tris[:, k]] - X[face.tris[:, 0]] for k in (1, 2)))
    assert np.all(n[:, 1] < 0.0)  # facing the skin
    # the tolerance sets the size: facets twice as large are off by more than it
    coarse = indenter_face(ind, box, 1.6, h_dot=2.0 * face_cap_size(face, cap), reach=sc.reach)
    assert max_chord_error(coarse, ind) > tol


def face_cap_size(face, cap):
    """Median edge length (plan) of the facets inside the cap."""
    X = face.points
    t = face.tris[np.all(_on_cap(cap, X)[face.tris], axis=1)]
    e = np.linalg.norm(X[t[:, [1, 2, 0]]][:, :, [0, 2]] - X[t][:, :, [0, 2]], axis=2)
    return float(np.median(e))


def _pad_sphere_deck(**load):
    """(scene, mesh, deck, parsed deck) of an R 2.5 sphere on the t = 1 quarter pad at 1.6 / 8
    under `load` (depth= or force=); the deck's names all defined."""
    sc = Scene(thickness=1.0, material="polyurethane", skin="pad", indenter="sphere", indenter_radius=2.5,
               dim=3, viscoelastic=False, mesh_size=1.6, refinement=8.0, **load)
    sm = build_mesh(sc)
    deck = deck_text(sc, sm, "calculix")
    p = parse_deck(deck.text)
    assert undefined_names(p) == []
    return sc, sm, deck, p


def test_sphere_deck_on_a_pad():
    """A sphere (R 2.5, 0.2 mm) on a quarter pad: counts, sets, supports, the face's wedges on
    the sphere at the pole (the ccx run: benchmarks/results/calculix_compare3d.md)."""
    sc, sm, deck, p = _pad_sphere_deck(depth=0.2)
    ids, X = _elements(p, "C3D10")
    assert len(ids) == deck.n_skin_cells == sm.mesh.nelements
    ids, X = _elements(p, "C3D6")
    assert len(ids) == deck.info["indenter_cells"] > 1000
    assert len(p["nodes"]) == deck.n_skin_nodes + deck.info["indenter_nodes"]
    assert {"indenter_nodes", "bone_interface", "outer_surface", "symmetry", "end_back"} <= set(p["nsets"])
    assert {"indenter_face", "outer_surface_faces"} <= set(p["surfaces"])
    bc = [b for b in p["blocks"] if b[0] == "BOUNDARY" and "AMPLITUDE" not in b[1]]
    assert {tuple(r) for b in bc for r in b[2]} == {
        ("bone_interface", "1", "3"), ("symmetry", "1", "1"), ("end_back", "3", "3"),
        ("indenter_nodes", "1", "1"), ("indenter_nodes", "3", "3")}
    assert deck.info["force_factor"] == 4.0 and 0.0 < deck.info["face_chord_error_mm"] <= 1e-3
    b = X[:, :3].reshape(-1, 3)
    pole = np.hypot(b[:, 0], b[:, 2]) < 1.0
    ind = indenter_for_scene(sc)
    assert pole.sum() > 100 and np.allclose(b[pole, 1], ind.surface_y(b[pole, 0], b[pole, 2]), atol=1e-12, rtol=0)
    assert b[:, 1].min() == pytest.approx(ind.y0, abs=1e-12)  # a node at the pole: it touches the pad's top
    assert "a flat flange beyond" in deck.text


def _steps(p):
    """The blocks of each *STEP ... *END STEP, in order."""
    out, cur = [], None
    for b in p["blocks"]:
        if b[0] == "STEP":
            cur = []
        elif b[0] == "END STEP":
            out.append(cur)
            cur = None
        elif cur is not None:
            cur.append(b)
    return out


def test_force_control_is_a_pressed_pre_step_then_the_force_on_the_tied_indenter():
    """A free rigid indenter at first touch has no stiffness in y (the penalty acts on
    penetration only): the deck presses it PRE_TRAVEL x the expected travel, then frees its y
    and ramps the force on the node every indenter node's y is tied to. Was refused
    (ParameterError on loading); ccx reaches the force (benchmarks/results/calculix_compare3d.md)."""
    from tactileskin.mesh.deck3d import PRE_TRAVEL

    sc, sm, deck, p = _pad_sphere_deck(force=0.3)
    ref = deck.n_skin_nodes + 1
    assert p["nsets"]["indenter_ref"] == [ref] and p["nsets"]["indenter_nodes"][0] == ref
    eq = next(rows for kw, _, rows in p["blocks"] if kw == "EQUATION")
    assert all(r == ["2"] for r in eq[::2])
    terms = eq[1::2]  # each other indenter node's y follows the reference node's, once
    assert sorted(int(r[0]) for r in terms) == list(range(ref + 1, ref + deck.info["indenter_nodes"]))
    assert all(r[1:] == ["2", "1.", str(ref), "2", "-1."] for r in terms)
    supports = {tuple(r) for kw, prm, rows in p["blocks"][:p["blocks"].index(next(b for b in p["blocks"]
                                                                                  if b[0] == "STEP"))]
                if kw == "BOUNDARY" for r in rows}
    assert supports == {("bone_interface", "1", "3"), ("symmetry", "1", "1"), ("end_back", "3", "3"),
                        ("indenter_nodes", "1", "1"), ("indenter_nodes", "3", "3")}
    pre, load = _steps(p)
    assert [(kw, prm.get("AMPLITUDE"), rows) for kw, prm, rows in pre if kw == "BOUNDARY"] == [
        ("BOUNDARY", "pre", [["indenter_ref", "2", "2", _num(-PRE_TRAVEL * sc.indentation)]])]
    new = [b for b in load if b[0] == "BOUNDARY"]
    assert len(new) == 1 and new[0][1].get("OP") == "NEW" and {tuple(r) for r in new[0][2]} == supports
    cload = [b for b in load if b[0] == "CLOAD"]
    assert cload == [("CLOAD", {"AMPLITUDE": "travel"}, [["indenter_ref", "2", _num(-0.3 / 4.0)]])]
    assert deck.info["force_factor"] == 4.0 and deck.info["force_n"] == 0.3 and deck.info["depth_mm"] is None
    assert "*NODE PRINT, NSET=indenter_ref\nU\n" in deck.text  # the travel, which force control finds
    # a depth scene keeps its one displacement step and no ties
    d = deck_text(sc.replace(force=None, depth=0.2), sm, "calculix")
    assert "*EQUATION" not in d.text and "*CLOAD" not in d.text and d.text.count("*STEP") == 1


def test_a_file_indenter_is_written_as_its_own_triangles(tmp_path):
    """A user's STL indenter: the wedges' faces S1 are its own triangles as the solver places
    them (the surface its gap measures: no chord error), all of those that reach below
    y0 + CAP_RISE x the travel over the skin; a face with walls there is refused, the file
    named. Was refused for every file ("not meshed as rigid 3D surfaces yet")."""
    trimesh = pytest.importorskip("trimesh")
    f = tmp_path / "ball.stl"
    trimesh.creation.icosphere(subdivisions=3, radius=2.5).export(f)
    sc = Scene(thickness=1.0, material="polyurethane", skin="pad", indenter="file", indenter_file=str(f),
               depth=0.2, dim=3, viscoelastic=False, mesh_size=1.6, refinement=8.0)
    sm = build_mesh(sc)
    deck = deck_text(sc, sm, "calculix")
    p = parse_deck(deck.text)
    assert undefined_names(p) == [] and deck.info["force_factor"] == 4.0
    ids, X = _elements(p, "C3D6")
    assert len(ids) == deck.info["indenter_cells"] > 0 and deck.info["face_chord_error_mm"] == 0.0
    ind = indenter_for_scene(sc)
    key = lambda t: tuple(sorted(map(tuple, np.round(t, 9))))  # noqa: E731 - a triangle, any order
    tris = ind.vertices[ind.faces]
    assert {key(t) for t in X[:, :3]} <= {key(t) for t in tris}
    low = tris[:, :, 1].max(axis=1) <= ind.y0 + 0.4  # CAP_RISE x 0.2 mm
    over = np.all((tris[:, :, [0, 2]] >= 0.0) & (tris[:, :, [0, 2]] <= 10.0), axis=(1, 2))  # the quarter pad
    assert (low & over).sum() >= 10 and {key(t) for t in tris[low & over]} <= {key(t) for t in X[:, :3]}
    assert X[:, :3, 1].min() == pytest.approx(ind.y0, abs=1e-12)
    bot, top = X[:, :3], X[:, 3:]
    n = np.cross(bot[:, 1] - bot[:, 0], bot[:, 2] - bot[:, 0])
    assert np.all(np.einsum("ij,ij->i", n, top.mean(1) - bot.mean(1)) > 0.0) and np.all(n[:, 1] > 0.0)
    box = tmp_path / "punch.stl"  # a flat punch: its side walls rise from its face
    trimesh.creation.box(extents=(2.0, 2.0, 2.0)).export(box)
    with pytest.raises(ParameterError, match=r"indenter_file=.*punch.stl.*walls"):
        deck_text(sc.replace(indenter_file=str(box)), sm, "calculix")


@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) not installed")
def test_ccx_runs_a_force_controlled_deck_on_a_coarse_mesh(tmp_path):
    """The pre-step must leave a contact that carries the first force increment: at 1 % of
    the expected travel (0.002 mm) the sphere at 0.3 N on the 1.6 / 4 pad left ccx 2.20 a
    singular matrix in step 2's first increment (spooles, exit 255; likewise the commit's
    1.6 / 8 deck under OMP_NUM_THREADS=2), so the deck written as good did not run. At 5 % it
    reaches the force (0.0750 N on the quarter) at a travel of 0.1947 mm (~12 s)."""
    import subprocess

    sc = Scene(thickness=1.0, material="polyurethane", skin="pad", indenter="sphere", indenter_radius=2.5,
               force=0.3, dim=3, viscoelastic=False, mesh_size=1.6, refinement=4.0)
    deck = deck_text(sc, build_mesh(sc), "calculix")
    (tmp_path / "f.inp").write_text(deck.text)
    run = subprocess.run(["ccx", "-i", "f"], cwd=tmp_path, capture_output=True, text=True, timeout=600,
                         env={**os.environ, "OMP_NUM_THREADS": "1"})
    assert run.returncode == 0 and "Job finished" in run.stdout, run.stdout[-2000:]
    dat = (tmp_path / "f.dat").read_text()
    fy = float(dat.split("for set BONE_INTERFACE")[-1].split()[4])
    assert fy == pytest.approx(0.3 / deck.info["force_factor"], rel=1e-3)
