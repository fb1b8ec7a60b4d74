"""Scan reading: the pixel cap is checked from the header before decoding, Pillow's
decompression-bomb error is a ParameterError, and the pixel-scale rule for 8/16/32-bit
and float images (an integer TIFF holding 0-255 values is read as such)."""

import json
import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from tactileskin.cli import main
from tactileskin.errors import ParameterError
from tactileskin.film import analyze_scan, image
from tactileskin.film.image import read_scan
from tactileskin.film.synthetic import gaussian_profile, render_scan, save_scan


def _png_claiming(path, w, h):
    """A valid 1-bit PNG header claiming w x h px with one tiny (truncated) IDAT: the file
    is a few dozen bytes whatever the claimed size."""
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))
    ihdr = struct.pack(">IIBBBBB", w, h, 1, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) +
                     chunk(b"IDAT", zlib.compress(b"\x00" * 64)) + chunk(b"IEND", b""))
    return path


def test_huge_header_is_refused_before_decoding(tmp_path, monkeypatch):
    # 8000 x 8000 (64 Mpx) is below Pillow's own bomb limit (179 Mpx): our cap refuses it;
    # decoding is never reached (a load() would fail on the truncated data instead)
    p = _png_claiming(tmp_path / "big.png", 8000, 8000)
    assert p.stat().st_size < 200
    loads = []
    monkeypatch.setattr(Image.Image, "load", lambda self: loads.append(1))
    with pytest.raises(ParameterError, match=r"at most 40 megapixels.*8000 x 8000 px = 64\.0 Mpx"):
        read_scan(p)
    assert loads == []


def test_decompression_bomb_is_a_parameter_error(tmp_path):
    # 50000 x 50000 = 2.5 Gpx: Pillow itself raises DecompressionBombError on open
    p = _png_claiming(tmp_path / "bomb.png", 50000, 50000)
    with pytest.raises(ParameterError, match="megapixels.*too large"):
        read_scan(p)


def test_cli_refuses_huge_scan_in_one_line(tmp_path, capsys):
    p = _png_claiming(tmp_path / "bomb.png", 50000, 50000)
    assert main(["film", "analyze", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "megapixels" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_cap_applies_just_above_the_limit(tmp_path, monkeypatch):
    Image.fromarray(np.full((10, 20), 100, np.uint8)).save(tmp_path / "s.png")
    monkeypatch.setattr(image, "MAX_PIXELS", 200)
    assert read_scan(tmp_path / "s.png")[0].shape == (10, 20)
    monkeypatch.setattr(image, "MAX_PIXELS", 199)
    with pytest.raises(ParameterError, match="megapixels"):
        read_scan(tmp_path / "s.png")


GRAY = np.array([[0, 17, 128], [200, 254, 255]])


@pytest.mark.parametrize("dtype, values, expect_note", [
    (np.uint8, GRAY, "8-bit"),
    (np.uint16, GRAY, "16-bit integer holding 0-255"),      # 8-bit data in a 16-bit TIFF
    (np.uint16, GRAY * 257, "16-bit integer: scaled"),       # full 16-bit range
    (np.int32, GRAY, "32-bit integer holding 0-255"),
    (np.int32, GRAY * 257, "32-bit integer holding 0-65535"),
    (np.float32, GRAY / 255.0, "float in [0, 1]"),
    (np.float32, GRAY, "float in [0, 255]"),
])
def test_pixel_scale_rule(tmp_path, dtype, values, expect_note):
    Image.fromarray(values.astype(dtype)).save(tmp_path / "s.tif")
    arr, note = read_scan(tmp_path / "s.tif")
    assert arr == pytest.approx(GRAY.astype(float), abs=1e-4)   # float32 rounding of /255
    assert expect_note in note


@pytest.mark.parametrize("dtype, values, match", [
    (np.float32, np.array([[0.0, 300.0]]), "float pixel values in"),
    (np.float32, np.array([[-1.0, 100.0]]), "float pixel values in"),
    (np.float32, np.array([[np.nan, 100.0]]), "finite float"),
    (np.int32, np.array([[0, 70000]]), "0-255 or 0-65535"),
    (np.int32, np.array([[-5, 100]]), "0-255 or 0-65535"),
])
def test_pixel_values_outside_every_rule_are_refused(tmp_path, dtype, values, match):
    Image.fromarray(values.astype(dtype)).save(tmp_path / "s.tif")
    with pytest.raises(ParameterError, match=match):
        read_scan(tmp_path / "s.tif")


def test_8bit_data_in_16bit_tiff_analyses_like_the_png(tmp_path, capsys):
    img = render_scan(gaussian_profile(0.4, 1.0), background_gs=245, noise_gs=1, seed=3)
    ref = analyze_scan(save_scan(img, tmp_path / "a.png"), box_px=(0, 20, 160, 52))
    Image.fromarray(img.astype(np.uint16)).save(tmp_path / "b.tif")   # values <= 255
    Image.fromarray(img).save(tmp_path / "c.tif")                     # uint8 TIFF
    for name in ("b.tif", "c.tif"):
        got = analyze_scan(tmp_path / name, box_px=(0, 20, 160, 52))
        assert got.pressure == pytest.approx(ref.pressure, abs=1e-12)
    assert main(["film", "analyze", str(tmp_path / "b.tif"), "--box-px", "0", "20", "160", "52",
                 "--out", str(tmp_path / "o")]) == 0
    summ = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summ["pixel_scale"].startswith("16-bit integer holding 0-255")
    assert summ["metrics_two_sided"]["peak"] == pytest.approx(ref.metrics["peak"], abs=1e-6)
