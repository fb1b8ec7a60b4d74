"""Film output folders and files go through fileio: a folder holding user files is refused
and left intact, `film compare` may write into the `film analyze` folder (its default), a
re-analysis removes the stale comparison, files get normal permissions."""

import json
import os

import numpy as np
import pytest

from tactileskin import fileio, outdir
from tactileskin.cli import main
from tactileskin.film.synthetic import gaussian_profile, render_scan, save_scan

S = np.linspace(0, 6, 121)


@pytest.fixture
def scan(tmp_path):
    return save_scan(render_scan(gaussian_profile(0.4, 1.0), background_gs=245), tmp_path / "s.png")


@pytest.fixture
def sim(tmp_path):
    d = tmp_path / "sim"
    d.mkdir()
    np.savetxt(d / "profile.csv", np.column_stack([S, gaussian_profile(0.4, 1.0)(S)]),
               delimiter=",", header="s_mm,pressure_mpa", comments="", fmt="%.10g")
    (d / "summary.json").write_text(json.dumps({"status": "ok"}))  # a complete result
    return d


def test_analyze_refuses_a_folder_with_user_files(tmp_path, capsys, scan):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("x")
    assert main(["film", "analyze", str(scan), "--out", str(out)]) == 2
    assert "did not write" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
    assert (out / "notes.txt").read_text() == "x"


def test_compare_into_the_film_folder_and_stale_comparison_removed(tmp_path, capsys, scan, sim):
    film = tmp_path / "film"
    assert main(["film", "analyze", str(scan), "--out", str(film)]) == 0
    assert main(["film", "compare", str(film), str(sim)]) == 0          # default: FILM_DIR
    assert (film / "comparison.json").exists() and (film / "overlay.png").exists()
    json.loads((film / "comparison.json").read_text(),
               parse_constant=lambda t: pytest.fail(f"non-strict token {t}"))
    mode = fileio.file_mode()
    assert all(os.stat(film / n).st_mode & 0o777 == mode
               for n in ("profile.csv", "summary.json", "pressure_map.png", "comparison.json"))
    # a new analysis in the same folder: the comparison of the old profile is gone
    assert main(["film", "analyze", str(scan), "--centre", "midspan", "--out", str(film)]) == 0
    assert not (film / "comparison.json").exists() and not (film / "overlay.png").exists()
    assert [p.name for p in tmp_path.iterdir() if ".tsk" in p.name] == []


def test_compare_into_a_foreign_folder_is_refused(tmp_path, capsys, scan, sim):
    film = tmp_path / "film"
    assert main(["film", "analyze", str(scan), "--out", str(film)]) == 0
    other = tmp_path / "other"
    other.mkdir()
    (other / "data.csv").write_text("1")
    assert main(["film", "compare", str(film), str(sim), "--out", str(other)]) == 2
    assert "did not write" in capsys.readouterr().err
    assert sorted(p.name for p in other.iterdir()) == ["data.csv"]
    # a new folder becomes a compare folder, and can be written again
    for _ in range(2):
        assert main(["film", "compare", str(film), str(sim), "--out", str(tmp_path / "cmp")]) == 0
    assert json.loads((tmp_path / "cmp" / outdir.MARKER).read_text())["kind"] == "film-compare"


def test_compare_refuses_a_folder_without_our_marker(tmp_path, scan, sim):
    film = tmp_path / "film"
    assert main(["film", "analyze", str(scan), "--out", str(film)]) == 0
    (film / outdir.MARKER).unlink()  # e.g. a user's copy of the profile and summary
    before = {p.name: p.read_bytes() for p in film.iterdir()}
    assert main(["film", "compare", str(film), str(sim)]) == 2
    assert {p.name: p.read_bytes() for p in film.iterdir()} == before


def test_calibrate_out_under_a_file(tmp_path, capsys):
    (tmp_path / "cal.csv").write_text("force_n,area_mm2,gray\n30,100,40\n17,100,120\n2,100,220\n")
    (tmp_path / "f").write_text("a file")
    assert main(["film", "calibrate", str(tmp_path / "cal.csv"), "--out",
                 str(tmp_path / "f" / "c.json")]) == 2
    err = capsys.readouterr().err.replace("\n", "")
    assert "cannot write" in err and "Traceback" not in err
    assert (tmp_path / "f").read_text() == "a file"


def test_compare_refuses_a_result_without_contact_and_warns_of_a_suspect_one(tmp_path, capsys, scan, sim):
    film = tmp_path / "film"
    assert main(["film", "analyze", str(scan), "--out", str(film)]) == 0
    (sim / "summary.json").write_text(json.dumps({"status": "suspect: no contact"}))
    np.savetxt(sim / "profile.csv", np.column_stack([S, 0.0 * S]), delimiter=",",
               header="s_mm,pressure_mpa", comments="", fmt="%.10g")
    assert main(["film", "compare", str(film), str(sim)]) == 2  # was: -100 % everywhere, exit 0
    assert "zero everywhere" in capsys.readouterr().err and not (film / "comparison.json").exists()
    np.savetxt(sim / "profile.csv", np.column_stack([S, gaussian_profile(0.4, 1.0)(S)]), delimiter=",",
               header="s_mm,pressure_mpa", comments="", fmt="%.10g")
    (sim / "summary.json").write_text(json.dumps({"status": "suspect: volume ratio J = 0.8"}))
    assert main(["film", "compare", str(film), str(sim)]) == 3  # written, and suspect
    assert "warning: the simulated result is suspect" in capsys.readouterr().err


