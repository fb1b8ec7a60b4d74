"""A/B of SolverOptions variants on named scenes: increments, Newton iterations, cut-backs,
peak, CPU and wall time per (case, variant), each solve in its own process (one BLAS thread;
PARDISO's threads as the variant's `threads`, default 1 here),
`--jobs` processes at a time.

Cases are Scene keyword sets, named; variants are SolverOptions keyword sets (plus
"penalty_factor", fe.model.PENALTY_FACTOR, "direct_after_failures",
fe.linsolve.DIRECT_AFTER_FAILURES_MAX, and "tol_relative", fe.model.Contact.tol_relative):

    .venv/bin/python benchmarks/solver_ab.py --set first_travel \
        --variant 'before:first_travel_radius=0' --variant 'now:' [--jobs 2] [--out FILE]

Built-in case sets (--set): "braille2d" (the 2D ridge at t = 1, 3, 5, both paper materials,
preview and default meshes), "paper2d" (the paper's 18 cases in 2D, preview and default), "braille3d" (the single 3D dot: t = 1 default, t = 3 preview,
t = 5 preview, silicone), "braille3d_default" (t = 3 and 5 at the default preset), "dots3d" (the single dot at
t = 1, 3, 5, both materials, default), "cell3d" (the full cell at t = 1, 3, 5, silicone, default), "chart" (the array chart's 3D dots at t = 5 on the pad, 0.4 mm), "shallow3d" (the single dot pressed 0.005-0.1 mm at
t = 1 and 5, default: the contact tolerance against the travel).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SETS = {
    "braille2d": {f"t{t:g}-{m}-braille-2d-{q}": dict(thickness=t, material=m, indenter="braille", quality=q)
                  for q in ("preview", "default") for m in ("silicone", "polyurethane") for t in (1.0, 3.0, 5.0)},
    "paper2d": {f"t{t:g}-{m}-{i}-2d-{q}": dict(thickness=t, material=m, indenter=i, quality=q)
                for q in ("preview", "default") for m in ("silicone", "polyurethane") for t in (1.0, 3.0, 5.0)
                for i in ("flat", "curved", "braille")},
    "braille3d": {
        "t1-silicone-dot-3d-default": dict(thickness=1.0, dim=3, indenter="braille", quality="default"),
        "t3-silicone-dot-3d-preview": dict(thickness=3.0, dim=3, indenter="braille", quality="preview"),
        "t5-silicone-dot-3d-preview": dict(thickness=5.0, dim=3, indenter="braille", quality="preview"),
    },
    "braille3d_default": {
        f"t{t:g}-silicone-dot-3d-default": dict(thickness=t, dim=3, indenter="braille", quality="default")
        for t in (3.0, 5.0)},
    "dots3d": {f"t{t:g}-{m}-dot-3d-default": dict(thickness=t, material=m, dim=3, indenter="braille",
                                                   quality="default")
               for m in ("silicone", "polyurethane") for t in (1.0, 3.0, 5.0)},
    "cell3d": {f"t{t:g}-silicone-cell-3d-default": dict(thickness=t, dim=3, indenter="braille", braille_text="\u283f",
                                                       quality="default")
               for t in (1.0, 3.0, 5.0)},
    "shallow3d": {f"t{t:g}-{m}-dot-3d-default-d{d:g}": dict(thickness=t, material=m, dim=3, indenter="braille",
                                                             quality="default", depth=d)
                  for m in ("silicone", "polyurethane") for t, d in ((1.0, 0.005), (1.0, 0.02), (5.0, 0.02),
                                                                     (5.0, 0.1))},
    "chart": {f"pad-t5-{m}-dot-3d-0.4mm": dict(thickness=5.0, material=m, dim=3, indenter="braille", skin="pad",
                                               pad_width=20.0, pad_length=20.0, depth=0.4, mesh_size=1.2,
                                               refinement=8.0)
              for m in ("silicone", "polyurethane")},
}


def one(case: dict, variant: dict) -> dict:
    from tactileskin.fe import solve
    from tactileskin.fe.solver import SolverOptions
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    case, variant = dict(case), dict(variant)
    if "penalty_factor" in variant:  # fe.model's module constant, not a SolverOptions field
        from tactileskin.fe import model as fe_model

        fe_model.PENALTY_FACTOR = float(variant.pop("penalty_factor"))
    if "direct_after_failures" in variant:  # fe.linsolve's back-off cap (0: off)
        from tactileskin.fe import linsolve

        linsolve.DIRECT_AFTER_FAILURES_MAX = int(variant.pop("direct_after_failures"))
    if "tol_relative" in variant:  # fe.model.Contact's penetration tolerance over the facet size
        import functools

        import tactileskin.fe as fe
        from tactileskin.fe.model import Contact

        fe.Contact = functools.partial(Contact, tol_relative=float(variant.pop("tol_relative")))
    q = case.pop("quality", None)
    sc = Scene(**case)
    if q:
        sc = with_quality(sc, q)
    c0, w0 = time.process_time(), time.perf_counter()
    r = solve(sc, options=SolverOptions(**variant))
    return dict(dofs=r.stats["dofs"], increments=r.stats["increments"], newton=r.stats["newton_iterations"],
                cutbacks=r.stats["cutbacks"], peak=r.peak, span=r.span, cpu=time.process_time() - c0,
                wall=time.perf_counter() - w0)


def parse_variant(text: str) -> tuple[str, dict]:
    name, _, body = text.partition(":")
    kw = {}
    for item in filter(None, (x.strip() for x in body.split(","))):
        k, _, v = item.partition("=")
        kw[k] = json.loads(v) if v[:1] in "[{\"" or v.replace(".", "", 1).replace("-", "", 1).replace("e", "", 1).isdigit() \
            else {"true": True, "false": False}.get(v.lower(), v)
    return name, kw


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", action="append", default=[], choices=sorted(SETS))
    ap.add_argument("--variant", action="append", default=[])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", default="", help="only the cases whose name contains this")
    ap.add_argument("--out", default=None)
    ap.add_argument("--one", nargs=2, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        print(json.dumps(one(json.loads(a.one[0]), json.loads(a.one[1]))))
        return 0
    cases = {k: v for s in a.set for k, v in SETS[s].items() if a.only in k}
    variants = dict(parse_variant(v) for v in a.variant) or {"now": {}}
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), MKL_NUM_THREADS="1", OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1")

    def run(item):
        (cname, case), (vname, var) = item
        p = subprocess.run([sys.executable, __file__, "--one", json.dumps(case), json.dumps(var)],
                           capture_output=True, text=True, env=env)
        if p.returncode != 0:
            return cname, vname, {"error": p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "failed"}
        return cname, vname, json.loads(p.stdout.strip().splitlines()[-1])

    items = [(c, v) for c in cases.items() for v in variants.items()]
    lines = ["| case | variant | dofs | increments | Newton | cut-backs | peak MPa | span mm | CPU s | wall s |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    with ThreadPoolExecutor(a.jobs) as pool:
        for cname, vname, r in pool.map(run, items):
            if "error" in r:
                line = f"| {cname} | {vname} | failed: {r['error'][:80]} | | | | | | | |"
            else:
                line = (f"| {cname} | {vname} | {r['dofs']:,} | {r['increments']} | {r['newton']} | {r['cutbacks']} | "
                        f"{r['peak']:.6g} | {r['span']:.3f} | {r['cpu']:.1f} | {r['wall']:.1f} |")
            print(line, flush=True)
            lines.append(line)
    if a.out:
        from tactileskin.fileio import atomic_write_text

        atomic_write_text(Path(a.out), "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
