"""fe.Model's reuse of a state's law: the tangent at the iterate whose residual was just
evaluated takes D from the spectral data the stress evaluation kept (no second eigen-
decomposition, no second S), and an evaluation at the very same u, dt and committed history
(a release, an Uzawa update: only contact changes) reuses kinematics, stresses and internal
forces. The reused results must be the fresh ones bit for bit, and no reuse may reach a
different state (another u, even by one ulp or by an in-place change, another dt, after a
commit)."""

from __future__ import annotations

import numpy as np
from skfem import MeshTet

from reuse_cases import fresh, random_state

from tactileskin.fe import material_law
from tactileskin.fe.model import Contact, Dirichlet, Model
from tactileskin.fe.verification import Sphere
from tactileskin.materials import get_material


def _model(reuse=True):
    mesh = MeshTet.init_tensor(np.linspace(0.0, 2.0, 4), np.linspace(-1.0, 0.0, 3), np.linspace(0.0, 2.0, 4))
    f = mesh.facets_satisfying
    b = {"bottom": f(lambda x: np.isclose(x[1], -1.0)), "top": f(lambda x: np.isclose(x[1], 0.0)),
         "sym_x": f(lambda x: np.isclose(x[0], 0.0))}
    mat = get_material("silicone")
    model = Model(mesh, b, material_law(mat.hyperfoam), [Dirichlet("bottom", (0, 1, 2)), Dirichlet("sym_x", (0,))],
                  prony=mat.prony, contact=Contact(Sphere(3.0), boundary="top"), stiffness=2 * mat.hyperfoam.mu0)
    model.reuse_state = reuse
    return model


def _state(model, seed):
    return random_state(model, seed)


T, DT = 0.08, 0.05   # the sphere 0.08 mm into the top: contact points active


def _fresh(u, t=T, dt=DT, lam=None, commits=()):
    """R and tangent of a model that reuses nothing (after the same commits)."""
    return fresh(_model, u, t, dt, lam, commits)


def test_tangent_takes_d_from_the_kept_spectral_data():
    model = _model()
    u = _state(model, 1)
    ev = model.evaluate(u, T, DT, tangent=False)
    assert ev.ok and ev.contact is not None and np.any(ev.contact[1] > 0)
    K = model.tangent(ev)
    # one law evaluation with the eigenproblem (the residual's), D from its kept data
    assert dict(model.counts) == {"law_stress": 1, "tangent_kept": 1}
    R0, K0 = _fresh(u)
    assert np.array_equal(ev.R, R0) and np.array_equal(K, K0)


def test_same_state_with_other_contact_reuses_the_bulk_and_matches_fresh():
    model = _model()
    u = _state(model, 5)
    ev1 = model.evaluate(u, T, DT, tangent=False)
    lam = np.maximum(ev1.contact[1], 0.0)            # an Uzawa update: other multipliers, same u
    ev2 = model.evaluate(u.copy(), T, DT, lam, tangent=False)
    K2 = model.tangent(ev2)
    assert model.counts["state_reused"] == 1 and model.counts["law_stress"] == 1
    assert model.counts["tangent_kept"] == 1 and model.counts["law_tangent"] == 0
    R0, K0 = _fresh(u, lam=lam)
    assert np.array_equal(ev2.R, R0) and np.array_equal(K2, K0)
    assert not np.array_equal(ev1.R, ev2.R)          # the contact part did change
    K1 = model.tangent(ev1)                          # the first evaluation's own tangent
    assert model.counts["tangent_kept"] == 1 and model.counts["law_tangent"] == 0   # D shared
    assert np.array_equal(K1, _fresh(u)[1])


