"""A scene as a complete Abaqus / CalculiX input deck (plane strain, per mm of depth).

`deck_text(scene, skinmesh, dialect)` writes: nodes; the skin's elements (CPE6 for the P2
triangles, CPE3 / CPE4 / CPE8 for the others); one *NSET per named boundary and one
element-face *SURFACE `<name>_faces` per boundary; the material as *HYPERFOAM (+ *VISCOELASTIC,
TIME=PRONY); *SOLID SECTION of thickness 1 mm (the paper's "thickness unit of 1"; every force
in the output is per mm of depth, as tactileskin's); the bone interface and nail edge fixed,
u_x = 0 on the symmetry line; the indenter moved down by the scene's travel over the scene's
ramp time; frictionless contact; one NLGEOM step; output requests.

Node ordering. scikit-fem's P2 triangle dofs are the 3 vertices then the edge nodes of edges
(0,1), (1,2), (0,2): Abaqus' CPE6 order (corners, then mid-side 1-2, 2-3, 3-1) unchanged;
the P2 tetrahedron's edges (0,1), (1,2), (0,2), (0,3), (1,3), (2,3) are C3D10's nodes 5-10
unchanged; quad9's edges (0,1), (1,2), (2,3), (0,3) are CPE8's 5-8 (the centre node dropped).
Abaqus wants the corners counter-clockwise (2D) / node 4 on the positive side of face 1-2-3
(3D); cells that are not are flipped (`abaqus_cells`). Tested by element areas and volumes.

Material (Abaqus Keywords Reference, *HYPERFOAM, and the Theory Manual's hyperfoam section):
U = sum_i 2 mu_i/alpha_i^2 [l1^a_i + l2^a_i + l3^a_i - 3 + (J^(-a_i beta_i) - 1)/beta_i],
beta_i = nu_i/(1 - 2 nu_i), initial shear modulus sum(mu_i): the same function and the same
mu_i, alpha_i, nu as `materials.Hyperfoam` (one nu for all terms: nu_i = nu). Data lines: all
(mu_i, alpha_i) pairs, then nu_1..nu_N, eight values a line (N = 2: one line of six values).
CalculiX reads the same layout (N <= 3) and evaluates the same derivative (its rubber.f:
dU/dC = sum 2 mu/alpha [sum_a l_a^(alpha-1) dl_a/dC - J^(-alpha beta - 1) dJ/dC]).
tactileskin's Prony series multiplies the instantaneous stress (g(0) = 1, `materials.prony`),
so the hyperfoam constants are *instantaneous*: MODULI=INSTANTANEOUS (Abaqus' default, LONG
TERM, would read the same numbers as the relaxed material, i.e. 1/g_inf stiffer at first:
1.78x for polyurethane). The series applies to the whole stress, so k_i = g_i on the
*VISCOELASTIC, TIME=PRONY lines (g_i, k_i, tau_i).

Dialects:
- "abaqus": the indenter is an analytical rigid surface (*SURFACE, TYPE=SEGMENTS; START /
  LINE / CIRCL, written from +x to -x so that the side to the left of the direction of
  travel, the surface's outward side in Abaqus' convention, faces the skin) on a *RIGID BODY
  whose reference node carries the travel; hard contact; *VISCO (viscoelastic) or *STATIC.
- "calculix" (ccx 2.20): no analytical surfaces and no *VISCOELASTIC (ccx has no Prony
  viscoelasticity), so the material is the instantaneous hyperfoam alone, the indenter face is
  a strip of CPE4 elements whose nodes are all moved by the travel (a rigid translation
  without *RIGID BODY), and the contact is surface-to-surface with a linear penalty
  (PRESSURE-OVERCLOSURE=LINEAR, slope `penalty` MPa/mm); *STATIC.
"""

from __future__ import annotations

import io
import logging
import math
import re
from dataclasses import dataclass, field

import numpy as np

from tactileskin.errors import ParameterError

log = logging.getLogger(__name__)

DIALECTS = ("abaqus", "calculix")

