"""Newton with a backtracking line search, augmented-Lagrangian contact loop, adaptive time steps.

- Newton uses the consistent tangent and a sparse solve of the free block (fe.linsolve:
  PARDISO with the ordering analysed once per model, else SuperLU; on large 3D models the
  factorisation is reused across iterations and increments as a GMRES preconditioner).
  A line search halves the step while the trial state is inadmissible (J <= 0, material
  overflow guard) or the residual norm does not decrease; the residual norm of every
  iteration is logged (quadratic convergence is visible at DEBUG).
- Each increment: Newton with Uzawa multiplier updates once |R| <= uzawa_rtol * scale
  (one per iteration, the sticky set kept), until the largest gap of a pressed point is
  below the tolerance; a fresh Newton solve per update (uzawa_inline=False) cost 2-5
  iterations each. The penalty grows at the pressed points when the gap stalls; points
  not pressed when an increment starts take the base penalty again.
- A Newton direction that is not a descent direction (indefinite tangent after the first
  step's overshoot released contact points) is recomputed with those points held active,
  else without the indenter-curvature term (SolverOptions.ascent_remedy); in 2D a step the
  line search cuts below 0.2 is retried the same way (SolverOptions.short_step).
- Increments grow after easy convergence and are cut back after a failure; below the
  minimum increment a ConvergenceError carries a diagnosis (time, increment, residual
  history, where the worst residual sits).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field, replace

import numpy as np

from tactileskin.errors import ConvergenceError
from tactileskin.fe.linsolve import (METHODS, PRECISIONS, SymmetricSolver, default_ordering, default_threads,
                                     pardiso_available)
from tactileskin.fe.model import Evaluation, Model
from tactileskin.solver_options import EASY_ITERATIONS, REUSE_MIN_DOFS, SHORT_STEP, SolverOptions  # noqa: F401 (API)

log = logging.getLogger(__name__)

# of penalty * tol_penetration: the largest pull a sticky point may keep. 0.1 released so
# many points that t3 silicone flat needed 548 Newton iterations (1.0: 67)
PULL_FRACTION = 1.0


class _Failure(Exception):
    """A failed increment solve. inline_uzawa: whether Newton updated the multipliers inline
    before failing (only then can a retry with one Newton solve per update differ)."""

    def __init__(self, why: str, diag: dict, inline_uzawa: bool = True):
        super().__init__(why)
        self.why, self.diag, self.inline_uzawa = why, diag, inline_uzawa


@dataclass
class Stats:
    increments: int = 0
    cutbacks: int = 0
    predictor_fallbacks: int = 0  # increments re-solved from u_n after the predicted start failed
    newton_iterations: int = 0
    uzawa_iterations: int = 0
    factorizations: int = 0
    force_trials: int = 0       # force control: increment solves at trial travels (fe.loading)
    wall_s: float = 0.0
    history: list = field(default_factory=list)


def _worst(model: Model, R: np.ndarray) -> dict:
    Rf = np.zeros_like(R)
    Rf[model.free] = np.nan_to_num(R[model.free], nan=np.inf)
    k = int(np.argmax(np.abs(Rf)))
    node = k // model.m
    return {"dof": k, "component": k % model.m, "point_mm": model.basis.doflocs[:, node].tolist(),
            "value": float(R[k]) if np.isfinite(R[k]) else None}


def linear_method(model: Model, nfree: int, opts: SolverOptions) -> str:
    """The fe.linsolve method for this model: opts.linear_method unless "auto"; auto reuses
    factorisations on 3D models of at least opts.reuse_min_dofs free dofs solved by PARDISO
    (there a factorisation costs tens of GMRES iterations), else refactorises every time."""
    m = opts.linear_method
    if m not in ("auto",) + METHODS:
        from tactileskin.errors import ParameterError

        raise ParameterError("linear_method", m, "auto, " + ", ".join(METHODS))
    if m != "auto":
        return m
    pardiso = opts.linear_solver == "pardiso" or (opts.linear_solver == "auto" and pardiso_available())
    return "reuse" if model.m == 3 and nfree >= opts.reuse_min_dofs and pardiso else "direct"


def _threads(model: Model, nfree: int, opts: SolverOptions) -> int:
    """Threads of PARDISO and of the compiled loops: opts.threads, else linsolve's default
    (more than one for the large systems, those solved with "reuse")."""
    if opts.threads > 0:
        return opts.threads
    return default_threads(large=linear_method(model, nfree, opts) == "reuse")


def _factor(model: Model, K, opts: SolverOptions):
    """Give the free block K to the model's linear solver (which keeps the symbolic analysis
    and, with method "reuse", the factorisation it may precondition with)."""
    ls = getattr(model, "_linsolve", None)
    if ls is None or opts.linear_solver not in ("auto", ls.backend) or \
            (opts.linear_method != "auto" and opts.linear_method != ls.method):
        method = linear_method(model, K.shape[0], opts)
        if opts.factor_precision not in ("auto",) + PRECISIONS:
            from tactileskin.errors import ParameterError

            raise ParameterError("factor_precision", opts.factor_precision, ", ".join(("auto",) + PRECISIONS))
        # single precision only preconditions: a "direct" solve keeps double
        precision = "single" if method == "reuse" and opts.factor_precision != "double" else "double"
        ls = model._linsolve = SymmetricSolver(K, opts.linear_solver, method,
                                               threads=_threads(model, K.shape[0], opts), precision=precision,
                                               ordering=default_ordering(model.m))
        log.debug("linear solver: %s, %s, %s ordering, %d free dofs, %d threads", ls.backend, ls.method,
                  ls.ordering, K.shape[0], ls.threads)
    return ls.factor(K)


def _lifted(model: Model, u0, dofs, vals, t, dt, lam, stats, opts):
    """Start state with the new prescribed values. A bare jump of the boundary values
    squeezes the first element layer, which the hyperfoam lock-up turns into a huge
    residual that Newton unwinds one e-fold per iteration; instead, spread the jump
    with one linear solve at the last converged state (the consistent predictor)."""
    u = u0.copy()
    jump = vals - u0[dofs]
    if np.any(jump != 0.0):
        ev0 = model.evaluate(u0, t, dt, lam, tangent=True)
        if ev0.ok:
            dup = np.zeros_like(u0)
            dup[dofs] = jump
            K = model.pattern.matrix(ev0.K)
            rhs = -(ev0.R + K @ dup)[model.free]
            try:
                du = _factor(model, model.pattern.free_matrix(ev0.K), opts).solve(rhs)
                stats.factorizations += 1
                cand = u0 + dup
                cand[model.free] += du
                if np.all(np.isfinite(cand)) and model.evaluate(cand, t, dt, lam, tangent=False).ok:
                    u = cand
            except RuntimeError:
                pass
    u[dofs] = vals
    return u


def _line_search(model: Model, u, du, ev, t, dt, lam, opts: SolverOptions, sticky=None):
    """Step length along the Newton direction du: returns (eta, |R_free|, evaluation).

    The residual is the gradient of an incremental potential (hyperelastic + QLV with
    frozen history + augmented-Lagrangian contact), so the line minimum is where
    s(eta) = du . R(u + eta du) vanishes (Crisfield's line search, as Abaqus does).
    Inadmissible states (J <= 0, material guard) halve the step. An overshoot into the
    exponential lock-up of the hyperfoam shows as s(1) >> |s(0)| and is cut back by a
    safeguarded regula falsi; accept when |s| <= 0.5 |s(0)|.
    """
    free = model.free
    s0 = float(du[free] @ ev.R[free])
    eta, trial = 1.0, None
    for _ in range(opts.max_halvings + 1):
        trial = model.evaluate(u + eta * du, t, dt, lam, tangent=False, sticky=sticky)
        if trial.ok:
            break
        log.debug("    eta %.4g: %s", eta, trial.why)
        eta *= 0.5
    else:
        return 0.0, np.inf, None
    s1 = float(du[free] @ trial.R[free])
    log.debug("    eta %.4g: s = %.3e (s0 = %.3e)", eta, s1, s0)
    if s0 >= 0.0 or s1 <= 0.0 or abs(s1) <= 0.5 * abs(s0):
        # not a descent direction (indefinite tangent: take it), or still descending at
        # the largest admissible step, or close enough to the line minimum
        return eta, float(np.linalg.norm(trial.R[free])), trial
    lo, slo, hi, shi = 0.0, s0, eta, s1
    best = (abs(s1), eta, trial)
    for _ in range(opts.max_halvings):
        rf = lo + (hi - lo) * (-slo) / (shi - slo)
        e = min(max(rf, lo + 0.1 * (hi - lo)), lo + 0.9 * (hi - lo))
        tr = model.evaluate(u + e * du, t, dt, lam, tangent=False, sticky=sticky)
        if not tr.ok:
            hi, shi = e, abs(shi)  # treat as overshoot
            continue
        se = float(du[free] @ tr.R[free])
        log.debug("    eta %.4g: s = %.3e", e, se)
        if abs(se) < best[0]:
            best = (abs(se), e, tr)
        if abs(se) <= 0.5 * abs(s0):
            break
        if se > 0:
            hi, shi = e, se
        else:
            lo, slo = e, se
    _, e, tr = best
    return e, float(np.linalg.norm(tr.R[free])), tr


def _stick(ev, sticky, released):
    """Add the points active at `ev` to the sticky set (same law value there: no re-evaluation);
    points released earlier in this solve keep the plain law (else they cycle: stick, pull,
    release, stick)."""
    if sticky is None or ev.contact is None:
        return sticky
    grow = (ev.contact[1] > 0.0) & ~released
    if np.any(grow & ~sticky):
        sticky = sticky | grow
        ev._sticky = sticky
    return sticky


def _release(model: Model, ev, sticky):
    """Points of the sticky set pulling by more than PULL_FRACTION * penalty * tol_penetration
    (a pull of eps * gap is a gap error like a penetration): returns the reduced set, or
    None when none pulls."""
    c = model.contact
    lim = PULL_FRACTION * model.penalty() * c.tol_penetration
    pull = sticky & (ev.contact[1] < -lim)
    if not np.any(pull):
        return None
    # with them, the barely pressed points next to them (they would pull next: one peel
    # per Newton restart otherwise)
    return sticky & ~(ev.contact[1] < lim)


def gap_error(ev) -> float:
    """Largest |gap| (mm) at the pressed contact points: the penetration, and the separation
    where the multipliers press more than the penalty law would (a predicted multiplier
    that overshoots leaves a pressed point off the indenter, which a penetration-only test
    would accept)."""
    g, lamN = ev.contact[0], ev.contact[1]
    act = lamN > 0
    return float(np.abs(g[act]).max()) if np.any(act) else 0.0


def _uzawa_update(model: Model, ev, lam):
    """The augmented-Lagrangian multiplier update lambda <- max(lambda_N, 0) if the
    penetration exceeds the tolerance, else None."""
    if gap_error(ev) <= model.contact.tol_penetration:
        return None
    return np.maximum(ev.contact[1], 0.0)


def newton(model: Model, u0: np.ndarray, t: float, dt: float, lam, opts: SolverOptions, stats: Stats):
    """Solve R(u) = 0 at time t; returns (u, evaluation, iterations, residual history).

    Contact points that turn active stay active for the rest of this solve (the linear law,
    which may pull slightly): at the edge of the contact zone grazing points otherwise toggle
    between free and penetrating from one iterate to the next and Newton cycles (measured:
    t = 3 mm flat, 8-10 iterations per increment). Points that end up pulling by more than
    penalty * tol_penetration are released and Newton continues.
    """
    free = model.free
    ls = getattr(model, "_linsolve", None)
    if ls is not None:
        ls.begin_increment()
    dofs, vals = model.prescribed(t)
    u = _lifted(model, u0, dofs, vals, t, dt, lam, stats, opts)
    sticky = None
    if model.surface is not None and opts.sticky_contact:
        sticky = np.zeros(model.surface.shape, bool)
    released = None if sticky is None else np.zeros_like(sticky)
    lam_run = lam
    # the points stuck from the committed state (stick_committed) in an increment whose travel
    # is below the committed one: they are leaving the indenter, and may keep no pull
    backing_off = model.surface is not None and model.travel(t) < model.d
    stuck = None
    if opts.start_hold_off > 0.0 and model.surface is not None and lam is not None:
        ev = model.evaluate(u, t, dt, lam, tangent=False, sticky=sticky)
        if ev.ok:
            step = abs(model.travel(t) - model.travel(model.t))
            off = (ev.contact[0] > -opts.start_hold_off * step) & (lam <= 0.0)
            if np.any(off):
                lam = np.where(off, -np.inf, lam)  # lambda_N = max(0, -inf) = 0 there
    ev = model.evaluate(u, t, dt, lam, tangent=False, sticky=sticky)
    if not ev.ok:
        raise _Failure(f"start state inadmissible ({ev.why})", {"history": []}, inline_uzawa=False)
    hist = []
    short_step = SHORT_STEP.get(model.m, 0.0) if opts.short_step is None else opts.short_step
    # points pressed at some iterate of this solve (ascent_remedy holds them active again)
    seen = None if sticky is None or ev.contact is None else ev.contact[1] > 0.0
    releases = 0
    it = 0
    last_uzawa = -1
    while True:
        Rf = ev.R[free]
        rn = float(np.linalg.norm(Rf))
        scale = float(np.linalg.norm(ev.fint))
        hist.append(rn)
        if ev.contact is not None and log.isEnabledFor(logging.DEBUG):
            log.debug("  newton %2d  |R| = %.3e  (scale %.3e), %d contact points active, %d sticky, %d pulling",
                      it, rn, scale, int(np.sum(ev.contact[1] > 0)), -1 if sticky is None else int(sticky.sum()),
                      int(np.sum(ev.contact[1] < 0)))
        else:
            log.debug("  newton %2d  |R| = %.3e  (scale %.3e)", it, rn, scale)
        converged = rn <= opts.rtol * scale + opts.atol
        if sticky is not None and (converged or rn <= opts.release_rtol * scale + opts.atol):
            reduced = _release(model, ev, sticky)
            if reduced is None and converged and stuck is not None:
                pull = stuck & sticky & (ev.contact[1] < 0.0)
                if np.any(pull):
                    reduced = sticky & ~pull
            if reduced is not None:
                releases += 1
                if releases > opts.max_releases:
                    raise _Failure("contact points keep pulling after release", {"history": hist},
                                   inline_uzawa=last_uzawa >= 0)
                log.debug("  releasing %d pulling contact points", int(np.sum(sticky & ~reduced)))
                released |= sticky & ~reduced
                sticky = reduced
                ev = model.evaluate(u, t, dt, lam, tangent=False, sticky=sticky)
                continue
        if converged and lam is lam_run:
            return u, ev, it, hist, lam
        if opts.uzawa_inline and ev.contact is not None and it > last_uzawa \
                and rn <= opts.uzawa_rtol * scale + opts.atol:
            lam_new = _uzawa_update(model, ev, lam)
            if lam_new is not None:
                log.debug("  inline uzawa: gap error %.2e mm", gap_error(ev))
                lam = lam_run = lam_new
                last_uzawa = it
                stats.uzawa_iterations += 1
                ev = model.evaluate(u, t, dt, lam, tangent=False, sticky=sticky)
                continue
        if it >= opts.max_newton * (1 + releases):  # a release starts a fresh budget
            break
        du = np.zeros_like(u)
        try:
            K = model.tangent(ev, curvature=it >= opts.curvature_after if model.surface else None)
            # the solve may refactorise too (a stale reused factorisation)
            forcing = min(1e-3, opts.linear_forcing * rn / scale) if scale > 0 else None
            du[free] = -_factor(model, model.pattern.free_matrix(K), opts).solve(Rf, rtol=forcing)
        except (RuntimeError, FloatingPointError) as e:  # singular factor
            raise _Failure(f"singular tangent ({e})", {"history": hist, **_worst(model, ev.R)},
                           inline_uzawa=last_uzawa >= 0) from None
        stats.factorizations += 1
        if opts.ascent_remedy and float(du[free] @ Rf) > 0.0:
            du, ev, sticky = _descent(model, u, ev, du, sticky, seen, released, t, dt, lam, it, rn, scale,
                                      opts, stats)
        if not np.all(np.isfinite(du)):
            raise _Failure("non-finite Newton step", {"history": hist, **_worst(model, ev.R)},
                           inline_uzawa=last_uzawa >= 0)
        eta, tn, trial = _line_search(model, u, du, ev, t, dt, lam, opts, sticky)
        if opts.ascent_remedy and eta < short_step and sticky is not None:
            # a descent direction that goes nowhere: the same remedy, kept if it does better
            d2, ev2, st2 = _descent(model, u, ev, du, sticky, seen, released, t, dt, lam, it, rn, scale,
                                    opts, stats, held_only=True)
            if d2 is not du:
                eta2, tn2, trial2 = _line_search(model, u, d2, ev2, t, dt, lam, opts, st2)
                log.debug("  short step (eta %.3g, |R| %.3e): held points give eta %.3g, |R| %.3e",
                          eta, tn, eta2, tn2)
                if trial2 is not None and (trial is None or tn2 < tn):
                    du, ev, sticky, eta, tn, trial = d2, ev2, st2, eta2, tn2, trial2
        if trial is None:
            raise _Failure("line search found no admissible state", {"history": hist, **_worst(model, ev.R)},
                           inline_uzawa=last_uzawa >= 0)
        if tn > opts.max_residual_growth * rn:
            # measured (t = 1 silicone, curved): an ascent direction (indefinite tangent)
            # taken at eta = 1/32 raised |R| 2400x into the lock-up; Newton then spent its
            # budget unwinding it. A smaller increment converges in 4-6 iterations.
            raise _Failure(f"Newton step raised the residual {tn / max(rn, 1e-300):.3g}x",
                           {"history": hist + [tn], **_worst(model, trial.R)}, inline_uzawa=last_uzawa >= 0)
        if eta < 1.0:
            log.debug("  line search eta = %.4g", eta)
        u = u + eta * du
        ev = trial
        if seen is not None and ev.contact is not None:
            seen |= ev.contact[1] > 0.0
        if lam is not lam_run:  # the held-off points rejoin after the first step
            lam = lam_run
            ev = model.evaluate(u, t, dt, lam, tangent=False, sticky=sticky)
        if it >= opts.stick_after:  # the first iterates overshoot: they would stick points that then pull
            sticky = _stick(ev, sticky, released)
        elif it == 0 and (model.m == 3 if opts.stick_committed is None else opts.stick_committed) \
                and sticky is not None and lam_run is not None:
            grow = (np.asarray(lam_run) > 0.0) & ~released & ~sticky
            if np.any(grow):  # a pressed point's law differs from the sticky one where it opened
                sticky = sticky | grow
                stuck = grow if backing_off else None
                ev = model.evaluate(u, t, dt, lam, tangent=False, sticky=sticky)
        stats.newton_iterations += 1
        it += 1
    raise _Failure("Newton did not converge", {"history": hist, **_worst(model, ev.R)},
                   inline_uzawa=last_uzawa >= 0)


def _solve_increment(model: Model, u_pred: np.ndarray, t: float, dt: float, opts: SolverOptions, stats: Stats):
    """Newton + Uzawa at time t; returns (u, evaluation, newton iterations of the first solve)."""
    surf = model.surface
    if surf is not None and opts.penalty_fresh_points:
        surf.scale[surf.lam <= 0.0] = 1.0
    return _newton_uzawa(model, u_pred, t, dt, opts, stats)


def _descent(model: Model, u, ev, du, sticky, seen, released, t, dt, lam, it, rn, scale, opts, stats,
             held_only: bool = False):
    """A descent direction in place of the ascent direction du (du . R > 0): with the points
    pressed at an earlier iterate held active again, else without the curvature term.
    Returns (du, evaluation, sticky); du unchanged when neither gives descent."""
    free = model.free
    forcing = min(1e-3, opts.linear_forcing * rn / scale) if scale > 0 else None
    curv = model.surface is not None and it >= opts.curvature_after
    held = sticky
    tries = []
    if sticky is not None and seen is not None:
        add = seen & ~sticky & ~released
        if np.any(add):
            held = sticky | add
            tries.append(("held", held, curv))
    if curv and not held_only:
        tries.append(("no curvature", held, False))
    evals = {id(sticky): ev}  # both tries may hold the same set: evaluate it once
    for why, st, c in tries:
        ev2 = evals.get(id(st))
        if ev2 is None:
            ev2 = evals[id(st)] = model.evaluate(u, t, dt, lam, tangent=False, sticky=st)
        if not ev2.ok:
            continue
        K = model.tangent(ev2, curvature=c)
        d2 = np.zeros_like(du)
        try:
            d2[free] = -_factor(model, model.pattern.free_matrix(K), opts).solve(ev2.R[free], rtol=forcing)
        except (RuntimeError, FloatingPointError):
            continue
        stats.factorizations += 1
        s = float(d2[free] @ ev2.R[free])
        log.debug("  ascent direction: %s -> du.R = %.3e", why, s)
        if np.all(np.isfinite(d2)) and s < 0.0:
            return d2, ev2, st
    return du, ev, sticky


def _newton_uzawa(model: Model, u_pred: np.ndarray, t: float, dt: float, opts: SolverOptions, stats: Stats):
    c = model.contact
    lam = None if model.surface is None else model.surface.lam.copy()
    if opts.predict_multipliers and getattr(model.surface, "lam_prev", None) is not None and model.dt_prev:
        lam = np.maximum(0.0, lam + (lam - model.surface.lam_prev) * (dt / model.dt_prev))
    try:
        u, ev, its, hist, lam = newton(model, u_pred, t, dt, lam, opts, stats)
    except _Failure as f:
        if not opts.uzawa_inline or model.surface is None or not f.inline_uzawa:
            raise
        # in the lock-up the inline updates can keep Newton from settling (1 mm silicone at
        # 40 %): retry the increment with a fresh Newton solve per update. Not when no update
        # was made: the retry would repeat the same iterates (the 3D dot's first increment at
        # t = 3 spent 10 Newton iterations on that)
        opts = replace(opts, uzawa_inline=False)
        lam = model.surface.lam.copy()
        u, ev, its, hist, lam = newton(model, u_pred, t, dt, lam, opts, stats)
    if model.surface is None:
        return u, ev, its
    last_pen = np.inf
    for k in range(c.max_uzawa):
        lamN = ev.contact[1]
        act = lamN > 0
        pen = gap_error(ev)
        change = float(np.abs(lamN - lam).max() / max(lamN.max(), 1e-300)) if np.any(act) else 0.0
        log.debug(" uzawa %d: gap error %.2e mm, multiplier change %.2e", k, pen, change)
        # the multipliers then change by at most eps * tol_penetration
        if pen <= c.tol_penetration:
            return u, ev, its
        if pen > 0.3 * last_pen:  # slow Uzawa contraction: stiffen the penalty where pressed
            model.surface.scale[act] *= 4.0
            log.debug(" uzawa: penalty raised to %.3g MPa/mm", float(model.penalty().max()))
        last_pen = pen
        lam = np.maximum(lamN, 0.0)
        stats.uzawa_iterations += 1
        u, ev, _, hist, lam = newton(model, u, t, dt, lam, opts, stats)
    raise _Failure("augmented Lagrangian did not settle", {"penetration_mm": pen, "multiplier_change": change})


def secant_start(model: Model, dt: float) -> np.ndarray | None:
    """u_n + (u_n - u_{n-1}) dt / dt_{n-1}: the secant predictor of the increment of length
    dt from the committed state, or None before two states are committed."""
    if model.u_prev is None or not model.dt_prev:
        return None
    return model.u + (model.u - model.u_prev) * (dt / model.dt_prev)


def _predicted_increment(model: Model, t: float, dt: float, opts: SolverOptions, stats: Stats):
    """_solve_increment from the secant predictor (opts.predictor), else or after its
    failure from the committed state. With the lock-up of the hyperfoam volume term an
    extrapolated start that overshoots into compression can fail where the last converged
    (softer) state converges (1 mm silicone); the fallback keeps that case as it was."""
    start = secant_start(model, dt) if opts.predictor else None
    if start is not None:
        try:
            return _solve_increment(model, start, t, dt, opts, stats)
        except _Failure as f:
            stats.predictor_fallbacks += 1
            log.debug("predicted start failed (%s); solving from the committed state", f.why)
    return _solve_increment(model, model.u, t, dt, opts, stats)


def _travel_capped_dt(model: Model, t: float, dt: float, opts: SolverOptions) -> float:
    """dt, shortened so that the indenter travels at most opts.first_travel_radius x its
    tip radius in it (the first increment; in 3D every one, travel_cap_every)."""
    R = getattr(getattr(model.contact, "indenter", None), "tip_radius", np.inf)
    if opts.first_travel_radius <= 0 or not np.isfinite(R) or dt <= 0:
        return dt
    step = abs(model.travel(t + dt) - model.travel(t))
    cap = opts.first_travel_radius * R
    return dt * cap / step if step > cap else dt


# what a depth ramp that cannot go on means, and what to try
_GIVES_OUT = ("the skin or its mesh gives out there: the material law's lock-up, elements too coarse for the "
              "strain or the contact; try a smaller depth or force, or a finer mesh: quality fine")


def _travel_text(model) -> str:
    """' after <d> mm of indenter travel' of a contact model, '' otherwise."""
    d = getattr(model, "d", None) if getattr(model, "contact", None) is not None else None
    return "" if d is None else f" after {float(d):.4g} mm of indenter travel"


@dataclass(frozen=True)
class IncrementInfo:
    """What `run(..., progress=)` reports after each converged increment."""

    increment: int         # number of converged increments so far
    t: float               # time reached (s)
    T: float               # end time (s)
    travel: float          # indenter travel d at t (mm)
    newton: int            # Newton iterations spent since the previous increment (incl. cutbacks)
    newton_total: int      # Newton iterations of the whole run so far
    cutbacks: int          # cut-back increments of the whole run so far


def run(model: Model, T: float, opts: SolverOptions | None = None, *, history: bool = False,
        record: callable = None, progress: callable = None, increment: callable = None,
        stats: Stats | None = None) -> tuple[Evaluation, Stats]:
    """Integrate from the committed state at model.t to time T; returns the last evaluation.
    progress: called with an IncrementInfo after each converged increment. increment: the
    increment solver (model, u, t, dt, opts, stats) -> (u, evaluation, iterations), by
    default Newton + Uzawa at the travel model.travel(t) (fe.loading.ForceIncrement finds
    the travel of a target force); it raises _Failure to cut back. stats: continue these
    (a loading history runs one segment after the other)."""
    opts = opts or SolverOptions()
    stats = stats if stats is not None else Stats()
    if hasattr(model, "free"):  # a Model (the tests' stand-ins have no dofs)
        model.threads = _threads(model, len(model.free), opts)
    newton_seen = stats.newton_iterations
    t0 = time.perf_counter() - stats.wall_s
    t = model.t
    span = T - t
    dt = _travel_capped_dt(model, t, opts.dt0_fraction * span, opts) if increment is None else opts.dt0_fraction * span
    dt_min = opts.dt_min_fraction * span
    dt_cap = np.inf  # opts.failed_dt_fraction x the shortest increment that failed
    easy = EASY_ITERATIONS.get(getattr(model, "m", 2), 7) if opts.easy_iterations is None else opts.easy_iterations
    ev = None
    if span <= 0:
        ev = model.evaluate(model.u, t, 0.0, tangent=False)
    while t < T - 1e-12 * span:
        dt = min(dt, T - t, opts.dt_max_fraction * span, dt_cap)
        cap_every = getattr(model, "m", 2) == 3 if opts.travel_cap_every is None else opts.travel_cap_every
        if cap_every and increment is None:
            dt = _travel_capped_dt(model, t, dt, opts)
        if T - (t + dt) < 1e-3 * dt:
            dt = T - t
        try:
            if increment is not None:  # e.g. force control: its own travel search per increment
                unew, ev, its = increment(model, model.u, t + dt, dt, opts, stats)
            else:
                unew, ev, its = _predicted_increment(model, t + dt, dt, opts, stats)
        except _Failure as f:
            stats.cutbacks += 1
            log.info("increment t=%.5g dt=%.3g failed (%s); cutting back", t + dt, dt, f.why)
            if dt * opts.cutback < dt_min:
                diag = {"time": t, "dt": dt, "reason": f.why, **f.diag}
                raise ConvergenceError(f"no convergence at t = {t:.6g} s{_travel_text(model)} with dt = {dt:.3g} s: "
                                       f"{f.why} ({_GIVES_OUT})", diag) from None
            if opts.failed_dt_fraction > 0.0:
                dt_cap = min(dt_cap, opts.failed_dt_fraction * dt)
                # no increment is longer than dt_cap from here (but a last one 1e-3 longer): past
                # max_increments a depth ramp cannot finish, so stop now rather than crawl there (a
                # confined pad under the flat plate: ~390 to 870 tiny steps, 15 to 24 s CPU, to fail:
                # benchmarks/confined_pad.py).
                # Force control keeps going: its errors name the force from the state it reached
                need = (T - t) / (1.001 * dt_cap) - 1.0
                if increment is None and need > opts.max_increments - stats.increments:
                    raise ConvergenceError(
                        f"no convergence at t = {t:.6g} s{_travel_text(model)} with dt = {dt:.3g} s: {f.why}, and "
                        f"at the {dt_cap:.3g} s allowed after it the rest of the load needs {need:.0f} more "
                        f"increments, past the {opts.max_increments} allowed ({_GIVES_OUT})",
                        {"time": t, "dt": dt, "dt_cap": dt_cap, "reason": f.why, **f.diag}) from None
            dt *= opts.cutback
            continue
        model.commit(ev, unew, t + dt, dt)
        t += dt
        stats.increments += 1
        log.debug("increment %d: t = %.5g s (dt %.3g), %d Newton iterations", stats.increments, t, dt, its)
        if history:
            stats.history.append({"t": t, **(record(model, ev) if record else {})})
        if progress is not None:
            progress(IncrementInfo(stats.increments, t, T, float(model.travel(t)),
                                   stats.newton_iterations - newton_seen, stats.newton_iterations, stats.cutbacks))
            newton_seen = stats.newton_iterations
        if its <= easy:
            dt *= opts.growth
        if stats.increments >= opts.max_increments:
            raise ConvergenceError(f"more than {opts.max_increments} increments", {"time": t, "dt": dt})
    stats.wall_s = time.perf_counter() - t0
    return ev, stats
