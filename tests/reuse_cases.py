"""Shared pieces of the state-reuse tests (test_state_reuse2d.py, test_state_reuse3d.py)."""

from __future__ import annotations

import numpy as np


def random_state(model, seed):
    """A displacement with every element deformed (J > 0): a small random affine map plus noise,
    fixed dofs zero."""
    rng = np.random.default_rng(seed)
    X = model.basis.doflocs.T
    d = X.shape[1]
    u = (X @ (0.04 * rng.standard_normal((d, d))).T + 0.01 * rng.standard_normal(X.shape)).ravel()
    u[model.fixed] = 0.0
    return u


def fresh(make_model, u, t, dt, lam=None, commits=()):
    """R and tangent of a model that reuses nothing (make_model(reuse=False)), after the same
    commits ((u, t, dt) each)."""
    m = make_model(reuse=False)
    for uc, tc, dtc in commits:
        m.commit(m.evaluate(uc, tc, dtc, tangent=False), uc, tc, dtc)
    ev = m.evaluate(u, t, dt, lam, tangent=True)
    assert ev.ok
    return ev.R, ev.K
