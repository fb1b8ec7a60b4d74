"""Finite-strain hyperfoam-viscoelastic contact solver on scikit-fem.

High level: `solve(scene, mesh=None, *, history=False, progress=None) -> Result` (progress:
called with a `solver.IncrementInfo` after each converged increment).
Low level (any mesh + named boundaries + BCs + indenter): `Model`, `Dirichlet`, `Contact`,
`run`, `SolverOptions`, `make_result`.

Choices (each measured; see tests/test_fe_*.py and benchmarks/solve.py):
- total Lagrangian, P2 displacements (plane strain F33 = 1, or tets), scikit-fem for the
  basis and quadrature, compiled (numba) element kernels (fe.kernels; their oracle is
  the literal transcription in tests/reference_kernels.py), assembly into a fixed CSR
  pattern, MKL PARDISO on the free block with the ordering analysed once per model
  (fe.linsolve; SuperLU where MKL is not installed);
- 3-point (triangle) / 4-point (tet) rule, as Abaqus CPE6 / C3D10;
- default 'mixed': three-field Hu-Washizu with element-constant dilatation and pressure,
  condensed (mean dilatation, F_bar = (theta/J)^(1/m) F): on the Lame cylinder the nodal
  pressure converges O(h^2) while the displacement formulation's is 20-100x worse;
- QLV Prony update on the PK2 stress at the quadrature points, S0 interpolated in time
  by the parabola through the last three states (tangent factor g_inf + sum gain_i);
- rigid frictionless contact on 2 Gauss points per P2 edge / 3 per P2 triangle (more
  over-constrain the multipliers), penalty 20 K0 / h with Uzawa updates (inside the Newton
  solve) until the gap at the pressed points is below 1e-4 h in 2D, 1e-3 h in 3D
  (Contact.tol_relative, fe.model.TOL_RELATIVE; h the contact facet size) and below 1e-3
  of the scene's travel (fe.model.TOL_TRAVEL); points stay
  active within a Newton solve (no active-set cycling);
- Newton with a Crisfield line search on s(eta) = du.R, inadmissible states halve the
  step; increments grow x1.5 after <= 7 iterations, cut back x0.35 on failure, and stay
  below 0.7 x a failed increment's length for the rest of the run;
- nodal pressure by L2 projection onto P1 (exact mass matrix for the 3-point rule); the
  2D bone profile by a local linear fit to element averages (fe.recovery.PointFit).
"""

from __future__ import annotations

import contextlib
import math
import logging
import os
import time

import numpy as np

from tactileskin.fe.model import Contact, Dirichlet, Model
from tactileskin.fe.output import indenter_force, make_result, reaction
from tactileskin.fe.solver import IncrementInfo, SolverOptions, run

log = logging.getLogger(__name__)

__all__ = ["solve", "read_sensors", "model_for_scene", "material_law", "Model", "Dirichlet", "Contact", "run",
           "SolverOptions", "IncrementInfo", "make_result", "reaction"]


def material_law(law):
    """C -> (S, D, ok) for a material law (any of tactileskin.materials.laws).

    A plane-strain C (C33 = 1, C13 = C23 = 0 exactly, as the 2D kinematics build it) takes
    the law's plane-strain path (hyperfoam: the compiled closed-form 2x2 loop, same values
    to rounding, ~3x cheaper than the 3x3 eigh; other laws: their 3D law on the embedded C);
    D is still the full (..., 3, 3, 3, 3), so a 3D state that happens to be plane is
    served correctly too. law(C, tangent=False) returns (S, None, ok) where the law can
    skip D (hyperfoam on both paths; residual-only evaluations).

    law(C, tangent=False, keep=True) returns (S, None, ok, kept): where the law can (hyperfoam,
    on both paths) `kept` is the spectral data from which `law.tangent_kept(kept)` gives D
    at the same C without the eigenproblem and the stress's powers (fe.Model: the tangent at
    the iterate whose residual was just evaluated; `tangent_kept(kept, in_plane=True)` its
    in-plane block, the same bits); None elsewhere (the caller then asks law(C, True)).
    """
    keeps = hasattr(law, "pk2_kept") and hasattr(law, "tangent_kept")

    def evaluate(C, tangent=True, keep=False):
        C = np.asarray(C, dtype=float)
        if (C.ndim >= 2 and C.shape[-2:] == (3, 3) and np.all(C[..., 2, 2] == 1.0)
                and not np.any(C[..., 2, :2]) and not np.any(C[..., :2, 2])):
            if keep and keeps and not tangent and hasattr(law, "pk2_kept_plane"):
                S, ok, kept = law.pk2_kept_plane(C[..., :2, :2], out_of_plane=True)
                return S, None, ok, kept
            out = law.pk2_tangent_plane(C[..., :2, :2], out_of_plane=True, tangent=tangent)
        elif keep and keeps and not tangent:
            S, ok, kept = law.pk2_kept(C)
            return S, None, ok, kept
        else:
            out = law.pk2_tangent(C, tangent=tangent)
        return (*out, None) if keep else out

    evaluate.tangent_kept = law.tangent_kept if keeps else None   # (kept, in_plane=False) for hyperfoam
    return evaluate


