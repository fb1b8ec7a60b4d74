"""Abaqus / CalculiX input decks (mesh.deck): node order, sets and surfaces, material
constants, the indenter, and that the deck parses back."""

from __future__ import annotations

import numpy as np
import pytest

from tactileskin.errors import ParameterError
from tactileskin.materials import get_material
from tactileskin.materials.hyperfoam import Hyperfoam, energy
from tactileskin.materials.presets import Material
from tactileskin.materials.prony import Prony
from tactileskin.mesh import build_mesh
from tactileskin.mesh.deck import (FACES, _FLIP, abaqus_cells, analytic_segments, boundary_faces,
                                   deck_text, indenter_strip, material_lines, parse_deck,
                                   segment_points, undefined_names)
from tactileskin.mesh.skinmesh import SkinMesh
from tactileskin.scene import Scene
from mesh_probe import c3d10_grad


@pytest.fixture(scope="module")
def scene_mesh():
    sc = Scene(thickness=1.0, material="polyurethane", indenter="flat", mesh_size=0.5, refinement=2.0)
    return sc, build_mesh(sc)


# --- isoparametric measures in Abaqus node order (independent of scikit-fem) -------------

def _p2_tri_grad(xi, eta):
    """dN/d(xi, eta) of CPE6 (corners 1-3, mid-sides 1-2, 2-3, 3-1), shape (6, 2)."""
    l1, l2, l3 = 1.0 - xi - eta, xi, eta
    dl = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
    L = (l1, l2, l3)
    rows = [(4 * L[i] - 1) * dl[i] for i in range(3)]
    for i, j in ((0, 1), (1, 2), (2, 0)):
        rows.append(4 * (L[i] * dl[j] + L[j] * dl[i]))
    return np.array(rows)


def _signed_measures(X: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """(integral of det J, min det J at the points) per cell, X (cells, nodes, dim); degree-4
    rules (det J of a P2 cell is degree 2 in 2D, 3 in 3D: integrated exactly)."""
    from skfem.quadrature import get_quadrature
    from skfem.refdom import RefTet, RefTri

    pts, w = get_quadrature(RefTri if dim == 2 else RefTet, 4)
    grad = _p2_tri_grad if dim == 2 else (lambda *a: c3d10_grad(np.array(a)))
    dets = np.stack([np.linalg.det(np.einsum("kd,ckD->cDd", grad(*pts[:, q]), X)) for q in range(len(w))], 1)
    return dets @ w, dets.min(axis=1)


def test_cpe6_order_gives_positive_areas_summing_to_the_mesh_area(scene_mesh):
    sc, sm = scene_mesh
    etype, pts, cells = abaqus_cells(sm)
    assert etype == "CPE6"
    area, jmin = _signed_measures(pts[cells], 2)
    assert np.all(jmin > 0.0)
    # the curved P2 cells' total area, by scikit-fem's own mapping; same quadrature degree
    # (exact for both), so only rounding separates them
    assert area.sum() == pytest.approx(sm.measure(), rel=1e-12)
    # a wrong mid-node order would move curved edges: check against the cell-by-cell skfem measure
    from skfem import Functional, CellBasis

    per_cell = Functional(lambda w: 1.0 + 0.0 * w.x[0]).elemental(CellBasis(sm.mesh, sm.mesh.elem()))
    assert np.allclose(area, per_cell, rtol=1e-11, atol=0)


def test_flip_reverses_orientation_of_curved_cells():
    """The reversal permutations keep each mid node between its two corners: the signed
    measure of a curved cell changes sign only (a wrong permutation changes its size)."""
    rng = np.random.default_rng(1)
    tri = np.array([[0, 0], [1, 0], [0, 1], [0.5, -0.1], [0.55, 0.5], [-0.05, 0.5]], float)
    tet = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    edges = ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))
    tet = np.concatenate([tet, [0.5 * (tet[i] + tet[j]) + 0.05 * rng.standard_normal(3) for i, j in edges]])
    for etype, X, dim in (("CPE6", tri, 2), ("C3D10", tet, 3)):
        a, _ = _signed_measures(X[None], dim)
        b, _ = _signed_measures(X[list(_FLIP[etype])][None], dim)
        assert a[0] > 0 and b[0] == pytest.approx(-a[0], rel=1e-13)


