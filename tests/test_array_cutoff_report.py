"""A cut-off the spectrum never reaches reads n/a, not a Nyquist pitch of 0.00 mm."""

from tactileskin.array.chart import Chart, ChartConfig
from tactileskin.report.array_chart import markdown


def _one_row_chart(t: float) -> Chart:
    """A paper-set chart of one accuracy row at t (mm), pitch 0.75 mm."""
    ch = Chart(ChartConfig(thicknesses=(t,), pitches=(0.75,), noise_fs=(0.01,), sets=("paper",)))
    ch.rows.append(dict(material="silicone", thickness_mm=t, set="paper", pitch_mm=0.75, taxel_mm=0.6,
                        noise_fs=0.01, noise_mpa=0.001, full_scale_mpa=0.3, bits=12, method="template",
                        accuracy=1.0, chance=1 / 3, n_test=16))
    ch.labels["paper"] = ["flat", "curved", "braille"]
    return ch


def test_an_unmeasurable_cutoff_is_not_a_zero_pitch():
    ch = _one_row_chart(1.0)
    ch.cutoffs.append({"material": "silicone", "thickness_mm": 1.0, "skin": "fingertip", "depth_mm": 0.2,
                       "peak_mpa": 0.04, "kc_rad_per_mm": float("inf"), "nyquist_pitch_mm": float("nan"),
                       "halfspace_nyquist_pitch_mm": 0.81})
    md = markdown(ch)
    row = next(ln for ln in md.splitlines() if ln.startswith("| silicone | 1 | 0.2 |"))
    assert "n/a (spectrum stays above 10 %) | n/a |" in row and "0.00" not in row and "nan" not in row


def test_the_depth_cap_sentence_says_whether_the_plate_touches():
    """A cap past the dot height (0.48 mm) read 'below the dot height, so the Braille plate
    never touches' (while the chart's notes said it touched)."""
    def md(cap):
        ch = Chart(ChartConfig(thicknesses=(3.0,), pitches=(0.75,), noise_fs=(0.01,), sets=("paper",), max_depth=cap))
        ch.labels["paper"] = ["flat", "curved", "braille"]
        return " ".join(markdown(ch).split())

    assert "capped at 0.4 mm" in md(0.4) and "never touches" in md(0.4)
    assert "capped at 0.55 mm" in md(0.55) and "never touches" not in md(0.55)
    assert "the Braille plate touches" in md(0.55)


def test_the_chart_figure_of_a_suspect_chart_says_so(tmp_path, monkeypatch):
    """The report listed the chart's suspect parts (here a note: the plate touches) while its
    figures were titled as a clean chart."""
    from tactileskin.report import array_chart

    ch = _one_row_chart(3.0)
    ch.notes.append("t = 3 mm: the depth 0.6 mm passes the dot height 0.48 mm: the plate touches")
    titles = []
    from tactileskin.report.figures import _plt

    # closed here, as the real _save closes it (it stayed open in pyplot)
    monkeypatch.setattr(array_chart, "_save",
                        lambda fig, out, stem: titles.append(fig._suptitle.get_text()) or _plt().close(fig) or [])
    array_chart.write_outputs(ch, tmp_path)
    assert len(titles) == 1 and "SUSPECT parts of the chart: 1 note in array_chart.md" in titles[0], titles


def test_the_accuracy_table_gives_the_noise_in_mpa_and_the_taxels_of_each_pitch():
    """The table's 'noise' column held fractions of a full scale the report never gave (it
    differs per thickness, so equal fractions are unequal noise), the pitches had no taxel
    count and the bold cells no legend."""
    ch = Chart(ChartConfig(thicknesses=(1.0, 2.0), pitches=(0.5, 2.5), noise_fs=(0.05,), sets=("paper",)))
    ch.labels["paper"] = ["flat", "curved", "braille"]
    for t, fs in ((1.0, 0.04), (2.0, 0.03)):
        for p in (0.5, 2.5):
            ch.rows.append(dict(material="silicone", thickness_mm=t, set="paper", pitch_mm=p, taxel_mm=0.8 * p,
                                noise_fs=0.05, noise_mpa=0.05 * fs, full_scale_mpa=fs, bits=12, method="template",
                                accuracy=0.96 if p == 0.5 else 0.9, chance=1 / 3, n_test=16))
    lines = markdown(ch).splitlines()
    # 8 mm window: floor(8 / 0.5) + 1 = 17 and floor(8 / 2.5) + 1 = 4 taxels a side
    assert "| t (mm) | noise (x full scale) | noise (MPa) | 0.5 mm (17 x 17) | 2.5 mm (4 x 4) |" in lines
    assert "| 1 | 0.05 | 0.002 | **0.96** | 0.90 |" in lines
    assert "| 2 | 0.05 | 0.0015 | **0.96** | 0.90 |" in lines
    legend = next(ln for ln in lines if ln.startswith("Accuracy (template)"))
    assert "**bold** at >= 0.95" in legend and "taxel centre to centre" in legend and "in MPa" in legend
    # the offsets' draw, not the readings' count, limits how sure a cell near 0.95 is
    assert "one draw of 16 random offsets, shared by all stimuli" in legend and "another `--seed`" in legend


