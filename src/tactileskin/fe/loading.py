"""Loading histories in the solver: displacement control, force control, holds, releases.

`run_program(model, program, ...)` runs the segments of a `tactileskin.loading` history one
after the other through `fe.solver.run`: a depth segment moves the travel linearly from where
it is (`Model.travel_path`), a force segment makes the reaction follow a linear ramp from
its current value, a hold keeps the last control's value while time passes (the QLV stress
relaxes at fixed travel; the indenter creeps at fixed force).

Force control (`ForceIncrement`): per increment the travel d is the unknown of the scalar
equation F(d) = F*(t), F the indenter's vertical reaction of the converged increment at
travel d, solved by a safeguarded secant (Illinois regula falsi once a bracket is found)
around the unchanged displacement-controlled increment solve. Why not the bordered system
(u and d together, with the force equation): every trial is then the proven increment solve
(line search, sticky active set, Uzawa updates, its own failure handling), while in one
bordered Newton the force equation inherits the active-set and multiplier kinks of the
contact (its derivative jumps as points enter contact) and a diverging iterate would need
the safeguards redone for d. F(d) is monotone for a stable skin, so a bracketed scalar
root is safe; the secant is taken in log-log (a contact's F ~ d^p) and the committed states
predict the next travel: 3-4 trial solves per increment at `preview`, 2D and 3D (stats
force_trials; benchmarks/results/force_control.md).
"""

from __future__ import annotations

import logging
import math
from dataclasses import replace

import numpy as np

from tactileskin.errors import ConvergenceError, ParameterError
from tactileskin.fe.solver import SolverOptions, Stats, _Failure, _solve_increment, run
from tactileskin.loading import MIN_RAMP_TIME

log = logging.getLogger(__name__)

FORCE_RTOL = 1e-4   # |F - F*| <= FORCE_RTOL |F*|: the contact tolerance (1e-4 h) moves F by ~3e-5 F
MAX_TRIALS = 16
NOISE_FRACTION = 0.1  # of slope x tol_penetration: the accepted reaction error (ForceIncrement._tolerance)
NOISE_CAP = 1e-3      # ... but never more than this fraction of the force (3D sphere at 0.3 mm: 3e-4)
# the steepest local exponent p of F ~ d^p measured (a 2D R 2.5 cylinder 0.6 mm into 1 mm silicone:
# 1.6 at 0.05 mm, 22 at 0.6 mm; the 3D sphere's reached 6): a converged trial whose force, raised to
# a failed deeper trial's travel by it, stays below the target cannot meet it in this increment
MAX_EXPONENT = 25.0
UNDERSHOOT = 0.05  # of a predicted travel step (about 3 % of it is the predictor's error)
SECANT_BASE = 0.1  # the committed states' force difference, as a fraction of the step it predicts
# a hold's increments end at times growing geometrically from HOLD_FIRST x the shortest Prony
# time: the relaxation (creep) is fastest at the hold's start, and the solver's equal quarters
# put a 300 s hold's first point at 75 s, after all of silicone's (tau 0.025-0.3 s)
HOLD_FIRST = 0.5
HOLD_GROWTH = 1.5         # largest ratio of successive end times (from the hold's start)
HOLD_MAX_INCREMENTS = 32  # bounds a long hold's cost (past it the ratio grows: 1e6 s of silicone, 1.80)


def vertical_reaction(model, ev) -> float:
    """The indenter's vertical force on the skin (fe.output.indenter_force: N on the whole
    indenter in 3D, N/mm of the half section in plane strain), as Result.reaction."""
    from tactileskin.fe.output import indenter_force

    return indenter_force(model, ev)


def _unit(model) -> str:
    """The reaction's unit: N on the whole indenter in 3D, N/mm of the half section in 2D."""
    from tactileskin.loading import force_unit

    return force_unit(getattr(model, "m", 3))