def test_c3d10_order_gives_the_tetrahedra_volumes():
    from skfem import CellBasis, Functional, MeshTet, MeshTet2

    m1 = MeshTet.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 2), np.linspace(0, 2, 3))
    # P2 nodes: the vertices, then the edge midpoints moved by a smooth field (curved cells)
    mid = 0.5 * (m1.p[:, m1.edges[0]] + m1.p[:, m1.edges[1]])
    mid += 0.03 * np.sin(3.0 * mid[[1, 2, 0]])
    m = MeshTet2(np.concatenate([m1.p, mid], axis=1), m1.t)
    assert np.allclose(m.doflocs[:, m1.nvertices:], mid)
    sm = SkinMesh(mesh=m, boundaries={}, dim=3, quality={})
    etype, pts, cells = abaqus_cells(sm)
    assert etype == "C3D10"
    vol, jmin = _signed_measures(pts[cells], 3)
    assert np.all(jmin > 0.0)
    per_cell = Functional(lambda w: 1.0 + 0.0 * w.x[0]).elemental(CellBasis(m, m.elem()))
    assert np.allclose(vol, per_cell, rtol=1e-11, atol=0)


def test_boundary_faces_are_the_facets_and_face_outwards(scene_mesh):
    sc, sm = scene_mesh
    etype, pts, cells = abaqus_cells(sm)
    for name, facets in sm.boundaries.items():
        rows = boundary_faces(sm, cells, etype, facets)
        assert len(rows) == len(facets)
        for (e, f), fc in zip(rows, facets):
            i, j = FACES[etype][f - 1]
            a, b = pts[cells[e, i]], pts[cells[e, j]]
            assert sorted((cells[e, i], cells[e, j])) == sorted(sm.mesh.facets[:, fc].tolist())
            t = b - a
            n = np.array([t[1], -t[0]])  # the outward side of a counter-clockwise cell
            centroid = pts[cells[e, :3]].mean(axis=0)
            assert n @ (0.5 * (a + b) - centroid) > 0.0


@pytest.mark.parametrize("dialect", ["abaqus", "calculix"])
def test_deck_parses_back_and_defines_every_name(scene_mesh, dialect, tmp_path):
    import meshio

    sc, sm = scene_mesh
    deck = deck_text(sc, sm, dialect)
    p = parse_deck(deck.text)
    assert undefined_names(p) == []
    assert len(p["elsets"]["skin"]) == deck.n_skin_cells == sm.mesh.t.shape[1]
    for name, facets in sm.boundaries.items():
        assert len(p["surfaces"][f"{name}_faces"][1]) == len(facets)
    # a node set per boundary = all nodes of its facets (P2: 2 per facet + 1)
    assert len(p["nsets"]["symmetry"]) == 2 * len(sm.boundaries["symmetry"]) + 1
    if dialect == "abaqus":  # meshio's reader does not know CPE4 (the CalculiX indenter strip)
        path = tmp_path / "deck.inp"
        path.write_text(deck.text)
        m = meshio.read(path)  # the mesh part: nodes and elements
        assert len(m.points) == len(p["nodes"]) == deck.n_skin_nodes + 1  # + the reference node
        # exact where the shortest round-trip text fits CalculiX's 20-character fields
        assert np.allclose(m.points[:deck.n_skin_nodes, :2], sm.mesh.doflocs.T, rtol=0, atol=1e-13)
        tri6 = [c for c in m.cells if c.type == "triangle6"]
        assert sum(len(c.data) for c in tri6) == deck.n_skin_cells
    kws = [b[0] for b in p["blocks"]]
    assert kws.count("STEP") == 1 and kws.count("END STEP") == 1
    step = next(b for b in p["blocks"] if b[0] == "STEP")
    assert "NLGEOM" in step[1]
    # the travel: the indenter is moved by -depth with the ramp amplitude
    moved = [b for b in p["blocks"] if b[0] == "BOUNDARY" and b[1].get("AMPLITUDE") == "travel"]
    assert float(moved[0][2][0][3]) == pytest.approx(-sc.indentation)
    amp = next(b for b in p["blocks"] if b[0] == "AMPLITUDE")
    assert [float(v) for v in amp[2][0]] == pytest.approx([0.0, 0.0, sc.duration, 1.0])


