"""`film analyze` marks a suspect profile (exit 3 and the reasons); `film compare` carries the
film's warnings and the simulation's status into comparison.json and stderr, and exits 3."""

import json
import re

import numpy as np

from tactileskin.cli import main
from tactileskin.film import paper_eq8
from tactileskin.film.calibration import Calibration
from tactileskin.film.synthetic import gaussian_profile, mirrored, render_scan, save_scan

S = np.linspace(0, 6, 121)


def _sim_dir(path, status="ok", peak=1.2):
    path.mkdir(parents=True)
    np.savetxt(path / "profile.csv", np.column_stack([S, gaussian_profile(peak, 1.0)(S)]), delimiter=",",
               header="s_mm,pressure_mpa", comments="", fmt="%.10g")
    (path / "summary.json").write_text(json.dumps({"status": status}))
    return path


def test_a_saturated_film_exits_3_and_its_comparison_says_why(tmp_path, capsys):
    # 1.2 MPa/mm at the peak: past Eq. 8's top (0.978), a third of the strip saturates
    scan = save_scan(render_scan(mirrored(S, gaussian_profile(1.2, 1.0)(S)), paper_eq8(), length_mm=14,
                                 background_gs=245), tmp_path / "scan.png")
    assert main(["film", "analyze", str(scan), "--out", str(tmp_path / "film")]) == 3
    err = capsys.readouterr().err
    assert "suspect profile (exit status 3): 1 reason(s)" in err and "summary.json" in err
    summary = json.loads((tmp_path / "film" / "summary.json").read_text())
    assert any("saturation" in w for w in summary["warnings"])
    _sim_dir(tmp_path / "sim")
    assert main(["film", "compare", str(tmp_path / "film"), str(tmp_path / "sim"), "-o",
                 str(tmp_path / "cmp")]) == 3  # written, suspect: as `analyze`, `solve`, `sweep`
    assert "the film profile is suspect" in capsys.readouterr().err
    doc = json.loads((tmp_path / "cmp" / "comparison.json").read_text())
    assert doc["status"] == "suspect" and any("saturation" in w for w in doc["warnings"])


def test_a_clean_film_against_a_suspect_simulation_is_a_suspect_comparison(tmp_path, capsys):
    scan = save_scan(render_scan(mirrored(S, gaussian_profile(0.4, 1.0)(S)), paper_eq8(), length_mm=14,
                                 background_gs=245), tmp_path / "scan.png")
    assert main(["film", "analyze", str(scan), "--out", str(tmp_path / "film")]) == 0
    _sim_dir(tmp_path / "sim", status="suspect: no contact")
    assert main(["film", "compare", str(tmp_path / "film"), str(tmp_path / "sim"), "-o",
                 str(tmp_path / "cmp")]) == 3
    doc = json.loads((tmp_path / "cmp" / "comparison.json").read_text())
    assert doc["status"] == "suspect" and doc["warnings"] == ["simulation: suspect: no contact"]
    _sim_dir(tmp_path / "sim_ok")
    assert main(["film", "compare", str(tmp_path / "film"), str(tmp_path / "sim_ok"), "-o",
                 str(tmp_path / "cmp2")]) == 0
    assert json.loads((tmp_path / "cmp2" / "comparison.json").read_text())["status"] == "ok"


def test_every_number_printed_has_its_unit(tmp_path, capsys):
    scan = save_scan(render_scan(mirrored(S, gaussian_profile(0.4, 1.0)(S)), paper_eq8(), length_mm=14,
                                 background_gs=245), tmp_path / "scan.png")
    assert main(["film", "analyze", str(scan), "--out", str(tmp_path / "film")]) == 0
    out = capsys.readouterr().out
    # the two areas: a pressure in MPa/mm integrated over s (mm) is in MPa ("MPa/mm mm" read as
    # MPa/mm^2); a pressure in MPa gives MPa mm
    assert "MPa/mm mm" not in out and len(re.findall(r"area [0-9.e+-]+ MPa;", out)) == 2
    _sim_dir(tmp_path / "sim")
    assert main(["film", "compare", str(tmp_path / "film"), str(tmp_path / "sim"), "-o", str(tmp_path / "c")]) == 0
    rows = [ln for ln in capsys.readouterr().out.splitlines() if ln.split()[:1] in (["peak"], ["span_mm"], ["auc"])]
    assert len(rows) == 3 and rows[2].endswith(" MPa / MPa mm")