# corners per cell type, and face -> local corner indices (Abaqus face numbers S1, S2, ...)
_CELL = {  # (dim, order, cell) -> (Abaqus type, nodes kept)
    (2, 1, "tri"): ("CPE3", 3), (2, 2, "tri"): ("CPE6", 6),
    (2, 1, "quad"): ("CPE4", 4), (2, 2, "quad"): ("CPE8", 8),
    (3, 1, "tri"): ("C3D4", 4), (3, 2, "tri"): ("C3D10", 10),
}
FACES = {
    "CPE3": ((0, 1), (1, 2), (2, 0)), "CPE6": ((0, 1), (1, 2), (2, 0)),
    "CPE4": ((0, 1), (1, 2), (2, 3), (3, 0)), "CPE8": ((0, 1), (1, 2), (2, 3), (3, 0)),
    "C3D4": ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)),
    "C3D10": ((0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)),
}
# node permutation that reverses a cell's orientation (Abaqus order in, Abaqus order out)
_FLIP = {
    "CPE3": (0, 2, 1), "CPE6": (0, 2, 1, 5, 4, 3),
    "CPE4": (0, 3, 2, 1), "CPE8": (0, 3, 2, 1, 7, 6, 5, 4),
    "C3D4": (0, 2, 1, 3), "C3D10": (0, 2, 1, 3, 6, 5, 4, 7, 9, 8),
}
_CORNERS = {"CPE3": 3, "CPE6": 3, "CPE4": 4, "CPE8": 4, "C3D4": 4, "C3D10": 4}


def _orientation(etype: str, X: np.ndarray) -> np.ndarray:
    """Signed area (2D, shoelace of the corners) or 6x volume (3D) per cell; X (cells, k, dim)."""
    n = _CORNERS[etype]
    c = X[:, :n]
    if c.shape[-1] == 2:
        x, y = c[..., 0], c[..., 1]
        return 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)
    a, b, d = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0], c[:, 3] - c[:, 0]
    return np.einsum("ij,ij->i", np.cross(a, b), d)


def abaqus_cells(skinmesh) -> tuple[str, np.ndarray, np.ndarray]:
    """(element type, points (n, dim), cells (m, k) 0-based in Abaqus node order, corners
    counter-clockwise / positive volume)."""
    m = skinmesh.mesh
    key = (skinmesh.dim, skinmesh.order, skinmesh.cell)
    if key not in _CELL:
        raise ParameterError("mesh", f"{key}", "a 2D triangle/quad or 3D tetrahedral skin mesh")
    etype, k = _CELL[key]
    pts = np.asarray(m.doflocs.T, dtype=float)
    cells = np.asarray(m.dofs.element_dofs[:k].T, dtype=np.int64).copy()
    neg = _orientation(etype, pts[cells]) < 0.0
    if np.any(neg):
        cells[neg] = cells[neg][:, list(_FLIP[etype])]
    return etype, pts, cells


def contact_nodes(skinmesh) -> np.ndarray:
    """(n, dim) positions of the vertices of the contact boundary (outer_surface)."""
    mesh = skinmesh.mesh
    return mesh.p[:, np.unique(mesh.facets[:, skinmesh.boundaries["outer_surface"]])].T


def boundary_faces(skinmesh, cells: np.ndarray, etype: str, facets: np.ndarray) -> np.ndarray:
    """(n, 2) rows (cell index, Abaqus face number 1..) of the given boundary facets."""
    m = skinmesh.mesh
    f2t = np.asarray(m.f2t[0, facets])
    fverts = np.sort(np.asarray(m.facets[:, facets]).T, axis=1)
    faces = FACES[etype]
    out = np.empty((len(facets), 2), dtype=np.int64)
    for i, (e, fv) in enumerate(zip(f2t, fverts)):
        corners = cells[e]
        for j, loc in enumerate(faces):
            if np.array_equal(np.sort(corners[list(loc)]), fv):
                out[i] = (e, j + 1)
                break
        else:  # pragma: no cover - a facet always belongs to its cell
            raise ParameterError("mesh", f"facet {facets[i]}", "a facet of its neighbouring cell")
    return out


# --- the indenter -------------------------------------------------------------------------