def _hyperfoam_rows(text):
    p = parse_deck(text)
    (name, blocks), = [(k, v) for k, v in p["materials"].items() if k != "indenter_rigid"]
    return {kw: (prm, rows) for kw, prm, rows in blocks}


@pytest.mark.parametrize("name", ["silicone", "polyurethane"])
def test_material_constants_round_trip(name):
    mat = get_material(name)
    d = _hyperfoam_rows(material_lines(mat, viscoelastic=True, dialect="abaqus"))
    prm, rows = d["HYPERFOAM"]
    n = int(prm["N"])
    assert prm["MODULI"] == "INSTANTANEOUS"  # g(0) = 1 multiplies the hyperfoam stress
    vals = [float(v) for r in rows for v in r]
    assert len(vals) == 3 * n
    mu, alpha, nus = vals[0:2 * n:2], vals[1:2 * n:2], vals[2 * n:]
    hf = Hyperfoam(tuple(mu), tuple(alpha), nus[0])
    assert hf == mat.hyperfoam and len(set(nus)) == 1
    # Abaqus' beta_i = nu_i / (1 - 2 nu_i) is the law's beta; its energy with these constants
    # (transcribed from the Abaqus formula) is materials.energy
    beta = nus[0] / (1.0 - 2.0 * nus[0])
    assert beta == pytest.approx(mat.hyperfoam.beta, rel=1e-15)
    lam = np.array([0.8, 1.1, 0.95])
    J = lam.prod()
    U = sum(2 * m / a ** 2 * (np.sum(lam ** a) - 3 + (J ** (-a * beta) - 1) / beta) for m, a in zip(mu, alpha))
    assert float(energy(mat.hyperfoam, np.diag(lam ** 2))) == pytest.approx(U, rel=1e-9)
    prm, rows = d["VISCOELASTIC"]
    assert prm["TIME"] == "PRONY"
    g, k, tau = (np.array([float(r[i]) for r in rows]) for i in range(3))
    assert np.array_equal(g, mat.prony.g) and np.array_equal(k, g) and np.array_equal(tau, mat.prony.tau)
    # CalculiX and elastic decks carry no *VISCOELASTIC and no MODULI
    for kw in ({"dialect": "calculix", "viscoelastic": True}, {"dialect": "abaqus", "viscoelastic": False}):
        d = _hyperfoam_rows(material_lines(mat, **kw))
        assert "VISCOELASTIC" not in d and "MODULI" not in d["HYPERFOAM"][0]


def test_hyperfoam_lines_wrap_at_eight_values():
    mat = Material("three", Hyperfoam((0.1, 0.05, 0.01), (2.0, 5.0, -1.0), 0.3), Prony((), ()))
    d = _hyperfoam_rows(material_lines(mat, viscoelastic=False, dialect="calculix"))
    assert [len(r) for r in d["HYPERFOAM"][1]] == [8, 1]  # mu1 a1 mu2 a2 mu3 a3 nu1 nu2 / nu3
    four = Material("four", Hyperfoam((0.1,) * 4, (2.0,) * 4, 0.3), Prony((), ()))
    with pytest.raises(ParameterError, match="CalculiX"):
        material_lines(four, viscoelastic=False, dialect="calculix")


@pytest.mark.parametrize("kind,text", [("flat", ""), ("curved", ""), ("braille", ""), ("braille", "ab"),
                                       ("cylinder", "")])
