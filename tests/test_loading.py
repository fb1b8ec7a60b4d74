"""Loading histories: force control, holds (QLV relaxation), releases, validation, cache keys."""

from __future__ import annotations

import numpy as np
import pytest

from tactileskin import cache
from tactileskin.errors import ConvergenceError, ParameterError
from tactileskin.loading import Segment
from tactileskin.materials import get_material
from tactileskin.scene import Scene

# coarse 2D curved press on a 2 mm skin: ~1 s per solve
BASE = Scene(thickness=2, indenter="curved", mesh_size=0.6, refinement=2, viscoelastic=False)


@pytest.fixture(scope="module")
def mesh():
    from tactileskin.mesh import build_mesh

    return build_mesh(BASE)


def test_default_scene_keys_unchanged_and_loading_enters_them():
    d = Scene().to_dict()
    assert not {"force", "force_rate", "load_time", "loading"} & set(d)
    keys = {cache.cache_key(s) for s in (Scene(), Scene(force=0.2), Scene(force=0.2, force_rate=1.0),
                                         Scene(loading=[{"hold": 1.0}]))}
    assert len(keys) == 4
    s = Scene(force=0.2, loading=[{"hold": 1.0}, {"depth": 0.0, "rate": 2.0}])
    assert Scene.from_dict(s.to_dict()) == s
    assert [g.kind for g in s.program()] == ["force", "hold", "depth"]


@pytest.mark.parametrize("fields, needle", [
    (dict(force=-1.0), "force"),
    # below the reaction's resolution: 1e-7 N/mm stalled in its first increment, unnamed
    (dict(force=1e-5), r"force.*\[0.0001, 10000\]"),
    (dict(loading=[{"force": 1e-7, "rate": 1.0}]), r"loading\[0\].force"),
    (dict(force=0.2, depth=0.3), "depth"),
    (dict(force_rate=1.0), "force_rate"),
    (dict(force=0.2, force_rate=1.0, load_time=1.0), "force_rate"),
    (dict(loading=[{"hold": 0.0}]), r"loading\[0\].hold"),
    (dict(loading=[{"hold": 1.0, "rate": 1.0}]), r"loading\[0\].hold"),
    (dict(loading=[{"depth": 5.0}]), r"loading\[0\].depth"),
    (dict(loading=[{"force": 1.0}]), r"loading\[0\].rate"),
    (dict(loading=[{"depth": 0.1, "force": 1.0}]), "exactly one"),
    (dict(loading=[{"squeeze": 1.0}]), "squeeze"),
    (dict(depth=0.4, loading=[{"depth": 0.4}]), "other than the previous"),
    # a ramp of 1e-20 s ends where it starts in float time (t0 + 1e-20 == t0): the solve
    # stopped with a ZeroDivisionError traceback
    (dict(loading=[{"depth": 0.1, "time": 1e-20}]), r"loading\[0\].time.*\[1e-06, 1e\+06\] s"),
    (dict(loading=[{"force": 0.05, "time": 1e-9}]), r"loading\[0\].time.*\[1e-06, 1e\+06\] s"),
    # the same by a rate: 2e-10 mm at 1e6 mm/s after a 100 s ramp ends where it starts in float
    # time (ZeroDivisionError traceback); so does a force step of 1e-10 N at 1e6 N/s
    (dict(loading=[{"depth": 0.1, "rate": 0.001}, {"depth": 0.1000000002, "rate": 1e6}]),
     r"loading\[1\].rate=1000000.0 is invalid; valid: <= 0.000199 mm/s.*2e-16 s.*1e-06 s"),
    (dict(force=0.05, force_rate=0.05, loading=[{"force": 0.0500000001, "rate": 1e6}]),
     r"loading\[0\].rate=1000000.0 is invalid; valid: <= 9.99e-05 N/s.*1e-06 s"),
])
def test_bad_histories_name_the_parameter(fields, needle):
    with pytest.raises(ParameterError, match=needle):
        Scene(**fields)


