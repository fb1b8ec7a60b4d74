"""Contact-spot size of the local plan against a fine reference (issue 13, target T3).

Under a thick skin the bone field cannot see detail much finer than the skin: this study
meshes a case at one level (default 1.6 / 8, the `default` preset from t = 3 mm) with the
local plan's contact-spot size scaled by factors k (mesh.sizing.SPOT_FACTOR; the bone balls
keep their size) and the plate strip's size by s (mesh.sizing.STRIP_FACTOR), solves each
in its own subprocess (benchmarks/convergence3d.solve_level: dofs, CPU s of the child, wall
s, increments / Newton, peak, span, bone map), and compares each with a reference level
(default 0.8 / 8) solved with k = s = 1 (the plan before the spot rule): peak and span
relative errors, the map's relative L2 (convergence3d.map_l2 on the variant's grid, one skin
thickness off the slab's free end, as the convergence study) and the map's interior peak.
Variants run interleaved per material (the machine is shared: compare CPU seconds).
With --reference equal to --level (the level itself at k = s = 1, the plan as it is) the
errors are how far a variant moves the default's results, not errors against a finer mesh
(and no per-mesh errors are fitted: the reference is one of the variants).
The full cell (--text "\u283f") writes its own file (spot_scale_t5_cell.md).

    PYTHONPATH=src .venv/bin/python benchmarks/spot_scale_t5.py --thickness 5 \
        --materials silicone,polyurethane --variants "1/1,1.5/1,2/1,3/1" --raw /tmp/raw \
        [--out benchmarks/results/spot_scale_t5.md]
    PYTHONPATH=src .venv/bin/python benchmarks/spot_scale_t5.py --thickness 5 --text "\u283f" \
        --reference 1.6/8 --variants "1/1,3/1" --raw /tmp/raw --out benchmarks/results/spot_scale_t5_cell.md
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import convergence3d as c3  # noqa: E402


def raw_path(raw: Path, t: float, material: str, text: str, h: float, r: float, k: float, s: float) -> Path:
    base = c3.raw_name(t, material, text, h, r, "local")
    return raw / (base if (k, s) == (1.0, 1.0) else base.replace(".json", f"_k{k:g}_s{s:g}.json"))


def solve_variant(args, material: str, h: float, r: float, k: float, s: float) -> dict:
    out = raw_path(args.raw, args.thickness, material, args.text, h, r, k, s)
    if not out.exists():
        cmd = [sys.executable, __file__, "--one", f"{h:g}/{r:g}", "--thickness", str(args.thickness),
               "--materials", material, "--text", args.text, "--raw", str(args.raw),
               "--variants", f"{k:g}/{s:g}"]
        print(f"[{time.strftime('%H:%M:%S')}] {material} {h:g}/{r:g} k={k:g} s={s:g} ...", flush=True)
        subprocess.run(cmd, check=True, env=dict(os.environ, PYTHONPATH=str(c3.ROOT / "src")))
    return json.loads(out.read_text(encoding="utf-8")) | {"k": k, "s": s}


def compare(level: dict, ref: dict) -> dict:
    """Errors of a level against the reference level (relative; map: L2 on the level's grid)."""
    t = float(ref["thickness"])
    l2 = c3.map_l2([level["map"], ref["map"]], ref_index=1, grid_index=0, z_margin=t)[0]
    mp, mr = c3.interior_map_peak(level), c3.interior_map_peak(ref)
    return {"peak_error": level["peak"] / ref["peak"] - 1.0, "span_error": level["span"] / ref["span"] - 1.0,
            "map_l2": l2, "map_peak_error": mp / mr - 1.0}


def table(rows: list[dict], ref: dict) -> str:
    out = ["| spot k / strip s | dofs | CPU s | wall s | incr. / Newton | peak MPa | peak err. | span err. | "
           "map L2 | map peak err. |", "|---|---|---|---|---|---|---|---|---|---|"]
    for d in rows:
        out.append(f"| {d['k']:g} / {d['s']:g} | {d['dofs']:,} | {d['cpu_s']:.1f} | {d['wall_s']:.1f} | "
                   f"{d['increments']} / {d['newton_iterations']} | {d['peak']:.5f} | {d['peak_error']:+.2%} | "
                   f"{d['span_error']:+.2%} | {d['map_l2']:.2%} | {d['map_peak_error']:+.2%} |")
    out.append(f"| reference {ref['mesh_size']:g} / {ref['refinement']:g}, k = s = 1 | {ref['dofs']:,} | "
               f"{ref['cpu_s']:.0f} | {ref['wall_s']:.0f} | {ref['increments']} / {ref['newton_iterations']} | "
               f"{ref['peak']:.5f} | | | | |")
    return "\n".join(out) + "\n"


def own_map_errors(levels: list[dict]):
    """(d, e, misfit): d[i, j] the map L2 of level i against level j (on the first level's grid,
    one skin thickness off the free end, relative to level j's map); e[i] each level's own map
    error under the model that the levels' errors are independent, |m_i - m_j|^2 = e_i^2 + e_j^2,
    fitted by non-negative least squares over all pairs; misfit the largest |model - measured|
    distance. The model reads the part of the error that changes from mesh to mesh; an error
    every mesh shares is not in it."""
    import numpy as np
    from scipy.optimize import nnls

    n = len(levels)
    t = float(levels[0]["thickness"])
    d = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            if i != j:
                d[i, j] = c3.map_l2([levels[0]["map"], levels[i]["map"], levels[j]["map"]],
                                    ref_index=2, grid_index=0, z_margin=t)[1]
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
    A = np.zeros((len(pairs), n))
    for row, (i, j) in enumerate(pairs):
        A[row, [i, j]] = 1.0
    b = np.array([(d[i, j] ** 2 + d[j, i] ** 2) / 2 for i, j in pairs])
    e2 = nnls(A, b)[0]
    misfit = max(abs(np.sqrt(e2[i] + e2[j]) - np.sqrt(b[row])) for row, (i, j) in enumerate(pairs))
    return d, np.sqrt(e2), float(misfit)


def map_noise(levels: list[dict], names: list[str]) -> str:
    """own_map_errors as a markdown table."""
    d, e, misfit = own_map_errors(levels)
    n = len(levels)
    out = ["| mesh | " + " | ".join(names) + " | own error (model) |",
           "|---|" + "---|" * (n + 1)]
    for i in range(n):
        out.append(f"| {names[i]} | " + " | ".join("" if i == j else f"{d[i, j]:.2%}" for j in range(n))
                   + f" | {e[i]:.2%} |")
    out.append(f"\nLargest misfit of the model over the {n * (n - 1) // 2} pairs: {misfit:.2%} "
               "(model distance - measured).")
    return "\n".join(out) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", type=float, default=5.0)
    ap.add_argument("--materials", default="silicone,polyurethane")
    ap.add_argument("--text", default="")
    ap.add_argument("--level", default="1.6/8")
    ap.add_argument("--reference", default="0.8/8")
    ap.add_argument("--variants", default="1/1,1.5/1,2/1,3/1", help="spot factor k / strip factor s, comma-separated")
    ap.add_argument("--raw", type=Path, required=True)
    ap.add_argument("--out", type=Path, default=HERE / "results" / "spot_scale_t5.md")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    variants = [tuple(float(x) for x in v.split("/")) for v in args.variants.split(",")]
    args.raw.mkdir(parents=True, exist_ok=True)
    if args.one:
        from tactileskin.mesh import sizing

        (h, r), = c3.parse_levels(args.one)
        (k, s), = variants
        sizing.SPOT_FACTOR, sizing.STRIP_FACTOR = k, s
        c3.solve_level(args.thickness, args.materials, args.text, h, r,
                       raw_path(args.raw, args.thickness, args.materials, args.text, h, r, k, s))
        return 0
    (h, r), = c3.parse_levels(args.level)
    (hr, rr), = c3.parse_levels(args.reference)
    materials = args.materials.split(",")
    refs = {m: solve_variant(args, m, hr, rr, 1.0, 1.0) for m in materials}
    rows = {m: [] for m in materials}
    for k, s in variants:  # interleaved: each variant for every material before the next
        for m in materials:
            d = solve_variant(args, m, h, r, k, s)
            rows[m].append(d | compare(d, refs[m]))
    parts = []
    for m in materials:
        key = c3.case_key(args.thickness, m, args.text)
        parts.append(f"## {key}: {h:g} / {r:g} with spot factor k, strip factor s, against "
                     f"{hr:g} / {rr:g}\n\n" + table(rows[m], refs[m]))
        if (h, r) == (hr, rr):
            continue  # the reference is the k = s = 1 variant itself: no second mesh to fit against
        names = [f"{hr:g} / {rr:g}"] + [f"{h:g} / {r:g} k {d['k']:g} s {d['s']:g}" for d in rows[m]]
        parts.append(f"### {key}: every mesh against every other (map L2)\n\n"
                     + map_noise([refs[m]] + rows[m], names))
        print(parts[-1])
    from tactileskin.fileio import atomic_write_text

    head = (f"# Contact-spot size at t = {args.thickness:g} mm (benchmarks/spot_scale_t5.py)\n\n"
            "Local plan (mesh.sizing.local_plan) with the contact-spot size times k and the plate strip "
            "times s; errors against the reference level solved with k = s = 1 (map L2 one skin "
            "thickness off the slab's free end, as benchmarks/convergence3d.py). CPU s: the child's "
            f"time.process_time (mesh + solve). Measured {_dt.date.today().isoformat()} on a shared "
            f"2-core machine ({platform.machine()}, other helpers' solves running).\n\n"
            + ("The reference is the level itself at k = s = 1: the \"errors\" below are how far each "
               "variant moves the plan's results, not errors against a finer mesh.\n\n" if (h, r) == (hr, rr) else ""))
    # a "## Notes" section (the reading of the tables, written by hand) is kept
    old = args.out.read_text(encoding="utf-8") if args.out.exists() else ""
    notes = old[old.index("\n## Notes"):] if "\n## Notes" in old else ""
    atomic_write_text(args.out, head + "\n".join(parts) + notes)
    return 0


if __name__ == "__main__":
    sys.exit(main())
