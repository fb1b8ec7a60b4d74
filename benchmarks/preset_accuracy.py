"""Accuracy of the `preview` and `default` quality presets against a Richardson-extrapolated
reference peak bone pressure, for the 18 paper cases.

Per case: solve at `preview` and at `default` (planner.QUALITY: the presets differ between
flat/curved and Braille), and a fixed mesh series at refinement 3 with mesh_size =
0.25 / sqrt(2)^k, k < levels (a preset equal to a series level reuses it). Reference: Richardson extrapolation of the three finest series peaks, with the
conventions of benchmarks/speed_vs_error.py (ratio sqrt(2), observed order
p = ln(d1/d2) / ln(sqrt(2)), plausible 0.5 <= p <= 4). If the differences change sign or do
not contract, or p is outside that range, the reference is the finest computed peak and the
row is flagged ("finest"), as an extrapolation with p -> 0 would be noise.

Errors: (P_peak - P_ref) / P_ref for preview and default (signed); profile: the RMS over
s <= 6 mm (the paper's window) of P_default(s) - P_finest(s), divided by P_ref (the
speed_vs_error profile error).

    .venv/bin/python benchmarks/preset_accuracy.py [--cases t1-silicone-flat,...] [--levels 3]
"""

from __future__ import annotations

import os

# one thread per process, before numpy loads (the machine is shared; timings comparable)
os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from tactileskin import fe  # noqa: E402
from tactileskin.errors import TactileSkinError  # noqa: E402
from tactileskin.mesh import build_mesh  # noqa: E402
from tactileskin.planner import QUALITY, with_quality  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402
from tactileskin.sweep import PAPER_INDENTERS, PAPER_MATERIALS, PAPER_THICKNESSES  # noqa: E402

ALL = [f"t{t:g}-{m}-{i}" for t in PAPER_THICKNESSES for m in PAPER_MATERIALS for i in PAPER_INDENTERS]
RATIO = math.sqrt(2.0)
ORDER_MIN, ORDER_MAX = 0.5, 4.0   # plausible observed orders (as in speed_vs_error.py)
WINDOW_S = 6.0                     # mm: profile window of the paper
DEFAULT_OK, PREVIEW_OK = 0.01, 0.05
# the reference series: mesh_size SERIES_H0 / sqrt(2)^k at refinement SERIES_RATIO, fixed
# (not the presets, which differ by indenter), so every case has the same kind of reference
SERIES_H0, SERIES_RATIO = 0.25, 3.0


@dataclass
class Solve:
    name: str
    mesh_size: float
    refinement: float
    dofs: int = 0
    increments: int = 0
    newton: int = 0
    peak: float = math.nan
    mesh_cpu: float = math.nan
    solve_cpu: float = math.nan
    s: np.ndarray | None = None
    p: np.ndarray | None = None
    failed: str = ""


def base_scene(label: str) -> Scene:
    t, mat, ind = label.split("-")
    return Scene(thickness=float(t[1:]), material=mat, indenter=ind)


def run(scene: Scene, name: str) -> Solve:
    r = Solve(name, scene.mesh_size, scene.refinement)
    try:
        c0 = time.process_time()
        mesh = build_mesh(scene)
        c1 = time.process_time()
        r.mesh_cpu = c1 - c0
        res = fe.solve(scene, mesh)
        r.solve_cpu = time.process_time() - c1
    except TactileSkinError as e:  # a failed solve is a result row, not a crash
        r.failed = f"{type(e).__name__}: {e}"[:100].replace("|", "/").replace("\n", " ")
        return r
    r.dofs, r.increments, r.newton = res.stats["dofs"], res.stats["increments"], res.stats["newton_iterations"]
    r.peak = res.peak
    r.s, r.p = res._profile()
    return r


def richardson(f: list[float]) -> tuple[float, float, str]:
    """(reference, observed order, flag) from three peaks on h, h/r, h/r^2 (r = sqrt(2)).
    flag "" when extrapolated; otherwise the finest value with the reason."""
    d1, d2 = f[1] - f[0], f[2] - f[1]
    if d1 == 0 or d2 == 0 or d1 * d2 < 0:
        return f[2], math.nan, "finest: differences change sign"
    if abs(d2) >= abs(d1):
        p = math.log(abs(d1 / d2)) / math.log(RATIO)
        return f[2], p, "finest: differences do not contract"
    p = math.log(abs(d1 / d2)) / math.log(RATIO)
    if not ORDER_MIN <= p <= ORDER_MAX:
        return f[2], p, f"finest: order outside {ORDER_MIN:g}..{ORDER_MAX:g}"
    return f[2] + d2 / (RATIO ** p - 1.0), p, ""


def profile_error(run_: Solve, ref: Solve, peak_ref: float) -> float:
    hi = min(WINDOW_S, ref.s[-1], run_.s[-1])
    x = np.linspace(0.0, hi, 400)
    e = np.interp(x, run_.s, run_.p) - np.interp(x, ref.s, ref.p)
    return float(np.sqrt(np.trapezoid(e * e, x) / hi) / peak_ref)


def fmt(x, f: str) -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, f)


