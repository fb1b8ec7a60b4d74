"""Film inputs checked with one-line errors (no traceback, nothing written): non-finite or
out-of-range options, malformed calibration JSON and CSV, degenerate presses, inverted
ranges; strict JSON out; output folders claimed with outdir."""

import json

import numpy as np
import pytest

from tactileskin.cli import main
from tactileskin.errors import ParameterError
from tactileskin.film import analyze_scan, calibrate_csv, fit_calibration, inputs, load_calibration
from tactileskin.film.calibration import Calibration
from tactileskin.film.synthetic import gaussian_profile, render_scan, save_scan


def _strict(text):
    def bad(tok):
        raise AssertionError(f"non-strict JSON token {tok}")
    return json.loads(text, parse_constant=bad)


@pytest.fixture
def scan(tmp_path):
    return save_scan(render_scan(gaussian_profile(0.4, 1.0), background_gs=245), tmp_path / "s.png")


def _fails(capsys, argv, *needles):
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 2, err
    assert "Traceback" not in err and "rror:" in err
    flat = err.replace("\n", "")   # the console wraps long lines
    for n in needles:
        assert n in flat, err
    return err


def test_a_box_in_mm_outside_the_image_states_the_range_in_mm(tmp_path, capsys, scan):
    """--box-mm -1 0 2 2 said "valid: 0 <= x0 < x1 <= 128, ... px": pixels for an option in mm."""
    from PIL import Image

    w, h = Image.open(scan).size
    err = _fails(capsys, ["film", "analyze", str(scan), "--px-per-mm", "8", "--box-mm", "-1", "0", "2", "2",
                          "--out", str(tmp_path / "o")], "box_mm")
    flat = " ".join(err.split())
    assert f"0 <= x0 < x1 <= {w / 8:.4g}, 0 <= y0 < y1 <= {h / 8:.4g} mm" in flat, flat
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("box, needles", [
    # ordered as given, but under a pixel: it said "(x1 <= x0 or y1 <= y0)"
    (["0", "0", "0.01", "0.01"], ["box_mm", "x1 - x0 and y1 - y0 >= 0.125 mm", "--box-mm is rounded to pixel edges",
                                  "x 0-0, y 0-0 px"]),
    # a pixel wide but under 3 along the strip: it said "region length=2 ... >= 3 px", no option named
    (["5", "2", "5.3", "7"], ["box_mm", ">= 0.375 mm along the strip (x)", "--box-mm", "2 px along it"]),
])
def test_a_box_in_mm_too_small_for_its_pixels_says_how_small_it_may_be(tmp_path, capsys, scan, box, needles):
    err = _fails(capsys, ["film", "analyze", str(scan), "--px-per-mm", "8", "--box-mm", *box,
                          "--out", str(tmp_path / "o")], *needles)
    assert "x1 <= x0" not in err and "region length" not in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("opts, needle", [
    (["--px-per-mm", "inf"], "px_per_mm"),
    (["--px-per-mm", "nan"], "px_per_mm"),
    (["--px-per-mm", "0"], "px_per_mm"),
    (["--px-per-mm", "-8"], "px_per_mm"),
    (["--px-per-mm", "1e300"], "px_per_mm"),
    (["--box-mm", "nan", "0", "10", "5"], "box_mm"),
    (["--box-mm", "0", "0", "inf", "5"], "box_mm"),
    (["--box-mm", "0", "0", "1e300", "5"], "box_mm"),
    (["--box-mm", "0", "0", "1e308", "1e308"], "box_mm"),  # x px/mm overflows: was an OverflowError
    (["--box-px", "50", "0", "40", "10"], "x1 <= x0"),
    (["--box-px", "0", "0", "500", "10"], "outside"),
    (["--box-px", "-1", "0", "10", "10"], "box_px"),
    (["--centre", "inf"], "centre"),
    (["--centre", "nan"], "centre"),
    (["--centre", "1e9"], "inside the image"),
    (["--centre", "-1"], "centre"),
    (["--centre", "middle"], "--centre"),
])
def test_bad_analyze_options_are_one_line_errors(tmp_path, capsys, scan, opts, needle):
    _fails(capsys, ["film", "analyze", str(scan), *opts, "--out", str(tmp_path / "o")], needle)
    assert not (tmp_path / "o").exists()


