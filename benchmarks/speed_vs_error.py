"""Speed against error of the 2D paper cases: mesh size, refinement ratio, element order,
increment control and contact tolerance, against a Richardson-extrapolated reference.

For each case (indenter x material x thickness) the script solves a mesh series
h = H0 / sqrt(2)^k at a fixed refinement ratio (the mesh-convergence series), then a few
variants (another refinement ratio, P1 elements, coarser increments, a looser contact
tolerance) on the series' meshes. Reference: the finest solution of the series, with the
peak Richardson-extrapolated from the three finest peaks (observed order printed). Errors:

- peak error |P_peak - P_ref| / P_ref (P_ref: extrapolated peak);
- profile error: the L2 norm of P(s) - P_ref(s) over the bone interface within 6 mm of
  s = 0 (the paper's window), divided by sqrt(window length) and by the reference peak,
  with P_ref(s) the finest profile (a pointwise extrapolation is too noisy to trust).

Wall time: the median of repeated solves (meshing included, reported separately) for
solves under `--repeat-below` seconds, otherwise one solve; the machine is shared.

Writes benchmarks/results/speed_vs_error_<case>.csv and .png (Pareto plot: error against
wall time) and benchmarks/results/speed_vs_error.md (all tables). Usage:

    .venv/bin/python benchmarks/speed_vs_error.py --quick
    .venv/bin/python benchmarks/speed_vs_error.py --only t3-silicone-flat --levels 5
"""

from __future__ import annotations

import argparse
import csv
import itertools
import logging
import math
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactileskin.errors import TactileSkinError
from tactileskin.fe import SolverOptions, make_result, model_for_scene, run
from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene

RESULTS = Path(__file__).parent / "results"
WINDOW_S = 6.0  # mm: the paper's window of the bone-pressure profile
ORDER_MIN, ORDER_MAX = 0.5, 4.0  # plausible observed orders for a Richardson reference
QUICK = [(1.0, "silicone", "flat"), (3.0, "silicone", "curved"), (3.0, "polyurethane", "braille")]


@dataclass
class Run:
    label: str
    mesh_size: float
    refinement: float
    order: int
    control: str
    contact_tol: float
    dofs: int = 0
    increments: int = 0
    newton: int = 0
    mesh_s: float = math.nan
    wall_s: float = math.nan      # median solve time (excluding meshing)
    times: list = field(default_factory=list)
    peak: float = math.nan
    span: float = math.nan
    s: np.ndarray | None = None
    p: np.ndarray | None = None
    failed: str = ""
    peak_err: float = math.nan
    l2_err: float = math.nan

    @property
    def total_s(self) -> float:
        return self.mesh_s + self.wall_s


CONTROLS = {
    "adaptive": SolverOptions(),
    # fewer, larger increments: one quarter of the loading per increment from the start
    "coarse-steps": SolverOptions(dt0_fraction=0.25, dt_max_fraction=0.5, growth=2.0),
}


def solve_once(scene: Scene, mesh, control: str, contact_tol: float):
    """fe.solve with a chosen contact tolerance (the low-level API exposes it)."""
    t0 = time.perf_counter()
    model, _ = model_for_scene(scene, mesh)
    model.contact.tol_penetration = contact_tol
    ev, stats = run(model, scene.duration, CONTROLS[control])
    stats.wall_s = time.perf_counter() - t0
    return make_result(model, ev, stats, s_of_point=scene.section().s_of_point), time.perf_counter() - t0


def measure(scene: Scene, r: Run, repeat: int, repeat_below: float) -> Run:
    try:
        t0 = time.perf_counter()
        mesh = build_mesh(scene)
        r.mesh_s = time.perf_counter() - t0
        res, dt = solve_once(scene, mesh, r.control, r.contact_tol)
        r.times.append(dt)
        while dt < repeat_below and len(r.times) < repeat:
            _, dt = solve_once(scene, mesh, r.control, r.contact_tol)
            r.times.append(dt)
    except TactileSkinError as e:
        r.failed = f"{type(e).__name__}: {e}"[:120]
        return r
    r.wall_s = statistics.median(r.times)
    r.dofs, r.increments, r.newton = res.stats["dofs"], res.stats["increments"], res.stats["newton_iterations"]
    r.peak, r.span = res.peak, res.span
    r.s, r.p = res._profile()
    return r


def richardson(h: list[float], f: list[float]) -> tuple[float, float]:
    """(extrapolated value, observed order) from three values on meshes h0 > h1 > h2 with a
    constant ratio; (f2, order or nan) if the differences do not contract monotonically or
    the observed order is outside [ORDER_MIN, ORDER_MAX] (an extrapolation with p -> 0
    diverges: it would be noise, not a reference)."""
    r = h[0] / h[1]
    d1, d2 = f[1] - f[0], f[2] - f[1]
    if d1 == 0 or d2 == 0 or d1 * d2 < 0 or abs(d2) >= abs(d1):
        return f[2], math.nan
    p = math.log(abs(d1 / d2)) / math.log(r)
    if not ORDER_MIN <= p <= ORDER_MAX:
        return f[2], p
    return f[2] + d2 / (r ** p - 1.0), p