def model_for_scene(scene, mesh=None) -> tuple[Model, object]:
    """The Model of a scene (the skin's bonded boundaries fixed, symmetry x = 0, indenter)."""
    from tactileskin.geometry.indenters import at_first_touch, indenter_for_scene
    from tactileskin.materials import get_material

    if mesh is None:
        from tactileskin.mesh import build_mesh  # gmsh only when no mesh is given

        mesh = build_mesh(scene)
    mat = get_material(scene.material)
    law = mat.law
    prony = mat.prony if scene.viscoelastic and mat.prony.n_terms else None
    m = scene.dim
    allc = tuple(range(m))
    # the skin's bonded surfaces are fixed (fingertip: bone and nail; pad: the board)
    # (a file skin lists the other bonded groups `tactileskin mesh` writes: fixed where present)
    bcs = [Dirichlet(name, allc) for name in scene.skin_kind.fixed_boundaries
           if name in mesh.boundaries or name == "bone_interface"]
    if mesh.halved:  # a whole model (a user's full skin, a full-width pad) has none
        bcs.append(Dirichlet("symmetry", (0,)))
    if m == 3 and getattr(mesh, "z_symmetric", False):
        bcs.append(Dirichlet("end_back", (2,)))
    # travel: the largest depth, or under force control the expected travel 0.2 t (DEPTH_FRACTION)
    contact = Contact(indenter_for_scene(scene), boundary="outer_surface", rate=scene.rate,
                      travel=scene.indentation)
    model = Model(mesh.mesh, mesh.boundaries, material_law(law), bcs, prony=prony,
                  formulation=scene.formulation.value, contact=contact, order=scene.order,
                  stiffness=max(law.K0, law.mu0))
    if model.surface is not None:
        # the travel counts from first touch (a user's skin higher off the axis than on it: a
        # flat plate started 0.019 mm inside a block sloping 0.04 mm over 4 mm, of a 0.2 mm press)
        contact.indenter = at_first_touch(scene, contact.indenter, model.surface.X)
    halved = mesh.halved
    # a model without the x = 0 plane (a user's full skin, a full-width pad under an
    # x-asymmetric indenter) has a profile across the centre: its span and AUC are halved
    # (Result.span), as its 2D force is, so that a halved and a whole model of one scene agree
    model.profile_sides = 1 if halved else 2
    if m == 3:  # the whole indenter's force
        model.force_factor = (2.0 if halved else 1.0) * (2.0 if getattr(mesh, "z_symmetric", False) else 1.0)
    else:  # per mm of the half section x >= 0: half the whole section's force
        model.force_factor = 1.0 if halved else 0.5
    return model, mesh


