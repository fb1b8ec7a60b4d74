"""Hard cases of the solver: near-incompressibility, large strain, a sharp dot on a thin
layer, thick skins, maximal confinement. Each must converge or stop with a
ConvergenceError whose diagnosis is populated; no NaN may reach a result.

Cases (the fingertip ones through `tactileskin.fe.solve`, the layer ones through the
low-level API `Model`/`Dirichlet`/`Contact`/`run` on a scikit-fem rectangle):

- nu0499-<material>: Table I with nu = 0.499 (a user material from TOML), t = 3 flat, 20 %;
- silicone-40pct: t = 3 silicone, flat plate, 40 % nominal strain;
- braille-t1: the Braille dot (2D section: the dot row as a ridge) on 1 mm silicone;
- t5-<material>: 5 mm skins, flat plate, 20 % (1 mm of travel);
- layer-bonded-<material>: a flat layer bonded to a rigid base, compressed by a frictionless
  plate wider than the layer (edge free: the layer bulges out);
- layer-confined-<material>: the same with the far edge held (u_x = 0): uniaxial strain,
  homogeneous, with the closed-form hyperfoam stress as the check (elastic).

`run_case(name, level)` returns a dict (outcome, increments, Newton iterations, wall time,
peak, ...). Usage (prints the table; --levels runs the mesh-convergence series):

    .venv/bin/python benchmarks/hard_cases.py [--levels 3] [--only layer] [--h0 1.0]
"""

from __future__ import annotations

import argparse
import itertools
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from tactileskin.errors import ConvergenceError

LAYER_WIDTH = 4.0   # mm (half width modelled: x in [0, W], symmetry at x = 0)
LAYER_HEIGHT = 1.0  # mm


def material_toml(base: str, nu: float, directory: str | Path) -> str:
    """Write the preset `base` with Poisson ratio nu as a user material; return its path."""
    import tomli_w

    from tactileskin.materials import get_material

    m = get_material(base)
    d = {"name": f"{base}-nu{nu:g}", "source": f"{m.source}, nu changed to {nu:g} (hard case)",
         "hyperfoam": {"mu": list(m.hyperfoam.mu), "alpha": list(m.hyperfoam.alpha), "nu": nu},
         "prony": {"g": list(m.prony.g), "tau": list(m.prony.tau)}}
    path = Path(directory) / f"{base}-nu{nu:g}.toml"
    path.write_text(tomli_w.dumps(d))
    return str(path)


def fingertip_scene(name: str, mesh_size: float, refinement: float, tmpdir: str):
    from tactileskin.scene import Scene

    kw = dict(mesh_size=mesh_size, refinement=refinement)
    if name.startswith("nu0499-"):
        mat = material_toml(name.split("-", 1)[1], 0.499, tmpdir)
        return Scene(thickness=3.0, material=mat, indenter="flat", **kw)
    if name == "silicone-40pct":
        return Scene(thickness=3.0, material="silicone", indenter="flat", depth_fraction=0.4, **kw)
    if name == "braille-t1":
        return Scene(thickness=1.0, material="silicone", indenter="braille", **kw)
    if name.startswith("t5-"):
        return Scene(thickness=5.0, material=name.split("-", 1)[1], indenter="flat", **kw)
    raise KeyError(name)


def layer_model(material: str, *, confined: bool, h: float, viscoelastic: bool = False,
                formulation: str = "mixed", width: float = LAYER_WIDTH, height: float = LAYER_HEIGHT):
    """A P2 model of the rectangle [0, W] x [0, H]: bottom bonded, x = 0 symmetry, top in
    contact with a flat plate wider than the layer, the far edge free or held in x."""
    from skfem import MeshTri

    from tactileskin.fe import Contact, Dirichlet, Model, material_law
    from tactileskin.geometry.indenters import make_indenter
    from tactileskin.materials import get_material

    nx = max(2, int(round(width / h))) + 1
    ny = max(2, int(round(height / h))) + 1
    mesh = MeshTri.init_tensor(np.linspace(0.0, width, nx), np.linspace(0.0, height, ny))
    tol = 1e-9
    mesh = mesh.with_boundaries({
        "bottom": lambda x: x[1] < tol,
        "top": lambda x: x[1] > height - tol,
        "symmetry": lambda x: x[0] < tol,
        "edge": lambda x: x[0] > width - tol,
    })
    bnd = {k: v for k, v in mesh.boundaries.items()}
    mat = get_material(material)
    bcs = [Dirichlet("bottom", (0, 1)), Dirichlet("symmetry", (0,))]
    if confined:
        bcs.append(Dirichlet("edge", (0,)))
    plate = make_indenter("flat", y0=height, dim=2)
    contact = Contact(plate, boundary="top", rate=1.0)
    hf = mat.hyperfoam
    prony = mat.prony if viscoelastic and mat.prony.n_terms else None
    return Model(mesh, bnd, material_law(hf), bcs, prony=prony, formulation=formulation, contact=contact,
                 order=2, stiffness=max(hf.K0, hf.mu0))