def test_force_control_matches_displacement_control_both_ways(mesh):
    from tactileskin.fe import solve

    # displacement -> force: the reaction of a depth-controlled press, asked as a force,
    # comes back at that depth with the same state
    rd = solve(BASE.replace(depth=0.3), mesh=mesh)
    rf = solve(BASE.replace(force=rd.reaction), mesh=mesh)
    lo = rf.loading
    # the force loop stops at |F - F*| <= 1e-4 F* (fe.loading.FORCE_RTOL)
    assert abs(lo["reached_force"] - rd.reaction) <= 1e-4 * rd.reaction
    assert rf.reaction == pytest.approx(lo["reached_force"], rel=1e-12)
    # F ~ d^1.5..2 near here: a 1e-4 force error is <= 1e-4 in travel; the contact
    # tolerance (1e-4 x facet) adds ~1e-5 mm
    assert lo["profile_travel_mm"] == pytest.approx(0.3, rel=2e-4)
    assert rf.peak == pytest.approx(rd.peak, rel=5e-4)
    # force -> displacement: the travel it found, prescribed, gives the same state
    rd2 = solve(BASE.replace(depth=lo["profile_travel_mm"]), mesh=mesh)
    assert rd2.reaction == pytest.approx(rf.reaction, rel=2e-4)
    assert rd2.peak == pytest.approx(rf.peak, rel=2e-4)
    assert np.allclose(rd2.pressure, rf.pressure, atol=2e-4 * rf.peak)
    assert rf.stats["force_trials"] >= rf.stats["increments"]


def test_elastic_hold_changes_nothing_and_release_opens_contact(mesh, tmp_path):
    from tactileskin.fe import solve

    s = BASE.replace(depth=0.2, loading=[{"hold": 1.0}, {"depth": 0.0, "rate": 1.0}])
    r = solve(s, mesh=mesh)
    h = r.history
    ramp_end = [x for x in h if x["segment"] == 0][-1]
    hold = [x for x in h if x["segment"] == 1]
    # an elastic hold only lets the contact multipliers settle further (gap tolerance 1e-4 h)
    for x in hold:
        assert x["reaction"] == pytest.approx(ramp_end["reaction"], rel=2e-4)
        assert x["peak_mpa"] == pytest.approx(ramp_end["peak_mpa"], rel=2e-4)
    final = r.loading["final"]
    assert final["travel_mm"] == 0.0
    assert all(np.isfinite(x["reaction"]) and np.isfinite(x["peak_mpa"]) for x in h)
    # back at first touch the elastic skin is undeformed: the reaction is zero to rounding
    assert abs(final["reaction"]) <= 1e-9 * ramp_end["reaction"]
    # the profile reports the peak-load state, so the released end is not "no contact"
    summ = r.summary()
    assert summ["status"] == "ok"
    assert r.loading["profile_t_s"] == pytest.approx(ramp_end["t"])
    assert r.reaction == pytest.approx(ramp_end["reaction"], rel=1e-12)
    out = r.write(tmp_path / "o")
    rows = np.loadtxt(out / "history.csv", delimiter=",", skiprows=1, ndmin=2, usecols=range(5))  # not the status
    assert rows.shape == (len(h), 5) and np.all(np.isfinite(rows))


def test_viscoelastic_step_hold_relaxes_by_the_prony_function(mesh):
    from tactileskin.fe import solve

    # a 2 % press in 0.4 ms (<< tau_1 = 0.1 s): a step, so F(t) / F_elastic = g(t) (QLV in the
    # small-strain limit: stresses scale with g at fixed geometry)
    pu = BASE.replace(material="polyurethane", depth=0.04, rate=100.0)
    fe_ = solve(pu, mesh=mesh).reaction
    r = solve(pu.replace(viscoelastic=True, loading=[{"hold": 2.0}]), mesh=mesh)
    g = get_material("polyurethane").prony
    tr = 0.04 / 100.0
    hold = [x for x in r.history if x["segment"] == 1]
    assert len(hold) >= 3
    for x in hold:
        # measured 2-3e-4: the ramp's finite length (t_r/2 shift taken) and 2 % strain
        assert x["reaction"] / fe_ == pytest.approx(float(g.relaxation(x["t"] - tr / 2)), rel=2e-3)
    assert hold[-1]["reaction"] / fe_ < 0.75  # it did relax (g(2 s) = 0.704)


