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
