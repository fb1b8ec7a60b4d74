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


def study_errors(level: dict, ref: dict, case: dict) -> dict:
    """Errors of a level against the convergence study's references (presets.json "cases3d":
    Richardson limits or the finest level, convergence3d.analyse), from `ref`, a solve of the
    study's finest level: each reference is ref's value / (1 + the finest level's stored error).
    The map L2 is against `ref` (the study measures maps against its finest level)."""
    finest = case["levels"][-1]
    if (finest["mesh_size"], finest["refinement"]) != (ref["mesh_size"], ref["refinement"]):
        raise ValueError("--reference must be the study's finest level")

    def err(value, ref_value, stored):
        return value / (ref_value / (1.0 + stored)) - 1.0

    t = float(ref["thickness"])
    return {"peak_error": err(level["peak"], ref["peak"], finest["peak_error"]),
            "span_error": err(level["span"], ref["span"], finest["span_error"]),
            "map_peak_error": err(c3.interior_map_peak(level), c3.interior_map_peak(ref), finest["map_peak_error"]),
            "map_l2": c3.map_l2([level["map"], ref["map"]], ref_index=1, grid_index=0, z_margin=t)[0]}


def store_level(path: Path, key: str, level: dict, k: float) -> dict:
    """Put a variant level (strip factor 1) into presets.json "cases3d"[key] with its errors
    against the study's references (study_errors) and "spot_factor" k, in dofs order, in place
    of a stored level of the same sizes and factor. Returns the stored record."""
    from tactileskin.fileio import atomic_write_json
    from tactileskin.presets import SCALE_BEFORE_RECORDS

    data = json.loads(path.read_text(encoding="utf-8"))
    case = data["cases3d"][key]
    rec = {"mesh_size": level["mesh_size"], "refinement": level["refinement"], "dofs": level["dofs"],
           **{e: round(level[e], 6) for e in ("peak_error", "map_l2", "span_error", "map_peak_error")},
           "cpu_s": round(level["cpu_s"], 1), "maxrss_mb": round(level["maxrss_mb"]),
           "bone_scale": level["bone_scale"], "spot_factor": k}

    def same(v):
        return ((v["mesh_size"], v["refinement"]) == (rec["mesh_size"], rec["refinement"])
                and v.get("spot_factor", SCALE_BEFORE_RECORDS["spot_factor"]) == k)

    case["levels"] = sorted([v for v in case["levels"] if not same(v)] + [rec], key=lambda v: v["dofs"])
    atomic_write_json(path, data)
    return rec


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
    ap.add_argument("--store", type=Path, help="presets.json: store each variant with s = 1 and k != 1 as a "
                    "level of the study's case, errors against the study's references (--reference: its finest level)")
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
    if args.store:
        for m in materials:
            key = c3.case_key(args.thickness, m, args.text)
            case = json.loads(args.store.read_text(encoding="utf-8"))["cases3d"][key]
            for d in rows[m]:
                e = study_errors(d, refs[m], case)
                if d["s"] == 1.0 and d["k"] != 1.0:
                    print(key, "stored", store_level(args.store, key, d | e, d["k"]))
                else:  # the study's own level again: how far the re-solved reference moves its errors
                    print(key, f"k {d['k']:g} s {d['s']:g} against the study:",
                          {n: f"{v:+.4%}" for n, v in e.items()})
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