def test_a_long_hold_resolves_the_relaxation(mesh):
    """A 300 s hold was sampled at quarters, its first point at 75 s: the relaxation (tau 0.1,
    1.38, 25.5 s) was mostly over by then and the history's curve went straight from the step to
    g(75 s), 31 % of the step's force above g(t) at t = 5.4 s. Now its points follow the Prony
    times (23 increments, first at 0.05 s, the curve within 0.44 %)."""
    from tactileskin.fe import solve

    pu = BASE.replace(material="polyurethane", depth=0.04, rate=100.0)  # a step, as above
    fe_ = solve(pu, mesh=mesh).reaction
    r = solve(pu.replace(viscoelastic=True, loading=[{"hold": 300.0}]), mesh=mesh)
    g = get_material("polyurethane").prony
    tr = 0.04 / 100.0
    hold = [x for x in r.history if x["segment"] == 1]
    t = np.array([tr] + [x["t"] for x in hold])
    f = np.array([r.history[len(r.history) - len(hold) - 1]["reaction"]] + [x["reaction"] for x in hold]) / fe_
    assert t[1] - tr <= min(g.tau) and t[-1] == pytest.approx(300.0 + tr) and len(hold) <= 32
    # each point on g(t) as in the 2 s hold above, and the curve through them too: within 1 %
    # of the step's force everywhere (the relaxation is 44 % of it)
    assert np.allclose(f[1:], g.relaxation(t[1:] - tr / 2), rtol=2e-3)
    dense = tr + np.geomspace(1e-3, 300.0, 400)
    assert np.max(np.abs(np.interp(dense, t, f) - g.relaxation(dense - tr / 2))) < 1e-2


def test_hold_times_follow_the_shortest_prony_time():
    from tactileskin.fe.loading import HOLD_MAX_INCREMENTS, hold_times
    from tactileskin.fe.solver import SolverOptions
    from tactileskin.materials.prony import Prony

    sil = get_material("silicone").prony  # tau 0.025, 0.15, 0.3 s
    t = hold_times(sil, 300.0, SolverOptions())
    assert t[0] == pytest.approx(0.5 * 0.025) and t[-1] == 300.0 and len(t) == 26
    assert np.all(t[1:] / t[:-1] <= 1.5 + 1e-12)
    assert len(hold_times(sil, 1e6, SolverOptions())) == HOLD_MAX_INCREMENTS  # bounded
    # the solver's quarters where they are as fine (a short hold) or nothing relaxes
    assert hold_times(sil, 0.04, SolverOptions()) is None and hold_times(Prony.elastic(), 300.0, SolverOptions()) is None


def test_viscoelastic_force_hold_creeps(mesh):
    from tactileskin.fe import solve

    pu = BASE.replace(material="polyurethane", viscoelastic=True, force=0.01, load_time=0.05,
                      loading=[{"hold": 1.0}])
    r = solve(pu, mesh=mesh)
    hold = [x for x in r.history if x["segment"] == 1]
    assert all(abs(x["reaction"] - 0.01) <= 1e-4 * 0.01 for x in hold)
    d = [x["d"] for x in hold]
    assert np.all(np.diff(d) > 0)  # the indenter sinks in as the skin relaxes


def test_law_state_is_the_extreme_over_the_whole_history(mesh):
    from tactileskin.fe import solve

    # press 0.3 mm fast, relax 100 s (g -> 0.56), press on to 0.33 mm: the deeper state has the
    # smaller reaction (0.179 against 0.228 N/mm), so the profile stays at 0.3 mm, but the
    # law's extremes (which tactileskin.quality judges) must be the deeper state's
    pu = BASE.replace(material="polyurethane", viscoelastic=True, depth=0.3, rate=100.0)
    r = solve(pu.replace(loading=[{"hold": 100.0}, {"depth": 0.33, "rate": 100.0}]), mesh=mesh)
    assert r.loading["profile_travel_mm"] == pytest.approx(0.3)
    at30 = solve(BASE.replace(material="polyurethane", depth=0.3), mesh=mesh).stats
    at33 = solve(BASE.replace(material="polyurethane", depth=0.33), mesh=mesh).stats
    assert at33["min_J"] < at30["min_J"] - 1.5e-3  # measured 2.1e-3 apart
    # the relaxed state's kinematics are the elastic ones up to the contact set's change
    # (measured 1e-4 apart; the profile state's min_J was 2.2e-3 off)
    assert r.stats["min_J"] == pytest.approx(at33["min_J"], abs=5e-4)


def test_unreachable_force_is_an_error(mesh):
    from tactileskin.fe import model_for_scene
    from tactileskin.fe.loading import run_program

    model, _ = model_for_scene(BASE, mesh)
    # a travel limit of 0.05 mm carries ~3e-3 N/mm here: 1 N/mm cannot be reached
    # the message names the force asked for, not the ramp's force at the failing increment, and
    # its unit (a 2D force is N/mm: '1000 not reached' left a 3D user guessing)
    with pytest.raises(ConvergenceError, match=r"force 1 N/mm not reached: the reaction is [0-9.e-]+ N/mm .*"
                                               r"\(on the way, at 0\.[0-9]+ N/mm\)"):
        run_program(model, [Segment("force", 1.0, time=1.0)], d_max=0.05, d_guess=lambda F: 0.02)


