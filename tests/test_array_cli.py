"""`tactileskin array`: user mistakes give one line and leave no output folder."""

import pytest

from tactileskin.cli import main
from tactileskin.errors import ParameterError


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


@pytest.fixture
def no_solves(monkeypatch):
    """A config that slipped through would start hours of 3D solves: fail the test instead."""
    from tactileskin.array import chart

    def refuse(*a, **k):
        raise AssertionError("the chart started solving")

    monkeypatch.setattr(chart, "compute", refuse)
    monkeypatch.setattr(chart, "validate_surrogate", refuse)


@pytest.mark.parametrize("text, words", [
    ("[array]\nthicknesses = \"x\"\n", ["thicknesses", "a list of numbers > 0 mm"]),   # was a ValueError traceback
    ("[array]\nseed = \"x\"\n", ["seed='x'", "an integer >= 0"]),                       # ditto
    ("[array]\npitches = \"abc\"\n", ["pitches", "[0.0809, 20] mm"]),   # was "ufunc 'isfinite'..."; the memory's bound
    ("[array]\nnoise_fs = \"abc\"\n", ["noise_fs", "[0, 1] x full scale"]),
    ("[array]\nmax_depth = \"abc\"\n", ["max_depth='abc'", "> 0 mm"]),
    ("[array]\nthicknesses = [1, \"x\"]\n", ["thicknesses", "'x'", "> 0 mm"]),
    ("[array]\ntaxel_fraction = \"a\"\n", ["taxel_fraction", "[0, 1]"]),
    ("[array]\nletters = 5\n", ["letters=5", "a-z, 0-9"]),
    ("[array]\nsets = \"papr\"\n", ["sets (--set)='papr'", "paper or letters or shapes"]),  # was set='p'
    ("[array]\nmaterials = \"silicon\"\n", ["material='silicon'"]),                   # was material='c'
    ("[array]\nwindow = -1\n", ["window=-1", ">= 0 mm"]),                            # solved 3 cases, then named n
    ("[array]\ntemplate_grid = 0\n", ["template_grid=0", ">= 1"]),
    ("[array]\nmesh_size = 0\n", ["mesh_size=0", "[0.01, 5] mm"]),
    ("[array]\nstandard = 1\n", ["standard=1"]),
    ("[array]\nvalidate = 3\n", ["validate=3", "a list of strings"]),
])
def test_config_values_are_checked_by_key_before_any_solve(tmp_path, capsys, no_solves, text, words):
    cfg = tmp_path / "a.toml"
    cfg.write_text(text)
    assert main(["array", "-o", str(tmp_path / "o"), "--config", str(cfg)]) == 2
    raw = capsys.readouterr().err
    err = " ".join(raw.split())
    assert all(w in err for w in words) and "Traceback" not in err, err
    assert raw.startswith("error:")
    assert not (tmp_path / "o").exists()


