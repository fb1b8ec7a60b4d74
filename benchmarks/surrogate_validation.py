"""The letters' surrogates against full 3D solves: the rows of data/surrogate_validation.json.

For each material, `array.chart.validate_surrogate` on the default chart (pad 20 x 20 mm, mesh
ChartConfig.mesh_for: 0.8 / 8 below t = 3 mm, 1.2 / 8 from it; --mesh one for all; the default pitches and window, so its read square; depth cap --max-depth) solves
the texts in full (through the result cache in --cache: a rerun only reads) and compares them
with every model. Prints the table (markdown) and, with --write, replaces the JSON's rows of
the "interaction" and "sum" models for (material, pad, mesh; --mesh another chart mesh) with these measurements (source:
this script, today's date). --reference-mesh solves the texts in full on a finer mesh than the
chart's (the rows say so; array.validity judges a chart by the finest reference measured).
Wall time from the start; the solves run on --workers processes.

    PYTHONPATH=src .venv/bin/python benchmarks/surrogate_validation.py --materials silicone,polyurethane \
        --thickness 0.5,1,2,3,5 --texts '⠿,l' --max-depth 0.4 --cache /tmp/val_cache [--write]
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "src" / "tactileskin" / "data" / "surrogate_validation.json"
MODELS = ("interaction", "sum", "plate + sum")  # the models a chart uses (validity.measured)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--materials", default="silicone,polyurethane")
    ap.add_argument("--thickness", default="0.5,1,2,3,5")
    ap.add_argument("--texts", default="⠿,l")
    ap.add_argument("--max-depth", type=lambda v: None if v.lower() == "none" else float(v), default=0.4,
                    help="depth cap (mm); 'none': the paper's 20 %% of t (the plate touches from t = 2.4 mm)")
    ap.add_argument("--cache", required=True)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--mesh", default=None,
                    help="mesh_size,refinement of the chart (its single dots and the rows' case); default the chart's")
    ap.add_argument("--reference-mesh", default=None,
                    help="mesh_size,refinement of the full solves (finer than the chart's); default the chart's")
    ap.add_argument("--write", action="store_true", help="replace the JSON rows of these measurements")
    a = ap.parse_args(argv)

    from tactileskin.array.chart import ChartConfig, validate_surrogate
    from tactileskin.cache import ResultCache
    from tactileskin.fileio import atomic_write_text
    from tactileskin.report.array_chart import validation_table

    t0 = time.perf_counter()
    ts = [float(x) for x in a.thickness.split(",")]
    mesh = {} if a.mesh is None else dict(zip(("mesh_size", "refinement"), (float(x) for x in a.mesh.split(","))))
    cfg = ChartConfig(thicknesses=tuple(ts), max_depth=a.max_depth, **mesh)
    cache = ResultCache(Path(a.cache))
    ref = None if a.reference_mesh is None else tuple(float(x) for x in a.reference_mesh.split(","))
    rows = {m: validate_surrogate(ts, m, a.texts.split(","), cfg, cache, progress=print, workers=a.workers,
                                  reference_mesh=ref)
            for m in a.materials.split(",")}
    wall = time.perf_counter() - t0
    for m, rs in rows.items():
        print("\n".join(validation_table(rs, f"### {m}: read square |s|, |z| <= {cfg.read_extent:g} mm")))
    print(f"wall {wall:.0f} s")
    if not a.write:
        return 0
    data = json.loads(DATA.read_text(encoding="utf-8"))
    source = f"benchmarks/surrogate_validation.py ({_dt.date.today().isoformat()})"
    for (m, mesh), rs in _by_case(rows, cfg).items():
        case = next((c for c in data["cases"] if c["material"] == m and c["skin"] == cfg.skin
                     and c["mesh"] == list(mesh)), None)
        if case is None:
            case = {"material": m, "skin": cfg.skin, "mesh": list(mesh), "rows": []}
            data["cases"].append(case)
        new = [{"thickness_mm": r["thickness_mm"], "depth_mm": round(r["depth_mm"], 9), "text": r["text"],
                "model": r["model"], "taxel_max_error": round(r["max_abs_over_peak_taxel"], 4),
                "extent_mm": r["extent_mm"], "reference_mesh": r["reference_mesh"],
                "taxel_mm": r["taxel_mm"], "source": source}
               for r in rs if r["model"] in MODELS]

        def key(r):
            return (r["thickness_mm"], r["depth_mm"], r["text"], r.get("model", "sum"),
                    tuple(r.get("reference_mesh") or case["mesh"]))

        measured = {key(r) for r in new}
        case["rows"] = [r for r in case["rows"] if key(r) not in measured] + new
    atomic_write_text(DATA, json.dumps(data, indent=2) + "\n")
    print(f"wrote {DATA}")
    return 0


def _by_case(rows: dict, cfg) -> dict:
    """{(material, (mesh_size, refinement) of the chart at the row's thickness): rows}: the
    JSON's cases are keyed by the chart's mesh, which ChartConfig.mesh_for sets per thickness."""
    out: dict = {}
    for m, rs in rows.items():
        for r in rs:
            out.setdefault((m, cfg.mesh_for(r["thickness_mm"])), []).append(r)
    return out


if __name__ == "__main__":
    sys.exit(main())
