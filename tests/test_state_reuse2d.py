"""fe.Model's reuse of a state's law in plane strain: the tangent at the iterate whose residual
was just evaluated takes D from the data the plane-strain stress evaluation kept (no second
point loop of S, logarithms and powers), and that data must never serve another state (another
u by one ulp or in place, another dt, another committed history). The reused results must be
the fresh ones bit for bit; the law-level kept path too (materials.hyperfoam)."""

from __future__ import annotations

import numpy as np
import pytest
from skfem import MeshTri

from reuse_cases import fresh, random_state

from tactileskin.fe import material_law
from tactileskin.fe.model import Contact, Dirichlet, Model
from tactileskin.fe.verification import Cylinder
from tactileskin.materials import get_material
from tactileskin.materials.hyperfoam import Hyperfoam

T, DT = 0.08, 0.05   # the cylinder 0.08 mm into the top: contact points active


def _model(reuse=True, material="silicone"):
    mesh = MeshTri.init_tensor(np.linspace(-2.0, 2.0, 7), np.linspace(-1.0, 0.0, 4))
    f = mesh.facets_satisfying
    b = {"bottom": f(lambda x: np.isclose(x[1], -1.0)), "top": f(lambda x: np.isclose(x[1], 0.0))}
    mat = get_material(material)
    model = Model(mesh, b, material_law(mat.hyperfoam), [Dirichlet("bottom", (0, 1))],
                  prony=mat.prony, contact=Contact(Cylinder(3.0), boundary="top"), stiffness=2 * mat.hyperfoam.mu0)
    model.reuse_state = reuse
    return model


def _state(model, seed):
    return random_state(model, seed)


def _fresh(u, t=T, dt=DT, lam=None, commits=()):
    """R and tangent of a model that reuses nothing (after the same commits)."""
    return fresh(_model, u, t, dt, lam, commits)


def test_plane_tangent_takes_d_from_the_kept_data():
    model = _model()
    u = _state(model, 1)
    ev = model.evaluate(u, T, DT, tangent=False)
    assert ev.ok and np.any(ev.contact[1] > 0)
    K = model.tangent(ev)
    assert dict(model.counts) == {"law_stress": 1, "tangent_kept": 1}
    R0, K0 = _fresh(u)
    assert np.array_equal(ev.R, R0) and np.array_equal(K, K0)