def test_analytic_segments_lie_on_the_indenter_and_face_the_skin(kind, text):
    """Every 2D kind, the cylinder along z too (it ended in an AttributeError traceback)."""
    from tactileskin.geometry.indenters import indenter_for_scene

    extra = {"indenter_radius": 3.0} if kind == "cylinder" else {}
    ind = indenter_for_scene(Scene(thickness=3.0, indenter=kind, braille_text=text, **extra))
    hi = min(6.0, 0.5 * ind.width)  # the face as wide as the kind makes it (a 3 mm cylinder: 2.7)
    segs = analytic_segments(ind, -1.5, hi)
    assert segs[0][0] == "START" and segs[0][1] == hi and segs[-1][1] == -1.5
    pts, nrm = segment_points(segs, 41)
    g, n = ind.gap(pts, 0.0)
    assert np.abs(g).max() < 1e-9
    ends = np.array([s[1:3] for s in segs])
    smooth = np.min(np.linalg.norm(pts[:, None] - ends[None], axis=2), axis=1) > 1e-6
    # Abaqus' outward side (left of the direction of travel) is the indenter's outward normal
    assert np.allclose(np.einsum("ij,ij->i", nrm[smooth], n[smooth]), 1.0, atol=1e-9)


def test_calculix_strip_lines_the_face():
    from tactileskin.geometry.indenters import indenter_for_scene

    ind = indenter_for_scene(Scene(thickness=3.0, indenter="braille"))
    pts, cells = indenter_strip(ind, -1.0, 5.0, 0.1)
    n = len(pts) // 2
    g, _ = ind.gap(pts[:n], 0.0)
    assert np.abs(g).max() < 1e-12
    X = pts[cells]
    x, y = X[..., 0], X[..., 1]
    area = 0.5 * np.sum(x * np.roll(y, -1, 1) - np.roll(x, -1, 1) * y, axis=1)
    assert np.all(area > 0)
    assert np.all(np.diff(pts[:n, 0]) <= 0.1 + 1e-12)
    a = 0.5 * ind.standard.base_diameter
    assert np.any(np.isclose(pts[:n, 0], a)) and np.any(np.isclose(pts[:n, 0], -a))  # the kinks


def test_deck_refuses_a_mismatched_mesh_and_unknown_dialect(scene_mesh):
    sc, sm = scene_mesh
    with pytest.raises(ParameterError, match="dialect"):
        deck_text(sc, sm, "nastran")
    with pytest.raises(ParameterError, match="mesh='2D'.*a 3D mesh"):
        deck_text(sc.replace(dim=3), sm)
    # one displacement step: force control and loading histories are refused, not dropped
    for other in (sc.replace(depth=None, force=0.5), sc.replace(depth=0.4, loading=[{"hold": 10.0}])):
        with pytest.raises(ParameterError, match="loading.*a depth ramp"):
            deck_text(other, sm)


@pytest.mark.parametrize("dialect", ["abaqus", "calculix"])
@pytest.mark.parametrize("text", ["", "d"])
def test_a_pad_deck_supports_its_own_boundaries(dialect, text):
    """A pad's deck fixes its board (it named the fingertip's nail_edge, never defined) and has
    the x = 0 symmetry support only where the model is halved ('d' on the pad is modelled whole);
    a whole model's analytic face spans its whole width."""
    sc = Scene(skin="pad", pad_width=20.0, thickness=2.0, indenter="braille", braille_text=text,
               mesh_size=1.0, refinement=5.0)
    sm = build_mesh(sc)
    text_ = deck_text(sc, sm, dialect).text
    assert undefined_names(parse_deck(text_)) == []
    assert "nail_edge" not in text_
    assert ("symmetry, 1, 1" in text_) == (text == "")
    if dialect == "abaqus" and text:
        xs = [float(line.split(",")[1]) for line in text_.split("*SURFACE, TYPE=SEGMENTS")[1].split("*RIGID")[0]
              .strip().splitlines()[1:]]
        assert min(xs) <= -10.0 and max(xs) >= 10.0


