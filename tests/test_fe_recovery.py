"""Boundary values by the local least-squares fit (fe.recovery.PointFit) against closed forms.

- A linear field is reproduced exactly at boundary points (the fit is exact for it), to
  round-off: 1e-12 relative.
- A smooth non-polynomial field, given as element averages the way the mixed pressure
  is, is recovered at the boundary to second order: halving h divides the error by about 4
  (accepted: >= 3, where the P1 L2 projection, first order at a boundary, gives about 2).
"""

import numpy as np
import pytest
from skfem import MeshTri

from tactileskin.fe import Dirichlet, Model, material_law
from tactileskin.fe.recovery import PointFit, Projector
from tactileskin.materials import get_material


def _model(n):
    m = MeshTri.init_tensor(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    # a non-uniform mesh: perturb the interior vertices
    rng = np.random.default_rng(1)
    p = m.p.copy()
    inner = (p[0] > 1e-9) & (p[0] < 1 - 1e-9) & (p[1] > 1e-9) & (p[1] < 1 - 1e-9)
    p[:, inner] += 0.15 / n * rng.uniform(-1, 1, (2, inner.sum()))
    m = MeshTri(p, m.t)
    b = {"bottom": m.facets_satisfying(lambda x: x[1] < 1e-9)}
    hf = get_material("silicone").hyperfoam
    return Model(m, b, material_law(hf), [Dirichlet("bottom", (0, 1))], formulation="mixed")


def _xq(model):
    return np.moveaxis(np.asarray(model.basis.mapping.F(model.basis.X)), 0, -1)


def _bottom_points(model):
    sd = model.facet_scalar_dofs("bottom")
    return model.basis.doflocs[:, sd].T


def test_linear_field_is_exact():
    model = _model(6)
    xq = _xq(model)
    q = 0.3 + 2.0 * xq[..., 0] - 1.5 * xq[..., 1]
    X = _bottom_points(model)
    got = PointFit(model, X).values(q)
    np.testing.assert_allclose(got, 0.3 + 2.0 * X[:, 0] - 1.5 * X[:, 1], rtol=0, atol=1e-12)


def _error(n, how):
    model = _model(n)
    xq = _xq(model)
    f = lambda x, y: np.exp(x) * np.cos(2 * y)  # noqa: E731
    # element averages (the volumetric part of the mixed pressure is element-constant)
    w = model.w
    qbar = (w * f(xq[..., 0], xq[..., 1])).sum(axis=1) / w.sum(axis=1)
    q = np.repeat(qbar[:, None], w.shape[1], axis=1)
    X = _bottom_points(model)
    if how == "fit":
        got = PointFit(model, X).values(q)
    else:
        sd = model.facet_scalar_dofs("bottom")
        got = Projector(model).project(q)[sd]
    return np.max(np.abs(got - f(X[:, 0], X[:, 1])))


@pytest.mark.parametrize("how,lo", [("fit", 3.0), ("projection", 1.5)])
def test_boundary_convergence_order(how, lo):
    e1, e2 = _error(8, how), _error(16, how)
    ratio = e1 / e2
    assert ratio >= lo, (how, e1, e2, ratio)
    if how == "projection":  # the reason for the fit: first order at the boundary
        assert ratio < 3.0, (e1, e2, ratio)