def phases(model: Model, **extra: float) -> dict:
    """Wall time (s) per phase of a solve: the model's residual / tangent / contact
    accumulators (contact is part of both), the linear solver's factor / solve, and
    `extra` (mesh, setup, recovery, total); 'other' is the remainder of total."""
    t = dict(model.timing)
    ls = getattr(model, "_linsolve", None)
    out = {k: round(float(v), 4) for k, v in extra.items()}
    for k in ("residual", "tangent", "contact"):
        out[k] = round(float(t.get(k, 0.0)), 4)
    for k in ("factor", "solve"):
        out[k] = round(float(ls.timing[k]) if ls is not None else 0.0, 4)
    if "total" in extra:
        known = sum(out[k] for k in ("mesh", "setup", "recovery", "residual", "tangent", "factor", "solve")
                    if k in out)
        out["other"] = round(max(0.0, extra["total"] - known), 4)
    return out


THREAD_VARS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def blas_threads():
    """One BLAS/OpenMP thread during a solve unless the user set a count in the environment.
    The solver's vectors and element blocks are small: threaded BLAS only spins, and on a
    busy 2-core machine a coarse 3D solve took 55 s CPU with the default threads against
    21 s with one (measured while benchmarking fe.linsolve's reuse method). The CLI, the
    tests and the Dask workers already set the variables; this covers library callers."""
    if any(os.environ.get(v) for v in THREAD_VARS):
        return contextlib.nullcontext()
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1)


def read_sensors(scene, model, result, *, z_symmetric: bool = False, sites=None):
    """The readings (sensors.SensorReadings) of the scene's sensor layouts (or of `sites`)
    from a result's nodal stress fields, interpolated inside the elements (fe.probe); the
    modelled half (x >= 0, and z >= 0 for a z-symmetric slab) answers for its mirror image."""
    from tactileskin import sensors
    from tactileskin.fe.probe import stress_sampler

    sites = sensors.sites_for(scene) if sites is None else sites
    # a whole model (no x = 0 line: a full-width pad under an x-asymmetric indenter) has x < 0
    # itself; mirroring there would read the other side's stress
    sampler = sensors.symmetric_sampler(stress_sampler(model, result.fields["point_data"]),
                                        mirror_x=getattr(model, "profile_sides", 1) == 1, mirror_z=z_symmetric)
    return sensors.read(sites, sampler)


def _unresolved_force(scene, asked: float, e) -> None:
    """Raise ParameterError naming the force when no force increment converged because the first
    one's target was out of reach of its trials (too much force), or lay between a trial that
    pressed no contact point and one already past it: the reaction rises faster than the travel
    resolves so small a force (the stiffest law a file may hold, mu0 = 1e4 MPa, asked for 1e-4 N/mm:
    0 N/mm to 2.6e-4 within 5e-7 mm of travel; the error blamed the law's lock-up and said to try a
    smaller force). Otherwise return (the caller re-raises)."""
    from tactileskin.errors import ParameterError
    from tactileskin.loading import force_unit

    diag = getattr(e, "diagnosis", None) or {}
    unit = force_unit(scene.dim)
    travels, errors, F = diag.get("travels_mm"), diag.get("force_errors"), diag.get("target")
    if "out of reach" in str(diag.get("reason", "")) and F is not None and diag.get("reached") is not None:
        # the first increment's force lies past a failed trial: too much force for this skin, not
        # its mesh or the law's lock-up (the softest law a file may hold, mu0 = 1e-6 MPa, asked
        # for 1e4 N/mm: 4.5e-6 N/mm at 0.89 mm of a 1.2 mm cap; the error named no parameter)
        raise ParameterError(
            "force", asked, f"a force the skin carries within its travel (at most {scene.max_travel:.3g} mm "
            "= 0.6 x thickness)",
            f"no increment converged: its target {F:.3g} {unit} was out of reach, the reaction {diag['reached']:.3g} "
            f"{unit} at travel {diag['travel_mm']:.3g} mm and a trial at {diag['failed_mm']:.3g} mm failed; give a "
            f"smaller force, or solve with depth (up to {scene.max_travel:.3g} mm) to see the force this skin "
            "carries") from None
    if not travels or not errors or F is None or not F > 0:
        return
    trials = sorted((float(d), float(f) + F) for d, f in zip(travels, errors))
    over = [(d, r) for d, r in trials if r > F]
    if not over:
        return
    d_hi, r_hi = over[0]
    free = [d for d, r in trials if r <= 0.0 and d < d_hi]
    if not free:
        return
    raise ParameterError(
        "force", asked, "a force whose ramp the contact resolves on this skin and mesh",
        f"no increment converged: its target {F:.3g} {unit} lies between no contact at travel {free[-1]:.6g} mm and "
        f"{r_hi:.3g} {unit} at {d_hi:.6g} mm, {d_hi - free[-1]:.2g} mm further: the skin's reaction rises faster "
        "than the travel resolves so small a force; give a larger force, or solve with depth control "
        "(a depth just past the first touch)") from None