class ForceIncrement:
    """Increment solver for fe.solver.run(increment=) under force control: finds the travel
    d at which the reaction equals target(t) to FORCE_RTOL.

    d_max: largest travel allowed (the skin's capacity for this history: a target not reached
    there raises ConvergenceError); d_guess(F): a travel for the first trial when no slope is
    known yet."""

    def __init__(self, target, d_max: float, d_guess, *, f_start: float = 0.0, prior: "ForceIncrement | None" = None,
                 rtol: float = FORCE_RTOL, goal: float | None = None):
        self.target, self.d_max, self.d_guess, self.rtol = target, float(d_max), d_guess, rtol
        self.goal = goal  # the segment's final force, named when the skin cannot carry it
        self.f_committed = self.reached = float(f_start)
        # what predicts the next increment's travel (kept across force-controlled segments):
        # the local slope dF/dd, the exponent p of F ~ d^p over the last increment's trials, and
        # the committed state before the last one
        self.slope, self.p, self.prev = (prior.slope, prior.p, prior.prev) if prior is not None else (None, None, None)

    def _tolerance(self, model, F: float, d: float, reached: float) -> float:
        """|F - F*| accepted: rtol |F*|, or the reaction's own resolution where that is
        coarser. The contact is enforced to a penetration tol_penetration (3D: 1e-3 of the
        facet size), and converged trials scatter about a smooth F(d) by about 5 % of slope x
        tol_penetration (measured on a 3D sphere: 3-4e-5 N of 0.19 N, 2e-4 of it): 4-7 trials
        an increment chased that scatter. Twice it is accepted, in 3D only: in 2D (1e-4 of the
        facet) rtol is reached as before, and slope x tol_penetration grows as 1/travel (a
        2 um press on a 2 mm skin stopped 0.23 % short of its force, 23 x rtol)."""
        tol_pen = getattr(getattr(model, "contact", None), "tol_penetration", None) or 0.0
        if getattr(model, "m", 3) != 3:
            tol_pen = 0.0
        k = self.slope if self.slope and self.slope > 0 else (reached / d if d > 0 and reached > 0 else 0.0)
        # at most NOISE_CAP |F|: slope x tol_penetration grows as 1/travel on a shallow press
        return max(self.rtol * abs(F), min(NOISE_FRACTION * k * tol_pen, NOISE_CAP * abs(F)), 1e-12)

    def _prev_spans(self, model, F: float, d0: float, f0: float) -> bool:
        """Whether the secant through the last two committed states may predict this step: their
        forces must differ by more than the reaction's resolution and by SECANT_BASE of the step.
        After a force hold they are equal to within the tolerance, and the line through them
        (an exponent of ~0.01) sent the next ramp's first trials to zero travel or to d_max
        (silicone, hold then unload to half: 3 cutbacks, 4x the Newton iterations)."""
        if self.prev is None:
            return False
        base = abs(f0 - self.prev[1])
        return base > 10.0 * self._tolerance(model, F, d0, f0) and base >= SECANT_BASE * abs(F - f0)

    def __call__(self, model, u0, t, dt, opts, stats: Stats):
        F = float(self.target(t))
        d0, f0 = model.d, self.f_committed
        # first trial: the log-log secant through the last two committed states (it carries the
        # relaxation between increments: a sphere's first trials within 0.5 % in travel), else
        # this state and the exponent of the last increment's trials, else the local slope
        d = _secant((self.prev[0], self.prev[1] - F), (d0, f0 - F), F) if self._prev_spans(model, F, d0, f0) else None
        if d is None and self.p and d0 > 0 and f0 > 0 and F > 0:
            d = d0 * (F / f0) ** (1.0 / self.p)
        if d is None:
            if self.slope and self.slope > 0:
                d = d0 + (F - f0) / self.slope
            else:
                d = self.d_guess(F) if d0 == 0.0 else d0 * max(F, 1e-300) / max(f0, 1e-300)
        elif d > d0:
            # aim short by UNDERSHOOT of the step: a first trial below the target hands the
            # second its state (a short step), one above it sends the second back to u0
            d = d0 + (1.0 - UNDERSHOOT) * (d - d0)
        d = min(max(d, 0.0), self.d_max)
        lo = hi = None            # (d, f) with f < 0 / f > 0
        pts = []                  # converged trials (d, f, u, ev, its)
        fails = 0
        try:
            for _ in range(MAX_TRIALS):
                model.travel_fixed = d
                # from the converged trial nearest below d, else the committed state (a trial at
                # a deeper travel is a bad start: its surface overlaps the indenter)
                below = [p for p in pts if p[0] <= d]
                start = max(below, key=lambda p: p[0])[2] if below else u0
                stats.force_trials += 1
                try:
                    u, ev, its = _solve_increment(model, start, t, dt, opts, stats)
                except _Failure as e:
                    # too deep for this step (lock-up) or a too large jump: step back towards lo
                    fails += 1
                    log.debug("force control: travel %.6g mm failed (%s)", d, e.why)
                    if fails > 3 or lo is None and d <= 1e-9:
                        raise _Failure(f"force control: no converged state reaches {F:.6g} {_unit(model)}"
                                       f"{self._on_way(F, model)} (failed at travel {d:.6g} mm: {e.why})",
                                       e.diag) from None
                    lo_d = lo[0] if lo is not None else (d0 if d0 < d else 0.0)
                    if hi is None or d < hi[0]:
                        hi = (d, math.inf)
                    self._reachable(lo, hi, F, model)
                    d = 0.5 * (lo_d + d)
                    continue
                f = vertical_reaction(model, ev) - F
                log.debug("force control: travel %.8g mm, reaction %.8g (target %.8g)", d, f + F, F)
                pts.append((d, f, u, ev, its))
                if abs(f) <= self._tolerance(model, F, d, f + F):
                    return self._accept(model, d, f + F, d0, u, ev, its, pts)
                if f < 0:
                    lo = (d, f)
                else:
                    hi = (d, f)
                self._reachable(lo, hi, F, model)
                d = self._next(d, f, lo, hi, pts, F, model)
        finally:
            model.travel_fixed = None
        last = pts[-1] if pts else (model.d, 0.0)
        raise _Failure(f"force control: reaction not within {self._tolerance(model, F, last[0], last[1] + F):.3g} "
                       f"of {F:.6g} after {MAX_TRIALS} trial travels",
                       {"travels_mm": [p[0] for p in pts], "force_errors": [p[1] for p in pts], "target": F})

    @staticmethod
    def _reachable(lo, hi, F: float, model) -> None:
        """Cut the increment back (raise _Failure) when the travels between a converged trial
        below the target (lo) and a failed deeper one (hi) cannot meet it: lo's force raised to
        hi's travel by MAX_EXPONENT is still short. The bisection used to creep up to the failed
        travel over all MAX_TRIALS: a 3D sphere asked for 1000 N spent 7 increments of 16 trials
        (the first 0.43 N of 250 N within 4e-5 mm of its failure at 0.3 mm), half of its trials."""
        if lo is None or hi is None or math.isfinite(hi[1]) or lo[0] <= 0.0 or lo[1] + F <= 0.0:
            return
        if (lo[1] + F) * (hi[0] / lo[0]) ** MAX_EXPONENT < F:
            raise _Failure(f"force control: {F:.6g} {_unit(model)} out of reach of this increment's trial travels "
                           f"(the reaction is {lo[1] + F:.6g} at travel {lo[0]:.6g} mm, a trial at {hi[0]:.6g} mm "
                           "failed)",
                           {"travel_mm": lo[0], "reached": lo[1] + F, "failed_mm": hi[0], "target": F})

    def _on_way(self, F: float, model) -> str:
        """' on the way to GOAL unit' when the ramp's force F at this increment is not the
        segment's final force (a failure names what was asked for, not only F)."""
        if self.goal is None or abs(self.goal - F) <= 1e-9 * max(abs(self.goal), 1.0):
            return ""
        return f" on the way to {self.goal:.6g} {_unit(model)}"

    def _next(self, d, f, lo, hi, pts, F, model) -> float:
        # the secant through the last two trials, in log-log where both reactions are
        # positive (a contact's F ~ d^p, p 1-2: the linear secant overshot a sphere's first
        # increment by 24 %), kept inside the bracket once there is one (else bisection)
        x = _secant(pts[-2][:2], pts[-1][:2], F) if len(pts) >= 2 else None
        if lo is not None and hi is not None:
            w = hi[0] - lo[0]
            if x is None:
                x = 0.5 * (lo[0] + hi[0])
            if not (lo[0] + 0.01 * w <= x <= hi[0] - 0.01 * w):
                x = 0.5 * (lo[0] + hi[0]) if not math.isfinite(hi[1]) else \
                    lo[0] - lo[1] * w / (hi[1] - lo[1])
                x = min(max(x, lo[0] + 0.1 * w), hi[0] - 0.1 * w)
            return x
        # no bracket yet: that secant, else the power law through this trial with the
        # committed state's local exponent (or Hertz's 1.5: it undershoots a stiffening layer
        # rather than overshooting into its lock-up), stepping at most 2x the distance covered
        if x is None:
            p = 1.5
            if self.slope and self.slope > 0 and model.d > 0 and self.f_committed > 0:
                p = min(max(self.slope * model.d / self.f_committed, 0.5), 4.0)
            x = d * (F / (f + F)) ** (1.0 / p) if d > 0 and f + F > 0 else (d + self.d_max) / 2 if f < 0 else 0.5 * d
        if f < 0:  # below the target: deeper
            if d >= self.d_max * (1 - 1e-12):
                goal = F if self.goal is None else self.goal
                unit = _unit(model)
                on_way = "" if abs(goal - F) <= 1e-9 * max(abs(goal), 1.0) else f" (on the way, at {F:.6g} {unit})"
                raise ConvergenceError(
                    f"force {goal:.6g} {unit} not reached: the reaction is {f + F:.6g} {unit} at the largest travel "
                    f"{self.d_max:.6g} mm (0.6 x thickness){on_way}; the skin cannot carry this force "
                    "within its depth range", {"force": goal, "ramp_force": F, "reached": f + F, "travel_mm": d})
            x = max(x, d + 1e-6 * self.d_max)
            return min(x, d + 2.0 * max(d - model.d, 1e-3 * self.d_max), self.d_max)
        return max(min(x, d), 0.5 * d)

    def _accept(self, model, d, Freached, d0, u, ev, its, pts):
        # the next increment's predictor: the exponent p of F ~ d^p between the accepted trial
        # and the one farthest from it (trials a few um apart differ by the contact's noise),
        # its slope p F / d, and the state this increment started from
        F = Freached - pts[-1][1]
        far = max(pts, key=lambda q: abs(q[0] - d))
        if abs(far[0] - d) > 0.01 * d and far[1] + F > 0 and Freached > 0 and far[0] > 0:
            p = math.log(Freached / (far[1] + F)) / math.log(d / far[0])
            self.p = p if 0 < p < 10 else self.p
        if self.p and d > 0 and Freached > 0:
            self.slope = self.p * Freached / d
        elif d != d0 and Freached != self.f_committed:
            self.slope = (Freached - self.f_committed) / (d - d0)
        if self.slope is not None and self.slope <= 0:
            self.slope = None
        self.prev = (d0, self.f_committed) if d0 > 0 and self.f_committed > 0 and d != d0 else None
        self.f_committed = self.reached = Freached
        self.travel = d
        model.travel_path = (lambda t, d=d: d)  # run() commits this travel (travel_fixed is cleared)
        return u, ev, its


