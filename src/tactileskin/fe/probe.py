"""Values of nodal fields at arbitrary points of the reference mesh, by interpolation inside
the element that holds each point (the element's own shape functions).

Like scikit-fem's `CellBasis.probes`, but the element search tolerates points on the boundary
or a round-off outside it (the curved P2 boundary of the mesh is within O(h^3) of the
analytic skin surface the sensor positions come from): each point is mapped to the reference
coordinates of its nearest candidate elements by Newton on the (isoparametric) geometry map,
without clipping, and the element whose reference point is least outside wins; a point more
than OUTSIDE_TOL (in reference coordinates) outside every candidate is refused.
"""

from __future__ import annotations

import numpy as np

from tactileskin.errors import ParameterError

OUTSIDE_TOL = 1e-3           # reference units: 0.1 % of an element outside is the boundary
_CANDIDATES = {2: 12, 3: 30}  # nearest elements (by centroid) tried per point
AFFINE_FIRST = 4              # of them, those Newton tries first (best affine coordinates)
EXPAND, EXPANSIONS = 4, 2     # a point outside all its candidates: EXPAND x as many, twice
# points located at once by stress_sampler: the search holds ~9 kB (affine) to ~160 kB (P2
# geometry) per point in 3D (the 30 candidates' Newton arrays), so a chunk ~10-170 MB; a valid
# sensor file of 19881 taxels of 16 x 16 points (5.1 M points) at once was killed at 20 GB
CHUNK = 1024


def _score(X: np.ndarray, simplex: bool) -> np.ndarray:
    """Smallest barycentric (simplex) or box coordinate: >= 0 inside the reference element."""
    if simplex:
        return np.minimum(X.min(axis=0), 1.0 - X.sum(axis=0))
    return np.minimum(X.min(axis=0), 1.0 - X.max(axis=0))


def _affine(model) -> tuple[np.ndarray, np.ndarray]:
    """(first vertex (n_el, dim), inverse of the vertex-edge matrix (n_el, dim, dim)) of each
    simplex: its affine map, exact for straight-sided elements (all but the curved boundary's)."""
    aff = getattr(model, "_probe_affine", None)
    if aff is None:
        mesh = model.mesh
        v = mesh.p[:, mesh.t].transpose(2, 1, 0)                  # (n_el, dim + 1, dim)
        A = (v[:, 1:, :] - v[:, :1, :]).transpose(0, 2, 1)        # columns: the edges from vertex 0
        aff = model._probe_affine = (v[:, 0, :], np.linalg.inv(A))
    return aff


def _newton(model, pts: np.ndarray, cand: np.ndarray, simplex: bool) -> tuple[np.ndarray, np.ndarray]:
    """(reference coordinates (dim, n*m), scores (n, m)) of points (n, dim) in their candidate
    elements cand (n, m), by Newton on the (isoparametric) geometry map."""
    mapping, dim = model.basis.mapping, pts.shape[1]
    n, m = cand.shape
    x = np.repeat(pts, m, axis=0).T[:, :, None]                  # (dim, n*m, 1)
    tind = cand.ravel()
    X = np.full(x.shape, 1.0 / (dim + 1))
    # scikit-fem's isoparametric mapping memoises every Jacobian it evaluates (its J, in
    # mapping._cache): the Newton iterates of every point sampled stayed in memory (~27 kB a
    # point on the 3D P2 meshes), so this call's entries are dropped after it
    before = set(getattr(mapping, "_cache", {}))
    try:
        for _ in range(12):  # Newton on the geometry map (one step when affine)
            dX = np.einsum("ijkl,jkl->ikl", mapping.invDF(X, tind), x - mapping.F(X, tind))
            X = X + dX
            if np.max(np.abs(dX)) < 1e-13:
                break
    finally:
        memo = getattr(mapping, "_cache", None)
        for h in set(memo or ()) - before:
            del memo[h]
    return X[:, :, 0], _score(X[:, :, 0], simplex).reshape(n, m)