def test_calibration_plot_labels_fit_in_the_figure_with_units(tmp_path, monkeypatch):
    """The residual panel's y-label was cut off at the left edge and had no unit; a CSV named
    calibration.csv gave the title "calibration calibration"."""
    from tactileskin.film import plots
    from tactileskin.film.calibration import calibrate_csv

    gs = [30, 60, 90, 125, 160, 190, 220]
    force = [30.6, 25.1, 20.2, 14.9, 10.3, 5.2, 2.0]  # residuals ~ +-0.008 MPa: wide tick labels
    csv = tmp_path / "calibration.csv"
    csv.write_text("force_n,area_mm2,gray\n" + "".join(f"{f},100,{g}\n" for f, g in zip(force, gs)))
    cal = calibrate_csv(csv)
    seen = {}
    save = plots._save

    def check(fig, path):
        fig.canvas.draw()
        r = fig.canvas.get_renderer()
        seen.update(title=fig.axes[0].get_title(), label=fig.axes[1].get_ylabel(),
                    x0=min(ax.yaxis.label.get_window_extent(r).x0 for ax in fig.axes[:2]))
        return save(fig, path)

    monkeypatch.setattr(plots, "_save", check)
    assert plots.calibration_plot(cal, tmp_path / "cal.png").exists()
    assert seen["x0"] >= 0, seen
    assert f"({cal.unit})" in seen["label"] and "residual" in seen["label"]
    assert "calibration calibration" not in seen["title"] and "calibration" in seen["title"]


