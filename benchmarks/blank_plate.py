"""The chart's blank Braille plate (array.chart.blank_scene: a flat plate over the whole 20 x 20 mm
pad at the plate's depth, depth - dot height, on mesh_size x refinement 1) against finer meshes:
the error of the maps the chart reads from it, inside its read square (|s|, |z| <=
ChartConfig.read_extent: 7.6 mm on the default chart), for the bone map and the map at the depth a
--sensor-height reads (t - height, map_of). Errors are over the reference map's peak in that
square: the largest pointwise difference (max) and the relative L2 norm over the reference's grid
(the coarse bone map interpolated bilinearly onto it; the maps at depth read both solves at the
same points). The reference is the finest mesh of --meshes. One solve at a time, through the
result cache in --cache (a rerun only reads).

    PYTHONPATH=src .venv/bin/python benchmarks/blank_plate.py --cache /tmp/blank_cache \
        [--thickness 3,5] [--materials silicone,polyurethane] [--meshes 1.2/1,0.8/1,0.6/1,0.6/2] [--height 0.4]

Prints a markdown table (benchmarks/results/blank_plate.md holds a run's); --write writes the
coarsest mesh's errors against the reference, with the next finer mesh's (reference_shift), to
src/tactileskin/data/blank_plate.json, replacing the rows of the materials and thicknesses run
(the rows array.chart.blank_measured reads: there they cover the blank solve's coarse_mesh flag).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import time
from pathlib import Path

import numpy as np


DATA = Path(__file__).resolve().parents[1] / "src" / "tactileskin" / "data" / "blank_plate.json"
ABOUT = ("Measured error of the sensor-array chart's blank Braille plate (array.chart.blank_scene: a flat plate over "
         "the whole pad at depth - dot height, mesh [mesh_size, refinement]) against the finer reference_mesh: the "
         "largest pointwise difference (max_error) and the relative L2 norm (l2_error) over the reference map's peak "
         "inside |s|, |z| <= extent_mm, of the bone map (sensor_height_mm null) or of the map that height above the "
         "bone (P = -tr(sigma) / 3; --sensor-height); reference_shift: the same of the next finer mesh measured against "
         "the reference (its last refinement step, standing for the reference's own error). A row whose max_error "
         "plus the reference's own error estimated from reference_shift (array.chart.reference_error: that step at "
         "the measured order) is within surrogate.TOLERANCE covers the blank solve's coarse_mesh flag for a chart "
         "reading within its extent at that height (array.chart.blank_measured). "
         "Written by benchmarks/blank_plate.py --write.")


def _in_square(m, extent):
    js = np.abs(m.s) <= extent + 1e-9
    jz = np.abs(m.z) <= extent + 1e-9
    return m.s[js], m.z[jz], m.pressure[np.ix_(jz, js)]


def errors(coarse, ref, extent) -> tuple[float, float, float]:
    """(max |coarse - ref| / peak, L2 relative, ref peak MPa) of two BoneMaps on ref's grid
    within the square |s|, |z| <= extent."""
    from scipy.interpolate import RegularGridInterpolator

    s, z, P = _in_square(ref, extent)
    f = RegularGridInterpolator((coarse.z, coarse.s), coarse.pressure, bounds_error=True)
    Z, S = np.meshgrid(z, s, indexing="ij")
    C = f(np.column_stack([Z.ravel(), S.ravel()])).reshape(P.shape)
    peak = float(np.abs(P).max())
    return (float(np.abs(C - P).max() / peak), float(np.linalg.norm(C - P) / np.linalg.norm(P)), peak)


def reference_maps(ref, extent, t, heights):
    """(bone map, at, maps at the heights) of the reference result `ref` in the read square:
    at(rec, h) is a result's map h mm above the bone on the square's modelled quarter (the
    maps are mirrored; a straight pad: s is s)."""
    from tactileskin.array.chart import _at_depth, bone_map_of
    from tactileskin.results import BoneMap

    rb = bone_map_of(ref)
    s, z, _ = _in_square(rb, extent)
    s, z = s[s >= 0], z[z >= 0]

    def at(rec, h):
        return BoneMap(s, z, _at_depth(rec, s, z, t - h)[1])

    return rb, at, {h: at(ref, h) for h in heights}


def main(argv=None) -> int:
    from tactileskin.array.chart import blank_scene, bone_map_of, dot_scene, solve_cached
    from tactileskin.array.config import ChartConfig

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", default="3,5")
    ap.add_argument("--materials", default="silicone,polyurethane")
    ap.add_argument("--meshes", default="1.2/1,0.8/1,0.6/1,0.6/2",
                    help="mesh_size/refinement, the finest last (at least two: the chart's and the reference)")
    ap.add_argument("--heights", default="0.4,1", help="--sensor-height values of the maps at depth (mm)")
    ap.add_argument("--cache", required=True)
    ap.add_argument("--write", action="store_true", help=f"write the first mesh's rows to {DATA.name}")
    ap.add_argument("--data", type=Path, default=DATA, help="the file --write writes (default: the package's)")
    a = ap.parse_args(argv)
    meshes = [tuple(float(v) for v in m.split("/")) for m in a.meshes.split(",")]
    if a.write and len(meshes) < 3:
        ap.error("--write needs three meshes or more: the chart's, the next finer (reference_shift), the reference")
    cfg = ChartConfig(thicknesses=tuple(float(t) for t in a.thickness.split(",")))
    extent = cfg.read_extent
    print(f"Blank plate (flat plate over the whole pad) at the plate's depth; errors inside |s|, |z| <= {extent:g} mm "
          f"over the reference's peak there; reference {meshes[-1][0]:g} / {meshes[-1][1]:g}; at depth: "
          "the sensor height in the table\n")
    heights = [float(h) for h in a.heights.split(",")]
    print("| material | t mm | plate depth mm | mesh | solve wall s | status | bone peak MPa | bone max | bone L2 | "
          + " | ".join(f"h {h:g}: peak MPa | max | L2" for h in heights) + " |")
    print("|---" * (9 + 3 * len(heights)) + "|")
    rows = []
    for material in a.materials.split(","):
        for t in cfg.thicknesses:
            blank = blank_scene(dot_scene(t, material, cfg))
            recs, secs = {}, {}
            for m in meshes:
                sc = blank.replace(mesh_size=m[0], refinement=m[1])
                t0 = time.perf_counter()
                recs[m] = solve_cached([sc], a.cache, workers=1)[sc]
                secs[m] = time.perf_counter() - t0
            ref = recs[meshes[-1]]
            rb, at, rd = reference_maps(ref, extent, t, heights)
            for m in meshes:
                eb = errors(bone_map_of(recs[m]), rb, extent)
                ed = [errors(at(recs[m], h), rd[h], extent) for h in heights]
                status = str(recs[m].summary.get("status", "ok")).split(":")[0]
                print(f"| {material} | {t:g} | {float(blank.indentation):.3g} | {m[0]:g} / {m[1]:g} | {float(recs[m].summary.get('wall_s', secs[m])):.0f} "
                      f"| {status} | {eb[2]:.4g} | {eb[0]:.2%} | {eb[1]:.2%} | "
                      + " | ".join(f"{e[2]:.4g} | {e[0]:.2%} | {e[1]:.2%}" for e in ed) + " |", flush=True)
                if m == meshes[0]:
                    shift = ([errors(bone_map_of(recs[meshes[-2]]), rb, extent)]
                             + [errors(at(recs[meshes[-2]], h), rd[h], extent) for h in heights])
                    rows += [{"material": material, "skin": "pad", "thickness_mm": t, "depth_mm": float(blank.indentation),
                              "mesh": list(m), "pad_mm": [blank.pad_width, blank.pad_length], "rate": blank.rate,
                              "extent_mm": extent, "sensor_height_mm": h, "max_error": round(e[0], 4),
                              "l2_error": round(e[1], 4), "reference_mesh": list(meshes[-1]),
                              "reference_shift": round(sh[0], 4), "shift_mesh": list(meshes[-2]),
                              "source": f"benchmarks/blank_plate.py, {_dt.date.today().isoformat()}"}
                             for h, e, sh in zip([None, *heights], [eb, *ed], shift)]
    if a.write:
        from tactileskin.fileio import atomic_write_text

        # the rows of the materials and thicknesses measured here replace theirs; the others stay
        done = {(r["material"], r["thickness_mm"]) for r in rows}
        kept = [r for r in json.loads(a.data.read_text(encoding="utf-8"))["cases"]
                if (r["material"], r["thickness_mm"]) not in done] if a.data.exists() else []
        atomic_write_text(a.data, json.dumps({"about": ABOUT, "cases": kept + rows}, indent=2, ensure_ascii=False) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