def profile_error(run: Run, ref: Run, peak_ref: float) -> float:
    hi = min(WINDOW_S, ref.s[-1], run.s[-1])
    x = np.linspace(0.0, hi, 400)
    e = np.interp(x, run.s, run.p) - np.interp(x, ref.s, ref.p)
    return float(np.sqrt(np.trapezoid(e * e, x) / hi) / peak_ref)


def pareto(runs: list[Run]) -> list[Run]:
    ok = sorted((r for r in runs if not r.failed), key=lambda r: (r.total_s, r.peak_err))
    front, best = [], math.inf
    for r in ok:
        if r.peak_err < best:
            front.append(r)
            best = r.peak_err
    return front


def run_case(t: float, mat: str, ind: str, a) -> dict:
    base = Scene(thickness=t, material=mat, indenter=ind)
    case = base.label()
    log = logging.getLogger("speed_vs_error")
    sizes = [a.h0 / math.sqrt(2.0) ** k for k in range(a.levels)]
    runs: list[Run] = []
    for h in sizes:  # the convergence series
        r = Run(f"h{h:.3g}-r{a.ratio:g}-P2", h, a.ratio, 2, "adaptive", 1e-4)
        runs.append(measure(base.replace(mesh_size=h, refinement=a.ratio), r, a.repeat, a.repeat_below))
        log.info("%s %s: %s", case, r.label, r.failed or f"peak {r.peak:.5g} in {r.wall_s:.2f} s")
    variants = []
    for h in sizes[:-1]:
        variants.append(Run(f"h{h:.3g}-r{a.ratio2:g}-P2", h, a.ratio2, 2, "adaptive", 1e-4))
        variants.append(Run(f"h{h:.3g}-r{a.ratio:g}-P2-coarse-steps", h, a.ratio, 2, "coarse-steps", 1e-4))
        variants.append(Run(f"h{h:.3g}-r{a.ratio:g}-P2-tol1e-3", h, a.ratio, 2, "adaptive", 1e-3))
    for h in sizes[1:] if a.p1 else []:
        h1 = h / 2.0  # P1 at half the size: the same number of nodes as P2 at h
        variants.append(Run(f"h{h1:.3g}-r{a.ratio:g}-P1", h1, a.ratio, 1, "adaptive", 1e-4))
    if a.no_variants:
        variants = []
    for r in variants:
        sc = base.replace(mesh_size=r.mesh_size, refinement=r.refinement, order=r.order,
                          formulation="displacement" if r.order == 1 else base.formulation)
        runs.append(measure(sc, r, a.repeat, a.repeat_below))
        log.info("%s %s: %s", case, r.label, r.failed or f"peak {r.peak:.5g} in {r.wall_s:.2f} s")

    series = [r for r in runs[: len(sizes)] if not r.failed]
    if len(series) < 3:
        return {"case": case, "runs": runs, "ref": None, "order": math.nan, "note": "fewer than 3 converged levels"}
    last3 = series[-3:]
    peak_ref, order = richardson([r.mesh_size for r in last3], [r.peak for r in last3])
    ref = series[-1]
    for r in runs:
        if not r.failed:
            r.peak_err = abs(r.peak - peak_ref) / peak_ref
            r.l2_err = profile_error(r, ref, peak_ref)
    return {"case": case, "runs": runs, "ref": ref, "peak_ref": peak_ref, "order": order}


def fmt(x, f):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, f)


