"""`tactileskin array`: user mistakes give one line and leave no output folder."""

import pytest

from tactileskin.cli import main


def test_bad_pitch_is_one_line_and_no_output(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["array", "-o", str(out), "--pitch", "0"]) == 2
    err = capsys.readouterr().err
    assert "pitch" in err and "Traceback" not in err
    assert not out.exists()


def test_unknown_config_key(tmp_path, capsys):
    cfg = tmp_path / "a.toml"
    cfg.write_text("[array]\npitchez = [1.0]\n")
    assert main(["array", "-o", str(tmp_path / "o"), "--config", str(cfg)]) == 2
    assert "pitchez" in capsys.readouterr().err


@pytest.mark.parametrize("text, words", [
    ("thicknesses = [1]\npitches = [1]\n", ["'pitches' outside the [array] table"]),  # no [array]: read as nothing
    ("foo = 1\n[array]\npitches = [1.0]\n", ["'foo' outside the [array] table"]),
])
def test_config_keys_outside_the_array_table_are_refused(tmp_path, capsys, text, words):
    """Settings outside [array] were ignored, and the whole default chart (36 full 3D letter
    solves) started; refused before any solve."""
    cfg = tmp_path / "a.toml"
    cfg.write_text(text)
    assert main(["array", "-o", str(tmp_path / "o"), "--config", str(cfg)]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert all(w in err for w in words) and "Traceback" not in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("flags, words", [
    (["--offsets", "1"], ["n_train (--offsets)=1", ">= 2"]),   # LDA: more readings than classes
    (["--bits", "0"], ["bits=0", "[1, 32]"]),                   # checked only after the solves before
])
def test_classifier_settings_are_checked_before_any_solve(tmp_path, capsys, flags, words):
    out = tmp_path / "o"
    assert main(["array", "--set", "paper", "-t", "1", "--pitch", "1", "-o", str(out), *flags]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert all(w in err for w in words) and "Traceback" not in err
    assert not out.exists()


def test_bad_fallback_in_a_config_is_one_line(tmp_path, capsys):
    cfg = tmp_path / "a.toml"
    cfg.write_text('[array]\nfallback = "sometimes"\n')
    assert main(["array", "-o", str(tmp_path / "o"), "--config", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert "fallback" in err and "true or false" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_refuses_a_foreign_folder(tmp_path, capsys):
    out = tmp_path / "o"
    out.mkdir()
    (out / "mine.txt").write_text("x")
    assert main(["array", "-o", str(out), "-t", "1", "--set", "paper"]) != 0
    assert (out / "mine.txt").read_text() == "x" and sorted(p.name for p in out.iterdir()) == ["mine.txt"]


@pytest.mark.slow
def test_a_chart_on_an_unvalidated_surrogate_is_written_and_exits_suspect(tmp_path, capsys):
    """A real (coarse) run: letters at t = 0.5 on a mesh nobody validated the surrogate on: the
    chart is written, says so, and the command exits 3 like a suspect solve or sweep."""
    out = tmp_path / "chart"
    rc = main(["array", "-o", str(out), "-t", "0.5", "-m", "polyurethane", "--set", "letters", "--letters", "abc",
               "--pitch", "0.5", "--noise", "0.01", "--offsets", "2", "--mesh-size", "1.6"])
    assert rc == 3
    md = (out / "array_chart.md").read_text(encoding="utf-8")
    assert "| 0.5 † | 0.01 |" in md and "not validated: indicative only" in md
    assert "suspect: polyurethane" in capsys.readouterr().err
