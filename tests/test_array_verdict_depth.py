"""The paper's claims checked on a chart say at which depth: the depth cap is not the paper's 20 %."""

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
    assert "(borderline: 0.96 on 48 readings, 95 % interval 0.86-0.99 spans 0.95)" in v["5 mm"]["evidence"]
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