def test_a_binary_config_is_one_line(tmp_path, capsys, no_solves):
    cfg = tmp_path / "a.toml"
    cfg.write_bytes(b"\xff\xfe[array]\x00\x81")  # was a UnicodeDecodeError traceback
    assert main(["array", "-o", str(tmp_path / "o"), "--config", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert "config=" in err and "a UTF-8 text file" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_a_single_value_in_a_config_is_a_one_element_list_as_on_the_command_line(tmp_path):
    """A string was iterated per character (sets = "paper" -> set='p')."""
    from tactileskin.array.chart import ChartConfig
    from tactileskin.cli.array import load_config

    p = tmp_path / "a.toml"
    p.write_text('[array]\nthicknesses = 1\nsets = "paper, letters"\nmaterials = "silicone"\nvalidate = "l"\n')
    kw = load_config(p)
    assert kw["thicknesses"] == (1,) and kw["sets"] == ("paper", "letters") and kw["validate"] == ("l",)
    assert ChartConfig(**{k: v for k, v in kw.items() if k != "validate"}).materials == ("silicone",)


@pytest.mark.parametrize("text", ["", "# a chart\n", "[array]\n"])
def test_an_empty_config_is_refused(tmp_path, capsys, no_solves, text):
    """An empty config silently started the default chart (36 full 3D solves, hours)."""
    cfg = tmp_path / "a.toml"
    cfg.write_text(text)
    assert main(["array", "-o", str(tmp_path / "o"), "--config", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert "config=" in err and "at least one setting" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_a_value_listed_twice_is_refused(tmp_path, capsys):
    """-t 1,1 (or a repeated pitch, noise, material, set) wrote every row of accuracies.csv
    twice; [1, 3, 1] is likely a typo for [1, 3, 5]: refused, naming the list, as a sweep does."""
    from tactileskin.array.chart import ChartConfig

    for kw, name in ((dict(thicknesses=(1, 1.0, 3)), "thicknesses"), (dict(pitches=(1, 2, 1)), "pitches"),
                     (dict(noise_fs=(0.01, 0.01)), "noise_fs"), (dict(materials=("silicone",) * 2), "materials"),
                     (dict(sets=("paper", "paper")), "sets")):
        with pytest.raises(ParameterError, match=f"{name}.*distinct values"):
            ChartConfig(**kw)
    out = tmp_path / "o"
    assert main(["array", "-t", "1,1", "--set", "paper", "-o", str(out)]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert "listed twice" in err and "Traceback" not in err and not out.exists()


@pytest.mark.parametrize("flags, words", [
    # LDA's covariance of 161 x 161 taxels is 5 GB a copy: a MemoryError traceback after the solves
    (["--pitch", "0.05,1"], ["pitches (--pitch)=0.05", "[0.08", "8 mm window", "memory"]),
    # the readings of 1e8 offsets filled the memory after the solves
    (["--offsets", "100000000"], ["n_train (--offsets)=100000000", "an integer in [2, "]),
])
def test_a_chart_too_big_for_memory_is_refused_before_any_solve(tmp_path, capsys, no_solves, flags, words):
    out = tmp_path / "o"
    assert main(["array", "--set", "paper", "-t", "1", "-o", str(out), *flags]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert all(w in err for w in words) and "Traceback" not in err, err
    assert not out.exists()


def test_the_memory_rule_keeps_the_default_chart_and_its_finest_allowed_pitch():
    from tactileskin.array import classify
    from tactileskin.array.chart import ChartConfig
    from tactileskin.errors import ParameterError

    ChartConfig()  # the default chart is far within it
    msg = ""
    try:
        ChartConfig(pitches=(0.05,), sets=("letters",))
    except ParameterError as e:
        msg = str(e)
    p = float(msg.split("[")[1].split(",")[0])
    cfg = ChartConfig(pitches=(p,), sets=("letters",))  # the pitch the message quotes is accepted
    assert classify.memory_bytes(36, cfg.spec(p).n ** 2, 16, 16, 4) <= classify.MAX_BYTES
    with pytest.raises(ParameterError, match="template_grid"):
        ChartConfig(pitches=(1.0,), template_grid=2000)
    # templates that fit with one test offset but not with two: template_grid named, not n_train
    # with the empty range "an integer in [2, 1]"
    with pytest.raises(ParameterError, match=r"template_grid=500 .*\[1, \d+\]"):
        ChartConfig(pitches=(4.0,), sets=("letters",), template_grid=500, n_train=2, n_test=2)


def test_the_validate_option_has_the_config_keys_limit(tmp_path, capsys, no_solves):
    """--validate took any number of texts (each a full 3D solve per thickness); the config's
    `validate` key is capped at MAX_TEXTS."""
    from tactileskin.cli.array import MAX_TEXTS

    out = tmp_path / "o"
    texts = ",".join(["l"] * (MAX_TEXTS + 1))
    assert main(["array", "--set", "letters", "-t", "1", "--pitch", "4", "-o", str(out), "--validate", texts]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert "validate" in err and f"at most {MAX_TEXTS}" in err and "Traceback" not in err, err
    assert not out.exists()
    # a repeated text (its rows were written twice) and an empty list (silently nothing) are refused
    for arg, words in (("l,r,l", "listed twice"), ("", "at least 1")):
        assert main(["array", "--set", "letters", "-t", "1", "--pitch", "4", "-o", str(out), "--validate", arg]) == 2
        err = " ".join(capsys.readouterr().err.split())
        assert "validate" in err and words in err and "Traceback" not in err, err
        assert not out.exists()


def test_the_fallback_help_says_the_run_rows_join_the_projects_measurements():
    """Since e5616da a run's --validate rows join data/surrogate_validation.json (the worse
    counts); --help and the README still said 'this run's --validate, else the project's'."""
    from pathlib import Path

    from click.testing import CliRunner

    from tactileskin.cli import cli

    text = " ".join(CliRunner().invoke(cli, ["array", "--help"]).output.split())
    assert "else the project's" not in text and "together with the project's measurements" in text
    root = Path(__file__).resolve().parents[1]
    for doc in ("README.md", "docs/commands.md"):  # the array cell moved to docs/commands.md
        assert "rows first, else the project's" not in " ".join((root / doc).read_text(encoding="utf-8").split())
    assert "this run's `--validate` rows together with the project's measurements" in " ".join(
        (root / "docs" / "commands.md").read_text(encoding="utf-8").split())


def test_the_help_says_what_pitch_and_full_scale_are():
    """--help read 'Array pitches (mm)' and 'Noise std as fractions of full scale' without saying
    that a pitch is the taxels' centre-to-centre spacing or what the full scale is (the set's
    largest pressure, per thickness: 0.042 MPa at t = 1, 0.032 at t = 2 for the letters)."""
    from click.testing import CliRunner

    from tactileskin.cli import cli

    text = " ".join(CliRunner().invoke(cli, ["array", "--help"]).output.split())
    assert "taxel centre to centre" in text
    assert "each set's largest pressure at that thickness" in text


def test_the_readme_names_every_column_of_accuracies_csv():
    """accuracies.csv's `n_test` (test readings per stimulus) was explained nowhere, nor were
    most of its columns: the README named only `status`. (The column list moved from the
    README's Commands table to docs/commands.md.)"""
    import re
    from pathlib import Path

    from tactileskin.array.chart import Chart, ChartConfig

    header = Chart(ChartConfig()).to_csv().splitlines()[0].split(",")
    doc = " ".join((Path(__file__).resolve().parents[1] / "docs" / "commands.md").read_text(encoding="utf-8").split())
    cell = re.search(r"- `accuracies\.csv`: (.*?) - `array_chart\.md`", doc).group(1)
    assert "n_test" in header and [c for c in header if f"`{c}`" not in cell] == []
    assert "test readings per stimulus" in cell


def test_the_pitch_range_states_the_bound_the_memory_rule_keeps(tmp_path, capsys, no_solves):
    """--pitch 0.04 was refused with "valid: [0.05, 20] mm", then --pitch 0.05 by the memory rule
    (">= 0.0809 mm over the 8 mm window"): the range must state the finest pitch this chart's
    window, sets and offsets allow, and that pitch must be accepted."""
    from tactileskin.array.chart import ChartConfig
    from tactileskin.errors import ParameterError

    out = tmp_path / "o"
    assert main(["array", "--set", "paper", "-t", "1", "-o", str(out), "--pitch", "0.04"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    lo = float(err.split("[")[1].split(",")[0])
    assert lo > 0.05 and "8 mm window" in err, err
    ChartConfig(pitches=(lo,), sets=("paper",))  # the bound it states is accepted
    with pytest.raises(ParameterError, match="memory"):
        ChartConfig(pitches=(0.95 * lo,), sets=("paper",))
    # a small window keeps the sampler's own 0.05 mm
    with pytest.raises(ParameterError, match=r"\[0\.05, 20\] mm"):
        ChartConfig(pitches=(0.04,), window=2.0)
    ChartConfig(pitches=(0.05,), window=2.0)
    assert not out.exists()
