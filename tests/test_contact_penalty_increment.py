"""Per-point penalty raises (SolverOptions.penalty_fresh_points): the Uzawa loop stiffens the
penalty only at the pressed points, and an increment starts the points that are not pressed
at its committed state from the model's penalty."""

from types import SimpleNamespace

import numpy as np

from tactileskin.fe import solver
from tactileskin.fe.solver import SolverOptions, Stats


def _model():
    surf = SimpleNamespace(lam=np.array([[0.0, 0.2, 0.0, 0.5]]), scale=np.array([[16.0, 16.0, 4.0, 4.0]]))
    return SimpleNamespace(contact=SimpleNamespace(penalty=10.0), surface=surf)


def _inner(model, u, t, dt, opts, stats):
    return model.surface.scale.copy()


def test_unpressed_points_start_from_the_model_penalty(monkeypatch):
    monkeypatch.setattr(solver, "_newton_uzawa", _inner)
    seen = solver._solve_increment(_model(), None, 1.0, 0.1, SolverOptions(), Stats())
    np.testing.assert_array_equal(seen, [[1.0, 16.0, 1.0, 4.0]])


def test_raises_carried_everywhere_when_asked(monkeypatch):
    monkeypatch.setattr(solver, "_newton_uzawa", _inner)
    seen = solver._solve_increment(_model(), None, 1.0, 0.1, SolverOptions(penalty_fresh_points=False), Stats())
    np.testing.assert_array_equal(seen, [[16.0, 16.0, 4.0, 4.0]])
