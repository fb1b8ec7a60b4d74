"""Plane strain against the cast sample: flat and curved indenters on the finite 3D block (issue 13).

The paper's experiments pressed cast blocks of finite length (the project's CAD: the
20 mm `sample_length` of data/geometry/fingertip.toml), ends free as cast, while its model
(and tactileskin's 2D solver) is plane strain: an infinitely long finger. This benchmark
solves each flat / curved case on the 3D sample (quarter model: x >= 0, z >= 0, the end
z = +L/2 free) and in 2D plane strain, and reports how much plane strain over- or
understates
- the peak bone pressure and the span (P >= 10 % of the peak) on the mid-plane z = 0 (where
  a film strip across the sample would read), and
- the peak of the bone map away from the bonded skin's edges (BoneMap.interior_peak with a
  margin of one skin thickness: Result.summary()['peak_map_mpa']), the map's larger value at
  an edge apart (the free end's corner singularity: peak_map_edge_mpa), and the span of the
  profile max_z P(s, z).

Two 3D mesh levels per case (the 3D `preview` and `default` presets by default, or
--levels) bound the 3D discretisation error: the table gives both and their difference.
The 2D answer is at the 2D `default` preset (peak within 0.4 % of mesh-converged,
docs/speed_vs_error.md). Each solve runs in its own subprocess, one at a time, and its
numbers are kept in benchmarks/results/raw_sample3d/ so a rerun resumes.

    .venv/bin/python benchmarks/sample3d.py [--thickness 1 3 5] [--indenter flat curved]
        [--material silicone polyurethane] [--levels 0.85/2,0.6/2] [--limit 1800] [--cached]

--cached solves nothing: it writes the table of the cases already in the raw folder (e.g.
after runs of different thickness lists per material).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RAW = ROOT / "benchmarks" / "results" / "raw_sample3d"
OUT = ROOT / "benchmarks" / "results" / "sample3d.md"


def case_name(t: float, indenter: str, material: str, dim: int, level: str) -> str:
    return f"t{t:g}-{material}-{indenter}-{dim}d-{level.replace('/', '_')}"


def solve_one(t: float, indenter: str, material: str, dim: int, level: str, out: Path) -> None:
    """Solve one case and write its numbers (JSON) to `out`."""
    from tactileskin import results
    from tactileskin.fe import solve
    from tactileskin.fileio import atomic_write_json
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    scene = Scene(thickness=t, indenter=indenter, material=material, dim=dim)
    if "/" in level:
        h, r = (float(v) for v in level.split("/"))
        scene = scene.replace(mesh_size=h, refinement=r)
    else:
        scene = with_quality(scene, level)
    c0, w0 = time.process_time(), time.perf_counter()
    res = solve(scene)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    summary = res.summary()
    row = {"thickness": t, "indenter": indenter, "material": material, "dim": dim, "level": level,
           "mesh_size": scene.mesh_size, "refinement": scene.refinement,
           "dofs": int(res.stats["dofs"]), "cpu_s": cpu, "wall_s": wall,
           "maxrss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
           "increments": int(res.stats.get("increments", 0)),
           "newton_iterations": int(res.stats.get("newton_iterations", 0)),
           "status": summary.get("status"),
           "peak": float(res.peak), "span": float(res.span),
           "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")}
    if dim == 3:
        bm = res.bone_map
        s, pmax, _ = bm.max_over_z()
        mpk, ms, mz = bm.peak()
        # the interior peak (margin: the skin thickness), as Result.summary() reports it; the
        # whole map's peak apart (at the free end's corner: grows with refinement)
        row.update(map_peak=summary["peak_map_mpa"], map_peak_s=summary["peak_map_s_mm"],
                   map_peak_z=summary["peak_map_z_mm"], map_edge_peak=mpk, map_edge_peak_s=ms,
                   map_edge_peak_z=mz, map_span=float(results.span(s, pmax)), z_extent=float(bm.z.max()))
    atomic_write_json(out, row)


def run_case(t, indenter, material, dim, level, limit, force=False, cached=False) -> dict:
    path = RAW / (case_name(t, indenter, material, dim, level) + ".json")
    if cached and not path.exists():
        return {"error": "not run"}
    if force or not path.exists():
        RAW.mkdir(parents=True, exist_ok=True)
        cmd = [sys.executable, __file__, "--one", "--thickness", f"{t:g}", "--indenter", indenter,
               "--material", material, "--dim", str(dim), "--levels", level]
        print(f"[{time.strftime('%H:%M:%S')}] {case_name(t, indenter, material, dim, level)} ...", flush=True)
        try:
            subprocess.run(cmd, check=True, timeout=limit, env=dict(os.environ, PYTHONPATH=str(ROOT / "src")))
        except subprocess.TimeoutExpired:
            return {"error": f"stopped at the {limit:g} s limit"}
        except subprocess.CalledProcessError as e:
            return {"error": f"exit {e.returncode}"}
    return json.loads(path.read_text(encoding="utf-8"))


def rel(a: float, b: float) -> str:
    return f"{(a - b) / b:+.1%}"


def edge(three: dict) -> str:
    # the whole map's peak where it exceeds the interior one (a corner singularity), else '-'
    pe = three.get("map_edge_peak")
    if pe is None or pe <= three["map_peak"]:
        return "-"
    return f"{pe:.4f} (z = {three['map_edge_peak_z']:.1f})"


def table(rows: list[dict], levels: list[str]) -> str:
    head = ("| t mm | material | indenter | 3D level | dofs | CPU s | incr. / Newton | 2D peak MPa | "
            "3D peak z=0 | 2D vs 3D peak | 3D map peak (>= t from edges) | 3D map edge peak | "
            "2D span mm | 3D span z=0 | 2D vs 3D span | "
            "3D max-z span |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        two = r["2d"]
        for lv in levels:
            three = r["3d"].get(lv, {})
            if "error" in two or "error" in three or not three:
                lines.append(f"| {r['t']:g} | {r['material']} | {r['indenter']} | {lv} | - | - | - | "
                             f"{two.get('error', '')} | {three.get('error', 'not run')} | | | | | | | |")
                continue
            lines.append(
                f"| {r['t']:g} | {r['material']} | {r['indenter']} | {lv} | {three['dofs']:,} | "
                f"{three['cpu_s']:.0f} | {three['increments']} / {three['newton_iterations']} | "
                f"{two['peak']:.4f} | {three['peak']:.4f} | {rel(two['peak'], three['peak'])} | "
                f"{three['map_peak']:.4f} | {edge(three)} | {two['span']:.3f} | {three['span']:.3f} | "
                f"{rel(two['span'], three['span'])} | {three['map_span']:.3f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", type=float, nargs="+", default=[1.0, 3.0, 5.0])
    ap.add_argument("--indenter", nargs="+", default=["flat", "curved"])
    ap.add_argument("--material", nargs="+", default=["silicone"])
    ap.add_argument("--levels", default="preview,default",
                    help="3D levels: quality preset names or mesh_size/refinement, comma-separated")
    ap.add_argument("--dim", type=int, default=3)
    ap.add_argument("--limit", type=float, default=1800.0, help="wall-time limit per solve (s)")
    ap.add_argument("--force", action="store_true", help="re-solve cases already in the raw folder")
    ap.add_argument("--cached", action="store_true",
                    help="solve nothing; tabulate the cases already in the raw folder")
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--out", type=Path, default=OUT)
    a = ap.parse_args(argv)
    levels = [v.strip() for v in a.levels.split(",") if v.strip()]
    if a.one:
        t, ind, mat, lv = a.thickness[0], a.indenter[0], a.material[0], levels[0]
        solve_one(t, ind, mat, a.dim, lv, RAW / (case_name(t, ind, mat, a.dim, lv) + ".json"))
        return 0

    rows = []
    for mat in a.material:
        for t in a.thickness:
            for ind in a.indenter:
                two = run_case(t, ind, mat, 2, "default", a.limit, a.force, a.cached)
                three = {lv: run_case(t, ind, mat, 3, lv, a.limit, a.force, a.cached) for lv in levels}
                if a.cached and all(c.get("error") == "not run" for c in [two, *three.values()]):
                    continue
                rows.append({"t": t, "material": mat, "indenter": ind, "2d": two, "3d": three})
                print("\n".join(table(rows[-1:], levels).splitlines()[2:]), flush=True)

    from tactileskin.fileio import atomic_write_text

    text = (a.out.read_text(encoding="utf-8").split("\n## Results")[0] if a.out.exists() else
            "# Plane strain against the cast sample (benchmarks/sample3d.py)\n")
    md = (text.rstrip() + "\n\n## Results\n\n" + table(rows, levels) + "\n\n"
          f"2D: plane strain at the `default` preset. 3D: the 20 mm cast sample (quarter model, end free), "
          f"levels {', '.join(levels)}; peaks and spans on the mid-plane z = 0 and of max over z of the bone "
          f"map; map peak: at least one skin thickness t from the bonded skin's edges (Result.summary() "
          f"peak_map_mpa), edge peak: the whole map's maximum where larger, at the free end z = 10 mm "
          f"(corner singularity, not mesh-converged). 'vs' = (2D - 3D) / 3D. CPU s: time.process_time of "
          f"the solve's process. Measured "
          f"{_dt.date.today().isoformat()} on a shared 2-core machine.\n")
    atomic_write_text(a.out, md)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