def analytic_segments(indenter, x_lo: float, x_hi: float) -> list[tuple]:
    """The 2D indenter face at d = 0 as Abaqus SEGMENTS, from x_hi to x_lo: ("START", x, y),
    ("LINE", x, y), ("CIRCL", x, y, xc, yc) (arc to (x, y) about (xc, yc))."""
    kind = indenter.kind
    y = lambda x: float(indenter.surface_y(np.array([x]))[0])  # noqa: E731
    if kind == "flat":
        return [("START", x_hi, y(x_hi)), ("LINE", x_lo, y(x_lo))]
    if kind in ("curved", "cylinder"):  # a cylinder along z is the 2D section's circle
        R = indenter.radius
        return [("START", x_hi, y(x_hi)), ("CIRCL", x_lo, y(x_lo), 0.0, indenter.y0 + R)]
    if kind != "braille":
        raise ParameterError("indenter", kind, "flat, curved, cylinder or braille for a deck",
                             "other kinds are 3D only")
    std = indenter.standard
    R, yb = std.sphere_radius, indenter.base_plane(0.0)
    yc, a = yb + std.centre_offset, 0.5 * std.base_diameter
    segs = [("START", x_hi, yb)]
    for cx in sorted(indenter.section_x, reverse=True):
        if cx + a <= x_lo or cx - a >= x_hi:
            continue
        segs += [("LINE", cx + a, yb), ("CIRCL", cx - a, yb, cx, yc)]
    segs.append(("LINE", x_lo, yb))
    return segs


def _x_lo(indenter, x_min: float = 0.0) -> float:
    """Left end of the modelled face: 1 mm past the skin's left end (x_min: the symmetry line
    of a half model, else the whole model's edge), extended to take in whole Braille dots that
    straddle it."""
    x = float(x_min) - 1.0
    if indenter.kind == "braille":
        a = 0.5 * indenter.standard.base_diameter
        x = min([x] + [c - a - 0.5 for c in indenter.section_x if c + a > x])
    return max(x, -0.5 * indenter.width)


def segment_points(segs: list[tuple], n: int = 50) -> tuple[np.ndarray, np.ndarray]:
    """Points along the segments and the unit normal to the left of the direction of travel
    (Abaqus' outward side); for tests and plots."""
    pts, nrm = [], []
    cur = np.array(segs[0][1:3], float)
    for s in segs[1:]:
        end = np.array(s[1:3], float)
        if s[0] == "LINE":
            t = np.linspace(0.0, 1.0, n)[:, None]
            p = cur + t * (end - cur)
            tan = np.broadcast_to(end - cur, p.shape)
        else:
            c = np.array(s[3:5], float)
            a0, a1 = (math.atan2(*(v - c)[::-1]) for v in (cur, end))
            da = (a1 - a0 + math.pi) % (2.0 * math.pi) - math.pi  # the arc under 180 degrees
            ang = a0 + np.linspace(0.0, 1.0, n) * da
            r = np.linalg.norm(cur - c)
            p = c + r * np.column_stack([np.cos(ang), np.sin(ang)])
            tan = np.sign(da) * np.column_stack([-np.sin(ang), np.cos(ang)])
        tan = tan / np.linalg.norm(tan, axis=1, keepdims=True)
        pts.append(p)
        nrm.append(np.column_stack([-tan[:, 1], tan[:, 0]]))  # tangent rotated +90 degrees
        cur = end
    return np.concatenate(pts), np.concatenate(nrm)


def indenter_strip(indenter, x_lo: float, x_hi: float, h: float, height: float = 0.5):
    """A strip of quadrilaterals under-lining the indenter face (CalculiX dialect): points
    (2n, 2) and CPE4 cells (n-1, 4) counter-clockwise, face S1 on the working face. The face
    points are spaced <= h and include the Braille dots' base edges (the kinks)."""
    xs = np.linspace(x_lo, x_hi, max(2, int(math.ceil((x_hi - x_lo) / h)) + 1))
    if indenter.kind == "braille":
        a = 0.5 * indenter.standard.base_diameter
        kinks = [c + s * a for c in indenter.section_x for s in (-1.0, 1.0)]
        xs = np.unique(np.concatenate([xs, [k for k in kinks if x_lo < k < x_hi]]))
    ys = indenter.surface_y(xs)
    n = len(xs)
    pts = np.concatenate([np.column_stack([xs, ys]), np.column_stack([xs, ys + height])])
    i = np.arange(n - 1)
    cells = np.column_stack([i, i + 1, n + i + 1, n + i])
    return pts, cells


