"""`film analyze`'s profile.csv named its pressure columns without a unit ('pressure', MPa/mm
under the paper's Eq. 8, MPa under a press calibration: only summary.json told which) and had
no status: a saturated film's profile read as a plain one, while the solver's profile.csv
marks every row. The columns now carry the calibration's unit and every row the status
(`film compare` reads the new and the earlier form)."""

from __future__ import annotations

import csv

import numpy as np

from tactileskin.cli import main
from tactileskin.film import paper_eq8
from tactileskin.film.synthetic import gaussian_profile, mirrored, render_scan, save_scan

S = np.linspace(0, 6, 121)


def _table(folder):
    with open(folder / "profile.csv", newline="") as f:
        return list(csv.DictReader(f))


def _sim(tmp_path):
    d = tmp_path / "sim"
    d.mkdir()
    np.savetxt(d / "profile.csv", np.column_stack([S, gaussian_profile(0.4, 1.0)(S)]),
               delimiter=",", header="s_mm,pressure_mpa", comments="", fmt="%.10g")
    (d / "summary.json").write_text('{"status": "ok"}')
    return d


def test_film_profile_columns_carry_the_unit_and_the_status(tmp_path):
    ok = save_scan(render_scan(gaussian_profile(0.4, 1.0), background_gs=245), tmp_path / "ok.png")
    sat = save_scan(render_scan(mirrored(S, gaussian_profile(1.2, 1.0)(S)), paper_eq8(), length_mm=14,
                                background_gs=245), tmp_path / "sat.png")
    assert main(["film", "analyze", str(ok), "--out", str(tmp_path / "ok")]) == 0
    assert main(["film", "analyze", str(sat), "--out", str(tmp_path / "sat")]) == 3
    for name, status in (("ok", "ok"), ("sat", "suspect: ")):
        rows = _table(tmp_path / name)
        assert list(rows[0]) == ["s_mm", "pressure_mpa_per_mm", "pressure_sd_mpa_per_mm", "band90_lo_mpa_per_mm",
                                 "band90_hi_mpa_per_mm", "status"], list(rows[0])
        assert all(r["status"].startswith(status) for r in rows), rows[0]
    assert "saturation" in _table(tmp_path / "sat")[0]["status"]
    sim = _sim(tmp_path)
    assert main(["film", "compare", str(tmp_path / "ok"), str(sim), "--out", str(tmp_path / "c")]) == 0