def test_no_reuse_at_another_state():
    """Stale reuse is the defect to fear: an ulp of one dof, the same array changed in
    place, another dt, or a commit in between must each evaluate afresh."""
    model = _model()
    u1 = _state(model, 3)
    ev1 = model.evaluate(u1, T, DT, tangent=False)
    k = int(model.free[len(model.free) // 2])
    u2 = u1.copy()
    u2[k] = np.nextafter(u2[k], np.inf)              # one ulp
    ev2 = model.evaluate(u2, T, DT, tangent=False)
    assert model.counts["state_reused"] == 0
    K2, K1 = model.tangent(ev2), model.tangent(ev1)  # each at its own state
    R2, K20 = _fresh(u2)
    assert np.array_equal(ev2.R, R2) and np.array_equal(K2, K20)
    assert np.array_equal(K1, _fresh(u1)[1]) and not np.array_equal(K1, K2)

    u = u1.copy()
    model.evaluate(u, T, DT, tangent=False)
    u[k] += 1e-3                                     # the same array, changed in place
    ev = model.evaluate(u, T, DT, tangent=False)
    assert model.counts["state_reused"] == 0
    R0, K0 = _fresh(u)
    assert np.array_equal(ev.R, R0) and np.array_equal(model.tangent(ev), K0)

    ev = model.evaluate(u, T, 2 * DT, tangent=False)  # another step: another QLV stress
    assert model.counts["state_reused"] == 0
    assert np.array_equal(ev.R, _fresh(u, dt=2 * DT)[0])

    model.commit(ev, u, T, 2 * DT)                    # a new committed history
    ev = model.evaluate(u, T + DT, DT, tangent=False)
    assert model.counts["state_reused"] == 0
    R0, K0 = _fresh(u, t=T + DT, commits=[(u, T, 2 * DT)])
    assert np.array_equal(ev.R, R0) and np.array_equal(model.tangent(ev), K0)


def test_reuse_switched_off_computes_afresh():
    model = _model(reuse=False)
    u = _state(model, 4)
    ev = model.evaluate(u, T, DT, tangent=False)
    model.evaluate(u, T, DT, tangent=False)
    model.tangent(ev)
    assert dict(model.counts) == {"law_stress": 2, "law_tangent": 1}


def test_solve_same_answer_with_and_without_reuse():
    """A whole small solve (Newton, line search, Uzawa, releases) gives the same bits."""
    from tactileskin.fe.solver import run

    out = {}
    for r in (True, False):
        model = _model(reuse=r)
        ev, stats = run(model, 0.15)
        out[r] = (model.u.copy(), ev.R.copy(), stats.newton_iterations, dict(model.counts))
    assert np.array_equal(out[True][0], out[False][0]) and np.array_equal(out[True][1], out[False][1])
    assert out[True][2] == out[False][2]
    c = out[True][3]
    assert c.get("law_tangent", 0) <= 1 and c["tangent_kept"] >= out[True][2] - 1


def test_no_reuse_after_the_history_restarts_its_parabola():
    """fe.loading starts each segment with the chord (history.dt_prev = None) without a
    commit: the QLV stress at the same u and dt changes, so the state must not be reused."""
    model = _model()
    u1, u = _state(model, 3), _state(model, 5)
    model.commit(model.evaluate(u1, T, DT, tangent=False), u1, T, DT)
    assert model.history.dt_prev == DT and model.prony.n_terms > 0
    ev1 = model.evaluate(u, T + DT, DT, tangent=False)
    model.history.dt_prev = None                     # as fe.loading.run_program at a segment start
    ev2 = model.evaluate(u, T + DT, DT, tangent=False)
    fresh = _model(reuse=False)
    fresh.commit(fresh.evaluate(u1, T, DT, tangent=False), u1, T, DT)
    fresh.history.dt_prev = None
    ev0 = fresh.evaluate(u, T + DT, DT, tangent=True)
    assert not np.array_equal(ev1.R, ev0.R)          # the chord's stress differs from the parabola's
    assert model.counts["state_reused"] == 0
    assert np.array_equal(ev2.R, ev0.R) and np.array_equal(model.tangent(ev2), ev0.K)
