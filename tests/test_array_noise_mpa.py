"""`--noise-mpa`: the chart's noise as a fixed std in MPa (a real sensor's noise floor), the
same at every thickness and set, instead of a fraction of each set's full scale."""

from types import SimpleNamespace

import numpy as np
import pytest

from tactileskin.array import chart, maps
from tactileskin.cli import main
from tactileskin.errors import ParameterError

GRID = np.linspace(-8, 8, 161)
WIDTH = {"flat": 3.0, "curved": 1.5, "braille": 0.4}  # three told-apart analytic stimuli


def _fake_solves(monkeypatch, asked: list):
    """No solve: each scene's bone profile and map are Gaussians of its indenter's width, and
    their peak falls with the thickness (so each thickness has its own full scale)."""
    def fake_solve(scenes, cache, on_event=None, workers=None):
        asked.extend(scenes)
        return {sc: SimpleNamespace(s=GRID, pressure=np.exp(-GRID ** 2 / WIDTH[sc.indenter] ** 2) / sc.thickness,
                                    scene=sc, path=None, summary={}) for sc in scenes}

    monkeypatch.setattr(chart, "solve_cached", fake_solve)
    monkeypatch.setattr(chart, "bone_map_of", lambda rec: maps.on_grid(
        lambda s, z: np.exp(-(s * s + z * z) / WIDTH[rec.scene.indenter] ** 2) / rec.scene.thickness, GRID, GRID))


CFG = dict(thicknesses=(1.0, 2.0), sets=("paper",), pitches=(0.5,), n_train=4, n_test=4, template_grid=2)


def test_the_noise_in_mpa_is_the_same_at_every_thickness_and_is_applied(monkeypatch):
    asked, said = [], []
    _fake_solves(monkeypatch, asked)
    cfg = chart.ChartConfig(**CFG, noise_mpa=(0.002, 5.0))
    assert cfg.noise_fs is None and cfg.noise_levels == (0.002, 5.0)
    ch = chart.compute(cfg, cache=None, progress=said.append)
    for t in (1.0, 2.0):
        rows = [r for r in ch.rows if r["thickness_mm"] == t]
        assert {r["noise_mpa"] for r in rows} == {0.002, 5.0}  # exactly as given, not a fraction of full scale
        for r in rows:  # its fraction of this thickness's full scale (1 / t here)
            assert r["full_scale_mpa"] == pytest.approx(1.0 / t)
            assert r["noise_fs"] == pytest.approx(r["noise_mpa"] * t)
        # looked up on the MPa axis; 5 MPa over a 1 / t MPa full scale leaves chance, 2 kPa does not
        assert ch.accuracy("silicone", t, "paper", 0.5, 0.002) == 1.0
        assert ch.accuracy("silicone", t, "paper", 0.5, 5.0) < 0.7
    # a noise level the chart was not made for (0.02 for 0.002) read NaN, silently
    with pytest.raises(ParameterError, match=r"noise=0\.02 is invalid; valid: one the chart was made for: 0\.002, 5"):
        ch.accuracy("silicone", 1.0, "paper", 0.5, 0.02)
    for args, name in ((("polyurethane", 1.0, "paper", 0.5, 0.002), "material"), (("silicone", 3.0, "paper", 0.5, 0.002), "t"),
                       (("silicone", 1.0, "letters", 0.5, 0.002), "set_"), (("silicone", 1.0, "paper", 1.5, 0.002), "pitch")):
        with pytest.raises(ParameterError, match=f"^{name}="):
            ch.accuracy(*args)
    with pytest.raises(ParameterError, match="^method="):
        ch.accuracy("silicone", 1.0, "paper", 0.5, 0.002, method="svm")
    assert "  silicone, t = 2 mm, paper: accuracy at noise 0.002, 5 MPa" in said
    # the noise is read after the solves: the same scenes (cache keys) as a chart in x full scale
    fs_asked = []
    _fake_solves(monkeypatch, fs_asked)
    chart.compute(chart.ChartConfig(**CFG), cache=None)
    assert fs_asked == asked


