"""What the scan file says: its recorded scale (dpi) against the one used, and transparency."""

import numpy as np
import pytest
from PIL import Image

from tactileskin.errors import ParameterError
from tactileskin.film import analyze_scan
from tactileskin.film.image import file_px_per_mm, read_scan
from tactileskin.film.synthetic import gaussian_profile, render_scan

DPI600 = 600 / 25.4  # px/mm


def _scan(ppm):
    return render_scan(gaussian_profile(0.4, 1.2), px_per_mm=ppm, background_gs=245)


def test_a_600_dpi_scan_read_at_the_default_scale_is_flagged(tmp_path):
    path = tmp_path / "s600.png"
    Image.fromarray(_scan(DPI600)).save(path, dpi=(600, 600))
    assert file_px_per_mm(path) == pytest.approx(DPI600, rel=1e-4)
    wrong = analyze_scan(path)  # the default 8 px/mm: the span read 2.95 x too wide, unflagged before
    assert any("600 dpi" in w and "--px-per-mm 23.62" in w for w in wrong.warnings)
    right = analyze_scan(path, px_per_mm=DPI600)
    assert right.warnings == [] and right.summary()["file_px_per_mm"] == pytest.approx(DPI600, rel=1e-4)
    assert wrong.folded["metrics"]["span_mm"] / right.folded["metrics"]["span_mm"] == pytest.approx(
        DPI600 / 8, rel=0.02)


def test_files_without_an_absolute_scale_are_not_checked(tmp_path):
    img = _scan(8.0)
    Image.fromarray(img).save(tmp_path / "a.png")        # no pHYs
    Image.fromarray(img).save(tmp_path / "a.tif")        # Pillow's 1 x 1 without a unit
    Image.fromarray(img).save(tmp_path / "b.tif", dpi=(203.2, 203.2))  # 8 px/mm exactly
    # the screen defaults editors stamp on any image (it advised --px-per-mm 2.835 for them)
    Image.fromarray(img).save(tmp_path / "c.png", dpi=(72, 72))
    Image.fromarray(img).save(tmp_path / "d.tif", dpi=(96, 96))
    assert all(file_px_per_mm(tmp_path / n) is None for n in ("a.png", "a.tif", "c.png", "d.tif"))
    assert file_px_per_mm(tmp_path / "b.tif") == pytest.approx(8.0)
    for name in ("a.png", "a.tif", "b.tif", "c.png", "d.tif"):
        assert analyze_scan(tmp_path / name).warnings == []


def test_transparent_pixels_are_refused_opaque_alpha_is_read(tmp_path):
    img = _scan(8.0)
    rgba = np.dstack([img, img, img, np.full(img.shape, 255, np.uint8)])
    Image.fromarray(rgba, "RGBA").save(tmp_path / "opaque.png")
    assert read_scan(tmp_path / "opaque.png")[0] == pytest.approx(img.astype(float), abs=0.51)
    rgba[:, :20] = 0  # transparent black margin: it read as the film's highest pressure
    Image.fromarray(rgba, "RGBA").save(tmp_path / "clear.png")
    with pytest.raises(ParameterError, match="transparent"):
        analyze_scan(tmp_path / "clear.png", box_px=(0, 0, 60, 20))
    la = np.dstack([img, np.full(img.shape, 255, np.uint8)])
    la[0, 0, 1] = 0
    Image.fromarray(la, "LA").save(tmp_path / "la.png")
    with pytest.raises(ParameterError, match="transparent"):
        read_scan(tmp_path / "la.png")


def test_a_tiff_resolution_without_a_unit_tag_is_dots_per_inch(tmp_path):
    """TIFF 6.0: ResolutionUnit defaults to inch; a 600 dpi scan whose writer left the tag
    out read as 'no scale' and was analysed at 8 px/mm unflagged (2.95 x too wide)."""
    from PIL import TiffImagePlugin

    tags = TiffImagePlugin.ImageFileDirectory_v2()
    tags[282], tags[283] = 600.0, 600.0  # XResolution, YResolution; no ResolutionUnit (296)
    Image.fromarray(_scan(DPI600)).save(tmp_path / "nounit.tif", tiffinfo=tags)
    assert 296 not in Image.open(tmp_path / "nounit.tif").tag_v2
    assert file_px_per_mm(tmp_path / "nounit.tif") == pytest.approx(DPI600, rel=1e-4)
    assert any("--px-per-mm 23.62" in w for w in analyze_scan(tmp_path / "nounit.tif").warnings)
    tags[296] = 1  # an explicit 'no absolute unit': still no scale
    Image.fromarray(_scan(DPI600)).save(tmp_path / "none.tif", tiffinfo=tags)
    assert file_px_per_mm(tmp_path / "none.tif") is None