def test_the_conditions_name_only_the_sets_computed_and_where_the_sensors_sit():
    """A letters-only chart read 'Skin: letters on the pad, the paper and shapes sets on the
    fingertip' and described the flat and curved profiles it had not computed."""
    def head(sets):
        ch = Chart(ChartConfig(thicknesses=(1.0,), pitches=(0.75,), noise_fs=(0.01,), sets=sets))
        ch.labels.update({s: ["a", "b"] for s in sets})
        return next(ln for ln in markdown(ch).splitlines() if ln.startswith("Skin:"))

    letters = head(("letters",))
    assert letters.startswith("Skin: letters on the pad. Sensor plane: the bonded surface, t below the contact surface")
    assert "fingertip" not in letters and "flat and curved" not in letters
    assert head(("paper",)).startswith("Skin: the paper set on the fingertip.")
    both = head(("letters", "paper", "shapes"))
    assert both.startswith("Skin: letters on the pad, the paper and shapes sets on the fingertip.")
    assert "flat and curved: 2D bone profiles extruded along z" in both


def test_the_filter_table_names_its_half_space_column_and_reads_the_nyquist_pitch():
    """The last column was 'half-space at depth t (mm)' (of what?), 'the paper's rule' was not
    given, and nothing said that a pitch past the Nyquist pitch can still tell the stimuli apart
    (t = 2 mm silicone: Nyquist 1.30 mm, letters 1.00 at 1.5 mm)."""
    ch = _one_row_chart(1.0)
    ch.cutoffs.append({"material": "silicone", "thickness_mm": 1.0, "skin": "pad", "depth_mm": 0.2,
                       "peak_mpa": 0.04, "kc_rad_per_mm": 4.51, "nyquist_pitch_mm": 0.70,
                       "halfspace_nyquist_pitch_mm": 0.81})
    md = " ".join(markdown(ch).split())
    assert "| Nyquist pitch (mm) | half-space Nyquist pitch at depth t (mm) |" in md
    assert "| silicone | 1 | 0.2 | pad | 0.0400 | 4.51 | 0.70 | 0.81 |" in md
    assert "not a limit on telling known stimuli apart" in md
    assert "The paper's rule (half the 1.5 mm span of the Braille pressure at t = 1) gives 0.75 mm" in md
    assert "travel into the skin from first touch" in md


def test_the_conditions_say_what_each_classifier_knows():
    """'rule: template (nearest template over 4x4 offsets; `lda` in the CSV)' did not say that the
    template rule is given the noise-free responses a trained decoder is not (t = 1 mm letters,
    2.5 mm pitch, noise 0.01: template 0.93, lda 0.38)."""
    md = " ".join(markdown(_one_row_chart(1.0)).split())
    assert ("rules: template: the nearest of every stimulus's noise-free readings at 4x4 offsets, a reader "
            "that knows each stimulus's response but not its position; lda: a linear discriminant trained on 16 noisy "
            "readings per stimulus, as a decoder trained on readings would be (the tables: template; the CSV: both);") in md


def test_a_letters_chart_past_the_dot_height_names_the_pad_size_its_maps_hold_for():
    """Past the dot height the letters' plate presses the whole pad, and the maps depend on the
    pad's size (a 40 x 40 mm pad's plate pressure is 2.0-2.5x the 20 x 20 mm pad's): the report
    did not say so. Below the dot height (t = 1: 0.2 mm, or a cap of 0.4 mm) nothing changes."""
    def md(t, cap=None, sets=("letters",)):
        ch = Chart(ChartConfig(thicknesses=t, pitches=(0.75,), noise_fs=(0.01,), sets=sets, max_depth=cap))
        for s in sets:
            ch.labels[s] = ["a", "b"]
        return " ".join(markdown(ch).split())

    text = md((1.0, 3.0))
    assert "At t = 3 mm the Braille plate presses the whole 20 x 20 mm pad" in text
    assert "t = 1, 3" not in text
    assert "presses the whole" not in md((1.0,))
    assert "presses the whole" not in md((3.0,), cap=0.4)
    assert "At t = 3 mm the Braille plate presses the whole" in md((3.0,), cap=0.55)
    assert "presses the whole" not in md((3.0,), sets=("paper",))


def test_the_pad_size_sentence_s_pressure_ratio_is_the_measured_one_at_the_thicknesses_it_names():
    """The sentence names t = 3 and 5 mm, and said a 40 x 40 mm pad's mean plate pressure is 2.0-2.3x the
    20 x 20 mm pad's: that is t = 5's range; at t = 3 silicone's is 2.50x (0.0684 / 0.0274 MPa,
    benchmarks/results/blank_pad_length.md). The range is read from the results' 1.2 / 1 rows."""
    import re
    from pathlib import Path

    md_file = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "blank_pad_length.md"
    mean = {}
    for line in md_file.read_text(encoding="utf-8").splitlines():
        c = [x.strip() for x in line.strip("|").split("|")]
        if len(c) > 7 and c[2] == "1.2 / 1" and c[3] in ("20 x 20", "40 x 40"):
            mean[(c[0], c[1], c[3])] = float(c[7])
    ratios = [mean[(m, t, "40 x 40")] / mean[(m, t, "20 x 20")] for m, t, p in mean if p == "20 x 20"]
    assert len(ratios) == 4
    ch = Chart(ChartConfig(thicknesses=(3.0, 5.0), pitches=(0.75,), noise_fs=(0.01,), sets=("letters",)))
    ch.labels["letters"] = ["a", "b"]
    text = " ".join(markdown(ch).split())
    lo, hi = re.search(r"mean plate pressure is ([\d.]+)-([\d.]+)x", text).groups()
    assert (float(lo), float(hi)) == (round(min(ratios), 1), round(max(ratios), 1)), (ratios, lo, hi)