# --- the deck -----------------------------------------------------------------------------

def skin_mesh_lines(fh, skinmesh, points: np.ndarray, cells: np.ndarray, etype: str, dim: int) -> None:
    """The node lines (after a *NODE keyword: every point, numbered from 1), the skin's
    *ELEMENT block, and an *NSET and a face *SURFACE for each named boundary."""
    from tactileskin.mesh.skinmesh import facet_nodes

    w = fh.write
    for i, p in enumerate(points):
        w(f"{i + 1}, " + ", ".join(_num(v) for v in p[:dim]) + "\n")
    w(f"*ELEMENT, TYPE={etype}, ELSET=skin\n")
    for i, c in enumerate(cells):
        w(f"{i + 1}, " + ", ".join(str(int(v) + 1) for v in c) + "\n")
    for name, facets in skinmesh.boundaries.items():
        nodes = np.unique(facet_nodes(skinmesh.mesh, facets, dim, skinmesh.order))
        w(f"*NSET, NSET={name}\n")
        _rows(fh, nodes + 1)
        w(f"*SURFACE, TYPE=ELEMENT, NAME={name}_faces\n")
        for e, f in boundary_faces(skinmesh, cells, etype, facets):
            w(f"{e + 1}, S{f}\n")


def indenter_mesh_lines(fh, ref: int, n_nodes: int, cells: np.ndarray, n_skin_cells: int, etype: str) -> None:
    """A meshed rigid indenter's node set (its nodes numbered from `ref`), its *ELEMENT block
    (numbered after the skin's cells) and its working face, face S1 of every cell."""
    w = fh.write
    w("*NSET, NSET=indenter_nodes, GENERATE\n")
    w(f"{ref}, {ref + n_nodes - 1}, 1\n")
    w(f"*ELEMENT, TYPE={etype}, ELSET=indenter\n")
    for i, c in enumerate(cells):
        w(f"{n_skin_cells + 1 + i}, " + ", ".join(str(ref + int(v)) for v in c) + "\n")
    w("*SURFACE, TYPE=ELEMENT, NAME=indenter_face\n")
    _rows(fh, [f"{n_skin_cells + 1 + i}, S1" for i in range(len(cells))], 1)


def _rows(fh, values, per_line: int = 16, fmt=str) -> None:
    values = list(values)
    for i in range(0, len(values), per_line):
        fh.write(", ".join(fmt(v) for v in values[i:i + per_line]) + "\n")


FIELD_WIDTH = 20  # CalculiX reads at most 20 characters per field ("*ERROR reading *NODE" beyond)


def _num(v: float) -> str:
    """Shortest text that reads back as the same double (coordinates round-trip exactly),
    unless that is wider than a CalculiX field: then the most significant digits that fit
    (-1.0000245733392007e-14, 22 characters, came out of a 3D mesh; 13 digits still leave a
    relative error below 1e-12)."""
    s = repr(float(v))
    for p in range(16, 0, -1):
        if len(s) <= FIELD_WIDTH:
            return s
        s = f"{float(v):.{p}g}"
    return s  # pragma: no cover - '%.1g' of a double is at most 8 characters