def test_library_checks_the_same(scan):
    with pytest.raises(ParameterError, match="box_px"):
        analyze_scan(scan, box_px=(0.5, 0, 10, 10))
    with pytest.raises(ParameterError, match="box_px"):
        analyze_scan(scan, box_px=(0, 0, 10))
    with pytest.raises(ParameterError, match="centre"):
        analyze_scan(scan, centre=float("inf"))


GOOD = Calibration(name="c", model="linear", params=(-0.004, 0.95), gs_range=(20.0, 230.0),
                   p_range=(0.0, 0.87)).to_dict()


@pytest.mark.parametrize("text, needle", [
    ("not json {", "not JSON"),
    ("[1, 2]", "JSON object"),
    (json.dumps({**GOOD, "params": "abc"}), "params"),
    (json.dumps({**GOOD, "params": [1.0]}), "params"),
    (json.dumps({**GOOD, "params": [True, 1.0]}), "params"),
    (json.dumps({k: v for k, v in GOOD.items() if k != "gs_range"}), "gs_range"),
    (json.dumps({**GOOD, "gs_range": [230, 20]}), "inverted"),
    (json.dumps({**GOOD, "p_range": [0.87, 0.0]}), "inverted"),
    (json.dumps({**GOOD, "model": "cubic"}), "model"),
    (json.dumps({**GOOD, "cov": [[1, 2]]}), "cov"),
    (json.dumps({**GOOD, "dof": "many"}), "dof"),
    (json.dumps(GOOD).replace("-0.004", "NaN"), "NaN is not a number"),
    (json.dumps(GOOD).replace("0.95", "Infinity"), "Infinity is not a number"),
    (json.dumps(GOOD).replace("0.95", "1e400"), "params"),   # parses as inf
    (b"\xff\xfe\x00bad", "not UTF-8"),
])
def test_malformed_calibration_json(tmp_path, capsys, scan, text, needle):
    p = tmp_path / "cal.json"
    p.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(ParameterError, match="calibration") as ei:
        load_calibration(p)
    assert str(p) in str(ei.value) and needle in str(ei.value)
    _fails(capsys, ["film", "analyze", str(scan), "-c", str(p), "--out", str(tmp_path / "o")],
           str(p), needle)


def test_good_calibration_json_loads_and_oversized_file_is_refused(tmp_path, monkeypatch):
    p = tmp_path / "cal.json"
    p.write_text(json.dumps(GOOD))
    assert load_calibration(p).params == (-0.004, 0.95)
    monkeypatch.setattr(inputs, "MAX_TEXT_BYTES", 100)
    with pytest.raises(ParameterError, match="larger than"):
        load_calibration(p)
    (tmp_path / "cal.csv").write_text(HEADER + ROWS * 10)
    with pytest.raises(ParameterError, match="calibration CSV.*larger than"):
        calibrate_csv(tmp_path / "cal.csv")


HEADER = "force_n,area_mm2,gray\n"
ROWS = "30,100,40\n20,100,100\n10,100,160\n2,100,220\n"


@pytest.mark.parametrize("body, needle", [
    (HEADER + ROWS + "5,100,120,extra\n", "line 6"),
    (HEADER + ROWS + "5,100,nan\n", "gray (cal.csv line 6)"),
    (HEADER + ROWS + "inf,100,120\n", "force_n (cal.csv line 6)"),
    (HEADER + ROWS + "5,,120\n", "area_mm2 (cal.csv line 6)"),
    (HEADER + ROWS + "5,100,300\n", "[0, 255]"),
    # F / A past any film: an OverflowError in the fit, or a fit of 4e-307 MPa written as ok
    (HEADER + ROWS + "1e308,100,120\n", "force_n/area_mm2 (cal.csv line 6)"),
    (HEADER + ROWS + "5,1e308,120\n", "force_n/area_mm2 (cal.csv line 6)"),
    (HEADER + ROWS + "1e5,0.001,120\n", "[1e-06, 10000] MPa"),
    (HEADER + ROWS + "5,100,abc\n", "gray (cal.csv line 6)"),
    ("force_n,area_mm2,image,x0,y0,x1,y1\n30,100,p.png,0,0,zz,4\n", "crop"),
    (HEADER + "5,100,10\n5,100,100\n5,100,200\n", "same force per area"),
    (HEADER + "30,100,90\n20,100,90\n10,100,90\n", "same grayscale"),
    (HEADER + "30,100,40\n", "calibration points=1"),
    (HEADER + "30,100,40\n10,100,160\n", "calibration points=2"),
    ("", "header"),
    # both: the gray value was used and the image silently ignored
    ("force_n,area_mm2,gray,image\n30,100,40,p.png\n20,100,100,p.png\n10,100,160,p.png\n", "not both"),
])
def test_bad_calibration_csv(tmp_path, capsys, body, needle):
    from PIL import Image
    Image.fromarray(np.full((4, 4), 90, np.uint8)).save(tmp_path / "p.png")
    (tmp_path / "cal.csv").write_text(body)
    with pytest.raises(ParameterError) as ei:
        calibrate_csv(tmp_path / "cal.csv")
    assert needle in str(ei.value)
    _fails(capsys, ["film", "calibrate", str(tmp_path / "cal.csv"), "--out",
                    str(tmp_path / "c.json")], needle)
    assert not (tmp_path / "c.json").exists()


