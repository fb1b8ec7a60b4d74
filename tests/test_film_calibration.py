"""Film calibration: Eq. 8 default, linear fit + 90 % bounds against closed forms,
AICc model selection, monotonicity and bad-input errors, JSON and CSV round trips."""

import json

import numpy as np
import pytest
from PIL import Image
from scipy import stats

from tactileskin.errors import ParameterError
from tactileskin.film import calibrate_csv, fit_calibration, load_calibration, paper_eq8
from tactileskin.film import models
from tactileskin.film.calibration import Calibration

GS = np.linspace(30.0, 220.0, 8)


def test_paper_eq8_values_and_clipping():
    cal = paper_eq8()
    assert cal.name == "paper_eq8" and cal.unit == "MPa/mm"
    # Eq. 8 exactly inside the activation range
    assert cal.pressure(100.0) == pytest.approx(-0.00425 * 100 + 0.978, rel=1e-12)
    assert cal.pressure(0.0) == pytest.approx(0.978)
    # lighter than GS = 0.978/0.00425 = 230.1 reads as unactivated film
    assert cal.pressure(240.0) == 0.0
    assert cal.threshold_gs == pytest.approx(0.978 / 0.00425, abs=1e-9)
    assert cal.band(100.0) is None  # the paper gives no bounds


def test_linear_bounds_match_textbook_regression():
    rng = np.random.default_rng(3)
    y = -0.004 * GS + 0.95 + rng.normal(0, 0.01, GS.size)
    cal = fit_calibration(GS, y, model="linear")
    lr = stats.linregress(GS, y)
    n, t = GS.size, stats.t.ppf(0.95, GS.size - 2)
    ci = np.array(cal.report["linear"]["param_ci90"])
    assert cal.params == pytest.approx((lr.slope, lr.intercept), rel=1e-10)
    assert ci[0] == pytest.approx([lr.slope - t * lr.stderr, lr.slope + t * lr.stderr], rel=1e-9)
    assert ci[1] == pytest.approx([lr.intercept - t * lr.intercept_stderr,
                                   lr.intercept + t * lr.intercept_stderr], rel=1e-9)
    # confidence band of the mean: t s sqrt(1/n + (x - xbar)^2 / Sxx)
    s = np.sqrt(np.sum((y - lr.intercept - lr.slope * GS) ** 2) / (n - 2))
    x0 = np.array([40.0, 125.0, 210.0])
    hw = t * s * np.sqrt(1 / n + (x0 - GS.mean()) ** 2 / np.sum((GS - GS.mean()) ** 2))
    lo, hi = cal.band(x0)
    assert (hi - lo) / 2 == pytest.approx(hw, rel=1e-9)
    res = np.array(cal.report["linear"]["residuals"])
    assert res == pytest.approx(y - (lr.intercept + lr.slope * GS), abs=1e-12)


def test_slope_interval_covers_truth_90_percent_of_the_time():
    # 2000 noisy calibrations of 6 presses: the binomial sd of the coverage is
    # sqrt(0.9*0.1/2000) = 0.0067, so +-0.025 (3.7 sd) is a fair two-sided check.
    rng = np.random.default_rng(7)
    x = np.linspace(30, 220, 6)
    hits = 0
    tq = models.fit("linear", x, -0.004 * x + 0.95 + rng.normal(0, 0.02, x.size)).t_factor
    assert tq == pytest.approx(stats.t.ppf(0.95, 4))
    for _ in range(2000):
        fr = models.fit("linear", x, -0.004 * x + 0.95 + rng.normal(0, 0.02, x.size))
        half = tq * np.sqrt(fr.cov[0, 0])  # what param_ci() computes, t hoisted for speed
        hits += abs(fr.params[0] + 0.004) <= half
    assert hits / 2000 == pytest.approx(0.90, abs=0.025)


def test_aicc_picks_linear_for_linear_data_and_exponential_for_exponential():
    rng = np.random.default_rng(11)
    lin = fit_calibration(GS, -0.004 * GS + 0.95 + rng.normal(0, 0.005, GS.size))
    assert lin.model == "linear"
    x = np.linspace(20, 230, 12)
    y = 1.2 * np.exp(-0.012 * x) * (1 + rng.normal(0, 0.005, x.size))
    ex = fit_calibration(x, y)
    assert ex.model == "exponential"
    assert ex.params == pytest.approx((1.2, -0.012), rel=0.02)  # 0.5 % noise on 12 points
    scored = {a["model"]: a["aicc"] for a in ex.report["alternatives"]}
    assert scored["exponential"] < scored["linear"] - 2
    # the inverse map reproduces grayscale inside the calibrated range
    g = np.linspace(25, 225, 9)
    assert ex.grayscale(ex.pressure(g)) == pytest.approx(g, abs=1e-9)


def test_fewer_than_three_points_is_an_error():
    with pytest.raises(ParameterError, match=r"calibration points=2.*>= 3"):
        fit_calibration([50, 150], [0.7, 0.3])