def material_lines(material, *, viscoelastic: bool, dialect: str) -> str:
    """*MATERIAL ... *HYPERFOAM [+ *VISCOELASTIC, TIME=PRONY] of a tactileskin Material."""
    hf, pr = material.hyperfoam, material.prony
    n = hf.n_terms
    if dialect == "calculix" and n > 3:
        raise ParameterError("material", f"{n} hyperfoam terms", "at most 3 for CalculiX (*HYPERFOAM, N=1..3)")
    if n > 6:
        raise ParameterError("material", f"{n} hyperfoam terms", "at most 6 for Abaqus (*HYPERFOAM, N<=6)")
    visco = viscoelastic and pr.n_terms > 0 and dialect == "abaqus"
    fh = io.StringIO()
    fh.write(f"*MATERIAL, NAME={_name(material.name)}\n")
    fh.write(f"*HYPERFOAM, N={n}" + (", MODULI=INSTANTANEOUS" if visco else "") + "\n")
    vals = [v for mu, al in zip(hf.mu, hf.alpha) for v in (mu, al)] + [hf.nu] * n
    _rows(fh, vals, 8, _num)
    if visco:
        fh.write("*VISCOELASTIC, TIME=PRONY\n")
        for g, tau in zip(pr.g, pr.tau):
            fh.write(f"{_num(g)}, {_num(g)}, {_num(tau)}\n")  # k_i = g_i: the whole stress relaxes
    return fh.getvalue()


def _name(s: str) -> str:
    """An Abaqus label: letters, digits, underscores, starting with a letter."""
    s = re.sub(r"[^A-Za-z0-9_]", "_", str(s))
    return s if s[:1].isalpha() else "M_" + s


@dataclass
class Deck:
    """The deck's text and what it numbers (0-based node ids of the skin are deck ids - 1)."""

    text: str
    dialect: str
    n_skin_nodes: int
    n_skin_cells: int
    etype: str
    info: dict = field(default_factory=dict)


def _check_dim(dim: int, dialect: str) -> None:
    if dim == 3 and dialect != "calculix":
        raise ParameterError("dialect", dialect, "calculix for a 3D deck (mesh.deck3d)",
                             "a 3D Abaqus deck would need R3D3 elements on a *RIGID BODY, not written yet")
    if dim not in (2, 3):  # pragma: no cover - scenes are 2D or 3D
        raise ParameterError("dim", dim, "2 or 3")


def _check_scene(scene, dialect: str) -> None:
    """What a deck cannot hold, checked before meshing: the dimension's dialect, a loading
    other than one depth ramp, a material law other than hyperfoam, and (as solve) an
    indenter that does not reach the skin within the depth: a deck of no contact."""
    from tactileskin.geometry.indenters import require_contact
    from tactileskin.materials import get_material

    _check_dim(scene.dim, dialect)
    program = scene.program()
    force_ok = scene.dim == 3 and len(program) == 1 and program[0].kind == "force"  # deck3d's two steps
    if not force_ok and (len(program) != 1 or program[0].kind != "depth"):
        raise ParameterError("loading", "force control" if scene.force is not None else "a loading history",
                             "a depth ramp (the deck has one displacement step), or in 3D one force ramp",
                             "2D force control and [[loading]] histories are not written to decks yet; export "
                             "the scene with its depth")
    mat = get_material(scene.material)
    if mat.law_name != "hyperfoam":  # was "valid: hyperfoam (use Material.law)", after meshing
        raise ParameterError(f"material {mat.name!r} law", mat.law_name,
                             "hyperfoam for a deck (it writes *HYPERFOAM)",
                             f"a {mat.law_name} material is not written to decks yet")
    require_contact(scene)


