"""The array sampler on analytic maps: lattice, area averaging, noise, quantisation."""

import numpy as np
import pytest
from scipy.special import erf

from tactileskin.array import maps
from tactileskin.array.sampler import ArraySpec, Readout, quantise, sample
from tactileskin.errors import ParameterError

S = np.linspace(-10, 10, 801)   # h = 0.025 mm
Z = np.linspace(-8, 8, 641)


def test_lattice_pitch_offset_and_rotation():
    spec = ArraySpec(pitch=0.75, n=5)
    c = spec.centres(offset=(0.1, -0.2))
    assert c.shape == (25, 2)
    assert np.allclose(np.unique(np.round(c[:, 0], 12)), (np.arange(5) - 2) * 0.75 + 0.1)
    assert np.allclose(np.unique(np.round(c[:, 1], 12)), (np.arange(5) - 2) * 0.75 - 0.2)
    r = ArraySpec(pitch=1.0, n=3, rotation_deg=90).centres()
    # a quarter turn maps the lattice onto itself, (1, 0) -> (0, 1)
    assert np.allclose(sorted(map(tuple, np.round(r, 12))), sorted(map(tuple, np.round(ArraySpec(1.0, n=3).centres(), 12))))


def test_point_taxels_read_the_field_where_they_are():
    # a bilinear map is reproduced exactly by the bilinear interpolant: readings are the field
    m = maps.on_grid(lambda s, z: 0.3 + 0.02 * s - 0.01 * z + 0.004 * s * z, S, Z)
    spec = ArraySpec(pitch=1.1, n=7)
    c = spec.centres((0.37, -0.21))
    expect = 0.3 + 0.02 * c[:, 0] - 0.01 * c[:, 1] + 0.004 * c[:, 0] * c[:, 1]
    assert np.allclose(sample(m, spec, (0.37, -0.21)), expect, atol=1e-12)


def test_area_average_of_linear_field_is_centre_value():
    m = maps.on_grid(lambda s, z: 1.0 + 0.05 * s + 0.08 * z, S, Z)
    for rot in (0.0, 30.0):
        spec = ArraySpec(pitch=1.0, taxel=0.9, n=5, rotation_deg=rot)
        c = spec.centres((0.2, 0.1))
        assert np.allclose(sample(m, spec, (0.2, 0.1)), 1.0 + 0.05 * c[:, 0] + 0.08 * c[:, 1], atol=1e-12)


def test_area_average_of_gaussian_has_closed_form():
    sig, a = 0.5, 0.8
    m = maps.on_grid(lambda s, z: np.exp(-(s * s + z * z) / (2 * sig**2)), S, Z)
    spec = ArraySpec(pitch=1.0, taxel=a, n=1, quad=12)
    got = sample(m, spec)[0]
    # mean over the square [-a/2, a/2]^2 of a separable Gaussian
    expect = (sig * np.sqrt(2 * np.pi) / a * erf(a / (2 * np.sqrt(2) * sig))) ** 2
    # bilinear interpolation error <= h^2/8 max|f''| = 0.025^2/8/0.25 = 3e-4; Gauss 12x12 is exact to 1e-10
    assert got == pytest.approx(expect, abs=4e-4)
    assert got < 1.0  # averaging lowers the peak


def test_quantisation_error_is_at_most_half_an_lsb():
    rng = np.random.default_rng(1)
    v = rng.uniform(0, 2.0, 10_000)
    q = quantise(v, 8, 2.0)
    lsb = 2.0 / 255
    assert np.max(np.abs(q - v)) <= 0.5 * lsb + 1e-15
    assert len(np.unique(q)) <= 256
    assert quantise(np.array([-1.0, 3.0]), 8, 2.0).tolist() == [0.0, 2.0]  # clipped to the range


def test_noise_std_as_asked():
    rng = np.random.default_rng(2)
    r = Readout(full_scale=0.05, noise_mpa=0.001, noise_fs=0.02)
    assert r.sigma == pytest.approx(0.002)
    out = r(np.zeros(40_000), rng)
    # sample std of 40k normals: relative standard error 1/sqrt(2 n) = 0.35 %; 4 sigma = 1.4 %
    assert np.std(out) == pytest.approx(0.002, rel=0.014)
    assert abs(np.mean(out)) < 4 * 0.002 / np.sqrt(40_000)


def test_bad_specs():
    with pytest.raises(ParameterError):
        ArraySpec(pitch=0.0)
    with pytest.raises(ParameterError):
        ArraySpec(pitch=1.0, taxel=1.5)
    with pytest.raises(ParameterError):
        Readout(bits=0)


def test_mirrored_quarter_map():
    q = maps.on_grid(lambda s, z: np.exp(-(s - 0) ** 2 - z**2), np.linspace(0, 3, 31), np.linspace(0, 2, 21))
    f = maps.mirrored(q)
    assert f.s[0] == pytest.approx(-3) and f.z[0] == pytest.approx(-2) and f.pressure.shape == (41, 61)
    assert np.allclose(f.pressure, f.pressure[::-1, ::-1])
