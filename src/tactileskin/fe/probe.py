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
# points located at once by stress_sampler: the search holds ~9 kB (affine) to ~160 kB (P2
# geometry) per point in 3D (the 30 candidates' Newton arrays), so a chunk ~10-170 MB; a valid
# sensor file of 19881 taxels of 16 x 16 points (5.1 M points) at once was killed at 20 GB
CHUNK = 1024


def _score(X: np.ndarray, simplex: bool) -> np.ndarray:
    """Smallest barycentric (simplex) or box coordinate: >= 0 inside the reference element."""
    if simplex:
        return np.minimum(X.min(axis=0), 1.0 - X.sum(axis=0))
    return np.minimum(X.min(axis=0), 1.0 - X.max(axis=0))


def locate(model, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(cells (n,), reference coordinates (dim, n)) of reference-configuration points (n, dim)."""
    from scipy.spatial import cKDTree

    mesh, mapping = model.mesh, model.basis.mapping
    dim = mesh.dim()
    pts = np.atleast_2d(np.asarray(points, float))
    if pts.shape[1] != dim:
        raise ParameterError("probe points", f"shape {pts.shape}", f"(n, {dim})")
    tree = getattr(model, "_probe_tree", None)
    if tree is None:
        tree = model._probe_tree = cKDTree(mesh.p[:, mesh.t].mean(axis=1).T)
    k = min(_CANDIDATES[dim], mesh.t.shape[1])
    _, cand = tree.query(pts, k=k)
    cand = cand.reshape(len(pts), k)
    x = np.repeat(pts, k, axis=0).T[:, :, None]                  # (dim, n*k, 1)
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
    simplex = "Tri" in type(mesh).__name__ or "Tet" in type(mesh).__name__
    score = _score(X[:, :, 0], simplex).reshape(len(pts), k)
    best = np.argmax(score, axis=1)
    rows = np.arange(len(pts))
    bad = score[rows, best] < -OUTSIDE_TOL
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        lo, hi = mesh.p.min(axis=1), mesh.p.max(axis=1)
        raise ParameterError("sample point", tuple(float(v) for v in pts[i]),
                             "inside the meshed skin (mesh box " + ", ".join(
                                 f"[{a:.4g}, {b:.4g}]" for a, b in zip(lo, hi)) + " mm)")
    pick = rows * k + best
    return cand[rows, best], X[:, pick, 0]


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