def test_non_utf8_csv(tmp_path):
    (tmp_path / "cal.csv").write_bytes(HEADER.encode() + b"\xff\xff,1,2\n")
    with pytest.raises(ParameterError, match="not UTF-8"):
        calibrate_csv(tmp_path / "cal.csv")


def test_three_presses_write_strict_json(tmp_path, capsys):
    # three points: the quadratic has no degrees of freedom left, so its adjusted R^2 and
    # AICc are undefined; they are written as null, never as NaN
    (tmp_path / "cal.csv").write_text(HEADER + "30,100,40\n17,100,120\n2,100,220\n")
    assert main(["film", "calibrate", str(tmp_path / "cal.csv"), "--out",
                 str(tmp_path / "c.json")]) == 0
    d = _strict((tmp_path / "c.json").read_text())
    quad = next(a for a in d["report"]["alternatives"] if a["model"] == "quadratic")
    assert quad["r2_adj"] is None and quad["aicc"] is None
    assert load_calibration(tmp_path / "c.json").model == d["model"]


def test_inverted_activation_range_is_refused(tmp_path, capsys):
    (tmp_path / "cal.csv").write_text(HEADER + ROWS)
    _fails(capsys, ["film", "calibrate", str(tmp_path / "cal.csv"), "--activation-range",
                    "0.3", "0.0", "--out", str(tmp_path / "c.json")], "activation_range", "inverted")
    _fails(capsys, ["film", "calibrate", str(tmp_path / "cal.csv"), "--activation-range",
                    "0", "inf", "--out", str(tmp_path / "c.json")], "activation_range")
    assert not (tmp_path / "c.json").exists()
    with pytest.raises(ParameterError, match="gs_range.*inverted"):
        Calibration(name="x", model="linear", params=(-0.004, 0.95), gs_range=(200.0, 20.0),
                    p_range=(0.0, 0.9))
    with pytest.raises(ParameterError, match="calibration pressure"):
        fit_calibration([40, 100, 160], [0.2, 0.2, 0.2])


@pytest.mark.parametrize("value", [0.95, 0.5, 90, "high", None, True])
def test_a_calibration_confidence_other_than_the_bands_level_is_refused(tmp_path, value):
    """`confidence` (0.9, written by film calibrate) is the level of the bands computed from the
    file's cov and dof, always models.CONFIDENCE; any other value was accepted and never read,
    so a file claiming 95 % bands got 90 % ones silently. It is now refused naming the field."""
    from tactileskin.film import models

    p = tmp_path / "cal.json"
    p.write_text(json.dumps({**GOOD, "confidence": value}))
    with pytest.raises(ParameterError, match=r"calibration confidence=.* valid: 0\.9 or absent") as ei:
        load_calibration(p)
    assert str(p) in str(ei.value) and models.CONFIDENCE == 0.9


def test_a_calibration_without_confidence_or_with_its_level_loads(tmp_path):
    p = tmp_path / "cal.json"
    assert GOOD["confidence"] == 0.9
    for doc in (GOOD, {k: v for k, v in GOOD.items() if k != "confidence"}):
        p.write_text(json.dumps(doc))
        assert load_calibration(p).params == (-0.004, 0.95)