def deck_text(scene, skinmesh, dialect: str = "abaqus", *, viscoelastic: bool | None = None,
              penalty: float | None = None, increments: int = 20) -> Deck:
    """The input deck of a scene on its mesh (3D: CalculiX only, mesh.deck3d). viscoelastic:
    default the scene's;
    penalty (CalculiX contact slope, MPa/mm): default 10 K0 / h_fine (100 K0 / h made ccx 2.20
    diverge on the t = 3 polyurethane flat case); increments: the first
    time increment is T / increments (both solvers adapt it)."""
    from tactileskin.geometry.indenters import at_first_touch, indenter_for_scene
    from tactileskin.materials import get_material

    if dialect not in DIALECTS:
        raise ParameterError("dialect", dialect, "one of " + ", ".join(DIALECTS))
    if skinmesh.dim != scene.dim:
        raise ParameterError("mesh", f"{skinmesh.dim}D", f"a {scene.dim}D mesh for the {scene.dim}D scene")
    _check_scene(scene, dialect)
    if not (isinstance(increments, int) and 1 <= increments <= 10000):
        raise ParameterError("increments", increments, "an integer in [1, 10000]")
    if scene.dim == 3:
        from tactileskin.mesh.deck3d import deck_text_3d

        return deck_text_3d(scene, skinmesh, penalty=penalty, increments=increments, viscoelastic=viscoelastic)
    mat = get_material(scene.material)
    visco = scene.viscoelastic if viscoelastic is None else bool(viscoelastic)
    ind = at_first_touch(scene, indenter_for_scene(scene), contact_nodes(skinmesh))  # as fe.model_for_scene
    etype, pts, cells = abaqus_cells(skinmesh)
    n_nodes, n_cells = len(pts), len(cells)
    T, depth = scene.duration, scene.indentation
    halved = skinmesh.halved
    x_lo = _x_lo(ind, 0.0 if halved else float(pts[:, 0].min()))
    x_hi = min(0.5 * ind.width, float(pts[:, 0].max()) + 1.0)
    h_fine = float(skinmesh.sizes.get("fine", scene.mesh_size / scene.refinement))
    hf = mat.hyperfoam
    if penalty is None:
        penalty = 10.0 * max(hf.K0, hf.mu0) / h_fine

    fh = io.StringIO()
    w = fh.write
    w("*HEADING\n")
    w(f"tactileskin {scene.label()}: plane strain, units mm s N MPa, per mm of depth ({dialect})\n")
    w("**\n** Skin\n")
    # one *NODE block for the skin and the indenter (readers such as meshio keep only one)
    ref = n_nodes + 1
    if dialect == "abaqus":
        ipts, icells = np.array([[0.0, ind.y0]]), None  # the rigid body's reference node
    else:
        ipts, icells = indenter_strip(ind, x_lo, x_hi, h_fine)
    w("*NODE\n")
    skin_mesh_lines(fh, skinmesh, np.concatenate([pts, ipts]), cells, etype, 2)
    mname = _name(mat.name)
    w(material_lines(mat, viscoelastic=visco, dialect=dialect))
    w(f"*SOLID SECTION, ELSET=skin, MATERIAL={mname}\n1.\n")

    w("**\n** Indenter (" + ind.kind + "): lowest point at y0 = " + _num(ind.y0) + " mm, moves by -"
      + _num(depth) + " mm over " + _num(T) + " s\n")
    if dialect == "abaqus":
        segs = analytic_segments(ind, x_lo, x_hi)
        w(f"*NSET, NSET=indenter_ref\n{ref}\n")
        w("*SURFACE, TYPE=SEGMENTS, NAME=indenter_face\n")
        for s in segs:
            w(", ".join([s[0]] + [_num(v) for v in s[1:]]) + "\n")
        w("*RIGID BODY, ANALYTICAL SURFACE=indenter_face, REF NODE=indenter_ref\n")
        moved, n_ind = "indenter_ref", 0
    else:
        n_ind = len(ipts)
        indenter_mesh_lines(fh, ref, n_ind, icells, n_cells, "CPE4")
        w("** the strip only carries the contact surface: all its nodes are prescribed\n")
        w("*MATERIAL, NAME=indenter_rigid\n*ELASTIC\n1e6, 0.3\n")
        w("*SOLID SECTION, ELSET=indenter, MATERIAL=indenter_rigid\n1.\n")
        moved = "indenter_nodes"

    w("**\n** Contact: frictionless (no *FRICTION)\n")
    w("*SURFACE INTERACTION, NAME=frictionless\n")
    if dialect == "abaqus":
        w("1.\n*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=HARD\n")
        w("*CONTACT PAIR, INTERACTION=frictionless\n")
    else:
        w("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n")
        w(f"{_num(penalty)}\n")
        w("*CONTACT PAIR, INTERACTION=frictionless, TYPE=SURFACE TO SURFACE\n")
    w("outer_surface_faces, indenter_face\n")
    w(f"*AMPLITUDE, NAME=travel\n0., 0., {_num(T)}, 1.\n")

    fixed = [b for b in scene.skin_kind.fixed_boundaries if b in skinmesh.boundaries]
    w("**\n** Supports: " + ", ".join(fixed) + " fixed" + ("; symmetry line x = 0" if halved else "") + "\n")
    w("*BOUNDARY\n" + "".join(f"{b}, 1, 2\n" for b in fixed) + ("symmetry, 1, 1\n" if halved else ""))
    if dialect == "abaqus":
        w(f"{moved}, 1, 1\n{moved}, 6, 6\n")
    else:
        w(f"{moved}, 1, 1\n")

    dt0 = T / increments
    w(f"**\n** indentation {_num(depth)} mm at {_num(scene.rate)} mm/s\n")
    if dialect == "abaqus":
        w("*STEP, NAME=indent, NLGEOM=YES, INC=10000\n")
    else:
        w("*STEP, NLGEOM, INC=10000\n")
    if dialect == "abaqus" and visco and mat.prony.n_terms:
        w(f"*VISCO, CETOL=1e-3\n{_num(dt0)}, {_num(T)}, {_num(T * 1e-6)}, {_num(T / 10)}\n")
    else:
        w(f"*STATIC\n{_num(dt0)}, {_num(T)}, {_num(T * 1e-6)}, {_num(T / 10)}\n")
    w("*BOUNDARY, AMPLITUDE=travel\n")
    w(f"{moved}, 2, 2, {_num(-depth)}\n")
    if dialect == "abaqus":
        w("*OUTPUT, FIELD\n*NODE OUTPUT\nU, RF\n*ELEMENT OUTPUT\nS, E, SINV\n")
        w("*CONTACT OUTPUT\nCPRESS, COPEN\n")
        w("*OUTPUT, HISTORY\n*NODE OUTPUT, NSET=indenter_ref\nU2, RF2\n")
        w("*NODE PRINT, NSET=bone_interface, TOTALS=YES\nRF\n")
    else:
        w("*NODE FILE\nU, RF\n*EL FILE\nS, E\n*CONTACT FILE\nCDIS, CSTR\n")
        w("*NODE PRINT, NSET=bone_interface, TOTALS=ONLY\nRF\n")
        w("*NODE PRINT, NSET=indenter_nodes, TOTALS=ONLY\nRF\n")
    w("*END STEP\n")
    info = {"indenter_nodes": n_ind, "penalty_mpa_per_mm": penalty if dialect == "calculix" else None,
            "viscoelastic": bool(visco and dialect == "abaqus" and mat.prony.n_terms),
            "time_s": T, "depth_mm": depth}
    if dialect == "calculix" and visco and mat.prony.n_terms:
        log.warning("CalculiX has no Prony viscoelasticity: the deck uses the instantaneous hyperfoam alone")
    return Deck(fh.getvalue(), dialect, n_nodes, n_cells, etype, info)