def _run_history(scene, model, section, program, options, progress, history: bool = False):
    """Run a force-controlled or multi-segment loading history (fe.loading.run_program).
    The Result is the peak-load state: the end of the depth or force ramp with the largest
    reaction (a hold or a release never replaces it, so a full release does not report an
    open contact); `Result.loading` adds the target and reached force, the travel, that
    state's time and the final state, and `Result.history` the time series (history.csv);
    `history`: also the displacement of every increment (result.pvd), as a depth ramp has."""
    from tactileskin.errors import ConvergenceError, ParameterError
    from tactileskin.fe.loading import run_program
    from tactileskin.fe.output import bone_peak, law_state
    from tactileskin.loading import force_unit

    multi = len(program) > 1
    peak_of = bone_peak(model) if multi else None
    best, first = {}, {}
    done = [0]  # segments finished (the next one is the one running)
    deepest = [0.0]  # the largest travel of any increment (a creep hold sinks past the peak load's)
    last = {}  # the last converged increment's travel and reaction
    worst = {}  # the material law's extremes over every increment (a creep hold or a second
    # ramp can go beyond the peak-load state's: tactileskin.quality flags them)

    def record(model, ev):
        last.update(d=float(model.d), reaction=float(indenter_force(model, ev)))
        deepest[0] = max(deepest[0], float(model.d))
        for k, v in law_state(ev, model.stress(ev)).items():
            worst[k] = v if k not in worst else (min if k == "min_J" else max)(worst[k], v)
        out = {"peak_mpa": peak_of(ev)} if peak_of is not None else {}
        if history:
            out["displacement"] = model.u.reshape(-1, model.m).copy()
        return out

    def on_segment(i, seg, ev):
        done[0] = i + 1
        F = indenter_force(model, ev)
        if i == 0 and not first:  # the scene's own ramp: what target_force asks for
            first.update(reaction=F, d=model.d)
        if seg.kind != "hold" and (not best or F > best["reaction"]):
            best.update(reaction=F, t=model.t, d=model.d, segment=i,
                        result=make_result(model, ev, _StatsView(), s_of_point=section.s_of_point,
                                           scene=scene.to_dict()))

    # a travel guess for the first force increment: the scene's expected travel at the full force
    full = max((g.target for g in program if g.kind == "force"), default=1.0)
    d_exp = scene.depth_fraction * scene.thickness
    try:
        ev, stats, hist = run_program(model, program, options, d_max=scene.max_travel,
                                      d_guess=lambda F: d_exp * min(1.0, F / full), record=record,
                                      progress=progress, on_segment=on_segment)
    except ConvergenceError as e:
        forced = [g.target for g in program if g.kind == "force"]
        if _force_controlled(program, done[0]) and not last:
            _unresolved_force(scene, scene.force if scene.force is not None else max(forced), e)
        lock_up = "increments" in str(e)
        if not _force_controlled(program, done[0]) or not last or not (lock_up or "trial travels" in str(e)):
            raise
        # a force beyond the law's lock-up: the increments shrink to nothing below the travel
        # cap (1000 N/mm on a 1 mm skin: 2000 increments, 88 s, "more than 2000 increments");
        # or no travel of an increment met its force (10000 N/mm on 1 mm silicone stalled at
        # 9.6 N/mm, "after 16 trial travels", the parameter unnamed)
        from tactileskin.materials import get_material
        from tactileskin.quality import MAX_STRESS_OVER_MU0_3D

        unit = force_unit(scene.dim)
        target = scene.force if scene.force is not None else max(forced)
        stress, mu0 = worst.get("max_abs_stress_mpa", float("nan")), float(get_material(scene.material).law.mu0)
        stalled = (f"the solve stalled at {last['reaction']:.4g} {unit} ({last['reaction'] / target:.2g} of the "
                   f"{target:.4g} {unit} asked), travel {last['d']:.4g} mm of the {scene.max_travel:.3g} mm allowed, "
                   f"with the material law at J = {worst.get('min_J', float('nan')):.3g} and "
                   f"|stress| up to {stress:.3g} MPa ({stress / mu0:.2g} mu0)")
        if lock_up:
            hint = stalled
        elif stress <= MAX_STRESS_OVER_MU0_3D * mu0:
            # a stall where the law is not stiffening is no force step's fault: a gel of mu0 2e-6 MPa
            # stalled at 6.2e-7 N, 0.08 mm, 0.64 mu0 (Newton failed a 1.3 um step) asked for 1e-3 N,
            # and said a smaller target may converge; a depth ramp to 0.6 mm gives it 4.1e-5 N, below
            # the smallest force allowed
            hint = (f"{stalled}: the law is not stiffening there; solve with depth (up to "
                    f"{scene.max_travel:.3g} mm) instead to see the force this skin carries")
        else:
            hint = f"{stalled}; a smaller target may converge (its ramp takes smaller force steps)"
        raise ParameterError("force", target,
                             f"a force the skin carries within its travel (at most "
                             f"{scene.max_travel:.3g} mm = 0.6 x thickness)" if lock_up else
                             "a force this solve reaches", hint) from None
    if not best:  # every ramp ended below zero force: report the final state
        on_segment(0, program[0], ev)
    res = best["result"]
    for k in ("increments", "newton_iterations", "cutbacks", "uzawa_iterations", "force_trials"):
        res.stats[k] = getattr(stats, k)
    for k, v in worst.items():
        res.stats[k] = min(res.stats[k], v) if k == "min_J" else max(res.stats[k], v)
    res.stats["max_travel_mm"] = deepest[0]
    if history and res.fields is not None:
        res.fields["steps"] = [(float(h["t"]), np.asarray(h["displacement"], float)) for h in hist
                               if "displacement" in h and "t" in h]
    res.history = [{k: v for k, v in h.items() if k != "displacement"} for h in hist] if multi else []
    last = hist[-1] if hist else {}
    res.loading = {
        "control": program[0].kind, "segments": [g.to_dict() for g in program],
        # the forces and reactions below: per mm of depth of the half section in 2D, on the
        # whole indenter in 3D
        "force_unit": force_unit(scene.dim),
        # reached at the end of the scene's force ramp (a later, larger force or depth segment
        # gives the peak-load state below, not the answer to target_force)
        "target_force": scene.force, "reached_force": first["reaction"] if scene.force is not None else None,
        "reached_travel_mm": first["d"] if scene.force is not None else None,
        "profile_state": "peak load",
        "law_state": "extremes over every increment (min_J, max_abs_stress_mpa, max_pressure_mpa)",
        "profile_t_s": best["t"], "profile_travel_mm": best["d"], "profile_reaction": best["reaction"],
        "final": {"t_s": float(model.t), "travel_mm": float(model.d),
                  "reaction": float(last.get("reaction", indenter_force(model, ev))),
                  **({"peak_mpa": last["peak_mpa"]} if "peak_mpa" in last else {})},
    }
    return res, ev, stats