def _secant(a, b, F: float) -> float | None:
    """The travel at which the line through trials a, b = (d, F - F*) reaches F*: in log-log
    where both travels and reactions are positive and the exponent is, else linear; None if
    the reaction does not grow with the travel between them."""
    (da, fa), (db, fb) = a, b
    Fa, Fb = fa + F, fb + F
    if da == db or fa == fb:
        return None
    if min(da, db, Fa, Fb) > 0 and F > 0:
        p = math.log(Fb / Fa) / math.log(db / da)
        if p > 0:
            return da * (F / Fa) ** (1.0 / p)
    k = (fb - fa) / (db - da)
    return da - fa / k if k > 0 else None


def hold_times(prony, span: float, opts: SolverOptions) -> np.ndarray | None:
    """End times (s from the hold's start) of a hold's increments: geometric from HOLD_FIRST x
    the shortest relaxation time to `span`, ratio at most HOLD_GROWTH unless that takes more
    than HOLD_MAX_INCREMENTS; None where the solver's own first increment is that short already
    (or nothing relaxes: no Prony terms)."""
    if prony is None or prony.n_terms == 0:
        return None
    first = HOLD_FIRST * min(prony.tau)
    if opts.dt0_fraction * span <= first:
        return None
    n = min(HOLD_MAX_INCREMENTS, math.ceil(math.log(span / first) / math.log(HOLD_GROWTH)) + 1)
    times = first * (span / first) ** (np.arange(n) / (n - 1))
    times[-1] = span
    return times