def test_area_units():
    from tactileskin.film.scan import area_unit

    assert [area_unit(u) for u in ("MPa", "MPa/mm", "kPa", "psi/mm", "MPa / mm")] == \
        ["MPa mm", "MPa", "kPa mm", "psi", "MPa"]


def test_the_figures_of_a_suspect_film_and_comparison_say_so(tmp_path, monkeypatch):
    """pressure_map.png and overlay.png of a suspect profile / comparison were titled as any other."""
    from tactileskin.film import plots

    titles = {}
    real = plots._save

    def save(fig, path):
        titles[path.name] = " ".join(ax.get_title() for ax in fig.axes)
        return real(fig, path)

    monkeypatch.setattr(plots, "_save", save)
    scan = save_scan(render_scan(mirrored(S, gaussian_profile(1.2, 1.0)(S)), paper_eq8(), length_mm=14,
                                 background_gs=245), tmp_path / "scan.png")  # saturated: suspect
    assert main(["film", "analyze", str(scan), "--out", str(tmp_path / "film")]) == 3
    assert "SUSPECT: 1 warning in summary.json" in titles["pressure_map.png"]
    _sim_dir(tmp_path / "sim")
    assert main(["film", "compare", str(tmp_path / "film"), str(tmp_path / "sim"), "-o", str(tmp_path / "cmp")]) == 3
    assert "SUSPECT: 1 warning in comparison.json" in titles["overlay.png"]


def test_an_inverted_scan_is_said_to_look_inverted(tmp_path, capsys):
    # white on black: its dark background read as the profile, and the reasons given were
    # 'still at 100 % of its peak at the region's ends: widen the region' (or 'try --axis y'
    # on a stained background), which no region or axis mends
    img = render_scan(gaussian_profile(0.4, 1.0), paper_eq8(), background_gs=245, noise_gs=1, seed=3)
    scan = save_scan(255 - img, tmp_path / "inverted.png")
    assert main(["film", "analyze", str(scan), "--out", str(tmp_path / "film")]) == 3
    assert "1 reason(s)" in capsys.readouterr().err
    warnings = json.loads((tmp_path / "film" / "summary.json").read_text())["warnings"]
    assert len(warnings) == 1 and "looks inverted" in warnings[0] and "widen the region" not in warnings[0]
    # the same scan the right way round is not
    assert main(["film", "analyze", str(save_scan(img, tmp_path / "scan.png")), "--out", str(tmp_path / "ok")]) == 0


def test_a_film_in_another_unit_than_mpa_is_a_suspect_comparison(tmp_path, capsys):
    # a calibration in kPa: the film read 400 kPa against the simulation's 0.4 MPa, -99.9 %, 'ok'
    eq8 = paper_eq8()
    kpa = Calibration(name="kpa", model="linear", params=tuple(1000 * v for v in eq8.params),
                      gs_range=eq8.gs_range, p_range=tuple(1000 * v for v in eq8.p_range), unit="kPa")
    kpa.save(tmp_path / "kpa.json")
    scan = save_scan(render_scan(mirrored(S, gaussian_profile(0.4, 1.0)(S)), paper_eq8(), length_mm=14,
                                 background_gs=245), tmp_path / "scan.png")
    assert main(["film", "analyze", str(scan), "-c", str(tmp_path / "kpa.json"), "--out", str(tmp_path / "film")]) == 0
    _sim_dir(tmp_path / "sim")
    capsys.readouterr()
    assert main(["film", "compare", str(tmp_path / "film"), str(tmp_path / "sim"), "-o",
                 str(tmp_path / "cmp")]) == 3
    assert "warning: units: the film reads in kPa, the simulation in MPa" in capsys.readouterr().err
    doc = json.loads((tmp_path / "cmp" / "comparison.json").read_text())
    assert doc["status"] == "suspect" and doc["percent_diff"]["peak"] < -99
    # the paper's MPa/mm (Eq. 8) is compared as MPa, as the paper does: no warning for it
    assert main(["film", "analyze", str(scan), "--out", str(tmp_path / "film8")]) == 0
    _sim_dir(tmp_path / "sim4", peak=0.4)
    assert main(["film", "compare", str(tmp_path / "film8"), str(tmp_path / "sim4"), "-o",
                 str(tmp_path / "cmp8")]) == 0
    doc = json.loads((tmp_path / "cmp8" / "comparison.json").read_text())
    assert doc["status"] == "ok" and abs(doc["percent_diff"]["peak"]) < 1


