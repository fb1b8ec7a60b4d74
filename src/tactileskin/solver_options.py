"""The Newton solver's settings (fe.solver.SolverOptions) and their by-dimension defaults.

Apart from the solver so that what only states them (the sweep report's run settings) does not
import it (numba, scikit-fem: ~0.3 s idle, ~0.8 s on a loaded machine, in every sweep's main
process); fe.solver takes these same objects.
"""

from __future__ import annotations

from dataclasses import dataclass

# free dofs from which a 3D model reuses factorisations (benchmarks/results/linsolve3d.md)
REUSE_MIN_DOFS = 10000


@dataclass
class SolverOptions:
    # residual norm relative to the internal-force norm. 1e-5 (was 1e-8; Abaqus' default is 5e-3
    # of the average force): Newton is quadratic there, and the iteration from ~1e-6 to 1e-14
    # that 1e-8 asked for moved no peak by more than 0.05 % (36 paper cases in 2D: 1233 -> 1135
    # Newton iterations; the six 3D default dots: -4 to -14 %, the same peaks to 5 digits;
    # benchmarks/results/contact_newton.md)
    rtol: float = 1e-5
    atol: float = 1e-12           # absolute residual floor (N)
    max_newton: int = 10           # healthy increments converge in <= 8; failing fast is cheaper
    max_halvings: int = 8
    # first increment as a fraction of the total time. 0.25 (was 0.1): with the second-order
    # QLV update the time error of 4 increments is 0.07-0.14 % of the peak (preview meshes,
    # against dt = 0.02), and every increment costs ~6-15 Newton iterations of contact
    # settling however short; 18 paper cases 1919 -> 1648 iterations, 97 -> 77 s CPU
    dt0_fraction: float = 0.25
    dt_min_fraction: float = 1e-5
    dt_max_fraction: float = 0.25
    growth: float = 1.5
    cutback: float = 0.35
    # grow the increment when Newton needed at most this many; None: EASY_ITERATIONS of the
    # model's dimension
    easy_iterations: int | None = None
    max_increments: int = 2000
    linear_solver: str = "auto"   # fe.linsolve backend: auto | pardiso | superlu
    # fe.linsolve method: direct (refactorise every Newton iteration) | reuse (GMRES with the
    # last factorisation, refactorised when that stops paying) | auto (reuse on 3D models of
    # at least reuse_min_dofs free dofs with PARDISO, else direct)
    linear_method: str = "auto"
    # auto takes "reuse" for 3D models with at least this many free dofs and PARDISO
    reuse_min_dofs: int = REUSE_MIN_DOFS
    # threads of PARDISO and of the compiled loops (fe.model.threads); 0: fe.linsolve.
    # default_threads (for the models solved with "reuse" TACTILESKIN_THREADS or
    # MKL_NUM_THREADS if set, else the available CPUs up to 4; for the others
    # MKL_NUM_THREADS if set, else 1)
    threads: int = 0
    # precision of the reused PARDISO factorisation (it only preconditions GMRES, which
    # solves in double precision to the same tolerance): "auto" takes single for the models
    # solved with "reuse" (factor 0.37 -> 0.22 s, triangular solves 15 -> 9 ms on the t = 3 mm
    # default dot's tangent, 47.5k free dofs, 2 threads), "double" or "single"
    factor_precision: str = "auto"
    # a reused-factorisation (GMRES) Newton step may stop at a relative linear residual of
    # linear_forcing * |R| / scale (capped at 1e-3, at least linsolve.KRYLOV_RTOL): it
    # shrinks with |R| as Newton converges, which keeps the convergence quadratic; 0: always
    # KRYLOV_RTOL. Direct solves are exact whatever it is.
    linear_forcing: float = 0.1
    sticky_contact: bool = True   # contact points stay active within a Newton solve (no cycling)
    max_residual_growth: float = 100.0  # a step raising |R| more than this fails the increment
    curvature_after: int = 2      # iterations before the indenter-curvature tangent term is added
    # points stick once active at an iterate after this many iterations (1 stuck the
    # overshoot of the second iterate, which then pulled and was released)
    stick_after: int = 2
    # check for pulling sticky points once |R| <= this * scale, not only at convergence (the
    # pulls are settled by then; t5 polyurethane curved: 180 -> 157 Newton iterations at
    # 1e-3; 1e-1 releases them before the quadratic tail is spent on a wrong set)
    release_rtol: float = 1e-1
    # Uzawa updates within the Newton solve (at most one per iteration) once |R| <= uzawa_rtol
    # * scale, keeping the sticky set, instead of a fresh Newton solve per update
    uzawa_inline: bool = True
    # 1e-2 (was 1e-4): the update's kick and the rest of the Newton residual then converge
    # together (18 preview cases, with start_hold_off: 2 fewer iterations per increment on
    # the flat/curved cases; benchmarks/results/contact_newton.md)
    uzawa_rtol: float = 1e-2
    # start an increment from the multipliers extrapolated linearly in time. Off: it saved
    # 1-3 % of the Newton iterations, but on the Hertz block (2 increments) the doubled
    # multipliers left the largest point pressure 2 % higher at the same gap tolerance
    predict_multipliers: bool = False
    # start each increment's Newton solve from the displacement extrapolated along the
    # secant of the last two committed states, u_n + (u_n - u_{n-1}) dt / dt_{n-1}
    # (path-following's standard predictor), falling back to u_n if that solve fails
    predictor: bool = False
    # the first Newton step of an increment leaves out the not yet pressed contact points
    # that the indenter's new position overlaps by less than this fraction of the travel
    # increment: the overlap at the last state is wider than the contact that forms (t5
    # flat: 6 points too many), and pressing them made the first step overshoot, the edge
    # stick too wide and pull, and each release cost ~3 iterations. 18 preview cases (with
    # uzawa_rtol 1e-2): 959 -> 744 Newton iterations; 0.3: less, 1.0 (only the pressed
    # points): more, with cutbacks. 0: off
    start_hold_off: float = 0.6
    # the Uzawa loop raises the penalty only at the pressed points, and an increment starts
    # the points not pressed at its committed state from the model's penalty. A raise carried
    # to every point (x16 by travel 0.3 mm on the t = 3 mm 3D dot, preview) made the plate's
    # first contact overshoot into the lock-up and cut back (17 -> 8 increments, 244 -> 166
    # Newton); dropping the raises altogether failed the 40 % lock-up of 1 mm silicone,
    # whose pressed points need them
    penalty_fresh_points: bool = True
    # releases of pulling sticky points within one Newton solve before it fails (and is
    # retried with one Newton solve per Uzawa update). 3: the 3D dot's plate-contact
    # increments peeled 62, 35, 10 and 3 points and failed at the fourth, nearly converged;
    # 8: 166 -> 138 Newton
    max_releases: int = 8
    # the first increment's indenter travel is at most this fraction of the indenter's tip
    # radius (Indenter.tip_radius; the contact strain goes as sqrt(d / R)): the 3D Braille dot
    # (R = 0.78 mm) at t = 3 mm failed its first 0.15 mm after 10 Newton iterations and
    # converged at 0.05 mm; 3D dots at t = 3 and 5: 29-38 % fewer Newton iterations, the 5 mm
    # polyurethane pad 2251 -> 126 (benchmarks/results/first_increment.md). 0: off
    first_travel_radius: float = 0.1
    # ... and so is every later increment's (depth control): grown increments jumped the 3D
    # dots' base-plate contact (t = 5 silicone: a cut-back at 1.5x) and their viscoelastic
    # update left the t = 3 polyurethane dot's peak 0.40 % low after 6 increments (8 capped:
    # 0.0321255 MPa, 16: 0.0321201, 31: 0.0321251); benchmarks/results/braille3d_default.md.
    # None: 3D models only; in 2D it cost the 36 paper cases 4-9 % more Newton iterations
    # (3-4 % CPU) for peaks within 0.09 %
    travel_cap_every: bool | None = None
    # the points pressed at the committed state (multiplier > 0) stick from the second Newton
    # iterate: the first step, which takes the indenter's travel, left about half of them
    # just open, the second then pushed them deep into the indenter and the line search cut
    # it to eta 0.01-0.1 (the t = 5 dots: 8-10 Newton iterations per increment, now 6-7).
    # Sticking points that pull are released as any (_release); in an increment whose travel
    # is below the committed one (a depth or force release) these points are leaving the
    # indenter and keep no pull at convergence (the pull of up to PULL_FRACTION x penalty x
    # tol_penetration each read an R 0.5 sphere raised from 0.45 to 0.1 mm 9.0 % low, and a full
    # release left -0.0026 N on the indenter; tests/test_increment_path.py). None: 3D models only; in 2D
    # it saved 1 % of the paper cases' iterations, and a 2D contact settled at the 1e-4 h
    # tolerance on another path: a late first touch ('ab', t = 1 preview) read 0.19 % low,
    # the same to 1e-6 at 1e-5 h
    stick_committed: bool | None = None
    # after a failed increment of length dt_f, no later increment of the run is longer than
    # this fraction of it: growth x1.5 after easy increments otherwise climbed back to the
    # length that failed and failed again (t = 3 default dot: 4 cut-backs, 145 -> 96 Newton,
    # 160 -> 93 s CPU; t = 5 default 166 -> 159; the 36 paper cases in 2D 1560 -> 1581,
    # peaks within 0.03 %; benchmarks/results/contact_tolerance3d.md). 0: off
    failed_dt_fraction: float = 0.7
    # a Newton direction that is not a descent direction of the incremental potential (an
    # indefinite tangent) is recomputed: first with the points pressed at an earlier iterate
    # of this solve held active again (the first step's overshoot releases points at the
    # dot's edge, and the squeezed layer under them is not stable on its own), then without
    # the indenter-curvature term. Every cut-back of the 2D t = 5 mm Braille ridge started so;
    # the 36 paper cases in 2D: 1581 -> 1346 Newton iterations, 17 -> 7 cut-backs (with
    # short_step: 1233, 4), peaks within 0.10 % (fewer increments;
    # benchmarks/results/ascent_remedy.md)
    ascent_remedy: bool = True
    # with ascent_remedy, a line-search step shorter than this (a descent direction that goes
    # nowhere) gets the held-points direction too, kept if its |R| is lower. None: SHORT_STEP
    # of the model's dimension (benchmarks/results/ascent_remedy.md)
    short_step: float | None = None


# SolverOptions.easy_iterations by dimension. 2D: 7 (5: t3 flat 10 increments, 7: 6). 3D: 6, one
# below 2D since rtol 1e-5 saves an iteration per increment: at 7 more increments of the dots
# grew, and the grown ones failed at the Braille plate's first contact (t = 3 silicone: 8 / 66 /
# 0 -> 10 / 85 / 2 increments / Newton / cut-backs; at 6: 8 / 61 / 0)
EASY_ITERATIONS = {2: 7, 3: 6}

# SolverOptions.short_step by dimension. 2D, 36 paper cases: default 755 -> 651 Newton
# iterations, 5 -> 2 cut-backs, preview 591 -> 582; in 3D the held points then pulled at the
# dots' plate contact (t = 3 / 5 preview: 66 -> 89, 121 -> 137), so it is off there
SHORT_STEP = {2: 0.2, 3: 0.0}