def run_program(model, program, opts=None, *, d_max: float, d_guess, record=None, progress=None,
                on_segment=None):
    """Run the segments of a loading history (tactileskin.loading.Segment list) from the
    model's committed state; returns (last evaluation, Stats, per-increment records).

    on_segment(index, segment, ev): called after each segment (e.g. to keep the peak-load
    state's result). Each record: t, travel d, reaction, segment index (+ record(model, ev))."""
    stats = Stats()
    opts = opts or SolverOptions()
    control, f_now, force_inc = None, 0.0, None
    ev = None
    for i, seg in enumerate(program):
        t0 = model.t

        def rec(model, ev, i=i):
            r = {"segment": i, "d": float(model.d), "reaction": vertical_reaction(model, ev)}
            if record is not None:
                r.update(record(model, ev))
            return r

        increment, stops = None, None
        if seg.kind != "hold" and not t0 + seg.duration(model.d if seg.kind == "depth" else f_now) > t0:
            # a rate ramp from where another control left it (a force ramp's end depth, which the
            # scene's check cannot know) to within the float spacing of t0: the path divides by T - t0
            raise ParameterError(f"loading segment {i} ({seg.describe(getattr(model, 'm', 3))})",
                                 seg.duration(model.d if seg.kind == "depth" else f_now),
                                 f"a ramp of at least {MIN_RAMP_TIME:g} s (from {model.d if seg.kind == 'depth' else f_now:g}"
                                 f" at t = {t0:g} s it ends where it starts)", "a smaller rate, or time = s")
        if seg.kind == "depth":
            d0, d1 = model.d, seg.target
            T = t0 + seg.duration(d0)
            model.travel_path = (lambda t, d0=d0, d1=d1, t0=t0, T=T: d0 + (d1 - d0) * min(1.0, (t - t0) / (T - t0)))
            control = "depth"
        elif seg.kind == "force":
            F0, F1 = f_now, seg.target
            T = t0 + seg.duration(F0)
            force_inc = ForceIncrement(lambda t, F0=F0, F1=F1, t0=t0, T=T: F0 + (F1 - F0) * min(1.0, (t - t0) / (T - t0)),
                                       d_max, d_guess, f_start=f_now, goal=F1,
                                       prior=force_inc if control == "force" else None)
            increment, control = force_inc, "force"
        else:  # hold
            T = t0 + seg.time
            stops = hold_times(getattr(getattr(model, "history", None), "prony", None), seg.time, opts)
            if control == "depth":
                model.travel_path = (lambda t, d=model.d: d)
            else:
                Fh = f_now
                force_inc = ForceIncrement(lambda t, Fh=Fh: Fh, d_max, d_guess, f_start=f_now,
                                           prior=force_inc if control == "force" else None)
                increment = force_inc
        # the rate of S0 jumps at a segment boundary (ramp -> hold): the parabola through the
        # last three states would carry the ramp into the hold (measured: the reaction fell
        # 2.7x too far in the first hold increment, then rose); start each segment with the chord
        if hasattr(model.history, "dt_prev"):
            model.history.dt_prev = None
        log.info("loading segment %d: %s (t %.4g -> %.4g s)", i, seg.describe(getattr(model, "m", 3)), t0, T)
        if stops is None:
            ev, stats = run(model, T, opts, history=True, record=rec, progress=progress, increment=increment,
                            stats=stats)
        else:  # one increment per stop (cut back as any), the progress told the hold's end
            one = replace(opts, dt0_fraction=1.0, dt_max_fraction=1.0)
            told = None if progress is None else (lambda info, T=T: progress(replace(info, T=T)))
            for stop in stops:
                ev, stats = run(model, t0 + stop, one, history=True, record=rec, progress=told,
                                increment=increment, stats=stats)
        f_now = vertical_reaction(model, ev)
        if increment is not None:
            f_now = increment.reached
        if not np.isfinite(f_now):
            raise ConvergenceError(f"non-finite reaction after loading segment {i}", {"segment": i})
        if on_segment is not None:
            on_segment(i, seg, ev)
    model.travel_path = (lambda t, d=model.d: d)
    return ev, stats, stats.history