def test_compare_refuses_a_simulation_without_its_summary(tmp_path, capsys, scan, sim):
    film = tmp_path / "film"
    assert main(["film", "analyze", str(scan), "--out", str(film)]) == 0
    (sim / "summary.json").unlink()  # written last: without it the result is incomplete
    assert main(["film", "compare", str(film), str(sim)]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert "summary.json" in err and "simulation result" in err and not (film / "comparison.json").exists()


def test_a_failed_analyze_leaves_no_folder(tmp_path, capsys, scan, monkeypatch):
    import errno

    from tactileskin.film import plots

    def too_large(fp, path, **k):
        raise fileio.OutputError(path, errno.errorcode[errno.EFBIG])

    monkeypatch.setattr(plots, "pressure_map", too_large)
    out = tmp_path / "film"
    assert main(["film", "analyze", str(scan), "--out", str(out)]) == 2
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == [scan.name]


def test_film_profile_write_refuses_a_folder_another_run_is_writing_into(tmp_path, scan):
    # only the CLI held the run lock: the API's write went into a folder a CLI run was writing
    import fcntl

    from tactileskin.film import analyze_scan

    fp = analyze_scan(scan)
    d = tmp_path / "film"
    fp.write(d)
    before = {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()}
    fd = os.open(d / outdir.RUN_LOCK, os.O_RDWR | os.O_CREAT, 0o666)  # held as another process's run holds it
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    try:
        with pytest.raises(fileio.OutputError, match="another tactileskin run"):
            fp.write(d)
    finally:
        os.close(fd)
    assert {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()} == before
    assert sorted(fp.write(d)) == ["map", "profile", "summary"]  # released: written


def test_compare_flags_a_result_changed_since_it_was_written(tmp_path, capsys, scan, sim):
    """A simulated profile.csv cut at a line end (a truncated copy, a disk that filled) reads
    as a valid, shorter profile: compare used it and said "ok" (span 2.0 for 2.27 mm). The
    folders' records of written files say it is not what tactileskin wrote: suspect, exit 3."""
    from tactileskin import ownership

    film = tmp_path / "film"
    assert main(["film", "analyze", str(scan), "--out", str(film)]) == 0
    for n in ("profile.csv", "summary.json"):  # as a solve records its files
        ownership.record_file(sim / n)
    assert main(["film", "compare", str(film), str(sim)]) == 0
    capsys.readouterr()
    lines = (sim / "profile.csv").read_text().splitlines(keepends=True)
    (sim / "profile.csv").write_text("".join(lines[:20]))  # s up to 1.9 mm of 6
    assert main(["film", "compare", str(film), str(sim)]) == 3
    assert "warning: simulation: profile.csv changed since tactileskin wrote it" in capsys.readouterr().err
    doc = json.loads((film / "comparison.json").read_text())
    assert doc["status"] == "suspect" and any("profile.csv changed" in w for w in doc["warnings"])
    # the film's own profile, damaged the same way
    (sim / "profile.csv").write_text("".join(lines))
    flines = (film / "profile.csv").read_text().splitlines(keepends=True)
    (film / "profile.csv").write_text("".join(flines[:-5]))
    assert main(["film", "compare", str(film), str(sim)]) == 3
    assert "the film profile is suspect: profile.csv changed since `film analyze` wrote it" in capsys.readouterr().err


def test_the_pressure_map_names_the_profile_it_plots(tmp_path, monkeypatch):
    """--rows centre plots the one row through the peak; its legend said "mean across width", as for
    the rows' mean (the default), so a figure of the centre line read as an average of the rows."""
    from tactileskin.film import plots
    from tactileskin.film.scan import analyze_scan

    img = render_scan(gaussian_profile(0.4, 1.0), background_gs=245)
    labels = []
    monkeypatch.setattr(plots, "_save", lambda fig, path: labels.append(
        [t.get_text() for t in fig.axes[1].get_legend().get_texts()]) or path)
    plots.pressure_map(analyze_scan(img), tmp_path / "all.png")
    plots.pressure_map(analyze_scan(img, rows="centre"), tmp_path / "centre.png")
    assert "mean across width" in labels[0]
    assert "mean across width" not in labels[1] and any("row through the peak" in t for t in labels[1]), labels


def test_a_centre_row_profile_leaves_its_spread_empty(tmp_path, scan, sim):
    """--rows centre reads one row: its pressure_sd (the spread across the width) was written as
    a column of 0 (a spread of one value), as if the film were uniform across the strip. It is
    left empty, as the band columns are without a band; the rows' mean keeps its spread, and
    `film compare` reads both folders (it reads s_mm and pressure)."""
    import csv

    def columns(folder):
        with open(folder / "profile.csv", newline="") as f:
            return list(csv.DictReader(f))

    for rows in ("all", "centre"):
        film = tmp_path / rows
        # a box inside the uniform strip: found automatically, its centre row is the strip's edge
        # row, whose noise against the white row beside it makes the profile suspect
        assert main(["film", "analyze", str(scan), "--rows", rows, "--box-px", "40", "20", "120", "50",
                     "--out", str(film)]) == 0
        table = columns(film)
        assert len(table) > 10 and all(float(r["pressure_mpa_per_mm"]) >= 0 for r in table)
        sd = [r["pressure_sd_mpa_per_mm"] for r in table]
        if rows == "centre":
            assert sd == [""] * len(table)
        else:
            assert max(float(v) for v in sd) > 0
        assert main(["film", "compare", str(film), str(sim)]) == 0


@pytest.mark.parametrize("out, plot, needle", [
    ("c.json", "c.svg", "--plot"),   # was written: PNG bytes in a file named .svg
    ("c.json", "c.pdf", "--plot"),
    ("c.csv", None, "--out"),        # was written: the calibration JSON in a file named .csv
])
def test_calibrate_refuses_a_file_name_of_another_format(tmp_path, capsys, out, plot, needle):
    (tmp_path / "cal.csv").write_text("force_n,area_mm2,gray\n30,100,40\n17,100,120\n2,100,220\n")
    args = ["film", "calibrate", str(tmp_path / "cal.csv"), "--out", str(tmp_path / out)]
    if plot:
        args += ["--plot", str(tmp_path / plot)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert needle in err and (".png" if needle == "--plot" else ".json") in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cal.csv"]


@pytest.mark.parametrize("out", [".tactileskin-files.json", "sub/.tactileskin-files.json"])
def test_calibrate_refuses_the_folders_record_as_its_output(tmp_path, capsys, out):
    """-o .tactileskin-files.json passed the .json check: the calibration was written there and
    then replaced by the folder's record of it (exit 0, 'wrote ...', the calibration lost).
    The record's and its lock's names are refused before the fit, nothing written."""
    (tmp_path / "cal.csv").write_text("force_n,area_mm2,gray\n30,100,40\n17,100,120\n2,100,220\n")
    assert main(["film", "calibrate", str(tmp_path / "cal.csv"), "--out", str(tmp_path / out)]) == 2
    assert "record" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cal.csv"]


def test_calibrate_takes_the_names_its_message_asks_for(tmp_path):
    """'-o .json' was refused as 'valid: a path ending in .json' (Path('.json').suffix is ''):
    the name check is the one mesh and export make (ends with), in any case."""
    (tmp_path / "cal.csv").write_text("force_n,area_mm2,gray\n30,100,40\n17,100,120\n2,100,220\n")
    assert main(["film", "calibrate", str(tmp_path / "cal.csv"), "-o", str(tmp_path / ".json"),
                 "--plot", str(tmp_path / "F.PNG")]) == 0
    assert json.loads((tmp_path / ".json").read_text())["model"]
    assert (tmp_path / "F.PNG").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