def test_a_one_row_letters_figure_keeps_its_suspect_title_inside_the_image(tmp_path, monkeypatch):
    """A one-thickness, one-noise letters chart (a 4.6 in wide figure) cut its title's '† indicative:
    the letters' surrogate not shown within its tolerance (array_chart.md)' line at both sides
    ('tive: the letters' ... (array_ch'): the figure said it was indicative only in part."""
    from tactileskin.report import array_chart
    from tactileskin.report.figures import _plt

    ch = Chart(ChartConfig(thicknesses=(3.0,), pitches=(0.5, 1.0, 1.5, 2.0, 2.5), noise_mpa=(0.002,),
                           sets=("letters",)))
    ch.labels["letters"] = list(ch.config.letters)
    for p in ch.config.pitches:
        ch.rows.append(dict(material="silicone", thickness_mm=3.0, set="letters", pitch_mm=p, taxel_mm=0.8 * p,
                            noise_fs=0.14, noise_mpa=0.002, full_scale_mpa=0.0147, bits=12, method="template",
                            accuracy=1.0, chance=1 / 36, n_test=16))
    seen = []

    def measure(fig, out, stem):
        fig.canvas.draw()
        seen.append((fig._suptitle.get_text(), fig._suptitle.get_window_extent(fig.canvas.get_renderer()),
                     fig.bbox.width))
        _plt().close(fig)
        return []

    monkeypatch.setattr(array_chart, "_save", measure)
    array_chart.write_figures(ch, tmp_path, indicative={("silicone", 3.0): "not validated"},
                              notes=["silicone: the letters' surrogate is not shown within 5% at t = 3 mm"])
    (text, box, width), = seen
    assert "† indicative" in text and "SUSPECT parts of the chart" in text
    assert box.x0 >= -1 and box.x1 <= width + 1, (box, width)


def test_an_accuracy_just_under_the_bar_does_not_read_as_the_bar(tmp_path, monkeypatch):
    """t = 3 mm silicone letters at 1.5 mm pitch read 0.9462 (under GOOD = 0.95, so not bold) and
    were shown '0.95' in the table (unbolded, beside '**bold** at >= 0.95'), on the figure and on the
    terminal: a reader took the pitch as passing. Shown to the decimals that keep it under."""
    from tactileskin.array.chart import accuracy_text
    from tactileskin.report import array_chart
    from tactileskin.report.figures import _plt

    assert accuracy_text(0.9461805555555556) == "0.946" and accuracy_text(0.9499) == "0.9499"
    assert accuracy_text(0.95) == "0.95" and accuracy_text(0.77) == "0.77" and accuracy_text(1.0) == "1.00"
    ch = _one_row_chart(3.0)
    ch.rows[0]["accuracy"] = 0.9461805555555556
    assert "| 0.946 |" in markdown(ch) and "0.95 |" not in markdown(ch).split("### ")[-1].split("Accuracy (")[0]
    texts = []

    def grab(fig, out, stem):
        texts.extend(t.get_text() for ax in fig.axes for t in ax.texts)
        _plt().close(fig)
        return []

    monkeypatch.setattr(array_chart, "_save", grab)
    array_chart.write_figures(ch, tmp_path)
    assert texts == ["0.946"], texts


def test_the_filter_table_tells_the_indentation_from_the_sensor_depth():
    """With --sensor-depth 1 the table read 'depth (mm) | 0.4' beside 'Sensor plane: 1 mm below
    the contact surface': that column is the stimulus's travel, not where the taxels sit."""
    ch = Chart(ChartConfig(thicknesses=(2.0,), pitches=(0.75,), noise_fs=(0.01,), sets=("paper",), sensor_depth=1.0))
    ch.labels["paper"] = ["flat", "curved", "braille"]
    ch.cutoffs.append({"material": "silicone", "thickness_mm": 2.0, "skin": "fingertip", "depth_mm": 0.4,
                       "peak_mpa": 0.008, "kc_rad_per_mm": 2.48, "nyquist_pitch_mm": 1.27,
                       "halfspace_nyquist_pitch_mm": 0.81})
    head = next(ln for ln in markdown(ch).splitlines() if ln.startswith("| material | t (mm) |"))
    cols = [c.strip() for c in head.strip("|").split("|")]
    assert "depth (mm)" not in cols and cols[2] == "indentation (mm)", cols
    assert cols[-1] == "half-space Nyquist pitch at depth 1 mm (mm)"
