"""How far the letters' surrogate is trusted at each thickness: its measured error against
full 3D solves, from this run's validation rows (`chart.validate_surrogate`) and the
project's measurements in tactileskin/data/surrogate_validation.json, the worse of them.

The error of a (material, skin, mesh, t, depth) is the worst taxel-averaged error over its
validated characters, inside a square around the cell at least as large as the chart reads,
against the full solves on the finest mesh measured for that character (a row's reference_mesh,
else the chart's), for the model the chart used ("interaction", the plain "sum", or past the dot height "plate + sum"; a row
without a model is the sum); where nothing matches it is not validated. Either way the chart
says so beside the letters' accuracies.
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from importlib import resources

DATA = ("data", "surrogate_validation.json")
# the taxel side (mm) the data file's rows were read with where a row does not say (its "about":
# the default chart's smallest taxel, 0.8 x 0.5 mm). A row answers for a chart whose smallest
# taxel is at least its own: smaller taxels (point sensors) see the sub-taxel ripple the box
# average hid (pointwise the surrogate was 9-12 % off where 0.4 mm taxels read 2.9-4.9 %)
DATA_TAXEL = 0.4
# the source named for this run's validation rows
RUN_SOURCE = "this run's validation"
# the Braille standard the data file's rows were measured on (a case's "standard", if it names
# one), from the shipped geometry files: they say nothing of other dots (ADA's 0.75 mm high,
# 2.4 mm apart) or of an edited braille.toml / indenters.toml (TACTILESKIN_GEOMETRY)
DATA_STANDARD = "standard_american"
DATA_GEOMETRY = ("braille.toml", "indenters.toml")


def _shipped_dots() -> bool:
    """Whether the Braille dots are built from the shipped geometry files."""
    from tactileskin.params import geometry_changes

    return not set(geometry_changes() or ()) & set(DATA_GEOMETRY)


@lru_cache(maxsize=1)
def load() -> dict:
    """The parsed measurement file (cached; do not mutate)."""
    return json.loads(resources.files("tactileskin").joinpath(*DATA).read_text(encoding="utf-8"))


def tolerance() -> float:
    """The surrogate's bound (surrogate.TOLERANCE), a fraction of the full map's peak."""
    from tactileskin.array.surrogate import TOLERANCE

    return float(TOLERANCE)


def _match(a: float, b: float) -> bool:
    return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-9)


def _covers(row: dict, extent: float | None) -> bool:
    """A row measured over the square |s|, |z| <= row["extent_mm"] answers for a chart that
    reads within `extent`; a row without one was measured over the whole map (any chart)."""
    return extent is None or "extent_mm" not in row or float(row["extent_mm"]) >= float(extent) - 1e-9


def _reference(row: dict, mesh) -> float:
    """The fine element size (mm) of the full solves a row was measured against: its
    reference_mesh (mesh_size / refinement), else the chart's mesh."""
    size, ratio = row.get("reference_mesh") or mesh
    return float(size) / float(ratio)


def _same_sensors(a, b) -> bool:
    """Two sensor depths (None: the bonded surface) are the same plane."""
    return (a is None) == (b is None) and (a is None or _match(a, b))


def _taxel_ok(row_taxel: float, taxel: float | None) -> bool:
    """A row read with taxels of side row_taxel answers for a chart whose smallest is `taxel`."""
    return taxel is None or float(row_taxel) <= float(taxel) + 1e-9


