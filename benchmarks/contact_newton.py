"""Newton iterations, cutbacks and CPU per phase of the contact solve (issue 13).

Runs the 18 paper cases in 2D at a quality preset, or one coarse 3D Braille dot
(`--dim3 1,3`: Scene(dim=3, indenter="braille", thickness=t, mesh_size=1.2, refinement=2)),
one case after the other in one process, one thread, under a contact variant:

  now        the solver's defaults
  before     the solver before issue 13 (SolverOptions BEFORE, absolute 1e-4 mm tolerance)
  tol=X      the defaults with an absolute penetration tolerance of X mm (e.g. tol=1e-6,
             the reference the tolerance study compares with)
  rel=X      the defaults with the penetration tolerance X * (contact facet size)
  pred       the defaults with the secant increment predictor (SolverOptions.predictor)
  set:k=v/.. the defaults with SolverOptions fields set (e.g. set:predictor=1/stick_after=1)

Prints per case: dofs, increments, Newton iterations (per increment), cutbacks, Uzawa
updates, peak, CPU s of the solve and the per-phase wall times (Result.stats['phases_s']);
then the sums. Tables go to stdout (paste into benchmarks/results/contact_newton.md).

    .venv/bin/python benchmarks/contact_newton.py --quality preview --variants now,tol=1e-6
    .venv/bin/python benchmarks/contact_newton.py --dim3 1,3
"""

from __future__ import annotations

import os

os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402

from tactileskin import fe  # noqa: E402
from tactileskin.fe.output import make_result, reaction  # noqa: E402
from tactileskin.fe.solver import SolverOptions, run  # noqa: E402
from tactileskin.mesh import build_mesh  # noqa: E402
from tactileskin.planner import with_quality  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402
from tactileskin.sweep import PAPER_INDENTERS, PAPER_MATERIALS, PAPER_THICKNESSES  # noqa: E402

ALL = [f"t{t:g}-{m}-{i}" for t in PAPER_THICKNESSES for m in PAPER_MATERIALS for i in PAPER_INDENTERS]
# the solver before issue 13's contact work: Uzawa by fresh Newton solves, multipliers
# carried over unchanged, sticky from the second iterate, releases checked at |R| <= 1e-3
BEFORE = dict(uzawa_inline=False, predict_multipliers=False, stick_after=1, release_rtol=1e-3)
# the secant increment predictor (SolverOptions.predictor)
OPTION_VARIANTS = {"before": BEFORE, "pred": dict(predictor=True)}
PHASES = ("setup", "residual", "tangent", "contact", "factor", "solve", "recovery", "other")


def scene_of(label: str, quality: str) -> Scene:
    t, mat, ind = label.split("-")
    return with_quality(Scene(thickness=float(t[1:]), material=mat, indenter=ind), quality)


def configure(model, variant: str) -> SolverOptions:
    """Apply a variant to the model's contact; return the solver options."""
    c = model.contact
    if variant.startswith("tol="):
        c.tol_penetration = float(variant[4:])
    elif variant.startswith("rel="):
        c.tol_penetration = float(variant[4:]) * model.surface_size()
    elif variant == "before":
        c.tol_penetration = 1e-4  # the former absolute default
        return SolverOptions(**BEFORE)
    elif variant in OPTION_VARIANTS:
        return SolverOptions(**OPTION_VARIANTS[variant])
    elif variant.startswith("set:"):  # set:name=value/name=value (SolverOptions fields)
        kw = {}
        for item in variant[4:].split("/"):
            k, v = item.split("=")
            default = getattr(SolverOptions(), k)  # None: a by-dimension default (solver.EASY_ITERATIONS)
            kw[k] = type(default)(float(v)) if default is not None else (int(v) if v.lstrip("-").isdigit() else float(v))
        return SolverOptions(**kw)
    elif variant != "now":
        raise SystemExit(f"unknown variant {variant!r}")
    return SolverOptions()


