"""Measured (film) against simulated pressure profile: metrics and percent differences.

The simulation is a half model: its profile runs over s >= 0 from the symmetry line. The
film profile is two-sided, centred on its origin (the peak by default); it is folded onto
s >= 0 (``scan.fold_profile``: mean of P(+s) and P(-s)) and peak, span (10 % of peak,
one-sided, as the paper's "distance from the center") and area (over s >= 0, the half
model's) are computed on both with ``tactileskin.results``.

Percent difference (paper Sec. V-B): 100 (sim - film) / film, signed; the paper reports
magnitudes (e.g. 231 %), and values above 200 % rule out the symmetric |a-b|/mean(a,b)
form, so the measurement is the reference. Units: the film reads in its calibration's unit
(MPa, or MPa/mm for paper_eq8); numbers are compared directly with the simulation's MPa as
the paper does (see calibration module docstring); a film in any other unit makes the
comparison suspect (SAME_AS_MPA).
"""

from __future__ import annotations

import csv
import io
import json
import logging
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tactileskin import fileio, outdir, ownership, staging
from tactileskin.errors import ParameterError
from tactileskin.film.inputs import read_text
from tactileskin.film.scan import (ASYMMETRY, COMPARE_NAMES, FilmProfile, fold_profile,
                                   profile_metrics)

log = logging.getLogger(__name__)

METRICS = ("peak", "span_mm", "auc")
# film units whose numbers are compared with the simulation's MPa as they are: MPa, and the
# paper's MPa/mm (Eq. 8, read as MPa as the paper does); any other (kPa, psi) is not comparable
SAME_AS_MPA = ("MPa", "MPa/mm")


def read_profile_csv(path, s_col: str, p_col: str) -> tuple[np.ndarray, np.ndarray]:
    path = Path(path)
    text = read_text(path, "profile", "a readable profile.csv")
    try:
        rows = list(csv.DictReader(io.StringIO(text, newline="")))
    except csv.Error as e:
        raise ParameterError("profile", str(path), "a CSV file", hint=str(e)) from None
    if not rows or s_col not in rows[0] or p_col not in rows[0]:
        raise ParameterError("profile", str(path), f"CSV with columns {s_col}, {p_col} and >= 2 rows")
    try:
        s = np.array([float(r[s_col]) for r in rows])
        p = np.array([float(r[p_col]) for r in rows])
    except (TypeError, ValueError) as e:
        raise ParameterError("profile", str(path), "numeric columns, every row complete",
                             hint=str(e)) from None
    if s.size < 2 or not (np.all(np.isfinite(s)) and np.all(np.isfinite(p))):
        raise ParameterError("profile", str(path), ">= 2 finite rows")
    order = np.argsort(s)
    return s[order], p[order]


def load_simulation(sim_dir) -> tuple[np.ndarray, np.ndarray, dict]:
    """profile.csv (s_mm, pressure_mpa) and summary.json of a solver result. summary.json is
    written last (staged_files' `last`): without it the folder holds no complete result (a
    failed or running write, or a profile the user put there), which is refused."""
    sim_dir = Path(sim_dir)
    s, p = read_profile_csv(sim_dir / "profile.csv", "s_mm", "pressure_mpa")
    summary = sim_dir / "summary.json"
    if not summary.is_file():
        raise ParameterError("simulation result", str(sim_dir), "a folder written by `tactileskin solve` "
                             "(profile.csv and summary.json)",
                             hint=f"{summary} is missing: no complete result there")
    meta = _read_json(summary, "simulation summary", "valid JSON")
    return s, p, meta


def changed_since_written(folder, names=("profile.csv", "summary.json")) -> list[str]:
    """Of `names` in `folder`, those its record of written files (ownership) lists with other
    contents: damaged (a truncated copy, a disk that filled) or edited since tactileskin wrote
    them. A profile cut at a line end reads as a valid, shorter one (span 2.0 for 2.27 mm)."""
    folder = Path(folder)
    rec = ownership.read_record(folder)
    changed = []
    for n in names:
        if n in rec:
            try:
                same = ownership.is_recorded(rec[n], fileio.file_sha256(folder / n))
            except OSError:
                same = False
            if not same:
                changed.append(n)
    return changed