def test_sweep_over_forces(tmp_path):
    from tactileskin.sweep import case_ids, expand_grid, load_spec

    spec = tmp_path / "sweep.toml"
    spec.write_text("[sweep]\nthicknesses = [1, 2]\nmaterials = ['silicone']\nindenters = ['curved']\n"
                    "forces = [0.1, 0.2]\n[scene]\nviscoelastic = false\n")
    sp = load_spec(spec)
    scenes = expand_grid(base=sp.pop("base"), **sp)
    assert sorted((s.thickness, s.force) for s in scenes) == [(1, 0.1), (1, 0.2), (2, 0.1), (2, 0.2)]
    ids = case_ids(scenes)
    assert len(set(ids)) == 4 and any(i.endswith("F0.2") for i in ids)
    with pytest.raises(ParameterError, match="forces"):
        expand_grid(thicknesses=[1], materials=["silicone"], indenters=["curved"], depths=[0.2], forces=[0.1])


def test_results_csv_gives_the_force_a_case_asked_for(tmp_path):
    """A force sweep's results.csv had no column for the force asked for: only the case id's
    'F0.2' told it, and depth_mm holds the travel reached. Now target_force_n_per_mm (2D) or
    target_force_n (3D), empty under displacement control."""
    import csv
    import dataclasses
    from types import SimpleNamespace

    from tactileskin.report.outputs import RESULT_COLUMNS, collect

    base = Scene(thickness=1.0, indenter="curved", viscoelastic=False)
    scenes = [dataclasses.replace(base, force=0.2), dataclasses.replace(base, dim=3, force=0.5), base]
    outcomes = [SimpleNamespace(scene=sc, status="failed", error="ConvergenceError: x", key="k", record=None)
                for sc in scenes]
    _, rows, _ = collect(outcomes, cache=None)
    assert [(r.get("target_force_n_per_mm"), r.get("target_force_n")) for r in rows] == \
        [(0.2, None), (None, 0.5), (None, None)]
    assert {"target_force_n_per_mm", "target_force_n"} <= set(RESULT_COLUMNS)
    buf = tmp_path / "r.csv"
    with open(buf, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=RESULT_COLUMNS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    assert [r["target_force_n_per_mm"] for r in csv.DictReader(open(buf))] == ["0.2", "", ""]


def test_cli_solve_force_and_history(tmp_path, capsys):
    import json

    from tactileskin.cli import main

    scene = tmp_path / "scene.toml"
    scene.write_text("thickness = 2\nindenter = 'curved'\nmesh_size = 0.6\nrefinement = 2\nviscoelastic = false\n"
                     "force = 0.05\n[[loading]]\nhold = 0.5\n[[loading]]\ndepth = 0.0\nrate = 1.0\n")
    assert main(["solve", "--scene", str(scene), "--out", str(tmp_path / "o")]) == 0
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert abs(s["loading"]["reached_force"] - 0.05) <= 1e-4 * 0.05 and s["status"] == "ok"
    assert (tmp_path / "o" / "history.csv").is_file()
    capsys.readouterr()
    assert main(["solve", "--force", "0.1", "--depth", "0.3", "--out", str(tmp_path / "b")]) == 2
    assert "depth" in capsys.readouterr().err and not (tmp_path / "b").exists()


def test_history_files_for_force_control_and_a_loading_history(mesh, tmp_path):
    """`history=True` (`solve --history`) gives result.pvd with the displacement of every
    increment for force control and for indent-hold-release too (it was ignored there): one
    step per increment, in time order, the last at the end of the run, all displacements finite;
    without it none."""
    from tactileskin.fe import solve

    base = BASE.replace(depth=0.2)
    target = 0.8 * solve(base, mesh=mesh).reaction
    for s in (BASE.replace(force=target), base.replace(loading=[{"hold": 1.0}, {"depth": 0.0, "rate": 1.0}])):
        r = solve(s, mesh=mesh, history=True)
        steps = r.fields["steps"]
        assert len(steps) == r.stats["increments"] >= 2
        t = [x[0] for x in steps]
        assert np.all(np.diff(t) > 0) and t[-1] == pytest.approx(r.loading["final"]["t_s"])
        assert all(u.shape == steps[0][1].shape and np.all(np.isfinite(u)) for _, u in steps)
        assert all("displacement" not in h for h in r.history)   # history.csv keeps its columns
        out = r.write(tmp_path / f"o{len(s.program())}")
        assert (out / "result.pvd").is_file() and len(list((out / "result_steps").iterdir())) == len(steps)
        assert not solve(s, mesh=mesh).fields["steps"]


def test_a_force_beyond_the_laws_lock_up_names_the_force(mesh):
    from tactileskin.fe import solve
    from tactileskin.fe.solver import SolverOptions

    # 1000 N/mm on a 2 mm skin: the increments shrink to nothing in the lock-up below the travel
    # cap (it ended as "more than 2000 increments" after 88 s); a short budget reaches the stall
    with pytest.raises(ParameterError, match="force") as e:
        solve(BASE.replace(force=1000.0), mesh=mesh, options=SolverOptions(max_increments=40))
    assert e.value.name == "force" and "stalled at" in str(e.value) and "N/mm" in str(e.value)


def test_a_force_no_trial_travel_meets_names_the_force(mesh):
    from tactileskin.fe import solve

    # 10000 N/mm on the same ramp time: an increment's force step outgrows what any travel of
    # it meets ("no convergence ... after 16 trial travels", the parameter unnamed)
    with pytest.raises(ParameterError, match="force") as e:
        solve(BASE.replace(force=10000.0), mesh=mesh)
    assert e.value.name == "force" and "a force this solve reaches" in str(e.value)
    assert "stalled at" in str(e.value) and "smaller target" in str(e.value)


def test_a_stall_far_from_the_laws_stiffening_does_not_blame_the_force_step(mesh, monkeypatch):
    import tactileskin.fe.loading as fl
    from tactileskin.fe import solve

    real = fl.run_program

    def stalling(model, program, opts=None, *, on_segment=None, **kw):
        # a gentle press commits (0.01 N/mm: far below the law's stiffening), then the ramp
        # stalls as a gel of mu0 2e-6 MPa did (Newton failed a 1.3 um step at 0.08 mm)
        real(model, [Segment("force", 0.01, time=0.2)], opts, **kw)
        raise ConvergenceError("no convergence at t = 1e-5 s: force control: reaction not within 1e-9 "
                               "of 0.011 after 16 trial travels")

    monkeypatch.setattr(fl, "run_program", stalling)
    with pytest.raises(ParameterError, match="force") as e:
        solve(BASE.replace(force=1.0), mesh=mesh)
    msg = str(e.value)
    # it said "a smaller target may converge": a smaller force stalls at the same travel
    assert e.value.name == "force" and "smaller target" not in msg
    assert "0.01 of the 1 N/mm asked" in msg and "of the 1.2 mm allowed" in msg
    assert "solve with depth (up to 1.2 mm)" in msg and "not stiffening" in msg


def test_an_increment_whose_target_is_out_of_reach_below_a_failed_trial_is_cut_back_early(mesh, monkeypatch):
    import tactileskin.fe.loading as fl
    from tactileskin.fe import model_for_scene
    from tactileskin.fe.solver import SolverOptions, Stats, _Failure

    real = fl._solve_increment

    def solve_increment(model, *a, **k):
        # Newton fails from the unloaded state beyond 0.3 mm, as a 3D sphere's first increment did
        if model.travel_fixed >= 0.3:
            raise _Failure("Newton did not converge", {})
        return real(model, *a, **k)

    monkeypatch.setattr(fl, "_solve_increment", solve_increment)
    model, _ = model_for_scene(BASE, mesh)
    stats = Stats()
    inc = fl.ForceIncrement(lambda t: 5.0, d_max=1.2, d_guess=lambda F: 0.05)
    with pytest.raises(_Failure, match="out of reach") as e:
        inc(model, model.u.copy(), 0.1, 0.1, SolverOptions(), stats)
    # ~0.14 N/mm at 0.3 mm of the 5 asked: the bisection crept up to the failed 0.3 mm over all
    # 16 trials (7 such increments were half of a 3D 1000 N run); now 6
    assert stats.force_trials <= 8 and e.value.diag["failed_mm"] == pytest.approx(0.3)
    assert 0.0 < e.value.diag["reached"] < 5.0 and model.travel_fixed is None


def test_a_stall_in_a_depth_segment_after_a_force_ramp_is_not_called_a_force_lock_up(mesh):
    from tactileskin.fe import _force_controlled, solve
    from tactileskin.fe.solver import SolverOptions

    prog = [Segment("force", 1.0, time=1.0), Segment("hold", time=1.0), Segment("depth", 0.5, time=1.0),
            Segment("hold", time=1.0)]
    assert [_force_controlled(prog, i) for i in range(5)] == [True, True, False, False, False]
    # the depth segment runs out of its increment budget: a solver failure, not "the force"
    base = BASE.replace(depth=0.2)
    target = 0.5 * solve(base, mesh=mesh).reaction
    scene = base.replace(loading=[{"force": target, "time": 0.2}, {"depth": 1.0, "time": 1.0}])
    with pytest.raises(ConvergenceError, match="increments"):
        solve(scene, mesh=mesh, options=SolverOptions(max_increments=4))


def test_the_force_secant_is_exact_on_a_power_law_and_linear_otherwise():
    from tactileskin.fe.loading import _secant

    # F = c d^p (a contact: Hertz p = 1.5): two trials give the root exactly in log-log
    for p in (1.0, 1.5, 2.3):
        F = lambda d: 0.7 * d ** p  # noqa: E731
        target = F(0.31)
        x = _secant((0.2, F(0.2) - target), (0.25, F(0.25) - target), target)
        assert x == pytest.approx(0.31, rel=1e-12)
    # a reaction that falls with the travel gives no root; a non-positive one the linear secant
    assert _secant((0.2, 0.1), (0.25, 0.05), 1.0) is None
    assert _secant((0.1, -1.5), (0.2, -0.5), 1.0) == pytest.approx(0.25)


def test_a_force_ramp_after_a_force_hold_starts_from_a_sane_trial(mesh):
    """After a creep hold the last two committed states carry the same force (to the
    tolerance): the log-log secant through them has an exponent of ~0.01 and sent the next
    ramp's first trials to zero travel (an unload) or to d_max (a reload); silicone, hold then
    unload to half, took 3 cutbacks and 4x the Newton iterations."""
    from tactileskin.fe import solve

    sc = BASE.replace(material="silicone", viscoelastic=True, force=0.01, load_time=0.05,
                      loading=[{"hold": 1.0}, {"force": 0.005, "time": 0.05}])
    r = solve(sc, mesh=mesh)
    assert r.stats["cutbacks"] == 0
    assert r.stats["force_trials"] <= 4 * r.stats["increments"]
    assert r.loading["final"]["reaction"] == pytest.approx(0.005, rel=5e-4)


def test_a_shallow_2d_force_ramp_reaches_its_force_to_rtol(mesh):
    """The reaction's noise allowance (slope x the contact's penetration tolerance, measured in
    3D) grows as 1/travel: in 2D it let a 2 um press stop 0.23 % short of its force."""
    from tactileskin.fe import solve
    from tactileskin.fe.loading import FORCE_RTOL

    base = BASE.replace(depth=0.002)
    target = solve(base, mesh=mesh).reaction
    r = solve(BASE.replace(force=target, depth=None, load_time=base.duration), mesh=mesh)
    assert abs(r.loading["reached_force"] - target) <= 1.01 * FORCE_RTOL * target


def test_the_3d_reaction_allowance_is_bounded_and_2d_keeps_rtol():
    from types import SimpleNamespace

    from tactileskin.fe.loading import FORCE_RTOL, NOISE_CAP, ForceIncrement

    inc = ForceIncrement(lambda t: 1.0, 1.0, lambda F: 0.1)
    contact = SimpleNamespace(tol_penetration=5e-4)
    m3, m2 = SimpleNamespace(m=3, contact=contact), SimpleNamespace(m=2, contact=contact)
    # F ~ d^1.5 at d = 0.3 mm: slope 1.5 F / d; the allowance 0.1 x slope x 5e-4 = 2.5e-4 F
    inc.slope = 1.5 / 0.3
    assert inc._tolerance(m3, 1.0, 0.3, 1.0) == pytest.approx(2.5e-4)
    assert inc._tolerance(m2, 1.0, 0.3, 1.0) == pytest.approx(FORCE_RTOL)
    # a shallow press (2 um): slope x tolerance grows as 1/travel; the allowance stops at the cap
    inc.slope = 1.5 / 0.002
    assert inc._tolerance(m3, 1.0, 0.002, 1.0) == pytest.approx(NOISE_CAP)


def test_a_force_ramp_that_fails_names_its_target_and_unit(monkeypatch):
    """`solve --force 1000` on a 1 mm skin failed with 'no converged state reaches 22.6337
    (failed at travel ...)': the ramp's force at that increment, without its unit, not the
    1000 N/mm asked for."""
    from types import SimpleNamespace

    from tactileskin.fe import loading
    from tactileskin.fe.solver import _Failure

    def fail(*a, **kw):
        raise _Failure("Newton did not converge", {})

    monkeypatch.setattr(loading, "_solve_increment", fail)
    inc = loading.ForceIncrement(lambda t: 22.6337, 0.6, lambda F: 0.05, goal=1000.0)
    model = SimpleNamespace(m=2, d=0.0, contact=None, travel_fixed=None)
    with pytest.raises(_Failure) as e:
        inc(model, None, 0.0045, 1e-6, None, SimpleNamespace(force_trials=0))
    assert "22.6337 N/mm" in e.value.why and "on the way to 1000 N/mm" in e.value.why, e.value.why


def test_reached_force_is_the_scene_force_ramps_not_a_later_segments(mesh):
    """summary.json `reached_force` answers `target_force` (the scene's force ramp): with a
    later, larger force segment it was that segment's reaction (0.08 reported as reached
    against the target 0.05: force control looked 60 % off), and `reached_travel_mm` is the
    travel of that state."""
    from tactileskin.fe import solve

    r = solve(BASE.replace(force=0.01, loading=[{"force": 0.02, "time": 0.2}]), mesh=mesh)
    lo = r.loading
    assert lo["target_force"] == 0.01
    assert abs(lo["reached_force"] - 0.01) <= 1e-4 * 0.01
    first = [x for x in r.history if x["segment"] == 0][-1]
    assert lo["reached_travel_mm"] == pytest.approx(first["d"], rel=1e-12)
    # the profile stays the peak-load state: the end of the 0.02 ramp, deeper
    assert abs(lo["profile_reaction"] - 0.02) <= 1e-4 * 0.02
    assert lo["profile_travel_mm"] > lo["reached_travel_mm"]


def test_a_segment_force_is_shown_in_the_scenes_unit(mesh, caplog):
    """The loading log said 'force to 0.01 N' in 2D, where a force is N/mm of the half section
    (plane strain); N stays for 3D."""
    import logging

    from tactileskin.fe import solve

    with caplog.at_level(logging.INFO, logger="tactileskin.fe.loading"):
        solve(BASE.replace(force=0.01, load_time=0.2), mesh=mesh)
    said = [r.getMessage() for r in caplog.records if "loading segment" in r.getMessage()]
    assert said and "force to 0.01 N/mm in 0.2 s" in said[0], said
    seg = Segment("force", 0.5, rate=2.0)
    assert seg.describe(3) == "force to 0.5 N at 2 N/s"
    assert seg.describe(2) == "force to 0.5 N/mm at 2 N/mm/s"
    assert Segment("depth", 0.4, time=1.0).describe(2) == "depth to 0.4 mm in 1 s"


def test_a_ramp_time_at_its_lower_end_solves(tmp_path, capsys):
    """The shortest ramp allowed after a force ramp (whose end depth the check cannot know) runs."""
    from tactileskin.cli import main

    (tmp_path / "s.toml").write_text("thickness = 1\nforce = 0.05\nforce_rate = 0.05\n"
                                     "[[loading]]\ndepth = 0.1\ntime = 1e-6\n")
    assert main(["solve", "--scene", str(tmp_path / "s.toml"), "--quality", "preview", "--elastic",
                 "-o", str(tmp_path / "o")]) == 0, capsys.readouterr().err


def test_a_ramp_that_ends_where_it_starts_in_float_time_is_refused_at_run_time():
    """A rate ramp from where a force ramp left the travel (unknown to the scene's check) to
    within 2e-16 s of it at t = 100 s: t0 + duration == t0, and the travel path divided by zero."""
    from types import SimpleNamespace

    from tactileskin.fe.loading import run_program

    model = SimpleNamespace(t=100.0, d=0.1, history=None, m=2)
    with pytest.raises(ParameterError, match=r"loading segment 0 .*depth to 0.1 mm at 1e\+06 mm/s.*1e-06 s"):
        run_program(model, [Segment("depth", 0.1000000002, rate=1e6)], d_max=1.0, d_guess=0.1)


def test_a_force_below_what_the_contact_resolves_names_the_force_not_the_lock_up(mesh, tmp_path):
    from tactileskin.fe import solve

    # the stiffest law a material file may hold (mu0 = 1e4 MPa) asked for the smallest force
    # (1e-4 N/mm): the reaction rises from 0 (no contact point pressed yet) to more than the
    # first increment's target within a travel step of ~1e-12 mm, below what the travel
    # resolves; no increment converged and the error blamed "the material law's lock-up" and
    # told to "try a smaller depth or force"
    mat = tmp_path / "stiff.toml"
    mat.write_text("[hyperfoam]\nmu = [1e4]\nalpha = [2.0]\nnu = 0.3\n")
    with pytest.raises(ParameterError, match="force") as e:
        solve(BASE.replace(force=1e-4, material=str(mat)), mesh=mesh)
    msg = str(e.value)
    assert e.value.name == "force" and "smaller" not in msg and "lock-up" not in msg
    assert "no contact" in msg and "larger force" in msg and "depth" in msg


def test_a_first_force_increment_out_of_reach_names_the_force(mesh, tmp_path):
    from tactileskin.fe import solve

    # the softest law a material file may hold (mu0 = 1e-6 MPa) asked for the largest force
    # (1e4 N/mm): the first increment's 0.197 N/mm was out of reach (4.5e-6 N/mm at 0.89 mm, a
    # trial at 1.2 mm failed), no increment converged, and the error named no parameter and
    # blamed "the material law's lock-up, elements too coarse" or the mesh
    mat = tmp_path / "soft.toml"
    mat.write_text("[hyperfoam]\nmu = [1e-6]\nalpha = [2.0]\nnu = 0.3\n")
    with pytest.raises(ParameterError, match="force") as e:
        solve(BASE.replace(force=1e4, material=str(mat)), mesh=mesh)
    msg = str(e.value)
    assert e.value.name == "force" and "lock-up" not in msg and "finer mesh" not in msg
    assert "out of reach" in msg and "0.893 mm" in msg and "depth" in msg


@pytest.mark.parametrize("fields, needle", [
    # the scene's own first ramp follows the rule of a [[loading]] ramp: >= MIN_RAMP_TIME
    (dict(thickness=3, rate=1e6), r"^rate=1000000.0 is invalid; valid: <= 6e\+05 mm/s.*1e-06 s"),
    (dict(thickness=3, depth=0.5, rate=1e6), r"^rate=1000000.0 is invalid; valid: <= 5e\+05 mm/s"),
    (dict(force=0.5, force_rate=1e6), r"^force_rate=1000000.0 is invalid; valid: <= 5e\+05 N/s"),
    (dict(force=0.5, load_time=1e-12), r"^load_time=1e-12 is invalid; valid: \[1e-06, 1e\+06\] s"),
    (dict(thickness=3, force=0.5, rate=1e6), r"^rate=1000000.0 is invalid; valid: <= 6e\+05 mm/s"),
])
def test_the_first_ramp_has_the_shortest_ramp_time_of_a_loading_segment(fields, needle):
    with pytest.raises(ParameterError, match=needle):
        Scene(**fields)


def test_one_rate_range_for_the_scene_and_loading_segments():
    from tactileskin import loading, scene

    assert scene.RATE is loading.RATE
    with pytest.raises(ParameterError, match=r"loading\[0\].rate.*\[1e-06, 1e\+06\]"):
        Scene(loading=[{"depth": 0.1, "rate": 2e6}])
    Scene(thickness=3, rate=6e5)  # 0.6 mm in 1e-6 s: the lower end runs as a segment's does


@pytest.mark.parametrize("fields, name", [
    ({"depth": 0.41256, "rate": 1e6}, "rate"),
    ({"force": 0.00041256, "force_rate": 1e6}, "force_rate"),
    ({"depth": 0.2, "rate": 1.0, "loading": [{"depth": 0.61256, "rate": 1e6}]}, r"loading\[0\].rate"),
])
def test_the_largest_rate_a_too_short_ramp_names_is_itself_accepted(fields, name):
    """The bound was printed to 3 digits rounded to nearest: travel 0.41256 mm said rate
    '<= 4.13e+05 mm/s', and rate = 4.13e5 was refused again (9.99e-07 s)."""
    import re

    from tactileskin.scene import Scene

    with pytest.raises(ParameterError, match=rf"^{name}=.*valid: <= (\S+) ") as e:
        Scene(thickness=3.0, **fields)
    bound = float(re.search(r"valid: <= (\S+) ", str(e.value)).group(1))
    key = name.replace("\\", "")
    if key.startswith("loading"):
        fields = {**fields, "loading": [{**fields["loading"][0], "rate": bound}]}
    else:
        fields = {**fields, key: bound}
    Scene(thickness=3.0, **fields)