def test_cli_export_writes_the_deck_and_rejects_bad_requests(tmp_path, capsys):
    from tactileskin.cli import main

    out = tmp_path / "case.inp"
    args = ["export", "-t", "1", "-m", "polyurethane", "--mesh-size", "0.5", "--refinement", "2"]
    assert main(args + ["--dialect", "calculix", "-o", str(out)]) == 0
    assert "CPE6" in capsys.readouterr().out
    p = parse_deck(out.read_text())
    assert undefined_names(p) == [] and "indenter_nodes" in p["nsets"]
    assert main(args + ["-o", str(tmp_path / "case.txt")]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and ".inp" in err and "Traceback" not in err
    # 3D decks are CalculiX only: refused before meshing, naming the option
    assert main(args + ["--dim", "3", "--dialect", "abaqus", "-o", str(tmp_path / "slab.inp")]) == 2
    err = capsys.readouterr().err
    assert "--dialect" in err and "calculix" in err and "Traceback" not in err
    assert sorted(q.name for q in tmp_path.iterdir()) == [".tactileskin-files.json", ".tactileskin-files.lock",
                                                          "case.inp"]  # its record of what it wrote, and its lock


@pytest.mark.parametrize("dim", ["2", "3"])
def test_export_refuses_a_law_the_deck_cannot_write_before_meshing(tmp_path, capsys, monkeypatch, dim):
    """A neo-Hookean material file was refused after meshing with 'valid: hyperfoam (use
    Material.law)', a Python hint, on the command line."""
    import tactileskin.mesh as mesh_pkg
    from tactileskin.cli import main

    si = get_material("silicone")
    mat = tmp_path / "nh.toml"
    mat.write_text(f'law = "neo_hookean"\n[neo_hookean]\nmu = {si.law.mu0!r}\nkappa = {si.law.K0!r}\n')
    monkeypatch.setattr(mesh_pkg, "build_mesh", lambda *a, **k: pytest.fail("meshed before the check"))
    out = tmp_path / "nh.inp"
    assert main(["export", "-t", "1", "-i", "flat", "--dim", dim, "-m", str(mat), "-o", str(out)]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert "neo_hookean" in err and "hyperfoam for a deck" in err and "Material.law" not in err, err
    assert "Traceback" not in err and not out.exists()


@pytest.mark.parametrize("argv", [
    ["--depth", "5e-324"],                                      # the flat plate: contact at 0 travel
    ["--depth", "1e-308"],
    ["-t", "1", "-i", "braille", "--braille-text", "ab"],       # dots at |x| = 3.1 mm: the plate alone
    ["-t", "1", "-i", "braille", "--braille-text", "ab", "--dim", "3", "--quality", "preview"],
])
def test_export_refuses_a_scene_without_contact_as_solve_does(tmp_path, capsys, argv):
    """`export --depth 5e-324` wrote an Abaqus deck moving the plate by 5e-324 mm over a
    5e-324 s *VISCO step (exit 0), and a Braille text whose dots touch nothing within the
    depth a deck of the base plate alone; `solve` refuses both ('no contact', require_contact).
    The deck now refuses them the same way, before meshing, and writes nothing."""
    from tactileskin.cli import main

    out = tmp_path / "d.inp"
    assert main(["export", *argv, "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "no contact" in err and "depth=" in err and "Traceback" not in err, err
    assert not out.exists()


def test_a_depth_at_the_first_touch_is_refused_with_a_range_it_is_outside(tmp_path, capsys, monkeypatch):
    """`--depth 5e-324` on the flat plate (first touch at 0 travel) was refused as 'depth=5e-324 is
    invalid; valid: > 0 mm': a value the message itself calls valid (contact needs depth > travel + 1e-9);
    likewise a first touch at 0.4764 mm refused depth 0.4762 under 'valid: > 0.476'. The bound shown is
    the one applied, rounded up."""
    import re

    import tactileskin.geometry.indenters as ind
    from tactileskin.cli import main
    from tactileskin.errors import ParameterError
    from tactileskin.scene import Scene

    assert main(["export", "--depth", "5e-324", "-o", str(tmp_path / "d.inp")]) == 2
    err = capsys.readouterr().err
    assert not 5e-324 > float(re.search(r"valid: > ([0-9.e+-]+) mm", err).group(1)), err
    monkeypatch.setattr(ind, "first_contact_travel", lambda scene: 0.4764)
    with pytest.raises(ParameterError) as e:
        ind.require_contact(Scene(thickness=1.0, depth=0.4762))
    assert not 0.4762 > float(re.search(r"valid: > ([0-9.e+-]+) mm", str(e.value)).group(1)), str(e.value)
