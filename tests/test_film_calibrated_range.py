"""A scan read outside its calibration's grayscale range says so (summary warnings)."""

import numpy as np
import pytest

from tactileskin.film import analyze_scan
from tactileskin.film.calibration import Calibration, fit_calibration
from tactileskin.film.synthetic import gaussian_profile, render_scan

TRUE = Calibration(name="true", model="linear", params=(-0.0015, 0.345), gs_range=(0.0, 255.0),
                   p_range=(0.0, 0.345))
PRESSES = np.array([0.05, 0.08, 0.11, 0.14, 0.17, 0.2])  # MPa: the scan's peak 0.3 is beyond them


def _scan():
    return render_scan(gaussian_profile(0.3, 1.2), TRUE, background_gs=245)


def test_pixels_held_at_the_darkest_press_below_the_activation_top_are_flagged():
    # the film's stated range reaches 1 MPa, the presses only 0.2: the darker pixels read
    # 0.2, a lower bound, not the film's saturation, so before they passed unflagged
    cal = fit_calibration(TRUE.grayscale(PRESSES), PRESSES, activation_range=(0.0, 1.0))
    fp = analyze_scan(_scan(), cal)
    assert fp.metrics["peak"] == pytest.approx(0.2)
    assert fp.saturated_fraction == 0.0
    assert fp.coverage["held_fraction"] > 0.1
    assert any("lower bound" in w for w in fp.warnings)
    assert fp.summary()["beyond_calibration"]["held_fraction"] == fp.coverage["held_fraction"]


def test_a_span_read_on_the_extrapolated_tangent_is_flagged():
    cal = fit_calibration(TRUE.grayscale(PRESSES), PRESSES)
    fp = analyze_scan(_scan(), cal)
    assert fp.coverage["extrapolated_fraction"] > 0
    assert any("span's 10 % level" in w and "extrapolated" in w for w in fp.warnings)
    # presses down to 0.01 MPa cover the span's 10 % level (0.03 MPa at most): no warning
    wide = np.linspace(0.01, 0.35, 8)
    cal2 = fit_calibration(TRUE.grayscale(wide), wide)
    fp2 = analyze_scan(_scan(), cal2)
    assert fp2.coverage["held_fraction"] == 0.0
    assert not any("span's 10 % level" in w or "lower bound" in w for w in fp2.warnings)


def test_the_paper_calibration_covers_every_gray_level():
    fp = analyze_scan(render_scan(gaussian_profile(0.4, 1.2), background_gs=245))
    assert fp.coverage["held_fraction"] == fp.coverage["extrapolated_fraction"] == 0.0
    assert fp.warnings == []


def test_a_region_that_cuts_the_profile_says_the_span_is_a_lower_bound():
    img = render_scan(gaussian_profile(0.3, 1.5), TRUE, background_gs=245)
    cut = analyze_scan(img, TRUE, box_mm=(8, 2, 12, 7))  # 4 mm of a profile 7 mm wide at 10 %
    assert any("cut there" in w and "lower bounds" in w for w in cut.warnings)
    whole = analyze_scan(img, TRUE)
    assert whole.warnings == []
    assert cut.folded["metrics"]["span_mm"] < 0.7 * whole.folded["metrics"]["span_mm"]


def test_a_fold_about_an_off_centre_origin_is_flagged():
    # two peaks at +-1.5 mm: the default origin (the largest pixel) sits on one of them and the
    # fold averaged unlike sides (asymmetry 1.0, span 4.5 mm for 3.0) without a word
    twin = lambda s: 0.3 * np.exp(-0.5 * ((np.abs(s) - 1.5) / 0.7) ** 2)  # noqa: E731
    img = render_scan(twin, TRUE, background_gs=245, noise_gs=1, seed=3)
    off = analyze_scan(img, TRUE)
    assert off.folded["asymmetry"] > 0.5
    assert any("not symmetric" in w and "--centre midspan" in w for w in off.warnings)
    mid = analyze_scan(img, TRUE, centre="midspan")
    assert mid.folded["asymmetry"] < 0.1 and mid.warnings == []


def test_unactivated_film_reads_zero_below_an_activation_threshold():
    # --activation-range 0.02 0.35 (a film that shows nothing below 0.02 MPa): white film read
    # 0.02, the clip's bottom, everywhere: over a box the strip's length the folded area was 0.585
    # for 0.451 (+30 %) with no warning, and at 0.05 the folded span 9.9 mm for 2.6 ("widen the region")
    wide = np.linspace(0.01, 0.35, 8)
    s = np.linspace(0, 10, 100001)
    for lo in (0.02, 0.05):
        p = gaussian_profile(0.3, 1.2)(s)
        truth = np.trapezoid(np.where(p >= lo, p, 0.0), s)  # the folded area the film can see
        cal = fit_calibration(TRUE.grayscale(wide), wide, activation_range=(lo, 0.35))
        assert cal.pressure(245.0) == 0.0 and cal.pressure(TRUE.grayscale(lo + 0.01)) > lo
        lo_b, hi_b = cal.band(np.array([245.0, 100.0]))
        assert lo_b[0] == 0.0 and lo_b[1] >= lo
        img = _scan()
        fp = analyze_scan(img, cal, box_px=(0, 16, img.shape[1], 56))
        assert fp.folded["metrics"]["auc"] == pytest.approx(truth, rel=0.02)
        assert not fp.cut_ends
        # 0.05 is above the span's 10 % level (0.03): the span ends at the threshold, said so
        assert any("activation threshold" in w for w in fp.warnings) == (lo > 0.03), (lo, fp.warnings)


def test_a_background_read_as_pressure_is_flagged():
    # unpressed film scanned at GS 228, darker than Eq. 8's zero (230.1): every column carries
    # 0.0089 MPa/mm, 2 % of the peak (below the 10 % of a cut end), and over the 30 mm strip the
    # folded area read 0.605 for 0.501 (+21 %) with no warning
    from tactileskin.film import paper_eq8

    prof = gaussian_profile(0.4, 1.0)
    dark = analyze_scan(render_scan(prof, paper_eq8(), length_mm=30, background_gs=228.0))
    assert dark.folded["metrics"]["auc"] > 1.15 * 0.4 * np.sqrt(2 * np.pi) / 2
    assert any("does not return to zero" in w for w in dark.warnings)
    for noise in (0.0, 2.0):
        clean = analyze_scan(render_scan(prof, paper_eq8(), length_mm=30, background_gs=245.0,
                                         noise_gs=noise, seed=4))
        assert clean.warnings == []
