"""The paper's claims checked on a chart say at which depth: the depth cap is not the paper's 20 %."""

import pytest

from tactileskin.array.chart import Chart, ChartConfig, verdicts


def _chart(max_depth):
    cfg = ChartConfig(thicknesses=(1.0, 5.0), pitches=(0.75, 2.0), noise_fs=(0.01,), sets=("paper", "letters"),
                      max_depth=max_depth)
    ch = Chart(cfg)
    for t in cfg.thicknesses:
        for set_ in ("paper", "letters"):
            for p in cfg.pitches:
                ch.rows.append(dict(material="silicone", thickness_mm=t, set=set_, pitch_mm=p, noise_fs=0.01,
                                    method="template", accuracy=1.0))
    return ch


def test_a_capped_5_mm_verdict_names_its_depth():
    v = {x["claim"][:4]: x for x in verdicts(_chart(0.4))}
    five = v["5 mm"]
    assert five["verdict"].startswith("not supported")
    assert "capped depth 0.4 mm, not the paper's 1 mm" in five["verdict"]
    assert "0.4 mm" in five["evidence"]
    assert v["0.75"]["verdict"] == "supported"  # t = 1 at 20 % = 0.2 mm, under the cap


def test_uncapped_verdicts_are_plain():
    v = verdicts(_chart(None))
    assert [x["verdict"] for x in v] == ["supported", "not supported"]


def test_a_verdict_within_sampling_noise_of_the_threshold_says_borderline():
    from tactileskin.array.chart import wilson

    ch = _chart(None)
    for r in ch.rows:  # 16 test reads of 3 stimuli: 48 readings; 46 right is 0.958
        r.update(n_test=16, chance=1 / 3)
        if r["set"] == "paper" and r["thickness_mm"] == 5.0:
            r["accuracy"] = 46 / 48
        if r["set"] == "letters":
            r.update(chance=1 / 36)  # 576 readings at 1.00: no doubt
    v = {x["claim"][:4]: x for x in verdicts(ch)}
    assert v["5 mm"]["verdict"] == "not supported"
    assert "(borderline: 0.96 on 48 readings at 16 offsets, 95 % interval 0.86-0.99 spans 0.95)" in v["5 mm"]["evidence"]
    assert v["0.75"]["verdict"] == "supported" and "borderline" not in v["0.75"]["evidence"]
    lo, hi = wilson(46 / 48, 48)
    assert lo < 0.95 < hi and 0.85 < lo


def test_a_chart_with_t_5_but_no_paper_set_does_not_say_there_is_no_t_5():
    # -t 1,5 --set shapes (or letters): the 5 mm claim is about the paper set, which is absent;
    # the verdict said "not evaluated (no t = 5 mm)" of a chart that has t = 5 mm
    for sets in (("letters",), ("shapes",)):
        cfg = ChartConfig(thicknesses=(1.0, 5.0), pitches=(0.75, 2.0), noise_fs=(0.01,), sets=sets, letters="abl")
        five = {x["claim"][:4]: x for x in verdicts(Chart(cfg))}["5 mm"]
        assert five["verdict"] == "not evaluated (no paper set)"
        assert "no t = 5" not in five["verdict"] and "paper set" in five["evidence"]
    # without t = 5 the reason stays the thickness
    cfg = ChartConfig(thicknesses=(1.0,), pitches=(0.75,), noise_fs=(0.01,), sets=("shapes",))
    assert {x["claim"][:4]: x for x in verdicts(Chart(cfg))}["5 mm"]["verdict"] == "not evaluated (no t = 5 mm)"


def test_the_accuracy_interval_counts_the_shared_offsets_as_clusters():
    """Every stimulus is read at the same test offsets, so readings at one offset are not
    independent: at t = 1, 2.5 mm, 1 % noise seeds 0-5 read 0.79-0.93 while the binomial
    (Wilson) interval over the 576 readings of seed 0 was 0.91-0.95. The interval is now the
    wider of Wilson's and a t-interval over the 16 offsets' own accuracies."""
    import numpy as np

    from tactileskin.array.chart import accuracy_interval, wilson

    by_offset = np.array([1.0] * 10 + [0.75] * 6)  # 36 letters: some offsets lose a quarter of them
    acc = float(by_offset.mean())                  # 0.906 on 576 readings
    lo_w, hi_w = wilson(acc, 576)
    lo, hi = accuracy_interval(acc, 576, by_offset)
    assert lo < lo_w - 0.02 and hi >= hi_w and hi <= 1.0
    # the t-interval of these 16 values: mean 0.906, sd 0.125, t(15) 2.131: 0.840-0.973
    assert lo == pytest.approx(acc - 2.131 * by_offset.std(ddof=1) / 4.0, abs=1e-3)
    # offsets that agree (all 0.9): no wider than Wilson's; no per-offset data: Wilson's
    assert accuracy_interval(0.9, 576, np.full(16, 0.9)) == wilson(0.9, 576)
    assert accuracy_interval(0.9, 576, None) == wilson(0.9, 576)


def test_chart_rows_and_csv_carry_the_interval():
    from tactileskin.array import chart as ch_mod

    assert "ci_low,ci_high,status" in Chart(ChartConfig()).to_csv().splitlines()[0]
    # a computed row: the evaluation's offsets give the interval, around its accuracy
    import numpy as np

    from tactileskin.array.classify import evaluate
    from tactileskin.array.sampler import ArraySpec, Readout
    from tactileskin.results import BoneMap

    s = np.linspace(-4, 4, 81)
    z = np.linspace(-4, 4, 81)
    S, Z = np.meshgrid(s, z)
    maps = {k: BoneMap(s, z, np.exp(-((S - c) ** 2 + Z ** 2) / 0.5), 0.0) for k, c in (("a", -0.6), ("b", 0.6))}
    ev = evaluate(maps, ArraySpec(pitch=2.5, taxel=2.0, n=3), Readout(full_scale=1.0, noise_fs=0.01, bits=12),
                  np.random.default_rng(0), n_train=4, n_test=16, template_grid=2)
    for m, acc in ev.accuracy.items():
        a = ev.offset_accuracy[m]
        assert a.shape == (16,) and np.mean(a) == pytest.approx(acc)
        lo, hi = ch_mod.accuracy_interval(acc, 32, a)
        assert lo <= acc <= hi


def test_a_borderline_interval_just_under_the_bar_is_not_shown_on_it():
    """accuracy_text kept an accuracy just under 0.95 off the bar, but the borderline note's
    interval still rounded its lower end onto it: 0.9496 read '95 % interval 0.95-0.98 spans
    0.95', an interval that seems to start at the bar it is said to span."""
    ch = _chart(None)
    for r in ch.rows:
        r.update(n_test=16, chance=1 / 3)
        if r["set"] == "paper" and r["thickness_mm"] == 5.0:
            r.update(accuracy=0.96, ci_low=0.9496, ci_high=0.98)
    five = {x["claim"][:4]: x for x in verdicts(ch)}["5 mm"]
    assert "95 % interval 0.9496-0.98 spans 0.95)" in five["evidence"]