# a depth ramp starts at this fraction of the travel to first touch (the sampled contour's
# first touch is within ~1e-5 mm of the true one; the margin keeps the start contact-free)
START_BEFORE_TOUCH = 0.9
# a first touch later than this travel (mm) is a late one (dots off a curved top's crown);
# below it the indenter touches at once (the pad's samples as 5e-8)
LATE_TOUCH = 1e-3


def _start_near_first_touch(scene, model) -> None:
    """Move the committed state of a depth ramp to just before the indenter's first touch: the
    skin is unloaded until then (zero stress, no relaxation), and increments spent on the free
    travel made the whole contact of a late touch ('ab' touches after 0.48 of 0.55 mm) come
    in one increment."""
    from tactileskin.geometry.indenters import BrailleIndenter, first_contact_travel

    # a Braille text's touch is exact (its dots' own planes on a built-in skin's contour); a
    # file's is sought on its tips' planes only, and a start past it would miss load
    if scene.skin == "file" or not isinstance(getattr(model.contact, "indenter", None), BrailleIndenter):
        return
    touch = first_contact_travel(scene)
    if touch <= LATE_TOUCH or touch >= scene.indentation:
        return
    model.t = START_BEFORE_TOUCH * touch / model.contact.rate
    model.d = model.travel(model.t)
    log.debug("free travel to first touch skipped: the ramp starts at %.4g mm", model.d)