def confined_closed_form(material: str, strain: float) -> float:
    """Mean pressure P = -(s1 + s2 + s3)/3 (MPa) of uniaxial strain (1, 1 - strain, 1)."""
    from tactileskin.materials import cauchy_principal, get_material

    sig = cauchy_principal(get_material(material).hyperfoam, np.array([1.0, 1.0 - strain, 1.0]))
    return float(-sig.sum() / 3.0)


def solve_layer(material: str, *, confined: bool, strain: float, h: float, viscoelastic: bool = False,
                options=None, contact_tol: float | None = None):
    """Compress the layer by `strain` x H; returns the Result (P(s) along the bottom, s = x).
    contact_tol: the augmented-Lagrangian penetration tolerance (mm; default the solver's)."""
    from tactileskin.fe import make_result, run

    model = layer_model(material, confined=confined, h=h, viscoelastic=viscoelastic)
    if contact_tol is not None:
        model.contact.tol_penetration = contact_tol
    T = strain * LAYER_HEIGHT / model.contact.rate
    t0 = time.perf_counter()
    ev, stats = run(model, T, options)
    stats.wall_s = time.perf_counter() - t0
    return make_result(model, ev, stats, s_of_point=lambda X: X[:, 0], path="bottom")


CASES = ["nu0499-silicone", "nu0499-polyurethane", "silicone-40pct", "braille-t1", "t5-silicone",
         "t5-polyurethane", "layer-bonded-silicone", "layer-bonded-polyurethane",
         "layer-confined-silicone", "layer-confined-polyurethane"]
LAYER_STRAIN = 0.2  # the paper's nominal strain


def run_case(name: str, mesh_size: float, refinement: float = 2.0, options=None) -> dict:
    """Solve one hard case at a mesh size; outcome 'converged' or 'ConvergenceError' (with
    its diagnosis); any other exception propagates (a bug, not an outcome)."""
    from tactileskin.fe import solve

    row = {"case": name, "mesh_size": mesh_size, "outcome": "", "increments": None, "newton": None,
           "cutbacks": None, "wall_s": None, "peak": None, "span": None, "dofs": None, "diagnosis": None}
    t0 = time.perf_counter()
    try:
        if name.startswith("layer-"):
            _, kind, mat = name.split("-")
            res = solve_layer(mat, confined=kind == "confined", strain=LAYER_STRAIN, h=mesh_size, options=options)
        else:
            with tempfile.TemporaryDirectory() as tmp:
                res = solve(fingertip_scene(name, mesh_size, refinement, tmp), options=options)
    except ConvergenceError as e:
        row.update(outcome="ConvergenceError", wall_s=time.perf_counter() - t0, diagnosis=e.diagnosis,
                   message=str(e))
        return row
    st = res.stats
    row.update(outcome="converged", increments=st["increments"], newton=st["newton_iterations"],
               cutbacks=st["cutbacks"], wall_s=time.perf_counter() - t0, peak=res.peak, span=res.span,
               dofs=st["dofs"], result=res)
    return row


