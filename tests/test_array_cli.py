"""`tactileskin array`: user mistakes give one line and leave no output folder."""

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


def test_refuses_a_foreign_folder(tmp_path, capsys):
    out = tmp_path / "o"
    out.mkdir()
    (out / "mine.txt").write_text("x")
    assert main(["array", "-o", str(out), "-t", "1", "--set", "paper"]) != 0
    assert (out / "mine.txt").read_text() == "x" and sorted(p.name for p in out.iterdir()) == ["mine.txt"]