def _reject_constant(token: str):
    raise ValueError(f"{token} is not a number in strict JSON")


def _read_json(path, what: str, valid: str) -> dict:
    text = read_text(path, what, valid)
    try:
        d = json.loads(text, parse_constant=_reject_constant)
    except ValueError as e:
        raise ParameterError(what, str(path), valid, hint=str(e)) from None
    if not isinstance(d, dict):
        raise ParameterError(what, str(path), valid, hint="not a JSON object")
    return d


def load_film(film_dir) -> tuple[np.ndarray, np.ndarray, dict]:
    """profile.csv (s_mm, pressure_<unit>; earlier files: pressure) and summary.json written
    by ``FilmProfile.write``."""
    from tactileskin.film.scan import unit_suffix

    film_dir = Path(film_dir)
    meta = _read_json(film_dir / "summary.json", "film result",
                      "a directory written by `film analyze`")
    if not isinstance(meta.get("unit", "MPa"), str):
        raise ParameterError("film result unit", meta.get("unit"), "text, e.g. MPa",
                             hint=str(film_dir / "summary.json"))
    path = film_dir / "profile.csv"
    col = "pressure_" + unit_suffix(meta.get("unit", "MPa"))
    head = read_text(path, "profile", "a readable profile.csv").split("\n", 1)[0]
    s, p = read_profile_csv(path, "s_mm", col if col in head.split(",") else "pressure")
    return s, p, meta


@dataclass
class Comparison:
    film_s: np.ndarray
    film_p: np.ndarray
    film_fold_s: np.ndarray
    film_fold_p: np.ndarray
    sim_s: np.ndarray
    sim_p: np.ndarray
    film_metrics: dict
    sim_metrics: dict
    percent_diff: dict
    film_unit: str
    asymmetry: float
    sim_meta: dict
    warnings: list = None   # what makes the comparison suspect: the film's and the simulation's
    sim_asymmetry: float = 0.0   # a two-sided simulated profile's fold_profile asymmetry about s = 0

    def __post_init__(self):
        if self.warnings is None:
            self.warnings = []

    @property
    def film_warnings(self) -> list:
        return [w[len("film: "):] for w in self.warnings if w.startswith("film: ")]

    @property
    def status(self) -> str:
        return "suspect" if self.warnings else "ok"

    def to_dict(self) -> dict:
        return {
            "status": self.status, "warnings": list(self.warnings),
            "film_metrics_folded": self.film_metrics, "sim_metrics": self.sim_metrics,
            "percent_diff": self.percent_diff,
            "percent_diff_definition": "100 * (sim - film) / film, film folded onto s >= 0",
            "film_unit": self.film_unit, "sim_unit": "MPa",
            "unit_note": ("same unit" if self.film_unit == "MPa" else "numbers compared directly, as the paper does"
                          if self.film_unit in SAME_AS_MPA else "unlike units: peak and area not comparable"),
            "film_asymmetry": self.asymmetry, "sim_asymmetry": self.sim_asymmetry,
            "sim_meta": self.sim_meta,
        }

    def write(self, out) -> dict[str, Path]:
        """comparison.json and overlay.png into ``out``, each atomically.

        ``out`` is claimed with outdir.claim_dir: a new or empty folder, a `film compare`
        folder, or a `film analyze` folder (the default of the CLI: the film's own folder).
        """
        from tactileskin.film import plots

        out = Path(out)
        if _is_analyze_folder(out):
            outdir.claim_dir(out, "film-analyze")
        else:
            outdir.claim_dir(out, "film-compare")
        doc = json.loads(json.dumps(self.to_dict(), default=str))
        with outdir.run_lock(out, "out"), staging.staged_files(out, COMPARE_NAMES) as tmp:  # both or neither
            fileio.atomic_write_json(tmp / "comparison.json", _finite_or_none(doc))
            plots.overlay(self, tmp / "overlay.png")
        return {"comparison": out / "comparison.json", "overlay": out / "overlay.png"}


