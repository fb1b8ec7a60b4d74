"""Classifiers on synthetic stimulus sets: separable (accuracy ~1) and inseparable (chance)."""

import numpy as np
import pytest

from tactileskin.array import classify, maps
from tactileskin.array.sampler import ArraySpec, Readout
from tactileskin.errors import ParameterError

S = np.linspace(-6, 6, 241)
Z = np.linspace(-6, 6, 241)


def _blob(cs, cz, w=0.6, a=1.0):
    return maps.on_grid(lambda s, z: a * np.exp(-((s - cs) ** 2 + (z - cz) ** 2) / (2 * w * w)), S, Z)


def test_separable_set_is_read_perfectly():
    # four blobs 2.5 mm apart on a 0.5 mm array: offsets of <= 0.25 mm cannot confuse them
    stim = {f"b{k}": _blob(*c) for k, c in enumerate([(-1.25, -1.25), (1.25, -1.25), (-1.25, 1.25), (1.25, 1.25)])}
    spec = ArraySpec(pitch=0.5, taxel=0.4, n=13)
    ev = classify.evaluate(stim, spec, Readout(full_scale=1.0, noise_fs=0.02, bits=10),
                           np.random.default_rng(0), n_train=12, n_test=12)
    assert ev.accuracy["template"] == 1.0 and ev.accuracy["lda"] >= 0.97
    assert np.trace(ev.confusion["template"]) == 4 * 12


def test_inseparable_set_is_at_chance():
    # five stimuli that differ by 1e-6 of their peak under noise of 0.2: no rule can tell them
    # apart, each read is a fair draw among the classes: correct ~ Binomial(N, 1/5)
    stim = {f"c{k}": _blob(0.0, 0.0, a=1.0 + 1e-6 * k) for k in range(5)}
    spec = ArraySpec(pitch=1.0, n=7)
    n_test = 80
    ev = classify.evaluate(stim, spec, Readout(full_scale=1.0, noise_fs=0.2), np.random.default_rng(3),
                           n_train=40, n_test=n_test)
    N, p = 5 * n_test, 0.2
    bound = 4 * np.sqrt(p * (1 - p) / N)  # 4 binomial standard deviations: P(outside) < 1e-4
    for m in ("template", "lda"):
        assert abs(ev.accuracy[m] - p) < bound, (m, ev.accuracy[m], bound)
    assert ev.chance == p


def test_array_too_coarse_confuses_shifted_dots():
    # two blobs 0.4 mm apart read through a 4 mm array at random offsets: one taxel per blob,
    # unknown position: accuracy far below 1 (and the fine array reads them)
    stim = {"left": _blob(-0.2, 0.0, w=0.3), "right": _blob(0.2, 0.0, w=0.3)}
    rng = np.random.default_rng(5)
    coarse = classify.evaluate(stim, ArraySpec(pitch=4.0, n=3), Readout(noise_fs=0.01), rng, n_test=60)
    fine = classify.evaluate(stim, ArraySpec(pitch=0.2, n=25), Readout(noise_fs=0.01), rng, n_test=60)
    assert coarse.accuracy["template"] < 0.8
    assert fine.accuracy["template"] > 0.95


def test_needs_two_stimuli():
    with pytest.raises(ParameterError):
        classify.evaluate({"a": _blob(0, 0)}, ArraySpec(pitch=1.0), Readout(), np.random.default_rng(0))