def case_row(label: str, levels: int) -> dict:
    base = base_scene(label)
    pv = run(with_quality(base, "preview"), "preview")
    dfs = with_quality(base, "default")
    series = [run(base.replace(mesh_size=SERIES_H0 / RATIO ** k, refinement=SERIES_RATIO), f"k{k}")
              for k in range(levels)]
    same = [r for r in series if (r.mesh_size, r.refinement) == (dfs.mesh_size, dfs.refinement)]
    df = same[0] if same else run(dfs, "default")
    out = {"label": label, "preview": pv, "default": df, "series": series,
           "ref": math.nan, "order": math.nan, "flag": "", "err_pv": math.nan, "err_df": math.nan,
           "prof_df": math.nan}
    failed = [r for r in [pv] + series if r.failed]
    if any(r.failed for r in series):
        out["flag"] = "no reference: series level failed"
    else:
        out["ref"], out["order"], out["flag"] = richardson([r.peak for r in series[-3:]])
        ref = out["ref"]
        if not pv.failed:
            out["err_pv"] = (pv.peak - ref) / ref
        out["err_df"] = (df.peak - ref) / ref
        out["prof_df"] = profile_error(df, series[-1], ref)
    if failed:
        out["flag"] = "; ".join([out["flag"]] * bool(out["flag"]) + [f"{r.name} failed: {r.failed}" for r in failed])
    return out


def header(levels: int) -> list[str]:
    names = ["preview", "default"] + [f"k{k}" for k in range(levels)]
    n = "/".join(names)
    return [f"| case | dofs {n} | peak MPa {n} | order | ref MPa | preview err | default err "
            f"| default profile err | solve CPU s {n} | Newton {n} | note |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]


def row_text(o: dict) -> str:
    runs = [o["preview"], o["default"]] + o["series"]
    dofs = "/".join("fail" if r.failed else str(r.dofs) for r in runs)
    peaks = "/".join("fail" if r.failed else f"{r.peak:.5f}" for r in runs)
    cpu = "/".join(fmt(r.solve_cpu, ".1f") for r in runs)
    newton = "/".join("-" if r.failed else str(r.newton) for r in runs)
    return (f"| {o['label']} | {dofs} | {peaks} | {fmt(o['order'], '.2f')} | {fmt(o['ref'], '.5f')} "
            f"| {fmt(o['err_pv'], '+.2%')} | {fmt(o['err_df'], '+.2%')} | {fmt(o['prof_df'], '.2%')} "
            f"| {cpu} | {newton} | {o['flag']} |")


def summary(rows: list[dict]) -> str:
    df = [abs(o["err_df"]) for o in rows if not math.isnan(o["err_df"])]
    pv = [abs(o["err_pv"]) for o in rows if not math.isnan(o["err_pv"])]
    flagged = [o["label"] for o in rows if o["flag"]]
    cpu = sum(r.solve_cpu + r.mesh_cpu for o in rows for r in {id(x): x for x in [o["preview"], o["default"]]
                                                                   + o["series"]}.values()
              if not math.isnan(r.solve_cpu))
    return (f"summary ({len(rows)} cases): max |default err| {fmt(max(df, default=math.nan), '.2%')}, "
            f"max |preview err| {fmt(max(pv, default=math.nan), '.2%')}; default within 1 %: "
            f"{sum(e <= DEFAULT_OK for e in df)}/{len(df)}, preview within 5 %: "
            f"{sum(e <= PREVIEW_OK for e in pv)}/{len(pv)}; flagged (reference = finest or failure): "
            f"{', '.join(flagged) or 'none'}; CPU (mesh + solve) {cpu:.0f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(ALL))
    ap.add_argument("--levels", type=int, default=3, help="series levels k < levels (>= 3)")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "preset_accuracy.md"))
    a = ap.parse_args()
    if a.levels < 3:
        ap.error("--levels must be >= 3 (Richardson needs three)")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=Path(__file__).parent).stdout.strip() or "unknown"
    qtxt = "; ".join(f"{q}: {QUALITY[q]['mesh'][0]:g}/{QUALITY[q]['mesh'][1]:g}, Braille "
                     f"{QUALITY[q]['braille_mesh'][0]:g}/{QUALITY[q]['braille_mesh'][1]:g}"
                     for q in ("preview", "default"))
    head = [f"# preset accuracy ({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, commit {commit})", "",
            f"Presets (mesh_size/refinement) {qtxt}. Series k: mesh_size {SERIES_H0:g}/sqrt(2)^k, refinement "
            f"{SERIES_RATIO:g}, k < {a.levels} (a preset equal to a series level reuses it). Reference: "
            f"Richardson of the three finest peaks "
            f"(order in {ORDER_MIN:g}..{ORDER_MAX:g}, monotone contracting differences), else the finest "
            f"peak (note \"finest\"). Errors signed, (P - P_ref) / P_ref; default profile err: RMS of "
            f"P_default - P_finest over s <= {WINDOW_S:g} mm / P_ref. CPU: process time of fe.solve "
            f"(meshing excluded), one thread.", ""]
    lines = header(a.levels)
    print("\n".join(head + lines), flush=True)
    out = Path(a.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    rows = []
    for label in a.cases.split(","):
        o = case_row(label, a.levels)
        rows.append(o)
        lines.append(row_text(o))
        print(lines[-1], flush=True)
        tmp = out.with_name("." + out.name + ".tmp")
        tmp.write_text("\n".join(head + lines + ["", summary(rows), ""]))
        tmp.replace(out)
    print("\n" + summary(rows), flush=True)


if __name__ == "__main__":
    main()