def planner_checks(mesh_size: float, refinement: float) -> None:
    """Measure what the planner's choices cost: truncation (full vs truncated section, P(s)
    on s <= 6 mm) for the cases with skin to cut, and the elastic vs viscoelastic peak
    against the bound 1 - g(T)."""
    from rich.console import Console
    from rich.table import Table

    from tactileskin.fe import solve
    from tactileskin.planner import check_truncation, truncated_scene, viscoelastic_bound
    from tactileskin.scene import Scene

    con = Console()
    tt = Table(title=f"truncation (h = {mesh_size:g}, refinement {refinement:g})")
    for c in ("case", "interface mm", "kept mm", "L2 diff", "peak diff", "wall full s", "wall truncated s"):
        tt.add_column(c, justify="right")
    for t, mat, ind in itertools.product((1.0, 3.0, 5.0), ("silicone", "polyurethane"), ("flat", "curved", "braille")):
        sc = Scene(thickness=t, material=mat, indenter=ind)
        if truncated_scene(sc) is None:
            continue
        d = check_truncation(sc, mesh_size=mesh_size, refinement=refinement)
        tt.add_row(sc.label(), f"{d['full_s']:.2f}", f"{d['keep_s']:.2f}", f"{d['l2']:.3%}", f"{d['peak']:.3%}",
                   f"{d['wall_full']:.2f}", f"{d['wall_truncated']:.2f}")
        con.print(sc.label(), d)
    con.print(tt)
    vt = Table(title=f"elastic vs viscoelastic peak (curved, h = {mesh_size:g})")
    for c in ("case", "rate mm/s", "T s", "bound 1-g(T)", "peak VE", "peak elastic", "relative diff", "diff/bound"):
        vt.add_column(c, justify="right")
    for t, mat, rate in itertools.product((1.0, 3.0), ("silicone", "polyurethane"), (1.0, 100.0)):
        sc = Scene(thickness=t, material=mat, indenter="curved", rate=rate, mesh_size=mesh_size,
                   refinement=refinement)
        ve, el = solve(sc), solve(sc.replace(viscoelastic=False))
        diff = (el.peak - ve.peak) / el.peak
        b = viscoelastic_bound(sc)
        vt.add_row(sc.label(), f"{rate:g}", f"{sc.duration:.3g}", f"{b:.3%}", f"{ve.peak:.5g}", f"{el.peak:.5g}",
                   f"{diff:.3%}", f"{diff / b:.2f}")
        con.print(sc.label(), rate, b, diff)
    con.print(vt)


def main() -> None:
    import logging

    ap = argparse.ArgumentParser()
    ap.add_argument("--only", default="")
    ap.add_argument("--h0", type=float, default=1.0, help="coarsest mesh size (mm)")
    ap.add_argument("--levels", type=int, default=1, help="mesh sizes h0 / 2^k, k < levels")
    ap.add_argument("--refinement", type=float, default=2.0)
    ap.add_argument("--planner", action="store_true", help="only the planner checks (truncation, viscoelasticity)")
    ap.add_argument("--out", default="hard_cases.md", help="markdown table in benchmarks/results/")
    ap.add_argument("-v", action="store_true")
    a = ap.parse_args()
    logging.basicConfig(level=logging.INFO if a.v else logging.WARNING)
    if a.planner:
        planner_checks(a.h0, a.refinement)
        return
    lines = [f"hard cases, refinement {a.refinement:g} ({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())})", "",
             "| case | h mm | outcome | dofs | incr | Newton | cutbacks | wall s | peak MPa | span mm | "
             "change vs previous h | note |", "|" + "---|" * 12]
    results = Path(__file__).parent / "results"
    results.mkdir(parents=True, exist_ok=True)
    total = time.perf_counter()
    f = lambda v, s: "-" if v is None else format(v, s)  # noqa: E731
    for name in CASES:
        if a.only and a.only not in name:
            continue
        prev = None
        for k in range(a.levels):
            h = a.h0 / 2 ** k
            row = run_case(name, h, a.refinement)
            note, change = "", ""
            if row["outcome"] == "converged":
                if prev is not None:
                    change = f"{(row['peak'] - prev) / prev:+.2%}"
                prev = row["peak"]
                if name.startswith("layer-confined"):
                    exact = confined_closed_form(name.split("-")[2], LAYER_STRAIN)
                    note = f"closed form {exact:.5g} ({(row['peak'] - exact) / exact:+.2%})"
            else:
                d = row["diagnosis"] or {}
                note = (f"{d.get('reason', '')} at t = {d.get('time', math.nan):.3g} s, dt = "
                        f"{d.get('dt', math.nan):.2g} s, worst residual at {d.get('point_mm')}")
            lines.append(f"| {name} | {h:g} | {row['outcome']} | {f(row['dofs'], 'd')} | {f(row['increments'], 'd')} | "
                         f"{f(row['newton'], 'd')} | {f(row['cutbacks'], 'd')} | {f(row['wall_s'], '.1f')} | "
                         f"{f(row['peak'], '.5g')} | {f(row['span'], '.3g')} | {change} | {note} |")
            print(lines[-1], flush=True)
            tmp = results / f".{a.out}.tmp"
            tmp.write_text("\n".join(lines) + "\n")
            tmp.replace(results / a.out)
    print(f"total wall time {time.perf_counter() - total:.1f} s")


if __name__ == "__main__":
    main()