def _force_controlled(program, i: int) -> bool:
    """Whether segment i of a loading program runs under force control: a force ramp, or a
    hold after one (a hold keeps the control of the segment before it)."""
    control = None
    for seg in program[:i + 1]:
        if seg.kind != "hold":
            control = seg.kind
    return i < len(program) and control == "force"


def _sizes_against_preview(scene) -> dict:
    """The scene's global and refined element sizes (mm) and the `preview` preset's for the
    same dimension, indenter, thickness and skin (the coarsest sizes whose error is measured),
    and the skin thickness (quality judges the refined size against it too)."""
    from tactileskin.scene import preset_mesh

    size, ratio = preset_mesh("preview", scene.dim, scene.indenter, scene.thickness, scene.skin)
    return {"global": float(scene.mesh_size), "refined": float(scene.mesh_size / scene.refinement),
            "preview_global": float(size), "preview_refined": float(size / ratio),
            "thickness": float(scene.thickness)}


class _StatsView:
    """Zero counters for make_result at an intermediate state (the run's totals are set after)."""
    increments = newton_iterations = cutbacks = uzawa_iterations = 0
    wall_s = 0.0
    history = ()


def solve(scene, mesh=None, *, history: bool = False, options: SolverOptions | None = None,
          progress=None):
    """Indent the scene's skin from first touch to its full depth at its rate; return a Result.
    Raises ParameterError before meshing if the indenter cannot reach the skin (no contact).
    progress: optional callable, given an IncrementInfo (increment, t, T, travel, Newton
    iterations) after each converged increment; nothing is printed either way."""
    from tactileskin.geometry.indenters import (BrailleIndenter, first_contact_travel, indenter_symmetry,
                                                mirrored_x, require_contact)
    from tactileskin.errors import ConvergenceError
    from tactileskin.materials import get_material
    from tactileskin.materials.laws import nu0

    law = get_material(scene.material).law  # a bad material (name or file) fails before the mesh is made
    require_contact(scene)
    t0 = time.perf_counter()
    t_mesh = 0.0
    sized = mesh is None  # meshed here at the scene's sizes (tactileskin.quality judges them)
    if mesh is None:
        from tactileskin.mesh import build_mesh

        mesh = build_mesh(scene)
        t_mesh = time.perf_counter() - t0
    t1 = time.perf_counter()
    model, sm = model_for_scene(scene, mesh)
    section = scene.section()
    sites = None
    if scene.sensors:
        from tactileskin import sensors

        # placed on the mesh solved (a file skin's faces; the built-in skins' are analytic) and
        # checked before the solve: a sensor off that mesh failed only after it
        sites = sensors.sites_for(scene, coords=scene.skin_kind.mesh_coordinates(scene, sm))
    t_setup = time.perf_counter() - t1

    def record(model, ev):
        # the displacement of each increment: result.pvd, a time series (fe.output.vtk_fields)
        return {"d": model.travel(model.t), "reaction": indenter_force(model, ev),
                "displacement": model.u.reshape(-1, model.m).copy()}

    program = scene.program()
    try:
        with blas_threads():
            if len(program) == 1 and program[0].kind == "depth":
                _start_near_first_touch(scene, model)
                ev, stats = run(model, scene.duration, options, history=history, record=record, progress=progress)
                res = None
            else:
                res, ev, stats = _run_history(scene, model, section, program, options, progress, history)
    except ConvergenceError as e:
        hint = scene.skin_kind.convergence_hint(scene)  # what to change, where the skin knows
        if not hint:
            raise
        raise ConvergenceError(f"{e}; {hint}", e.diagnosis) from None
    t2 = time.perf_counter()
    if res is None:
        res = make_result(model, ev, stats, s_of_point=section.s_of_point, scene=scene.to_dict())
        # a depth ramp's travel from first touch (summary.json depth_mm; a history's is in `loading`)
        res.stats["depth_mm"] = float(model.d)
    if scene.sensors:
        res.sensors = read_sensors(scene, model, res, z_symmetric=bool(getattr(sm, "z_symmetric", False)),
                                   sites=sites)
    stats.wall_s = time.perf_counter() - t0
    res.stats["wall_s"] = stats.wall_s
    res.stats["phases_s"] = phases(model, mesh=t_mesh, setup=t_setup,
                                   recovery=time.perf_counter() - t2, total=stats.wall_s)
    if getattr(model, "_linsolve", None) is not None:
        res.stats["linear_solver"] = model._linsolve.describe()
    ind = getattr(model.contact, "indenter", None)
    cap = ind.working_travel(section, scene.sample_length) if hasattr(ind, "working_travel") else math.inf
    travel = res.stats.get("max_travel_mm", float(model.d))
    cap_info = {}
    if travel > cap:  # the indenter went past its printed working face: its edges or mount would press
        cap_info = {"travel_mm": travel, "cap_mm": float(cap)}
    if res.contact_points is not None and len(res.contact_points):
        # the contact reaches past the printed face's extent, where the model's gap continues it
        # (a cylinder's whole circle) and the printed part has its sides or mount
        faces = getattr(ind, "face_halfwidths", lambda: (math.inf, math.inf))
        half = np.asarray(faces()[: model.m - 1], float)
        reach = np.abs(np.asarray(res.contact_points, float)[:, [0, 2][: model.m - 1]]).max(axis=0)
        if np.any(reach > half):
            k = int(np.argmax(reach - half))
            cap_info.update(travel_mm=travel, contact_mm=float(reach[k]), face_half_mm=float(half[k]), axis="xz"[k])
    if cap_info:
        res.stats["indenter_cap"] = cap_info
    eb = scene.skin_kind.buckling_strain(scene)
    if eb is not None and travel / scene.thickness > eb:  # the model cannot buckle: the skin would
        res.stats["buckling"] = {"strain": travel / scene.thickness, "euler_strain": eb}
    if sm.halved and mirrored_x(scene):
        res.stats["mirrored_x"] = True
    if getattr(sm, "z_symmetric", False) and not indenter_symmetry(scene)[1]:  # a file's symmetry_z
        res.stats["mirrored_z"] = True
    # tactileskin.quality judges the volume ratio and the element by the law's compressibility
    res.stats["material_nu0"] = float(nu0(law))
    res.stats["material_mu0_mpa"] = float(law.mu0)  # ... and the stress range by its modulus
    res.stats["order"] = int(scene.order)
    if sized and scene.skin != "file":
        res.stats["mesh_sizes_mm"] = _sizes_against_preview(scene)
        touch = first_contact_travel(scene) if scene.dim == 3 and isinstance(ind, BrailleIndenter) else 0.0
        if touch > LATE_TOUCH:
            # dots off a curved top's crown touch late (the t = 0.5 full cell: after 0.069 of 0.1 mm):
            # quality judges how far the deepest-pressed one went in against the dot patch's size.
            # A centred dot is not judged: pressed 0.05 mm (a quarter of preview's patch) it read -2.9 %
            res.stats["mesh_sizes_mm"]["dot_indentation"] = max(0.0, travel - touch)
            # ... against the size meshed there (mesh.sizing.spot_factor: a t >= 5 dot's at 3x)
            patches = (getattr(sm, "sizes", None) or {}).get("patches") or ()
            if patches:
                res.stats["mesh_sizes_mm"]["dot_patch"] = float(max(b[4] for b in patches))
    log.info("%s: peak %.4g MPa, %d dofs, %d increments, %d Newton iterations, %.2f s",
             scene.label(), res.peak, res.stats["dofs"], stats.increments, stats.newton_iterations,
             stats.wall_s)
    return res