def test_plane_kept_data_serves_no_other_state():
    model = _model()
    u1 = _state(model, 3)
    ev1 = model.evaluate(u1, T, DT, tangent=False)
    k = int(model.free[len(model.free) // 2])
    u2 = u1.copy()
    u2[k] = np.nextafter(u2[k], np.inf)              # one ulp
    ev2 = model.evaluate(u2, T, DT, tangent=False)
    assert model.counts["state_reused"] == 0
    K2, K1 = model.tangent(ev2), model.tangent(ev1)  # each at its own state
    assert model.counts["tangent_kept"] == 2 and model.counts["law_tangent"] == 0
    assert np.array_equal(K2, _fresh(u2)[1]) and np.array_equal(K1, _fresh(u1)[1])
    assert not np.array_equal(K1, K2)

    u = u1.copy()
    model.evaluate(u, T, DT, tangent=False)
    u[k] += 1e-3                                     # the same array, changed in place
    ev = model.evaluate(u, T, DT, tangent=False)
    assert model.counts["state_reused"] == 0
    R0, K0 = _fresh(u)
    assert np.array_equal(ev.R, R0) and np.array_equal(model.tangent(ev), K0)

    ev = model.evaluate(u, T, 2 * DT, tangent=False)  # another step: another QLV stress and gamma
    assert model.counts["state_reused"] == 0
    R0, K0 = _fresh(u, dt=2 * DT)
    assert np.array_equal(ev.R, R0) and np.array_equal(model.tangent(ev), K0)

    model.commit(ev, u, T, 2 * DT)                    # a new committed history
    ev = model.evaluate(u, T + DT, DT, tangent=False)
    assert model.counts["state_reused"] == 0
    R0, K0 = _fresh(u, t=T + DT, commits=[(u, T, 2 * DT)])
    assert np.array_equal(ev.R, R0) and np.array_equal(model.tangent(ev), K0)


@pytest.mark.parametrize("material", ["silicone", "polyurethane"])
def test_plane_solve_same_answer_with_and_without_reuse(material):
    from tactileskin.fe.solver import run

    out = {}
    for r in (True, False):
        model = _model(reuse=r, material=material)
        ev, stats = run(model, 0.15)
        out[r] = (model.u.copy(), ev.R.copy(), stats.newton_iterations, dict(model.counts))
    assert np.array_equal(out[True][0], out[False][0]) and np.array_equal(out[True][1], out[False][1])
    assert out[True][2] == out[False][2]
    c = out[True][3]
    assert c.get("law_tangent", 0) <= 1 and c["tangent_kept"] >= out[True][2] - 1


def _plane_points():
    """In-plane C of general, coincident-stretch, rest, extreme (clipped) and non-finite points."""
    rng = np.random.default_rng(7)
    F = np.eye(2) + 0.3 * rng.standard_normal((200, 2, 2))
    F[:, 0, 0] = np.abs(F[:, 0, 0]) + 0.2
    F[:, 1, 1] = np.abs(F[:, 1, 1]) + 0.2
    C = np.einsum("nki,nkj->nij", F, F)
    C[0] = np.eye(2)
    C[1] = 1.3 * np.eye(2)
    C[2] = [[1.0 + 1e-15, 0.0], [0.0, 1.0]]
    C[3] = [[1e-30, 0.0], [0.0, 1e30]]
    C[4] = [[np.nan, 0.0], [0.0, 1.0]]
    C[5] = [[0.5, 0.5], [0.5, 0.5]]                  # singular
    return C.reshape(10, 20, 2, 2)


@pytest.mark.parametrize("material", ["silicone", "polyurethane"])
@pytest.mark.parametrize("out_of_plane", [False, True])
def test_plane_kept_gives_the_bits_of_the_full_evaluation(material, out_of_plane):
    law = get_material(material).hyperfoam
    C2 = _plane_points()
    S, D, ok = law.pk2_tangent_plane(C2, out_of_plane=out_of_plane)
    Sk, okk, kept = law.pk2_kept_plane(C2, out_of_plane=out_of_plane)
    S0, _, ok0 = law.pk2_tangent_plane(C2, tangent=False)
    assert np.array_equal(Sk, S0, equal_nan=True) and np.array_equal(okk, ok0)
    assert np.array_equal(Sk, S, equal_nan=True) and np.array_equal(okk, ok)
    Dk = law.tangent_kept(kept)
    assert Dk.shape == D.shape and np.array_equal(Dk, D, equal_nan=True)
    D2 = law.tangent_kept(kept, in_plane=True)       # what a 2D model's tangent takes
    assert D2.shape == C2.shape[:-2] + (2, 2, 2, 2)
    assert np.array_equal(D2, D[..., :2, :2, :2, :2], equal_nan=True)


def test_solid_kept_gives_its_in_plane_block():
    law = get_material("silicone").hyperfoam
    rng = np.random.default_rng(2)
    F = np.eye(3) + 0.2 * rng.standard_normal((50, 3, 3))
    C = np.einsum("nki,nkj->nij", F, F)
    D = law.pk2_tangent(C)[1]
    kept = law.pk2_kept(C)[2]
    assert np.array_equal(law.tangent_kept(kept), D)
    assert np.array_equal(law.tangent_kept(kept, in_plane=True), D[..., :2, :2, :2, :2])


def test_plane_kept_of_another_material_is_refused():
    a = get_material("silicone").hyperfoam
    b = Hyperfoam(mu=(0.1,), alpha=(4.0,), nu=0.2)
    _, _, kept = a.pk2_kept_plane(_plane_points())
    with pytest.raises(Exception, match="kept"):
        b.tangent_kept(kept)


def _contact_fresh(model, u, d, eps, lam, tangent, sticky=None, curvature=False, indenter=None):
    """ContactSurface.evaluate on a new surface of the same model (no gaps kept)."""
    from tactileskin.fe.contact import ContactSurface

    s = ContactSurface(model.mesh, model.element, model.boundaries["top"], 2, intorder=3)
    return s.evaluate(u, indenter or model.contact.indenter, d, eps, lam, tangent, sticky, curvature)


def _same(a, b):
    fa, Ka, (ga, la, xa, na) = a
    fb, Kb, (gb, lb, xb, nb) = b
    return (np.array_equal(fa, fb) and (Ka is None) == (Kb is None) and (Ka is None or np.array_equal(Ka, Kb))
            and all(np.array_equal(p, q) for p, q in ((ga, gb), (la, lb), (xa, xb), (na, nb))))


def test_contact_tangent_takes_the_residuals_gaps_and_no_stale_ones():
    """The contact tangent at the residual's state takes its gaps (x, g, n); another surface
    displacement (one ulp of one surface dof), travel or indenter evaluates them afresh, and
    every result equals a surface that keeps nothing, bit for bit; the kept arrays are read-only."""
    model = _model()
    s, ind = model.surface, model.contact.indenter
    u = _state(model, 1)
    eps, lam = model.penalty(), np.zeros(s.shape)
    calls = []

    class Counting:
        def gap(self, x, d):
            calls.append(1)
            return ind.gap(x, d)

    cind = Counting()
    r = s.evaluate(u, cind, T, eps, lam, False)
    assert np.any(r[2][1] > 0) and len(calls) == 1
    sticky = r[2][1] > 0.0
    for tangent, st, curv in ((True, None, False), (True, sticky, False), (True, None, True)):
        n0 = len(calls)
        out = s.evaluate(u.copy(), cind, T, eps, lam, tangent, st, curv)
        assert len(calls) == n0 + (2 * 2 if curv else 0)    # the gaps kept; dn/dx's differences only
        assert _same(out, _contact_fresh(model, u, T, eps, lam, tangent, st, curv))
    with pytest.raises(ValueError):
        r[2][0][0, 0] = 1.0                               # the kept g is read-only
    k = int(s.sdofs[3, 1]) * 2 + 1                        # a surface node's y dof
    u2 = u.copy()
    u2[k] = np.nextafter(u2[k], np.inf)
    for args in ((u2, cind, T), (u, cind, 1.01 * T), (u, Counting(), T)):
        n0 = len(calls)
        out = s.evaluate(args[0], args[1], args[2], eps, lam, True)
        assert len(calls) == n0 + 1                       # evaluated afresh
        assert _same(out, _contact_fresh(model, args[0], args[2], eps, lam, True))
    u3 = u.copy()                                         # the same array changed in place
    s.evaluate(u3, cind, T, eps, lam, False)
    u3[k] += 1e-3
    assert _same(s.evaluate(u3, cind, T, eps, lam, True), _contact_fresh(model, u3, T, eps, lam, True))


def test_contact_einsum_path_kept_per_shape_gives_the_planned_bits():
    model = _model()
    s = model.surface
    rng = np.random.default_rng(5)
    spec = "fq,fqa,fqb,fqik->faibk"
    for f in (1, 2, 3, 7, 1, 2, len(s.w)):
        ops = (rng.random((f, 2)), rng.random((f, 2, 3)), rng.random((f, 2, 3)), rng.random((f, 2, 2, 2)))
        assert np.array_equal(s._einsum(spec, *ops), np.einsum(spec, *ops, optimize=True))


def test_contact_gaps_kept_for_a_3d_surface_take_a_float32_displacement():
    """The kept gaps are compared by the bits of the surface displacements: a float32 u of a 3D
    model (3 components, 12 bytes per node) after a float64 one raised ValueError (an int64 view
    of 12-byte rows); it evaluates as a fresh surface does (float64 arithmetic, the same bits)."""
    from skfem import MeshTet

    from tactileskin.fe.contact import ContactSurface
    from tactileskin.fe.verification import Sphere

    mesh = MeshTet.init_tensor(np.linspace(-1.0, 1.0, 4), np.linspace(-1.0, 0.0, 3), np.linspace(-1.0, 1.0, 4))
    f = mesh.facets_satisfying
    b = {"bottom": f(lambda x: np.isclose(x[1], -1.0)), "top": f(lambda x: np.isclose(x[1], 0.0))}
    mat = get_material("silicone")
    model = Model(mesh, b, material_law(mat.hyperfoam), [Dirichlet("bottom", (0, 1, 2))], prony=mat.prony,
                  contact=Contact(Sphere(3.0), boundary="top"), stiffness=2 * mat.hyperfoam.mu0)
    s, ind = model.surface, model.contact.indenter
    u = np.zeros(model.ndof)
    u[1::3] = -0.01 * (model.basis.doflocs[1] + 1.0)
    eps, lam = model.penalty(), np.zeros(s.shape)
    s.evaluate(u, ind, 0.05, eps, lam, True)
    u32 = u.astype(np.float32)
    out = s.evaluate(u32, ind, 0.05, eps, lam, True)
    fresh = ContactSurface(mesh, model.element, b["top"], 3, intorder=2).evaluate(u32, ind, 0.05, eps, lam, True)
    assert _same(out, fresh)
