"""The chart's blank Braille plate (array.chart.blank_scene: a flat plate over the whole 20 x 20 mm
pad) by pad size: does the pad's bonded edge, where quality flags its peak at t = 5 mm (edge_peak),
reach into the square the chart reads (|s|, |z| <= ChartConfig.read_extent: 7.6 mm)? The same
blank is solved on larger pads (the plate, a half-space, still presses the whole top) and each
pad's maps, as the chart reads them (the bone map and the maps --sensor-height reads:
blank_plate.errors), are compared inside that square with the largest pad's on the same mesh: the
largest pointwise difference (max) and the relative L2 norm, over the largest pad's peak there;
with the plate's force and its mean pressure (force / pad area). One solve at a time, through the
result cache in --cache (a rerun only reads).

    PYTHONPATH=src .venv/bin/python benchmarks/blank_pad_length.py --cache /tmp/blank_cache \
        [--thickness 5] [--materials silicone,polyurethane] [--pads 20x20,20x40,30x30,40x40] \
        [--meshes 1.2/1] [--heights 0.4,1]

Prints a markdown table (benchmarks/results/blank_pad_length.md holds runs of it).
"""

from __future__ import annotations

import argparse
import time

from blank_plate import _in_square, errors, reference_maps


def _pads(text: str) -> list[tuple[float, float]]:
    return [tuple(float(v) for v in p.split("x")) for p in text.split(",")]


def main(argv=None) -> int:
    from tactileskin.array.chart import blank_scene, bone_map_of, dot_scene, solve_cached
    from tactileskin.array.config import ChartConfig

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", default="5")
    ap.add_argument("--materials", default="silicone,polyurethane")
    ap.add_argument("--pads", default="20x20,20x40,30x30,40x40", help="width x length (mm), the reference last")
    ap.add_argument("--meshes", default="1.2/1", help="mesh_size/refinement")
    ap.add_argument("--heights", default="0.4,1", help="--sensor-height values of the maps at depth (mm)")
    ap.add_argument("--cache", required=True)
    a = ap.parse_args(argv)
    pads = _pads(a.pads)
    meshes = [tuple(float(v) for v in m.split("/")) for m in a.meshes.split(",")]
    heights = [float(h) for h in a.heights.split(",")]
    cfg = ChartConfig(thicknesses=tuple(float(t) for t in a.thickness.split(",")))
    extent = cfg.read_extent
    print(f"Blank plate by pad size; errors inside |s|, |z| <= {extent:g} mm against the pad "
          f"{pads[-1][0]:g} x {pads[-1][1]:g} mm on the same mesh, over its peak there; bone peak: each pad's own "
          "bone map's peak there\n")
    print("| material | t mm | mesh | pad mm | solve wall s | flags | force N | mean MPa | bone peak MPa | bone max | bone L2 | "
          + " | ".join(f"h {h:g}: max | L2" for h in heights) + " |")
    print("|---" * (11 + 2 * len(heights)) + "|")
    for material in a.materials.split(","):
        for t in cfg.thicknesses:
            base = blank_scene(dot_scene(t, material, cfg))
            for m in meshes:
                recs, secs = {}, {}
                for p in pads:
                    sc = base.replace(mesh_size=m[0], refinement=m[1], pad_width=p[0], pad_length=p[1])
                    t0 = time.perf_counter()
                    recs[p] = solve_cached([sc], a.cache, workers=1)[sc]
                    secs[p] = time.perf_counter() - t0
                ref = recs[pads[-1]]
                rb, at, rd = reference_maps(ref, extent, t, heights)
                for p in pads:
                    sm = recs[p].summary
                    own = bone_map_of(recs[p])
                    eb = errors(own, rb, extent)
                    ed = [errors(at(recs[p], h), rd[h], extent) for h in heights]
                    flags = str(sm.get("status", "ok")).split(":")[0]
                    codes = _codes(sm)
                    print(f"| {material} | {t:g} | {m[0]:g} / {m[1]:g} | {p[0]:g} x {p[1]:g} | "
                          f"{float(sm.get('wall_s', secs[p])):.0f} | {flags} ({', '.join(codes) or '-'}) | "
                          f"{float(sm['reaction_n']):.4g} | {float(sm['reaction_n']) / (p[0] * p[1]):.4f} | "
                          f"{float(abs(_in_square(own, extent)[2]).max()):.4g} | {eb[0]:.2%} | {eb[1]:.2%} | "
                          + " | ".join(f"{e[0]:.2%} | {e[1]:.2%}" for e in ed) + " |", flush=True)
    return 0


def _codes(summary: dict) -> list[str]:
    from tactileskin import quality

    return [f.code for f in quality.flags(summary)]


if __name__ == "__main__":
    raise SystemExit(main())
