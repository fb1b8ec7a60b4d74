"""The first increment's travel is capped at a fraction of the indenter's tip radius
(SolverOptions.first_travel_radius): the contact strain of a small dot goes as sqrt(d / R)."""

import numpy as np
import pytest

from tactileskin import fe
from tactileskin.fe.solver import SolverOptions
from tactileskin.geometry.braille import get_standard
from tactileskin.geometry.indenters import indenter_for_scene
from tactileskin.mesh import build_mesh
from tactileskin.planner import with_quality
from tactileskin.scene import Scene


def test_tip_radius_of_each_kind():
    std = get_standard("standard_american")
    assert indenter_for_scene(Scene(indenter="braille")).tip_radius == pytest.approx(std.sphere_radius)
    assert std.sphere_radius == pytest.approx((0.72 ** 2 + 0.48 ** 2) / (2 * 0.48))
    assert indenter_for_scene(Scene(indenter="curved")).tip_radius == pytest.approx(12.0)
    assert indenter_for_scene(Scene(dim=3, indenter="sphere", indenter_radius=2.5)).tip_radius == 2.5
    assert indenter_for_scene(Scene(indenter="flat")).tip_radius == float("inf")


@pytest.fixture(scope="module")
def braille_t3():
    scene = with_quality(Scene(thickness=3.0, indenter="braille"), "preview")
    mesh = build_mesh(scene)
    out = {}
    for name, frac in (("capped", 0.1), ("off", 0.0)):
        travels = []
        r = fe.solve(scene, mesh, options=SolverOptions(first_travel_radius=frac),
                     progress=lambda info: travels.append(info.travel))
        out[name] = (r, travels)
    return out


def test_first_increment_travel_is_capped(braille_t3):
    R = get_standard("standard_american").sphere_radius
    r, travels = braille_t3["capped"]
    assert travels[0] <= 0.1 * R * (1 + 1e-9)
    # off: the first increment is a quarter of the 0.6 mm travel (cut back if it fails)
    assert braille_t3["off"][1][0] > 0.1 * R
    assert travels[-1] == pytest.approx(0.6)


def test_capped_first_increment_keeps_the_answer(braille_t3):
    """Other increments, same end state: peak and span agree within the QLV time error of a
    few increments (0.07-0.14 % at 4 increments, docs/speed_vs_error.md)."""
    a, b = braille_t3["capped"][0], braille_t3["off"][0]
    assert a.peak == pytest.approx(b.peak, rel=1e-3)
    assert a.span == pytest.approx(b.span, rel=1e-3)


def test_a_failed_increment_length_is_not_tried_again():
    """SolverOptions.failed_dt_fraction: after an increment of length dt_f fails, the run's
    later increments stay at or below that fraction of dt_f, where growth x1.5 alone would
    climb back past dt_f and fail again (0 turns it off: the sawtooth returns)."""
    from types import SimpleNamespace

    from tactileskin.fe.solver import SolverOptions, _Failure, run

    def fake_model():
        m = SimpleNamespace(t=0.0, u=np.zeros(1), contact=None)
        m.travel = lambda t: t
        m.commit = lambda ev, u, t, dt: setattr(m, "t", t)
        return m

    def tried_lengths(fraction):
        tried = []

        def increment(model, u, t, dt, opts, stats):
            tried.append(dt)
            if dt > 0.1:  # everything longer than 0.1 fails
                raise _Failure("too long", {})
            return u, SimpleNamespace(), 3  # easy: the increment grows x1.5 next
        opts = SolverOptions(dt0_fraction=0.25, dt_max_fraction=0.25, failed_dt_fraction=fraction)
        run(fake_model(), 1.0, opts, increment=increment)
        return tried

    capped = tried_lengths(0.7)
    failed = [k for k, dt in enumerate(capped) if dt > 0.1]
    # 0.25 fails (cap 0.175), the grown 0.131 fails (cap 0.092), then nothing longer is tried
    assert len(failed) == 2
    for k in failed:
        assert max(capped[k + 1:]) <= 0.7 * capped[k] + 1e-12
    sawtooth = tried_lengths(0.0)
    assert sum(dt > 0.1 for dt in sawtooth) > 4          # without it the growth fails again and again


def test_a_late_first_touch_starts_the_ramp_just_before_it():
    # 'ab' has no dot on the centre line: its dots touch the fingertip after 0.476 mm of the
    # 0.55 mm travel. The free travel is skipped (no load, no relaxation there), so the
    # contact gets the increments; the peak equals a 100-increment solve's to its time error.
    from tactileskin.geometry.indenters import first_contact_travel

    scene = with_quality(Scene(thickness=1.0, indenter="braille", braille_text="ab", depth=0.55), "preview")
    touch = first_contact_travel(scene)
    assert 0.45 < touch < 0.5
    mesh = build_mesh(scene)
    travels = []
    r = fe.solve(scene, mesh, progress=lambda info: travels.append(info.travel))
    # increments over the contact, not the free travel (before: travels 0.078, 0.195,
    # 0.333, 0.47, 0.55 mm, the whole contact in the last)
    assert travels[0] > 0.9 * touch and sum(d > touch for d in travels) >= 3
    ref = fe.solve(scene, mesh, options=SolverOptions(dt0_fraction=0.01, dt_max_fraction=0.01))
    assert r.peak == pytest.approx(ref.peak, rel=5e-4)  # measured 1.5e-4
    assert r.status == "ok"