@pytest.mark.parametrize("scale", [1e300, 1e200, 1e160])
def test_pressures_past_what_the_fit_can_square_are_a_parameter_error(scale):
    """From Python (any unit: the CSV path checks MPa), pressures of 1e200-1e300 stopped the fit
    with an OverflowError, and 1e160 gave a band of zero width (J^T J overflowed to inf)."""
    with pytest.raises(ParameterError, match=r"calibration pressure=.*\|P\| <= 1e\+100"):
        fit_calibration([200, 150, 100, 50], [1 * scale, 2.1 * scale, 2.9 * scale, 4 * scale])
    # at the bound the band is the scaled one of unit pressures
    c = fit_calibration([200, 150, 100, 50], [0.25e100, 0.525e100, 0.725e100, 1e100])
    ref = fit_calibration([200, 150, 100, 50], [0.25, 0.525, 0.725, 1.0])
    lo, hi = c.band(np.array([125.0]))
    assert np.allclose([lo[0] / 1e100, hi[0] / 1e100], [b[0] for b in ref.band(np.array([125.0]))], rtol=1e-9)


def test_presses_a_scan_cannot_tell_apart_are_rejected():
    # 1e-4 gray levels apart: fitted a slope of 1e4 MPa per level (overflow warnings), and
    # read 82 % of a normal scan as saturated
    with pytest.raises(ParameterError, match=r"calibration gray=.*200.0001, 200.0003.*at least 2 gray levels"):
        fit_calibration([200.0001, 200.0002, 200.0003], [0.3, 0.17, 0.02])


def test_flat_or_v_shaped_presses_are_rejected():
    x = np.array([40, 80, 120, 160, 200.0])
    with pytest.raises(ParameterError, match="monotonic"):
        fit_calibration(x, [0.2, 0.5, 0.8, 0.5, 0.2])


def test_turning_fit_is_rejected_even_with_a_clear_trend():
    # P = 1 - 0.008 GS + 2.2e-5 GS^2 turns at GS = 182 inside [20, 220]; AICc prefers the
    # quadratic by far, and it is not one-to-one.
    x = np.linspace(20, 220, 11)
    y = 1 - 0.008 * x + 2.2e-5 * x ** 2
    with pytest.raises(ParameterError, match="strictly monotonic"):
        fit_calibration(x, y)
    with pytest.raises(ParameterError, match="strictly monotonic"):
        fit_calibration(x, y, model="quadratic")


def test_outside_range_saturates_dark_and_extrapolates_light():
    cal = fit_calibration(GS, -0.004 * GS + 0.95, model="linear")
    top = -0.004 * GS.min() + 0.95
    assert cal.p_range == pytest.approx((0.0, top))
    assert cal.pressure(5.0) == pytest.approx(top)                # darker: saturated
    assert cal.pressure(225.0) == pytest.approx(-0.004 * 225 + 0.95)  # tangent continuation
    assert cal.pressure(250.0) == 0.0                              # clipped at zero


def test_json_round_trip(tmp_path):
    rng = np.random.default_rng(5)
    cal = fit_calibration(GS, -0.004 * GS + 0.95 + rng.normal(0, 0.01, GS.size))
    p = cal.save(tmp_path / "sub" / "cal.json")
    back = load_calibration(p)
    g = np.linspace(0, 255, 31)
    assert back == cal
    assert back.pressure(g) == pytest.approx(cal.pressure(g), abs=0)
    assert back.band(g)[1] == pytest.approx(cal.band(g)[1], abs=0)
    assert json.loads(p.read_text())["report"]["criterion"].startswith("AICc")
    assert load_calibration("paper_eq8") == paper_eq8()
    assert [f.name for f in (tmp_path / "sub").iterdir()] == ["cal.json"]  # no temp files left
    with pytest.raises(ParameterError, match="calibration"):
        load_calibration(tmp_path / "missing.json")


def test_csv_with_images_and_gray_values(tmp_path):
    grays = [40, 80, 120, 160, 200, 230]
    forces = [30, 24, 18, 12, 6, 1]
    for g in grays:  # uniform colour scans of each press: R=G=B=g has luma g
        Image.new("RGB", (20, 10), (g, g, g)).save(tmp_path / f"press_{g}.png")
    (tmp_path / "cal.csv").write_text("force_n,area_mm2,image\n" + "".join(
        f"{f},100,press_{g}.png\n" for f, g in zip(forces, grays)))
    cal = calibrate_csv(tmp_path / "cal.csv", model="linear")
    direct = fit_calibration(grays, np.array(forces) / 100.0, model="linear")
    assert cal.params == pytest.approx(direct.params, rel=1e-12)  # P = F/A, Eq. 7
    assert cal.unit == "MPa" and cal.report["points"]["force_n"] == forces
    (tmp_path / "bad.csv").write_text("force,area_mm2,gray\n1,100,30\n")
    with pytest.raises(ParameterError, match="force_n"):
        calibrate_csv(tmp_path / "bad.csv")
    (tmp_path / "neg.csv").write_text("force_n,area_mm2,gray\n1,0,30\n2,100,20\n3,100,10\n")
    with pytest.raises(ParameterError, match="area_mm2"):
        calibrate_csv(tmp_path / "neg.csv")


def test_bad_json_format_is_rejected():
    with pytest.raises(ParameterError, match="format"):
        Calibration.from_dict({"format": "something else"})
