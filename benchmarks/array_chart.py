"""The sensor-array design chart at a coarse 3D mesh, with the surrogate-validation table.

    PYTHONPATH=src python benchmarks/array_chart.py [--skin pad] [--thickness 1] [--mesh 1.2,4] [--cache DIR]

Each 3D solve runs in its own subprocess with a time limit (--solve-timeout), one at a time,
into the cache; the chart and the validation then only read the cache.

Writes benchmarks/results/array_chart.md (the report section, the time it took, CPU and
wall) and the figures/CSV into benchmarks/results/array_chart/. Solves go through the
result cache (--cache), so a rerun only classifies.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from tactileskin import fileio  # noqa: E402
from tactileskin.array.chart import ChartConfig, compute, validate_surrogate  # noqa: E402
from tactileskin.cache import ResultCache  # noqa: E402
from tactileskin.report.array_chart import markdown, write_figures  # noqa: E402

HERE = Path(__file__).resolve().parent / "results"
CAVEATS = """### Caveats

- The skin is the flat pad (20 x 20 mm, bonded to a rigid board; sensor plane the bonded
  surface), where a dot's response translates exactly and x-asymmetric characters are solved
  on the full width: the paper's 0.75 mm claim is for its curved fingertip, not for this pad.
- Coarse 3D meshes: the dot's contact patch spans a few elements; the maps' shapes, not only
  their peaks, are mesh-dependent (the validation table compares solves at the same sizes).
- The letters set rests on the superposition surrogate, whose error against full solves is in
  the validation table above: where it exceeds 5 % of the peak the letters chart is indicative
  only.
- Only t = 1 on the pad: at the scenes' depth (20 % of t) a t = 3 skin is indented 0.6 mm, past
  the dot height (0.48 mm, American standard): the Braille plate then loads the pad too and a
  single-dot kernel would count the plate once per dot (compute() flags this in Chart.notes).
  A t >= 2.4 mm letters chart needs a depth below the dot height (a fixed depth or force).
- Flat and curved are 2D plane-strain profiles extruded along z: they differ from the dot in
  magnitude by an order, so the paper set is told apart at any pitch while magnitude is read.