def write_case(res: dict) -> str:
    RESULTS.mkdir(parents=True, exist_ok=True)
    case = res["case"]
    cols = ["label", "mesh_size", "refinement", "order", "control", "contact_tol", "dofs", "increments",
            "newton", "mesh_s", "wall_s", "n_timings", "peak", "span", "peak_err", "l2_err", "failed"]
    tmp = RESULTS / f".speed_vs_error_{case}.csv.tmp"
    with open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for r in res["runs"]:
            w.writerow([r.label, f"{r.mesh_size:.4g}", r.refinement, r.order, r.control, r.contact_tol, r.dofs,
                        r.increments, r.newton, f"{r.mesh_s:.3f}", f"{r.wall_s:.3f}", len(r.times),
                        f"{r.peak:.6g}", f"{r.span:.4g}", f"{r.peak_err:.3e}", f"{r.l2_err:.3e}", r.failed])
    tmp.replace(RESULTS / f"speed_vs_error_{case}.csv")
    front = {id(r) for r in pareto(res["runs"])}
    lines = [f"### {case}", ""]
    if res.get("ref") is None:
        lines += [f"no reference: {res.get('note')}", ""]
    else:
        extrap = res["peak_ref"] != res["ref"].peak
        lines += [f"reference peak {res['peak_ref']:.5g} MPa ("
                  + ("Richardson, three finest of the series" if extrap else
                     "the finest computed: Richardson not applicable") +
                  f"), observed order {fmt(res['order'], '.2f')}; finest computed {res['ref'].peak:.5g} MPa", ""]
    lines += ["| run | dofs | incr | Newton | mesh s | solve s (median of n) | peak MPa | peak err | profile L2 err | Pareto |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for r in res["runs"]:
        if r.failed:
            lines.append(f"| {r.label} | - | - | - | {fmt(r.mesh_s, '.2f')} | failed | {r.failed} | | | |")
            continue
        lines.append(f"| {r.label} | {r.dofs} | {r.increments} | {r.newton} | {r.mesh_s:.2f} | "
                     f"{r.wall_s:.2f} ({len(r.times)}) | {r.peak:.5g} | {fmt(r.peak_err, '.2%')} | "
                     f"{fmt(r.l2_err, '.2%')} | {'*' if id(r) in front else ''} |")
    plot_case(res)
    return "\n".join(lines) + "\n"


def plot_case(res: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = [r for r in res["runs"] if not r.failed and r.peak_err > 0]
    if not runs:
        return
    fig, ax = plt.subplots(figsize=(6, 4.2))
    groups = {}
    for r in runs:
        key = ("P1" if r.order == 1 else "P2") + (f" r{r.refinement:g}") + (
            "" if r.control == "adaptive" else f" {r.control}") + ("" if r.contact_tol == 1e-4 else f" tol {r.contact_tol:g}")
        groups.setdefault(key, []).append(r)
    for key, rs in groups.items():
        ax.loglog([r.total_s for r in rs], [r.peak_err for r in rs], "o-", label=f"{key}: peak")
    front = pareto(res["runs"])
    ax.loglog([r.total_s for r in front], [max(r.peak_err, 1e-6) for r in front], "k--", lw=1, label="Pareto front")
    ax.axhline(0.01, color="gray", lw=0.5)
    ax.axhline(0.05, color="gray", lw=0.5)
    ax.set_xlabel("wall time, meshing + solve (s)")
    ax.set_ylabel("relative peak error")
    ax.set_title(res["case"])
    ax.legend(fontsize=7)
    fig.tight_layout()
    tmp = RESULTS / f".speed_vs_error_{res['case']}.tmp.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(RESULTS / f"speed_vs_error_{res['case']}.png")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help=f"only {QUICK}")
    ap.add_argument("--only", default="", help="substring of the case label, e.g. t3-silicone-flat")
    ap.add_argument("--h0", type=float, default=1.0, help="coarsest mesh size (mm)")
    ap.add_argument("--levels", type=int, default=4, help="mesh sizes h0/sqrt(2)^k, k < levels")
    ap.add_argument("--ratio", type=float, default=3.0, help="refinement ratio of the series")
    ap.add_argument("--ratio2", type=float, default=2.0, help="refinement ratio of the variant")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--repeat-below", type=float, default=5.0, help="repeat solves faster than this (s)")
    ap.add_argument("--no-variants", action="store_true")
    ap.add_argument("--p1", action="store_true",
                    help="also P1 elements (they lock on triangles: see docs/speed_vs_error.md)")
    ap.add_argument("--out", default="speed_vs_error.md")
    ap.add_argument("-v", action="store_true")
    a = ap.parse_args()
    logging.basicConfig(level=logging.INFO if a.v else logging.WARNING, format="%(asctime)s %(message)s")
    logging.getLogger("speed_vs_error").setLevel(logging.INFO)
    cases = QUICK if a.quick else list(itertools.product((1.0, 3.0, 5.0), ("silicone", "polyurethane"),
                                                         ("flat", "curved", "braille")))
    text = [f"# speed against error ({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())})", "",
            f"series h = {a.h0:g}/sqrt(2)^k, k < {a.levels}, refinement {a.ratio:g}; variants: "
            + ("none" if a.no_variants else f"refinement {a.ratio2:g}, coarse steps, contact tolerance 1e-3 mm"
               + (", P1 at h/2" if a.p1 else "")), ""]
    RESULTS.mkdir(parents=True, exist_ok=True)
    for t, mat, ind in cases:
        label = Scene(thickness=t, material=mat, indenter=ind).label()
        if a.only and a.only not in label:
            continue
        res = run_case(t, mat, ind, a)
        text.append(write_case(res))
        print(text[-1], flush=True)
        tmp = RESULTS / f".{a.out}.tmp"
        tmp.write_text("\n".join(text))
        tmp.replace(RESULTS / a.out)


if __name__ == "__main__":
    main()
