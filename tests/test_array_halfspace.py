"""The half-space filter against its closed forms."""

import numpy as np
import pytest
from scipy import integrate
from scipy.special import j0

from tactileskin.array import halfspace as hs
from tactileskin.errors import ParameterError


def test_boussinesq_closed_form_and_equilibrium():
    d, P = 1.5, 2.0
    # on the axis: 3 P / (2 pi d^2)
    assert hs.boussinesq_szz(0.0, d, P) == pytest.approx(3 * P / (2 * np.pi * d**2), rel=1e-14)
    r = 0.7
    assert hs.boussinesq_szz(r, d, P) == pytest.approx(3 * P * d**3 / (2 * np.pi * np.hypot(r, d) ** 5), rel=1e-14)
    # vertical equilibrium: the stress at depth d carries the whole load (quad to 1e-8)
    tot, _ = integrate.quad(lambda r: 2 * np.pi * r * hs.boussinesq_szz(r, d, P), 0, np.inf, epsabs=1e-12)
    assert tot == pytest.approx(P, rel=1e-8)


def test_flamant_equilibrium_and_spectrum():
    d, q = 0.8, 1.3
    tot, _ = integrate.quad(lambda x: hs.flamant_szz(x, d, q), -np.inf, np.inf, epsabs=1e-12)
    assert tot == pytest.approx(q, rel=1e-8)
    for k in (0.0, 0.5, 2.0, 6.0):
        # 1D Fourier transform of the even kernel (cosine transform), normalised by the load
        ft, _ = integrate.quad(lambda x: 2 * hs.flamant_szz(x, d, 1.0), 0, np.inf, weight="cos", wvar=k)
        assert ft == pytest.approx(float(hs.spectrum(k, d)), abs=1e-8)


def test_boussinesq_spectrum_is_the_same_filter():
    # 2D Fourier transform of a radial kernel = Hankel transform 2 pi int K(r) J0(k r) r dr
    d = 1.0
    for k in (0.3, 1.0, 3.0):
        ht, _ = integrate.quad(lambda r: 2 * np.pi * r * hs.boussinesq_szz(r, d) * j0(k * r), 0, 60, limit=400)
        assert ht == pytest.approx(float(hs.spectrum(k, d)), abs=1e-6)  # tail beyond 60 d < 1e-6


def test_cutoff_solves_the_level_equation():
    for level in (0.5, 0.1, 0.01):
        for d in (0.5, 1.0, 5.0):
            kc = hs.cutoff(d, level)
            assert kc > 0 and float(hs.spectrum(kc, d)) == pytest.approx(level, rel=1e-10)
            assert hs.nyquist_pitch(d, level) == pytest.approx(np.pi / kc)
    # deeper sensors: proportionally coarser pitch suffices
    assert hs.nyquist_pitch(3.0) == pytest.approx(3 * hs.nyquist_pitch(1.0))


def test_measured_cutoff_of_flamant_kernel():
    d = 1.0
    x = np.linspace(-200, 200, 2**16, endpoint=False)
    kc, k, amp = hs.measured_cutoff(x, hs.flamant_szz(x, d))
    # the discrete spectrum of the finely sampled kernel is the closed form to ~1e-4
    # (the kernel beyond |x| = 200 d carries < 1e-6 of the load; spacing 0.006 d)
    assert np.max(np.abs(amp[k < 20] - hs.spectrum(k[k < 20], d))) < 1e-4
    assert kc == pytest.approx(hs.cutoff(d), rel=1e-3)


def test_bad_inputs():
    with pytest.raises(ParameterError):
        hs.cutoff(0.0)
    with pytest.raises(ParameterError):
        hs.cutoff(1.0, level=1.5)