def _is_analyze_folder(out: Path) -> bool:
    """A folder `film analyze` wrote: its marker says so."""
    try:
        return json.loads((out / outdir.MARKER).read_text()).get("kind") == "film-analyze"
    except (OSError, ValueError, AttributeError):
        return False


def _finite_or_none(o):
    if isinstance(o, dict):
        return {k: _finite_or_none(v) for k, v in o.items()}
    if isinstance(o, list):
        return [_finite_or_none(v) for v in o]
    if isinstance(o, float) and not math.isfinite(o):
        return None
    return o


def compare(film, sim) -> Comparison:
    """film: FilmProfile or a `film analyze` directory; sim: directory or (s, p) arrays."""
    if isinstance(film, FilmProfile):
        fs, fpr, unit = film.s_mm, film.pressure, film.unit
        film_warnings = list(film.warnings)
    else:
        fs, fpr, meta = load_film(film)
        unit = meta.get("unit", "MPa")
        film_warnings = meta.get("warnings") or []
        if not isinstance(film_warnings, list):
            film_warnings = [str(film_warnings)]
    if isinstance(sim, (str, Path)):
        ss, sp, smeta = load_simulation(sim)
    else:
        ss, sp = (np.asarray(a, float) for a in sim)
        smeta = {}
    if not np.any(sp > 0):  # a result without contact: every difference would read -100 %
        raise ParameterError("simulated profile", "zero everywhere", "a result with bone pressure",
                             hint=f"its status: {smeta.get('status', 'not recorded')}")
    sim_asym, sim_peak_s = 0.0, 0.0
    if ss[0] < -1e-9:  # a full (two-sided) simulated profile: fold it the same way
        sim_peak_s = float(ss[int(np.argmax(sp))])
        ss, sp, sim_asym = fold_profile(ss, sp)
    hs, hp, asym = fold_profile(fs, fpr)
    fm, sm = profile_metrics(hs, hp), profile_metrics(ss, sp)
    diff = {}
    for k in METRICS:
        if fm[k] == 0:
            raise ParameterError(f"film {k}", 0.0, "non-zero (percent difference is relative "
                                 "to the film)")
        diff[k] = 100.0 * (sm[k] - fm[k]) / fm[k]
    log.info("film vs sim: %s", diff)
    warnings = [f"film: {w}" for w in film_warnings]
    if not isinstance(film, FilmProfile) and (changed := changed_since_written(film)):
        warnings.append(f"film: {', '.join(changed)} changed since `film analyze` wrote it (damaged or edited)")
    if unit not in SAME_AS_MPA:  # 218 kPa against 0.22 MPa read -99.9 %, status ok
        warnings.append(f"units: the film reads in {unit}, the simulation in MPa: the peak and area differences "
                        "compare unlike units (only MPa and the paper's MPa/mm are compared as they are); "
                        "calibrate in MPa (`film calibrate` does)")
    status = str(smeta.get("status", "ok"))
    if status != "ok":
        warnings.append(f"simulation: {status}")
    if isinstance(sim, (str, Path)) and (changed := changed_since_written(sim)):
        warnings.append(f"simulation: {', '.join(changed)} changed since tactileskin wrote it (damaged or "
                        "edited): its numbers may not be the solve's")
    if sim_asym > ASYMMETRY:  # as the film's fold is flagged (an off-centre dot on a full-width pad)
        warnings.append(f"simulation: its two-sided profile is not symmetric about s = 0 (peak at s = "
                        f"{sim_peak_s:.3g} mm): |P(+s) - P(-s)| reaches {sim_asym:.2f} of the peak (> "
                        f"{ASYMMETRY:g}), so folded onto s >= 0 it averages unlike sides (the film is folded "
                        "about its own origin)")
    return Comparison(fs, fpr, hs, hp, ss, sp, fm, sm, diff, unit, asym, smeta, warnings, sim_asym)