def write_deck(scene, path, skinmesh=None, dialect: str = "abaqus", **kw) -> Deck:
    """Mesh the scene (unless given) and write its deck atomically (fileio)."""
    from tactileskin import fileio

    if skinmesh is None:
        _check_scene(scene, dialect)  # before meshing
        from tactileskin.mesh import build_mesh

        skinmesh = build_mesh(scene)
    deck = deck_text(scene, skinmesh, dialect, **kw)
    fileio.atomic_write_text(path, deck.text)
    log.info("wrote %s (%s deck)", path, dialect)
    return deck


# --- reading a deck back (tests, the CalculiX benchmark) ----------------------------------

def _params(line: str) -> tuple[str, dict]:
    parts = [p.strip() for p in line[1:].split(",")]
    kw = parts[0].upper()
    prm = {}
    for p in parts[1:]:
        if p:
            k, _, v = p.partition("=")
            prm[k.strip().upper()] = v.strip()
    return kw, prm


def parse_deck(text: str) -> dict:
    """Keyword blocks of a deck: {"blocks": [(keyword, params, data rows)], "nodes": {id: xy},
    "elements": {id: (type, nodes)}, "nsets", "elsets", "surfaces" (names -> data),
    "materials" (name -> [(keyword, params, rows)])}."""
    blocks, cur = [], None
    for raw in text.splitlines():
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            cur = (*_params(line), [])
            blocks.append(cur)
        elif cur is not None:
            cur[2].append([v.strip() for v in line.split(",") if v.strip()])
    out = {"blocks": blocks, "nodes": {}, "elements": {}, "nsets": {}, "elsets": {}, "surfaces": {},
           "materials": {}}
    mat = None
    for kw, prm, rows in blocks:
        if kw == "NODE":
            ids = []
            for r in rows:
                out["nodes"][int(r[0])] = np.array([float(v) for v in r[1:]])
                ids.append(int(r[0]))
            if "NSET" in prm:
                out["nsets"].setdefault(prm["NSET"], []).extend(ids)
        elif kw == "ELEMENT":
            ids = []
            for r in rows:
                out["elements"][int(r[0])] = (prm["TYPE"], [int(v) for v in r[1:]])
                ids.append(int(r[0]))
            if "ELSET" in prm:
                out["elsets"].setdefault(prm["ELSET"], []).extend(ids)
        elif kw == "NSET" and "GENERATE" in prm:
            for r in rows:
                a, b, step = (int(v) for v in (r + ["1"])[:3])
                out["nsets"].setdefault(prm["NSET"], []).extend(range(a, b + 1, step))
        elif kw == "NSET":
            out["nsets"].setdefault(prm["NSET"], []).extend(int(v) for r in rows for v in r)
        elif kw == "ELSET":
            out["elsets"].setdefault(prm["ELSET"], []).extend(int(v) for r in rows for v in r)
        elif kw == "SURFACE":
            out["surfaces"][prm["NAME"]] = (prm.get("TYPE", "ELEMENT"), rows)
        if kw == "MATERIAL":
            mat = prm["NAME"]
            out["materials"][mat] = []
        elif kw in ("HYPERFOAM", "VISCOELASTIC", "ELASTIC") and mat is not None:
            out["materials"][mat].append((kw, prm, rows))
        elif kw not in ("DENSITY", "EXPANSION"):
            mat = None
    return out


