"""The consistent bone traction of benchmarks/bone_traction3d.py on a homogeneous 3D state.

Confined compression of a tet block (bottom bonded, sides on rollers, top pressed): the
stress is uniform, an exact solution of the discrete equations, so the traction the study
recovers from the bone nodes' reactions (M_s t = R on the P2 surface) must be that stress's
normal component at every bone node, vertex and mid-side alike, and so must its P1
smoothing, its kernel averages and the fitted stress; its integral is the bone's reaction.
A wrong normal sign, a wrong surface mass matrix or quadrature fails this.
"""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from skfem import MeshTet

from tactileskin.fe import Dirichlet, Model, SolverOptions, material_law, run
from tactileskin.fe.assembly import vector_dofs
from tactileskin.fe.output import STRESS_COMPONENTS
from tactileskin.fe.recovery import PointFit
from tactileskin.materials import get_material

_spec = importlib.util.spec_from_file_location(
    "bone_traction3d", Path(__file__).resolve().parents[1] / "benchmarks" / "bone_traction3d.py")
bt = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(bt)

LAM = 0.99  # silicone locks in volume under confinement (design.md hard case 1): keep J near 1


@pytest.fixture(scope="module")
def confined():
    m = MeshTet.init_tensor(np.linspace(0, 2, 3), np.linspace(0, 1, 3), np.linspace(0, 2, 3))
    b = {"bone_interface": m.facets_satisfying(lambda x: x[1] < 1e-9),
         "top": m.facets_satisfying(lambda x: x[1] > 1 - 1e-9),
         "xs": m.facets_satisfying(lambda x: (x[0] < 1e-9) | (x[0] > 2 - 1e-9)),
         "zs": m.facets_satisfying(lambda x: (x[2] < 1e-9) | (x[2] > 2 - 1e-9))}
    bcs = [Dirichlet("bone_interface", (0, 1, 2)), Dirichlet("xs", (0,)), Dirichlet("zs", (2,)),
           Dirichlet("top", (1,), value=lambda t: (LAM - 1.0) * t)]
    model = Model(m, b, material_law(get_material("silicone").hyperfoam), bcs, formulation="mixed")
    ev, _ = run(model, 1.0, SolverOptions(rtol=1e-8, dt0_fraction=0.5))
    return model, ev


def test_consistent_traction_of_a_uniform_state(confined):
    model, ev = confined
    syy = model.stress(ev)[..., 1, 1]
    assert np.ptp(syy) < 1e-6 * abs(syy.mean()) and syy.mean() < -1e-3   # uniform compression
    nodes, t, n = bt.consistent_traction(model, ev)
    np.testing.assert_allclose(n, np.tile([0.0, -1.0, 0.0], (len(nodes), 1)), atol=1e-12)  # out of the skin
    tn = -np.einsum("kd,kd->k", t, n)
    np.testing.assert_allclose(tn, -syy.mean(), rtol=1e-6)
    ts = bt.p1_smoothed(model, nodes, t)
    np.testing.assert_allclose(-np.einsum("kd,kd->k", ts, n), -syy.mean(), rtol=1e-6)
    R = np.asarray(ev.fint, float)[vector_dofs(nodes, 3)]
    F = bt.integrate_traction(model, t, nodes)
    np.testing.assert_allclose(F[1], R[:, 1].sum(), rtol=1e-10)
    np.testing.assert_allclose(F[1], -syy.mean() * 4.0, rtol=1e-6)  # the bone pushes up on 2 x 2 mm


def test_kernel_averages_and_balance_of_the_fit(confined):
    model, ev = confined
    nodes, t, n = bt.consistent_traction(model, ev)
    R = np.asarray(ev.fint, float)[vector_dofs(nodes, 3)]
    sig_q = model.stress(ev)
    fit = PointFit(model, model.basis.doflocs[:, nodes].T)
    sig = np.zeros((model.nsdof, 3, 3))
    for i, j in STRESS_COMPONENTS.values():
        sig[nodes, i, j] = sig[nodes, j, i] = fit.values(sig_q[..., i, j])
    P = np.zeros(model.nsdof)
    P[nodes] = -np.trace(sig[nodes], axis1=1, axis2=2) / 3
    syy = float(sig_q[..., 1, 1].mean())
    for rho, k in bt.kernel_averages(model, nodes, R, n, sig, P, radii=(0.7, 1.5)).items():
        np.testing.assert_allclose([k["fit_nn"], k["cons_tn"]], -syy, rtol=1e-6, err_msg=rho)
        np.testing.assert_allclose(k["fit_P"], -np.trace(sig_q[0, 0]) / 3, rtol=1e-6)
    np.testing.assert_allclose(bt.integrate_stress(model, sig)[1], R[:, 1].sum(), rtol=1e-6)
