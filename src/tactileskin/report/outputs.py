"""Turn sweep outcomes into results.csv, profiles.csv, figures, renders and report.md."""

from __future__ import annotations

import csv
import hashlib
import io
import logging
import re
from pathlib import Path

from tactileskin import quality
from tactileskin.fileio import atomic_write_text, make_dirs
from tactileskin.results import without_status
from tactileskin.staging import staged_files

log = logging.getLogger(__name__)

RESULT_COLUMNS = ["case", "key", "status", "thickness_mm", "material", "indenter", "braille_text",
                  "depth_mm", "rate_mm_s", "target_force_n_per_mm", "target_force_n", "peak_mpa", "span_mm", "auc_mpa_mm", "reaction_n_per_mm", "reaction_n",
                  "min_J", "max_abs_stress_mpa",
                  "dofs", "increments", "newton_iterations", "wall_s", "error"]
# the columns that hold numbers (MPa, mm, N, s) whether or not a row has one: a 2D sweep's
# reaction_n, the target forces without force control, a failed case's metrics
FLOAT_COLUMNS = ("depth_mm", "target_force_n_per_mm", "target_force_n", "peak_mpa", "span_mm", "auc_mpa_mm", "reaction_n_per_mm",
                 "reaction_n", "min_J", "max_abs_stress_mpa", "wall_s")


def collect(outcomes, cache):
    """(records, rows, failures) from run_sweep outcomes. Rows and records carry the case id
    (sweep.case_ids), unique within the sweep. A cached record was validated by the cache
    (finite metrics and profile), which is the gate against damaged entries."""
    from tactileskin.report.markdown import at_paper_conditions
    from tactileskin.scene import material_labels
    from tactileskin.sweep import case_ids, case_variant_labels, case_variants

    scenes = [oc.scene for oc in outcomes]
    ids, variants, labels = case_ids(scenes), case_variants(scenes), case_variant_labels(scenes)
    # a material file by its stem in every table and figure (not its path: the user's folders)
    mat_label = material_labels(sc.material for sc in scenes)
    records, rows, failures = [], [], []
    for oc, case, variant, vlabel in zip(outcomes, ids, variants, labels):
        sc = oc.scene
        # the key the sweep computed (its entry's name), not the files' as they are now
        row = dict(case=case, variant=variant, variant_label=vlabel, paper=at_paper_conditions(sc), key=oc.key or cache.key(sc),
                   thickness_mm=sc.thickness, material=mat_label[sc.material],
                   indenter=sc.indenter.value, braille_text=sc.braille_text, depth_mm=sc.indentation,
                   rate_mm_s=sc.rate, dim=sc.dim)
        if sc.force is not None:  # force control: the force asked for (the reaction columns hold what it reached)
            row["target_force_n" if sc.dim == 3 else "target_force_n_per_mm"] = sc.force
        # solved by this run, or read from the cache (a rerun's report told them apart nowhere)
        row["source"] = {"cached": "cached", "done": "solved"}.get(oc.status, "failed")
        if oc.status == "failed":
            row.update(status=quality.failed_status(oc.error), error=oc.error)
            if sc.force is not None:  # the depth is the solve's output: none without one (not 0.2 t)
                row["depth_mm"] = None
            failures.append(oc)
        else:
            rec = oc.record if oc.record is not None else cache.load(sc)
            rec.case, rec.variant, rec.variant_label = case, variant, vlabel
            rec.material_label = mat_label[sc.material]
            records.append(rec)
            # recomputed from the numbers (not the stored string): the ranges are quality's
            row.update(status=quality.status(rec.summary), **{k: rec.summary.get(k) for k in
                                       ("peak_mpa", "span_mm", "auc_mpa_mm", "reaction_n_per_mm", "reaction_n", "min_J",
                                        "max_abs_stress_mpa", "dofs", "increments",
                                        "newton_iterations", "wall_s")})
            lo = rec.summary.get("loading")
            if lo:  # force control / a history: the travel of the reported (peak-load) state
                row["depth_mm"] = lo.get("profile_travel_mm", row["depth_mm"])
        rows.append(row)
    return records, rows, failures


PROFILE_COLUMNS = ["case", "status", "s_mm", "pressure_mpa"]


def profile_rows(records):
    """(case, status, s_mm, pressure_mpa) of every profile point, in long form; the status is
    results.csv's, on every row (a suspect case's profile read like an ok one's)."""
    for rec in records:
        status = quality.status(rec.summary)
        for s, p in zip(rec.s, rec.pressure):
            yield rec.case, status, float(s), float(p)