def test_cli_noise_mpa_reaches_the_report_and_the_csv(tmp_path, monkeypatch, close_figures):
    _fake_solves(monkeypatch, [])
    out = tmp_path / "o"
    rc = main(["array", "-o", str(out), "-t", "1,2", "--set", "paper", "--pitch", "0.5", "--offsets", "4",
               "--noise-mpa", "0.002"])
    assert rc == 0
    md = (out / "array_chart.md").read_text(encoding="utf-8")
    assert "Gaussian noise of a fixed std in MPa (--noise-mpa)" in md
    # the MPa column as given at both thicknesses; the fraction of each full scale derived
    assert "| 1 | 0.002 | 0.002 | **1.00** |" in md and "| 2 | 0.004 | 0.002 | **1.00** |" in md
    import csv

    rows = list(csv.DictReader((out / "accuracies.csv").open()))
    assert {r["noise_mpa"] for r in rows} == {"0.002"} and {r["noise_fs"] for r in rows} == {"0.002", "0.004"}


@pytest.mark.parametrize("flags, config, words", [
    (["--noise-mpa", "0"], None, ["noise_mpa (--noise-mpa)=0.0", "(0, 10000] MPa"]),
    (["--noise-mpa", "-0.1"], None, ["noise_mpa (--noise-mpa)=-0.1", "(0, 10000] MPa"]),
    (["--noise-mpa", "inf"], None, ["noise_mpa (--noise-mpa)='inf'", "finite numbers"]),
    # was charted (accuracy at chance, status ok) with noise_fs = inf in accuracies.csv
    (["--noise-mpa", "1e308"], None, ["noise_mpa (--noise-mpa)=1e+308", "(0, 10000] MPa"]),
    (["--noise", "0.01", "--noise-mpa", "0.001"], None, ["noise_mpa (--noise-mpa)", "not with --noise"]),
    ([], "[array]\nnoise_fs = [0.01]\nnoise_mpa = [0.001]\n", ["noise_mpa (--noise-mpa)", "not with noise_fs"]),
    ([], "[array]\nnoise_mpa = \"x\"\n", ["noise_mpa (--noise-mpa)='x'", "(0, 10000] MPa"]),
    # --noise is a fraction of full scale: 5 (meant as 5 %) charted 500 % noise, accuracy at
    # chance, after the chart's 42 solves
    (["--noise", "5"], None, ["noise_fs (--noise)=5.0", "[0, 1] x full scale", "0.05 is 5 %"]),
    (["--noise", "0.01,1.5"], None, ["noise_fs (--noise)=1.5", "[0, 1] x full scale"]),
    ([], "[array]\nnoise_fs = [10]\n", ["noise_fs (--noise)=10", "[0, 1] x full scale"]),
])
def test_bad_noise_mpa_is_one_line_before_any_solve(tmp_path, capsys, monkeypatch, flags, config, words):
    def refuse(*a, **k):
        raise AssertionError("the chart started solving")

    monkeypatch.setattr(chart, "compute", refuse)
    if config:
        (tmp_path / "a.toml").write_text(config)
        flags = [*flags, "--config", str(tmp_path / "a.toml")]
    assert main(["array", "-o", str(tmp_path / "o"), "--set", "paper", "-t", "1", *flags]) == 2
    raw = capsys.readouterr().err
    err = " ".join(raw.split())
    assert raw.startswith("error:") and all(w in err for w in words) and "Traceback" not in err, err
    assert not (tmp_path / "o").exists()


def test_a_noise_flag_replaces_the_configs_noise_axis(tmp_path, monkeypatch):
    """--noise-mpa with a config holding noise_fs (or --noise with noise_mpa): the flag's axis,
    as flags override the config elsewhere, not a refusal of two axes."""
    seen = []
    monkeypatch.setattr(chart, "compute", lambda cfg, *a, **k: seen.append(cfg) or (_ for _ in ()).throw(
        chart.ParameterError("stop", 0, "-")))
    (tmp_path / "a.toml").write_text("[array]\nnoise_fs = [0.01]\n")
    main(["array", "-o", str(tmp_path / "o"), "--config", str(tmp_path / "a.toml"), "--noise-mpa", "0.001"])
    (tmp_path / "b.toml").write_text("[array]\nnoise_mpa = [0.001]\n")
    main(["array", "-o", str(tmp_path / "o"), "--config", str(tmp_path / "b.toml"), "--noise", "0.05"])
    assert [(c.noise_fs, c.noise_mpa) for c in seen] == [(None, (0.001,)), ((0.05,), None)]