def test_rows_centre_reads_the_row_through_the_peak(tmp_path, capsys):
    # a round press: the default reading (the rows' mean) is suspect and names --rows centre; with it, the
    # row through the peak is read, exit 0, and the region printed and saved is that row
    cal = paper_eq8()  # a Hertzian spot, a = 1.5 mm, off the pixel grid, at 8 px/mm
    x = (np.arange(160) + 0.5) / 8 - 10.03
    y = (np.arange(96) + 0.5) / 8 - 6.04
    p = 0.5 * np.sqrt(np.clip(1 - (x[None, :] ** 2 + y[:, None] ** 2) / 1.5 ** 2, 0, None))
    gs = cal.grayscale(p)
    img = np.clip(np.rint(np.where(np.abs(gs - cal.threshold_gs) < 0.5, 245.0, gs)), 0, 255).astype(np.uint8)
    scan = save_scan(img, tmp_path / "scan.png")
    assert main(["film", "analyze", str(scan), "--out", str(tmp_path / "all")]) == 3
    assert "--rows centre" in json.loads((tmp_path / "all" / "summary.json").read_text())["warnings"][0]
    capsys.readouterr()
    assert main(["film", "analyze", str(scan), "--rows", "centre", "--out", str(tmp_path / "c")]) == 0
    out = capsys.readouterr().out
    assert "y 48-49 px" in out and "centre: the row through the peak, y 48 px" in out
    summ = json.loads((tmp_path / "c" / "summary.json").read_text())
    assert summ["width_px"] == 1 and summ["warnings"] == [] and abs(summ["metrics_two_sided"]["peak"] - 0.5) < 0.003
    assert main(["film", "analyze", str(scan), "--rows", "middle", "--out", str(tmp_path / "bad")]) == 2
    assert not (tmp_path / "bad").exists()


def test_a_line_a_few_pixels_wide_exits_3_naming_its_width_and_a_dpi(tmp_path, capsys):
    """A 0.4 mm line at 8 px/mm under 1.5 px blur read its peak 36 % low with exit 0: now exit 3, the reason
    naming its width in px and mm and the dpi to scan at."""
    scan = save_scan(render_scan(gaussian_profile(0.5, 1.0), paper_eq8(), width_mm=0.4, blur_px=1.5,
                                 background_gs=245), tmp_path / "scan.png")
    assert main(["film", "analyze", str(scan), "--out", str(tmp_path / "film")]) == 3
    summary = json.loads((tmp_path / "film" / "summary.json").read_text())
    said = [w for w in summary["warnings"] if "resolution is too coarse" in w]
    assert len(said) == 1 and " px (0.4" in said[0] and " mm) wide across the strip (y)" in said[0]
    assert " dpi or more" in said[0] and "--px-per-mm" in said[0] and "span" not in said[0] and "suspect profile (exit status 3): 1 reason(s)" in capsys.readouterr().err
    assert summary["metrics_two_sided"]["peak"] < 0.7 * 0.5  # the premise: > 30 % low