def _write_parquet(path: Path, columns: list[str], rows) -> None:
    """A Parquet table (pyarrow) of `rows`, written atomically; the columns keep their types."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from tactileskin.fileio import atomic_path, os_errors
    from tactileskin.report.arrow import column

    data = {c: [r[i] if isinstance(r, tuple) else r.get(c) for r in rows] for i, c in enumerate(columns)}
    # typed as the DataFrame of ts.sweep: a column no row filled was written as type null
    # (pandas: object of None), one a row filled as double
    types = {**dict.fromkeys(FLOAT_COLUMNS + ("s_mm", "pressure_mpa"), pa.float64()), "error": pa.string()}
    # arrow.column: pa.array's arrays without its import of pandas (~0.2 s CPU of the sweep)
    table = pa.table({c: column(v, type=types.get(c)) for c, v in data.items()})
    with atomic_path(path) as tmp, os_errors(path):
        pq.write_table(table, tmp)


# the files a sweep writes into its folder (fnmatch patterns; fig9_: one render per material)
SWEEP_FILES = ("results.csv", "profiles.csv", "results.parquet", "profiles.parquet", "report.md", "sensors.csv",
               *(f"{stem}.{ext}" for stem in ("metrics_vs_thickness", "fig10_profiles", "fig11_peak", "fig12_span",
                                              "fig13_auc") for ext in ("png", "svg")),
               "metrics_vs_thickness.pdf", "fig9_*.png")
# the ones every sweep writes, failed cases or not (checked before solving: cli.sweep)
SWEEP_ALWAYS_WRITTEN = ("results.csv", "profiles.csv", "results.parquet", "profiles.parquet", "report.md")


def write_outputs(out: Path, outcomes, cache, wall_s: float, *, render: bool = True,
                  figures: bool = True) -> dict:
    """The sweep's tables, figures and report in `out` (claimed by the caller: claim_dir),
    staged and moved in together (report.md last): a failed write leaves the earlier outputs
    as they were, and figures of an earlier sweep this one has not are removed."""
    out = make_dirs(out)
    with staged_files(out, SWEEP_FILES, last="report.md") as tmp:
        res = _write_outputs(tmp, outcomes, cache, wall_s, render=render, figures=figures)
    for k in ("results", "profiles", "report"):
        res[k] = out / res[k].name
    res["figures"] = [out / p.name for p in res["figures"]]
    res["renders"] = [out / p.name for p in res["renders"]]
    return res


def _write_sensors(path: Path, records) -> None:
    """sensors.csv of the sweep: every case's sensor readings (the cache entry's sensors.csv)
    with the case id and its status (results.csv's) in front; not written when no case has sensors."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    header = None
    for rec in records:
        f = rec.path / "sensors.csv"
        if not f.is_file():
            continue
        rows = list(csv.reader(io.StringIO(f.read_text(encoding="utf-8"))))
        if not rows:
            continue
        if without_status(rows[0]) != rows[0]:  # the solve's own status column: the sweep puts its own in front
            rows = [r[:-1] for r in rows]
        if header is None:
            header = rows[0]
            w.writerow(["case", "status"] + header)
        elif rows[0] != header:  # one writer (sensors.SensorReadings) made every file
            log.warning("sensors.csv of %s has other columns; left out of the sweep's sensors.csv", rec.case)
            continue
        # a suspect case's readings were listed like an ok case's: its status on every row
        status = quality.status(rec.summary)
        w.writerows([rec.case, status] + r for r in rows[1:])
    if header is not None:
        atomic_write_text(path, out.getvalue())


# figure_jobs drawn in a second process: the first two (the designer's figure in three
# formats and Fig. 10, about half the drawing time of a paper sweep) while this one draws the
# rest, the renders and writes the tables
BACKGROUND_JOBS = 2


def _figures(records, rows, out: Path, cache, meanwhile=lambda: None) -> list[Path]:
    """figure_jobs into `out`, and meanwhile() (the tables and renders) while they are drawn; their files
    are kept in the cache under their inputs' digest (figures.figures_key), and a sweep whose
    figures are there already (a cached rerun) writes those bytes instead of drawing them
    again. An entry whose bytes changed is not used."""
    from tactileskin.errors import TactileSkinError
    from tactileskin.fileio import atomic_write_bytes
    from tactileskin.report.background import Background
    from tactileskin.report.figures import _plt, figure_jobs, figures_key

    name = f"figures-{figures_key(records, rows)}"
    kept = cache.load_files(name)
    if kept is not None:
        paths = [atomic_write_bytes(out / fname, data) for fname, data in kept]
        meanwhile()
        return paths
    jobs = figure_jobs(records, rows)
    if not jobs:
        meanwhile()
        return []
    there, here = jobs[:BACKGROUND_JOBS], jobs[BACKGROUND_JOBS:]
    make_dirs(out)
    _plt()  # imported before the fork: the child needs no import of its own
    # drawn here (no child, or it failed) straight into `out`, as in one process
    with Background(lambda folder: [p for job in there for p in job(folder)], here=out) as bg:
        mine = [p for job in here for p in job(out)]
        meanwhile()
        paths = [atomic_write_bytes(out / fname, data) for fname, data in bg.files()] + mine
    if paths:
        try:
            cache.store_files(name, paths)
        except (TactileSkinError, OSError) as e:  # the figures are written; only the copy is lost
            log.warning("the figures were not kept in the cache %s: %s", cache.root, e)
    return paths


def _render(render_case, vtu: Path, png: Path, rec, cache) -> Path:
    """render_case of a case into `png`; a 2D render (matplotlib, the same bytes for the same
    inputs) is kept in the cache under the digest of its result.vtu, scene, title and file
    name (figures.drawing_digest for the rest) and copied on a rerun instead of drawn."""
    import hashlib
    import json

    from tactileskin.errors import TactileSkinError
    from tactileskin.fileio import atomic_write_bytes, file_sha256
    from tactileskin.report.figures import drawing_digest

    # force control, a history: the indenter where the result's state has it, not at the
    # scene's nominal depth (drawn 0.2 mm deep on a skin pressed 0.056 mm)
    depth = (rec.summary.get("loading") or {}).get("profile_travel_mm")
    if rec.scene.dim != 2:  # pyvista's off-screen render: not known to repeat its bytes
        return render_case(vtu, png, title=rec.case, scene=rec.scene, depth=depth)
    payload = [drawing_digest(), file_sha256(vtu), rec.scene.to_dict(), rec.case, png.name, depth]
    name = "render-" + hashlib.sha256(json.dumps(payload, sort_keys=True, default=repr).encode()).hexdigest()[:24]
    kept = cache.load_files(name)
    if kept is not None and [f for f, _ in kept] == [png.name]:
        return atomic_write_bytes(png, kept[0][1])
    path = render_case(vtu, png, title=rec.case, scene=rec.scene, depth=depth)
    try:
        cache.store_files(name, [path])
    except (TactileSkinError, OSError) as e:  # the render is written; only the copy is lost
        log.warning("the render %s was not kept in the cache %s: %s", png.name, cache.root, e)
    return path


def _renders(records, out: Path, cache) -> list[Path]:
    """One Fig. 9A-style render per material at the thinnest skin, flat plate; a suspect case
    (no contact, the law out of its range) is not shown as a result."""
    from tactileskin.report.render import render_case

    shown = [r for r in records if quality.status(r.summary) == "ok"]
    renders, thinnest, used = [], {}, set()
    for r in shown:
        m = r.scene.material
        thinnest[m] = min(thinnest.get(m, r.scene.thickness), r.scene.thickness)
    for rec in shown:
        sc = rec.scene
        vtu = rec.path / "result.vtu"
        if sc.indenter.value == "flat" and sc.thickness == thinnest[sc.material] and vtu.is_file():
            try:
                name = re.sub(r"[^A-Za-z0-9._=,\[\]-]", "_", rec.case)
                if name in used:  # two case ids made alike by the substitution ('gel-ä', 'gel-ö')
                    name += "-" + hashlib.sha256(rec.case.encode()).hexdigest()[:8]
                used.add(name)
                renders.append(_render(render_case, vtu, out / f"fig9_{name}.png", rec, cache))
            except Exception as e:  # noqa: BLE001 - a render failure must not lose the report
                log.warning("render of %s failed: %s", rec.case, e)
    return renders


def _write_tables(out: Path, rows, records) -> None:
    """results.csv / .parquet, profiles.csv / .parquet and sensors.csv into `out`."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=RESULT_COLUMNS + ["dim", "variant"], extrasaction="ignore")
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(out / "results.csv", buf.getvalue())
    _write_parquet(out / "results.parquet", RESULT_COLUMNS + ["dim", "variant"], rows)

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")  # quoted where needed: a case id can hold a comma (braille[,a,])
    w.writerow(PROFILE_COLUMNS)
    prof = list(profile_rows(records))
    w.writerows((case, status, f"{s:.6g}", f"{p:.6g}") for case, status, s, p in prof)
    atomic_write_text(out / "profiles.csv", buf.getvalue())
    _write_parquet(out / "profiles.parquet", PROFILE_COLUMNS, prof)

    _write_sensors(out / "sensors.csv", records)


def _write_outputs(out: Path, outcomes, cache, wall_s: float, *, render: bool, figures: bool) -> dict:
    from tactileskin.report.markdown import build_report

    records, rows, failures = collect(outcomes, cache)
    renders: list[Path] = []

    def meanwhile() -> None:
        # the tables and renders, written while the second process draws its figures: that
        # one has the longer share of the drawing, so this one would otherwise wait for it
        _write_tables(out, rows, records)
        if render and records:
            renders.extend(_renders(records, out, cache))

    drawn = _figures(records, rows, out, cache, meanwhile=meanwhile) if records and figures else []
    if not (records and figures):
        meanwhile()
    report = build_report(rows, records, failures, drawn, renders, wall_s,
                          scenes=[oc.scene for oc in outcomes])
    atomic_write_text(out / "report.md", report)
    return dict(results=out / "results.csv", profiles=out / "profiles.csv", report=out / "report.md",
                figures=drawn, renders=renders, failures=failures, rows=rows, records=records)