def locate(model, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(cells (n,), reference coordinates (dim, n)) of reference-configuration points (n, dim).
    A point's candidates are its nearest elements by centroid (_CANDIDATES); on simplices they
    are ranked by their affine coordinates (exact for straight-sided elements) and Newton runs
    on the AFFINE_FIRST best, then, for a point none of them holds, on all of them. A point
    still outside every candidate is searched again among EXPAND x as many: on a graded mesh the
    element holding a point near a vertex of small elements can rank past the first 30 (a point
    inside the default 3D Braille mesh ranked 31st and was refused as off the skin)."""
    from scipy.spatial import cKDTree

    mesh = model.mesh
    dim, n_el = mesh.dim(), mesh.t.shape[1]
    pts = np.atleast_2d(np.asarray(points, float))
    if pts.shape[1] != dim:
        raise ParameterError("probe points", f"shape {pts.shape}", f"(n, {dim})")
    tree = getattr(model, "_probe_tree", None)
    if tree is None:
        tree = model._probe_tree = cKDTree(mesh.p[:, mesh.t].mean(axis=1).T)
    simplex = "Tri" in type(mesh).__name__ or "Tet" in type(mesh).__name__
    n = len(pts)
    cells, Xb, sb = np.zeros(n, int), np.zeros((dim, n)), np.full(n, -np.inf)

    def keep(idx, cand, X, score):  # the better of each point's best so far and its best here
        best = np.argmax(score, axis=1)
        r = np.arange(len(idx))
        better = score[r, best] > sb[idx]
        j = idx[better]
        cells[j] = cand[r, best][better]
        Xb[:, j] = X[:, r * cand.shape[1] + best][:, better]
        sb[j] = score[r, best][better]

    todo, k = np.arange(n), min(_CANDIDATES[dim], n_el)
    for level in range(EXPANSIONS + 1):
        _, cand = tree.query(pts[todo], k=k)
        cand = cand.reshape(todo.size, k)
        rest = todo
        if simplex and k > AFFINE_FIRST:
            v0, Ainv = _affine(model)
            Xa = np.einsum("nkij,nkj->ink", Ainv[cand], pts[todo, None, :] - v0[cand])   # (dim, n, k)
            first = np.argsort(-_score(Xa.reshape(dim, -1), True).reshape(todo.size, k), axis=1)[:, :AFFINE_FIRST]
            short = np.take_along_axis(cand, first, axis=1)
            keep(todo, short, *_newton(model, pts[todo], short, simplex))
            # in none of them (a curved element, round-off): all the first candidates; the
            # further ones only by their affine ranks (a point off the skin costs little)
            rest = np.flatnonzero(sb[todo] < 0.0) if level == 0 else np.zeros(0, int)
            cand, rest = cand[rest], todo[rest]
        if rest.size:
            keep(rest, cand, *_newton(model, pts[rest], cand, simplex))
        todo = todo[sb[todo] < -OUTSIDE_TOL]
        if not todo.size or k == n_el:
            break
        k = min(EXPAND * k, n_el)
    bad = sb < -OUTSIDE_TOL
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        lo, hi = mesh.p.min(axis=1), mesh.p.max(axis=1)
        raise ParameterError("sample point", tuple(float(v) for v in pts[i]),
                             "inside the meshed skin (mesh box " + ", ".join(
                                 f"[{a:.4g}, {b:.4g}]" for a, b in zip(lo, hi)) + " mm)")
    return cells, Xb


def interpolation_matrix(model, points: np.ndarray):
    """Sparse (n, model.nsdof) matrix: nodal scalar field -> its values at the points."""
    import scipy.sparse as sp

    cells, X = locate(model, points)
    el = model.element
    phi = np.stack([el.lbasis(X, a)[0] for a in range(model.sdofs.shape[1])], axis=-1)  # (n, A)
    n, A = phi.shape
    return sp.csr_matrix((phi.ravel(), (np.repeat(np.arange(n), A), model.sdofs[cells].ravel())),
                         shape=(n, model.nsdof))


def stress_sampler(model, point_data: dict):
    """points (n, dim) in the reference configuration -> Cauchy stress (n, 3, 3) interpolated
    from the nodal components sxx, syy, szz, sxy[, syz, sxz] of `point_data` (fe.output's
    result fields; missing shear components, as in plane strain, are zero)."""

    from tactileskin.errors import TactileSkinError
    from tactileskin.fe.output import FIELD_UNITS, STRESS_COMPONENTS

    # a field is named bare (sxx) or with its unit (sxx_MPa, as in result.vtu)
    keys = {n: next((k for k in (n, f"{n}_{FIELD_UNITS.get(n, '')}") if k in point_data), None)
            for n in STRESS_COMPONENTS}
    # only the out-of-plane shears may be absent (plane strain: zero); anything else missing
    # would read as a silent zero stress
    needed = [n for n in STRESS_COMPONENTS if n not in ("syz", "sxz") or model.m == 3]
    missing = [n for n in needed if keys[n] is None]
    if missing:
        raise TactileSkinError(f"stress fields {missing} not in the result's point data "
                               f"(has {sorted(point_data)})")

    def sample(points):
        points = np.atleast_2d(np.asarray(points, float))
        sig = np.zeros((len(points), 3, 3))
        for a in range(0, len(points), CHUNK):  # bounded memory (CHUNK)
            M = interpolation_matrix(model, points[a:a + CHUNK])
            for name, (i, j) in STRESS_COMPONENTS.items():
                if keys[name] is not None:
                    v = M @ np.asarray(point_data[keys[name]], float)
                    sig[a:a + CHUNK, i, j] = sig[a:a + CHUNK, j, i] = v
        return sig

    return sample


def result_sampler(path):
    """stress_sampler of a saved result.vtu (as fe.output.vtk_fields writes it: the scalar dofs'
    positions as points, each cell's dofs in scikit-fem's order): the stresses of a cached solve
    at any point of its reference mesh, without solving again. Read back at the bonded surface
    it gives the bone map to 2e-10 of its peak (t = 1 mm pad, single dot)."""
    import skfem
    from scipy.spatial import cKDTree

    from tactileskin.errors import TactileSkinError
    from tactileskin.results import read_vtu

    try:
        m = read_vtu(path)
    except (OSError, ValueError) as e:
        raise TactileSkinError(f"cannot read the result {path}: {e}") from None
    kinds = {"tetra10": (skfem.MeshTet2, skfem.ElementTetP2), "tetra": (skfem.MeshTet1, skfem.ElementTetP1),
             "triangle6": (skfem.MeshTri2, skfem.ElementTriP2), "triangle": (skfem.MeshTri1, skfem.ElementTriP1)}
    block = next((c for c in m.cells if c.type in kinds), None)  # the skin's cells (then the boundaries')
    if block is None:
        raise TactileSkinError(f"no skin cells in {path} (has {[c.type for c in m.cells]})")
    mesh_cls, element = kinds[block.type]
    dim = 3 if block.type.startswith("tetra") else 2
    X = np.ascontiguousarray(m.points[:, :dim])
    mesh = mesh_cls(np.ascontiguousarray(X.T), np.ascontiguousarray(block.data.T), sort_t=False)
    basis = skfem.Basis(mesh, element(), intorder=2)
    # the rebuilt basis numbers its edge dofs itself: each dof's point in the file
    dist, idx = cKDTree(X).query(basis.doflocs.T)
    if basis.N != len(X) or dist.max() > 1e-9 * max(1.0, float(np.abs(X).max())):
        raise TactileSkinError(f"the mesh of {path} does not rebuild (its nodes are not a P{element().maxdeg} mesh's)")
    model = _Model(mesh, basis, element(), basis.element_dofs.T, basis.N, dim)
    return stress_sampler(model, {k: np.asarray(v)[idx] for k, v in m.point_data.items()})


class _Model:
    """What the probe needs of a model (mesh, basis, element, scalar dofs; its caches)."""

    def __init__(self, mesh, basis, element, sdofs, nsdof, m):
        self.mesh, self.basis, self.element, self.sdofs, self.nsdof, self.m = mesh, basis, element, sdofs, nsdof, m
