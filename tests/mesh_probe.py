"""Mesh measurements shared by the 3D mesh tests."""

import numpy as np


def edges_near(sm, name, centre, radius):
    """Median edge length of the `name` facets whose centroid is within radius of centre."""
    m = sm.mesh
    f = m.facets[:, sm.boundaries[name]]
    d = np.linalg.norm(m.p[:, f].mean(axis=1) - np.asarray(centre, float)[:, None], axis=0)
    sel = f[:, d < radius]
    e = np.concatenate([np.linalg.norm(m.p[:, sel[i]] - m.p[:, sel[(i + 1) % 3]], axis=0) for i in range(3)])
    return float(np.median(e)), sel.shape[1]


def c3d10_grad(x):
    """dN/dxi of C3D10 (corners 1-4, mid-edges 1-2, 2-3, 3-1, 1-4, 2-4, 3-4), shape (10, 3),
    from the element's definition (independent of scikit-fem)."""
    L = (1.0 - x.sum(), *x)
    dl = np.array([[-1.0, -1.0, -1.0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    rows = [(4 * L[i] - 1) * dl[i] for i in range(4)]
    for i, j in ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)):
        rows.append(4 * (L[i] * dl[j] + L[j] * dl[i]))
    return np.array(rows)