def undefined_names(parsed: dict) -> list[str]:
    """Names a deck uses that it does not define (node/element sets, surfaces, materials,
    amplitudes, interactions): empty for a consistent deck."""
    defined = {"nset": set(parsed["nsets"]), "elset": set(parsed["elsets"]),
               "surface": set(parsed["surfaces"]), "material": set(parsed["materials"]),
               "amplitude": set(), "interaction": set()}
    for kw, prm, _ in parsed["blocks"]:
        if kw == "AMPLITUDE":
            defined["amplitude"].add(prm["NAME"])
        if kw == "SURFACE INTERACTION":
            defined["interaction"].add(prm["NAME"])
    missing = []

    def need(kind, name):
        if name not in defined[kind]:
            missing.append(f"{kind} {name}")

    for kw, prm, rows in parsed["blocks"]:
        if kw == "SOLID SECTION":
            need("elset", prm["ELSET"])
            need("material", prm["MATERIAL"])
        elif kw in ("BOUNDARY", "CLOAD"):
            if "AMPLITUDE" in prm:
                need("amplitude", prm["AMPLITUDE"])
            for r in rows:
                if not r[0].isdigit():
                    need("nset", r[0])
        elif kw == "CONTACT PAIR":
            need("interaction", prm["INTERACTION"])
            for r in rows:
                for s in r:
                    need("surface", s)
        elif kw == "RIGID BODY":
            need("surface", prm["ANALYTICAL SURFACE"])
            need("nset", prm["REF NODE"])
        elif kw in ("NODE PRINT", "NODE OUTPUT") and "NSET" in prm:
            need("nset", prm["NSET"])
        elif kw == "SURFACE" and prm.get("TYPE", "ELEMENT") == "ELEMENT":
            for r in rows:
                if int(r[0]) not in parsed["elements"]:
                    missing.append(f"element {r[0]}")
    for name, ids in parsed["nsets"].items():
        if any(i not in parsed["nodes"] for i in ids):
            missing.append(f"nodes of nset {name}")
    return missing