def measured(material: str, skin: str, mesh: tuple, t: float, depth: float, validation=None,
             model: str = "sum", extent: float | None = None, taxel: float | None = None,
             standard: str = DATA_STANDARD, sensor_depth: float | None = None) -> dict:
    """{"error": worst taxel error over the peak or None, "texts": the validated characters,
    "source": where the numbers come from, "status": "within" | "exceeds" | "not validated",
    "reference_mesh": (mesh_size, refinement) of the full solves judged against, finer than
    `mesh` or `mesh` itself}; `extent`: the half side (mm) of the square the chart reads
    (ChartConfig.read_extent), which a row's own extent must cover; `taxel`: the chart's smallest
    taxel side (mm; 0 = point sensors), which must be at least the rows' (DATA_TAXEL where a row
    does not say); `standard`: the chart's Braille standard (the data file's rows answer only
    for the dots they were measured on: DATA_STANDARD, from the shipped geometry files);
    `sensor_depth`: the chart's sensor depth below the contact surface (None: the bonded
    surface), which a row's "sensor_depth_mm" must match (the data file's rows are all on the
    bonded surface: at another depth only this run's validation answers)."""
    rows = []
    for r in validation or ():
        rt = float(r.get("taxel_mm", DATA_TAXEL))
        key = "max_abs_over_peak_taxel" if rt > 0 else "max_abs_over_peak"  # taxel 0: pointwise
        if r.get("model", "sum") == model and r["material"] == material and _match(r["thickness_mm"], t) \
                and _match(r.get("depth_mm", depth), depth) and key in r \
                and _covers(r, extent) and _taxel_ok(rt, taxel) and r.get("solve_status", "ok") == "ok" \
                and _same_sensors(r.get("sensor_depth_mm"), sensor_depth):
            rows.append({"text": r["text"], "taxel_max_error": r[key],
                         "reference_mesh": r.get("reference_mesh"), "source": RUN_SOURCE})
    shipped = _shipped_dots()
    for case in load()["cases"]:
        if not shipped or case.get("standard", DATA_STANDARD) != standard or sensor_depth is not None:
            continue
        if case["material"] != material or case["skin"] != skin or \
                not all(_match(x, y) for x, y in zip(case["mesh"], mesh)):
            continue
        for r in case["rows"]:
            if r.get("model", "sum") == model and _match(r["thickness_mm"], t) and _match(r["depth_mm"], depth) \
                    and _covers(r, extent) and _taxel_ok(r.get("taxel_mm", DATA_TAXEL), taxel):
                rows.append(r)
    if not rows:
        return {"error": None, "texts": [], "source": "", "status": "not validated"}
    # each character against the finest reference measured for it: a full solve on a coarser
    # mesh carries its own discretisation error (t = 1 mm full cell at 1.2 / 8: -3.3 % in the
    # peak). This run's rows join the file's, never replace them: a run that validated one
    # character does not hide a worse one measured before
    finest = {}
    for r in rows:
        finest[r["text"]] = min(finest.get(r["text"], math.inf), _reference(r, mesh))
    rows = [r for r in rows if _reference(r, mesh) == finest[r["text"]]]
    worst = max(rows, key=lambda r: float(r["taxel_max_error"]))
    err = float(worst["taxel_max_error"])
    sources = list(dict.fromkeys(r["source"] for r in rows))
    ref = tuple(float(v) for v in (worst.get("reference_mesh") or mesh))
    # the worst error against full solves on the chart's own mesh (None: none measured there):
    # with each character at its own finest reference, the worst row may be a finer mesh's
    # while another character exceeds against the chart's own (finer_reference)
    own = [float(r["taxel_max_error"]) for r in rows if not _reference(r, mesh) < _reference({}, mesh) * (1.0 - 1e-9)]
    return {"error": err, "texts": list(dict.fromkeys(r["text"] for r in rows)), "source": "; ".join(sources),
            "status": "within" if err <= tolerance() else "exceeds", "reference_mesh": ref,
            "own_mesh_error": max(own) if own else None}


def finer_reference(m: dict, mesh) -> bool:
    """Whether a `measured` answer judged the chart's `mesh` against full solves on a finer one
    only: its worst error is a finer mesh's, and no character exceeds the tolerance against
    full solves on the chart's own mesh (those would fall back)."""
    own = m.get("own_mesh_error")
    return (m.get("reference_mesh") is not None and _reference(m, mesh) < _reference({}, mesh) * (1.0 - 1e-9)
            and not (own is not None and own > tolerance()))


def finer_mesh_reason(m: dict, mesh) -> str:
    """Why letters measured past the tolerance only against full solves on a finer mesh stay
    on the surrogate (finer_reference): one wording for the run's progress and the report."""
    ref = m["reference_mesh"]
    return (f"full solves on the finer {ref[0]:g} / {ref[1]:g} mesh; full solves on the chart's "
            f"{mesh[0]:g} / {mesh[1]:g} would carry its error too, so no fallback: the letters stay on the "
            "surrogate, marked indicative (a finer --mesh-size with --validate answers it)")
