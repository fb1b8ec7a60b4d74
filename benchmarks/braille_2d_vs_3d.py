"""2D ridge against 3D dots: peak bone pressure and span of a Braille indenter (issue 7).

For each skin thickness and Braille text, solves
- the 3D slab (quarter model, real spherical-cap dots; P2 tetrahedra) with the bone
  profile on the section plane through the dot row nearest z = 0 (fe.output.plane_profile),
- the 2D plane-strain section with the same row as a ridge (the paper's model), on the same
  nominal mesh size (like for like) and at the `default` quality preset (the 2D reference),
and prints peak, span (results.span: P >= 10 % of the peak) and the relative differences
(2D - 3D) / 3D. Each solve runs in its own subprocess with a wall-time limit, one at a
time (shared 2-core machine); a 3D solve that fails reports its ConvergenceError diagnosis,
one stopped by the limit the travel it reached.

    .venv/bin/python benchmarks/braille_2d_vs_3d.py [--thickness 1 3] [--text a] \
        [--mesh-size 1.0] [--refinement 2] [--limit 1500] [--elastic] [--out benchmarks/results/braille_2d_vs_3d.md]

Texts: "a" (one dot, dot 1) and "\u283f" (the full cell, all six dots, Unicode braille).
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

TEXTS = {"a": "single dot ('a')", "\u283f": "full cell (U+283F, dots 1-6)"}


def case_scene(t: float, text: str, dim: int, h: float | None, r: float | None, elastic: bool, material: str):
    from tactileskin.scene import Scene

    kw = {} if h is None else dict(mesh_size=h, refinement=r)
    return Scene(thickness=t, material=material, indenter="braille", braille_text=text, dim=dim,
                 viscoelastic=not elastic, **kw)


def solve_with_contact_rule(scene, intorder: int, *, extra_bcs=(), plane_z=None, mesh=None, planes=None):
    """fe.solve with the contact points of the outer surface on a scikit-fem facet rule of
    order `intorder` (the library uses 3: 6 points per P2 triangle in 3D; 2 gives 3 points).
    A measurement aid for the solver note in benchmarks/results/braille_2d_vs_3d.md, not a
    library path. extra_bcs: more Dirichlet conditions (e.g. u_z = 0 on end_front)."""
    from tactileskin.fe import make_result, model_for_scene, run
    from tactileskin.fe.contact import ContactSurface
    from tactileskin.fe.model import Model

    t0 = time.perf_counter()
    model, sm = model_for_scene(scene, mesh)
    if extra_bcs:
        model = Model(model.mesh, model.boundaries, model.law, list(model.dirichlet) + list(extra_bcs),
                      prony=model.prony, formulation=model.formulation, contact=model.contact,
                      order=scene.order, stiffness=model.stiffness)
    model.surface = ContactSurface(model.mesh, model.element, model.boundaries["outer_surface"], model.m,
                                   intorder=intorder)
    ev, stats = run(model, scene.duration)
    stats.wall_s = time.perf_counter() - t0
    if planes is not None:  # one solve, the profile on several planes
        return [make_result(model, ev, stats, s_of_point=scene.section().s_of_point, plane_z=z) for z in planes]
    return make_result(model, ev, stats, s_of_point=scene.section().s_of_point, scene=scene.to_dict(),
                       plane_z=plane_z)


def run_one(args) -> dict:
    """Solve one case in this process; returns a JSON-able dict (outcome ok | failed)."""
    import logging

    from tactileskin.errors import ConvergenceError
    from tactileskin.fe import solve
    from tactileskin.planner import with_quality

    logging.basicConfig(level=logging.INFO, stream=sys.stderr, format="%(asctime)s %(name)s %(message)s")
    for name in ("skfem", "tactileskin.mesh"):
        logging.getLogger(name).setLevel(logging.WARNING)
    sc = case_scene(args.t, args.text, args.dim, args.h, args.r, args.elastic, args.material)
    args.contact_rule = getattr(args, "contact_rule", None)
    if args.h is None:
        sc = with_quality(sc, "default")
    t0 = time.perf_counter()
    try:
        res = solve(sc) if args.contact_rule is None else solve_with_contact_rule(sc, args.contact_rule)
    except ConvergenceError as e:
        d = dict(e.diagnosis)
        hist = d.get("history", [])
        return {"outcome": "failed", "error": str(e), "travel_mm": sc.rate * float(d.get("time", 0.0)),
                "history_tail": [float(x) for x in hist[-6:]], "point_mm": d.get("point_mm"),
                "wall_s": time.perf_counter() - t0}
    return {"outcome": "ok", "peak": res.peak, "span": res.span, "auc": res.auc, "reaction": res.reaction,
            "dofs": res.stats["dofs"], "increments": res.stats["increments"],
            "newton": res.stats["newton_iterations"], "wall_s": res.stats["wall_s"],
            "travel_mm": sc.indentation,
            "plane_z": res.stats.get("profile_plane_z"), "s": res.s.tolist(), "p": res.pressure.tolist()}


def run_case(t, text, dim, h, r, elastic, material, limit, contact_rule=None) -> dict:
    cmd = [sys.executable, __file__, "--one", "--t1", str(t), "--text1", text, "--dim1", str(dim),
           "--material", material] + (["--elastic"] if elastic else [])
    if contact_rule is not None and dim == 3:
        cmd += ["--contact-rule", str(contact_rule)]
    if h is not None:
        cmd += ["--h1", str(h), "--r1", str(r)]
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=limit)
    except subprocess.TimeoutExpired as e:
        log = (e.stderr or b"").decode() if isinstance(e.stderr, bytes) else (e.stderr or "")
        last = re.findall(r"increment (\d+): t = ([0-9.e-]+) s", log)
        return {"outcome": "time limit", "wall_s": time.perf_counter() - t0,
                "increments": int(last[-1][0]) if last else 0,
                "travel_mm": float(last[-1][1]) if last else 0.0}  # rate 1 mm/s
    if p.returncode != 0:
        return {"outcome": "crashed", "error": p.stderr.strip().splitlines()[-1:] if p.stderr else "",
                "wall_s": time.perf_counter() - t0}
    return json.loads(p.stdout.strip().splitlines()[-1])


def flat_check(contact_rule: int, thickness: float = 3.0, length: float = 1.0, depth: float = 0.1) -> str:
    """3D slab under a flat plate with u_z = 0 on both ends (plane strain: the 3D solution is
    uniform along z) against the 2D section, on two meshes; profile on three planes."""
    import numpy as np

    from tactileskin.fe import Dirichlet, solve
    from tactileskin.mesh.slab3d import build_slab_mesh
    from tactileskin.planner import profile_difference
    from tactileskin.scene import Scene

    lines = ["| mesh (h / refinement) | plane z (mm) | 3D peak | 2D peak | peak diff | rel. L2 (s <= 6) | "
             "3D span | 2D span | 3D dofs | 3D wall (s) |", "|---" * 10 + "|"]
    for h, r in ((1.0, 2.0), (0.7, 2.0)):
        sc = Scene(thickness=thickness, indenter="flat", dim=3, mesh_size=h, refinement=r, viscoelastic=False,
                   depth=depth)
        r2 = solve(sc.replace(dim=2))
        mesh = build_slab_mesh(sc, length=length)
        planes = (0.0, 0.25 * length, 0.5 * length)
        res = solve_with_contact_rule(sc, contact_rule, extra_bcs=[Dirichlet("end_front", (2,))], mesh=mesh,
                                      planes=planes)
        for z, r3 in zip(planes, res):
            d = profile_difference(r3, r2)
            lines.append(f"| {h:g} / {r:g} | {z:g} | {r3.peak:.5g} | {r2.peak:.5g} | {d['peak']:.2%} | "
                         f"{d['l2']:.2%} | {r3.span:.3g} | {r2.span:.3g} | {r3.stats['dofs']} | "
                         f"{r3.stats['wall_s']:.1f} |")
            print(lines[-1], flush=True)
    return "\n".join(lines)


def rel(a, b):
    return (a - b) / b


def table(rows) -> str:
    out = ["| t (mm) | indenter | 3D peak (MPa) | 3D span (mm) | 2D same-h peak | 2D same-h span | "
           "2D default peak | 2D default span | peak diff (2D same-h) | span diff (2D same-h) | "
           "peak diff (2D default) | span diff (2D default) | 3D solve |",
           "|---" * 13 + "|"]
    for r in rows:
        d3, ds, dd = r["3d"], r["2d_same"], r["2d_default"]

        def f(x, k, fmt):
            return format(x[k], fmt) if x.get("outcome") == "ok" else "-"

        def diff(x, k):
            return (f"{rel(x[k], d3[k]):+.1%}" if x.get("outcome") == "ok" and d3.get("outcome") == "ok"
                    else "-")

        if d3["outcome"] == "ok":
            how = (f"{d3['dofs']} dofs, {d3['increments']} incr., {d3['newton']} Newton, "
                   f"{d3['wall_s']:.0f} s")
        else:
            how = f"{d3['outcome']} at {d3.get('travel_mm', 0):.3g} mm travel after {d3['wall_s']:.0f} s"
        out.append(f"| {r['t']:g} | {TEXTS.get(r['text'], r['text'])} | {f(d3, 'peak', '.4g')} | "
                   f"{f(d3, 'span', '.3g')} | {f(ds, 'peak', '.4g')} | {f(ds, 'span', '.3g')} | "
                   f"{f(dd, 'peak', '.4g')} | {f(dd, 'span', '.3g')} | {diff(ds, 'peak')} | "
                   f"{diff(ds, 'span')} | {diff(dd, 'peak')} | {diff(dd, 'span')} | {how} |")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--thickness", type=float, nargs="+", default=[1.0, 3.0])
    ap.add_argument("--text", nargs="+", default=list(TEXTS))
    ap.add_argument("--material", default="silicone")
    ap.add_argument("--mesh-size", type=float, default=1.0)
    ap.add_argument("--refinement", type=float, default=2.0)
    ap.add_argument("--limit", type=float, default=1500.0, help="wall-time limit per 3D solve (s)")
    ap.add_argument("--elastic", action="store_true", help="drop the Prony series (both models)")
    ap.add_argument("--out", default=None, help="markdown file for the table")
    ap.add_argument("--json", default=None, help="also dump all case results (profiles included)")
    ap.add_argument("--contact-rule", type=int, default=None,
                    help="3D only: facet quadrature order of the contact points (library: 3; 2 = 3 points "
                         "per P2 triangle, see the solver note)")
    ap.add_argument("--flat-check", action="store_true",
                    help="only the flat-plate plane-strain check of the 3D profile against 2D")
    # internal: one solve in this process
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--t1", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--text1", help=argparse.SUPPRESS)
    ap.add_argument("--dim1", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--h1", type=float, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--r1", type=float, default=None, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.one:
        ns = argparse.Namespace(t=a.t1, text=a.text1, dim=a.dim1, h=a.h1, r=a.r1, elastic=a.elastic,
                                material=a.material, contact_rule=a.contact_rule)
        print(json.dumps(run_one(ns)))
        return 0
    if a.flat_check:
        print(flat_check(a.contact_rule or 3))
        return 0
    rows = []
    for t in a.thickness:
        for text in a.text:
            row = {"t": t, "text": text}
            for key, dim, h, r, lim in (("2d_same", 2, a.mesh_size, a.refinement, a.limit),
                                        ("2d_default", 2, None, None, a.limit),
                                        ("3d", 3, a.mesh_size, a.refinement, a.limit)):
                row[key] = run_case(t, text, dim, h, r, a.elastic, a.material, lim, a.contact_rule)
                res = row[key]
                print(f"t={t:g} {text!r} {key}: {res['outcome']}"
                      + (f" peak {res['peak']:.4g} span {res['span']:.3g} ({res['wall_s']:.0f} s)"
                         if res["outcome"] == "ok" else f" {res.get('error', '')} travel {res.get('travel_mm')}"),
                      flush=True)
            rows.append(row)
    tab = table(rows)
    print(tab)
    if a.json:
        Path(a.json).write_text(json.dumps(rows))
    if a.out:
        head = (f"<!-- {' '.join(sys.argv)} ; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} ; "
                f"{a.material}, 3D mesh_size {a.mesh_size:g} refinement {a.refinement:g}"
                f"{', elastic' if a.elastic else ''} -->\n")
        Path(a.out).write_text(head + tab + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