"""


def solve_each(scenes, cache_dir: str, timeout: float) -> list[str]:
    """Solve each scene not in the cache in its own subprocess (time limit `timeout` s), one at
    a time; returns one line per solve (case, CPU and wall seconds, or the failure)."""
    import subprocess
    import sys

    from tactileskin.cache import ResultCache

    cache, lines = ResultCache(cache_dir), []
    for sc in scenes:
        if cache.has(sc):
            continue
        code = ("import sys, time; from tactileskin.cache import ResultCache; from tactileskin.scene import Scene; "
                "from tactileskin.array.chart import solve_cached; "
                "sc = Scene.from_dict(__import__('json').loads(sys.argv[1])); c0 = time.process_time(); "
                "solve_cached([sc], ResultCache(sys.argv[2])); print(f'{time.process_time() - c0:.0f}')")
        w0 = time.perf_counter()
        try:
            r = subprocess.run([sys.executable, "-c", code, __import__("json").dumps(sc.to_dict()), cache_dir],
                               capture_output=True, text=True, timeout=timeout)
            ok = r.returncode == 0
            cpu = r.stdout.strip().splitlines()[-1] if ok and r.stdout.strip() else "?"
            msg = f"{sc.label()}: {cpu} s CPU, {time.perf_counter() - w0:.0f} s wall" if ok else \
                f"{sc.label()}: failed ({(r.stderr.strip().splitlines() or ['?'])[-1]})"
        except subprocess.TimeoutExpired:
            msg = f"{sc.label()}: not solved within {timeout:g} s"
        print(msg, flush=True)
        lines.append(msg)
    return lines


def convergence(rows) -> str:
    """The validation of the sample at other meshes (size, refinement of kernel and full solves)."""
    if not rows:
        return ""
    out = ["### The validation's mesh dependence", "",
           "| mesh (size, ref.) | t (mm) | text | model | rel. L2 | max error / peak | peak error |", "|---|---|---|---|---|---|---|"]
    for r in sorted(rows, key=lambda r: (r.get("text", ""), r.get("model", ""), float(r["mesh"].split(",")[1]))):
        if "error" in r:
            out.append(f"| {r['mesh']} | | | | not solved: {r['error'][:80]} | | |")
        else:
            out.append(f"| {r['mesh']} | {r['thickness_mm']:g} | {r['text']} | {r['model']} | {r['rel_l2']:.1%} | "
                       f"{r['max_abs_over_peak']:.1%} | {r['peak_rel']:+.1%} |")
    return "\n".join(out) + "\n\n"


def pitch_note(chart) -> str:
    """What the chart says about the paper's 0.75 mm rule: the coarsest pitch that still reads
    the letters, per thickness and noise, beside the measured Nyquist pitch of the dot."""
    from tactileskin.array.chart import GOOD

    cfg, out = chart.config, ["### On the paper's 0.75 mm rule", ""]
    if "letters" not in cfg.sets:
        return ""
    for c in chart.cutoffs:
        if c.get("skin") != cfg.skin:
            continue
        t = c["thickness_mm"]
        best = {n: max([p for p in cfg.pitches if chart.accuracy(c["material"], t, "letters", p, n) >= GOOD],
                       default=float("nan")) for n in cfg.noise_fs}
        out.append(f"- {c['material']}, t = {t:g} mm on the {cfg.skin}: the single dot's Nyquist pitch "
                   f"{c['nyquist_pitch_mm']:.2f} mm (half-space {c['halfspace_nyquist_pitch_mm']:.2f} mm); the "
                   "coarsest pitch reading the letters at >= 0.95: " + ", ".join(
                       f"{v:g} mm at noise {n:g}" for n, v in best.items()) + ". So 0.75 mm is enough here, "
                   "and coarser arrays also read the letters at low noise (the rule reads a dot, the "
                   "classifier a whole cell); the paper's rule is for its fingertip.")
    return "\n".join(out) + "\n\n"


def verdict(rows) -> str:
    """Which surrogate model meets the issue's tolerance on every validated text."""
    models = sorted({r["model"] for r in rows})
    ok = [m for m in models if all(r["within_tolerance"] for r in rows if r["model"] == m)]
    worst = {m: max(r["max_abs_over_peak"] for r in rows if r["model"] == m) for m in models}
    text = ("### Verdict on the surrogate\n\n"
            + (f"Within 5 % of the peak on every validated text: {', '.join(ok)}.\n\n" if ok else
               "No surrogate model is within 5 % of the peak on every validated text (worst max error / peak: "
               + ", ".join(f"{m} {v:.1%}" for m, v in worst.items())
               + "): the letters chart above is indicative only; a letters chart that meets the issue's tolerance "
               "needs full solves of the letters (or a mesh at which the validation passes; see the mesh "
               "dependence table).\n\n"))
    return text


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--skin", default="pad")
    ap.add_argument("--thickness", default="1")
    ap.add_argument("--validate-thickness", default="1")
    ap.add_argument("--texts", default="⠿,l,r")
    ap.add_argument("--mesh", default="1.2,4", help="3D mesh size, refinement")
    ap.add_argument("--sets", default="paper,letters")
    ap.add_argument("--also-mesh", default="1.2,2;1.2,6", help="other meshes ('size,ref;...') for the validation's convergence")
    ap.add_argument("--also-texts", default="⠿")
    ap.add_argument("--solve-timeout", type=float, default=900.0)
    ap.add_argument("--cache", default="/tmp/tactileskin_array_cache")
    a = ap.parse_args()
    ts = tuple(float(x) for x in a.thickness.split(","))
    ms, rf = (float(x) for x in a.mesh.split(","))
    cfg = ChartConfig(thicknesses=ts, skin=a.skin, mesh_size=ms, refinement=rf, sets=tuple(a.sets.split(",")))
    cache = ResultCache(a.cache)
    texts = [x for x in a.texts.split(",") if x]
    vts = [float(x) for x in a.validate_thickness.split(",") if x]
    from tactileskin.array.chart import dot_scene
    ws, cs = time.perf_counter(), time.process_time()
    solves = solve_each([dot_scene(t, "silicone", cfg, skin=k) for t in ts
                         for k, set_ in (("fingertip", "paper"), (a.skin, "letters")) if set_ in cfg.sets]
                        + [dot_scene(t, "silicone", cfg, x) for t in vts for x in ["", *texts]], a.cache, a.solve_timeout)
    ws = time.perf_counter() - ws
    w0, c0 = time.perf_counter(), time.process_time()
    solved = []

    def progress(msg: str) -> None:
        print(msg, flush=True)
        if msg.startswith("  done"):
            solved.append(msg)

    chart = compute(cfg, cache, progress=progress)
    w1, c1 = time.perf_counter(), time.process_time()
    rows = []
    for t in vts:
        rows += validate_surrogate([t], "silicone", texts, cfg, cache, progress=print)
    conv = []
    import dataclasses
    for m in [x for x in a.also_mesh.split(";") if x]:
        ms2, rf2 = (float(v) for v in m.split(","))
        cfg2 = dataclasses.replace(cfg, mesh_size=ms2, refinement=rf2)
        tx2 = [x for x in a.also_texts.split(",") if x]
        solves += solve_each([dot_scene(t, "silicone", cfg2, x) for t in vts for x in ["", *tx2]], a.cache,
                             a.solve_timeout)
        try:
            conv += [{**r, "mesh": m} for t in vts for r in validate_surrogate([t], "silicone", tx2, cfg2, cache)]
        except Exception as e:  # a solve that did not finish: say so in the table
            conv.append({"mesh": m, "error": str(e)})
    conv += [{**r, "mesh": f"{ms:g},{rf:g}"} for r in rows if r["text"] in a.also_texts.split(",")]
    w2, c2 = time.perf_counter(), time.process_time()
    out = HERE / "array_chart"
    fileio.make_dirs(out)
    fileio.atomic_write_text(out / "accuracies.csv", chart.to_csv())
    write_figures(chart, out)
    log = "\n".join(f"- {x}" for x in solves) or "- none (all read from the cache)"
    text = ("# Sensor-array design chart (coarse 3D mesh)\n\n"
            f"Command: `PYTHONPATH=src python benchmarks/array_chart.py --skin {a.skin} --sets {a.sets} --thickness {a.thickness} "
            f"--validate-thickness {a.validate_thickness} --texts {a.texts} --mesh {a.mesh}`. 3D solves "
            f"{ws:.0f} s wall (each in a subprocess, one at a time, on a shared 2-core machine), then chart "
            f"{w1 - w0:.0f} s wall ({c1 - c0:.0f} s CPU; the 2D flat/curved sections solved in it if not cached), "
            f"validation {w2 - w1:.0f} s wall. Figures and CSV: benchmarks/results/array_chart/.\n\n"
            f"3D solves of this run:\n\n{log}\n\n" + markdown(chart, rows) + "\n" + convergence(conv)
            + verdict(rows) + pitch_note(chart) + CAVEATS)
    fileio.atomic_write_text(HERE / "array_chart.md", text)
    print(text)


if __name__ == "__main__":
    main()