def solve(scene: Scene, mesh, variant: str):
    """fe.solve with the variant applied to the model (same phases as fe.solve reports)."""
    t0 = time.perf_counter()
    model, _ = fe.model_for_scene(scene, mesh)
    opts = configure(model, variant)
    section = scene.section()
    t_setup = time.perf_counter() - t0
    with fe.blas_threads():
        ev, stats = run(model, scene.duration, opts)
    t2 = time.perf_counter()
    res = make_result(model, ev, stats, s_of_point=section.s_of_point, scene=scene.to_dict())
    total = time.perf_counter() - t0
    res.stats["phases_s"] = fe.phases(model, mesh=0.0, setup=t_setup, recovery=time.perf_counter() - t2,
                                      total=total)
    res.stats["reaction"] = float(reaction(model, ev)[1])
    res.stats["predictor_fallbacks"] = stats.predictor_fallbacks
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quality", default="default")
    ap.add_argument("--cases", default=",".join(ALL))
    ap.add_argument("--dim3", default="", help="comma-separated thicknesses of coarse 3D single dots")
    ap.add_argument("--variants", default="now")
    ap.add_argument("--json", default="", help="also write the rows to this JSON file")
    a = ap.parse_args()
    if a.dim3:
        scenes = [(f"3d-t{t}-dot", Scene(dim=3, indenter="braille", thickness=float(t), mesh_size=1.2,
                                          refinement=2)) for t in a.dim3.split(",")]
        print("coarse 3D single dots (mesh_size 1.2, refinement 2)\n")
    else:
        scenes = [(label, scene_of(label, a.quality)) for label in a.cases.split(",")]
        print(f"quality {a.quality}\n")
    print("| case | variant | dofs | incr | Newton | Newton/incr | cutbacks | Uzawa | peak MPa | solve CPU s | "
          + " | ".join(PHASES) + " |")
    print("|---|---|---|---|---|---|---|---|---|---|" + "---|" * len(PHASES))
    rows = []
    for label, sc in scenes:
        mesh = build_mesh(sc)
        for v in a.variants.split(","):
            c0 = time.process_time()
            r = solve(sc, mesh, v)
            cpu = time.process_time() - c0
            st, ph = r.stats, r.stats["phases_s"]
            row = {"case": label, "variant": v, "dofs": st["dofs"], "increments": st["increments"],
                   "newton": st["newton_iterations"], "cutbacks": st["cutbacks"],
                   "uzawa": st["uzawa_iterations"], "peak": r.peak, "cpu": cpu, "phases": ph,
                   "reaction": st["reaction"], "fallbacks": st["predictor_fallbacks"]}
            rows.append(row)
            print(f"| {label} | {v} | {st['dofs']} | {st['increments']} | {st['newton_iterations']} | "
                  f"{st['newton_iterations'] / max(st['increments'], 1):.1f} | {st['cutbacks']} | "
                  f"{st['uzawa_iterations']} | {r.peak:.5f} | {cpu:.2f} | "
                  + " | ".join(f"{ph.get(k, 0.0):.2f}" for k in PHASES) + " |", flush=True)
    print()
    for v in a.variants.split(","):
        rs = [r for r in rows if r["variant"] == v]
        inc = sum(r["increments"] for r in rs)
        new = sum(r["newton"] for r in rs)
        print(f"{v}: {len(rs)} cases, {inc} increments, {new} Newton ({new / max(inc, 1):.2f}/increment), "
              f"{sum(r['cutbacks'] for r in rs)} cutbacks, {sum(r['fallbacks'] for r in rs)} predictor fallbacks, "
              f"{sum(r['uzawa'] for r in rs)} Uzawa, "
              f"solve CPU {sum(r['cpu'] for r in rs):.1f} s; phases "
              + ", ".join(f"{k} {sum(r['phases'].get(k, 0.0) for r in rs):.1f}" for k in PHASES))
    if a.json:
        from tactileskin.fileio import atomic_write_json

        atomic_write_json(a.json, rows)


if __name__ == "__main__":
    main()
