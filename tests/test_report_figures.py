"""Sweep figures that scale to the grid, the metrics-against-thickness figure, report settings."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tactileskin import __version__
from tactileskin.planner import with_quality
from tactileskin.report import figures
from tactileskin.report.markdown import quality_name, run_settings
from tactileskin.scene import Scene
from tactileskin.sweep import CaseRecord

THICK = [round(0.5 + 0.5 * i, 1) for i in range(11)]  # 0.5 .. 5.5 mm: 11 thicknesses


# the `_save` stubs here keep each figure to look at, so _save's close never runs (conftest.py)
pytestmark = pytest.mark.usefixtures("close_figures")


def _grid():
    recs, rows = [], []
    s = np.linspace(0, 8, 81)
    for mat in ("silicone", "polyurethane"):
        for t in THICK:
            for ind, pk in (("flat", 0.5), ("curved", 0.4), ("braille", 0.3)):
                w = 1 + t / 2
                p = pk / (1 + t) * np.exp(-(s / w) ** 2)
                recs.append(CaseRecord(Scene(thickness=t, material=mat, indenter=ind), s, p, {}, Path(".")))
                rows.append(dict(status="ok", material=mat, thickness_mm=t, indenter=ind, braille_text="",
                                 peak_mpa=float(p.max()), span_mm=1.5 * w, auc_mpa_mm=float(np.trapezoid(p, s))))
    return recs, rows


def test_figures_of_eleven_thicknesses_are_blocks_not_strips(tmp_path):
    recs, rows = _grid()
    paths = figures.all_figures(recs, rows, tmp_path)
    for p in paths:
        if p.suffix == ".png":
            w, h = Image.open(p).size
            # before: one row of 11 panels, 4716 x 460 px; now wrapped at MAX_COLUMNS
            assert w <= 2600 and w / h < 4.5, (p.name, w, h)
        elif p.suffix == ".svg":
            assert "<text" in p.read_text()  # SVG with text, not outlined glyphs
        else:  # the designer's figure as PDF, its labels as font text
            assert p.name == "metrics_vs_thickness.pdf"
            data = p.read_bytes()
            assert data[:5] == b"%PDF-" and b"/Font" in data
    assert sum(p.suffix == ".pdf" for p in paths) == 1


def test_a_figure_that_cannot_be_written_is_closed_all_the_same(tmp_path, monkeypatch):
    """A failed write (a full disk) left the figure open in pyplot: a notebook's sweeps each
    kept one more, until matplotlib warned of more than 20."""
    import errno

    import matplotlib.pyplot as plt

    from tactileskin.fileio import OutputError

    def full(path, data):
        raise OutputError(path, errno.errorcode[errno.ENOSPC])

    monkeypatch.setattr(figures, "atomic_write_bytes", full)
    before = set(plt.get_fignums())
    with pytest.raises(OutputError):
        figures.thickness_figure(_grid()[1], tmp_path)
    assert set(plt.get_fignums()) == before


def test_metrics_against_thickness_plots_each_series_in_thickness_order(tmp_path, monkeypatch):
    recs, rows = _grid()
    rows.append(dict(rows[0], thickness_mm=9.0, status="failed: x", peak_mpa=None))  # left out
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.thickness_figure(rows, tmp_path)
    fig = got["metrics_vs_thickness"]
    for ax, (metric, _) in zip(fig.axes, figures.METRICS):
        assert len(ax.lines) == 6  # 3 indenters x 2 materials
        for line in ax.lines:
            ind, mat = line.get_label().split(", ")
            want = sorted((r["thickness_mm"], r[metric]) for r in rows
                          if r["indenter"] == ind and r["material"] == mat and r["status"] == "ok")
            assert list(line.get_xdata()) == [t for t, _ in want]
            assert list(line.get_ydata()) == pytest.approx([v for _, v in want])


def test_compared_panels_share_their_y_axis(tmp_path, monkeypatch):
    recs, rows = _grid()
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.all_figures(recs, rows, tmp_path)
    for stem in ("fig10_profiles", "fig11_peak"):
        axes = [a for a in got[stem].axes if a.get_visible()]
        assert len(axes) > 1
        assert all(a.get_shared_y_axes().joined(axes[0], a) for a in axes), stem


def test_report_states_version_preset_and_mesh_sizes():
    pre = with_quality(Scene(thickness=1.0), "preview")
    custom = Scene(thickness=1.0, mesh_size=0.77, refinement=2.0)
    assert quality_name(pre) == "preview" and quality_name(Scene()) == "default"
    assert quality_name(custom) == "custom"
    text = "\n".join(run_settings([pre, pre, custom]))
    assert f"tactileskin {__version__}" in text
    assert f"| preview | {pre.mesh_size:g} | {pre.refinement:g} |" in text and "| 2 |" in text
    assert "| custom | 0.77 | 2 | 0.385 |" in text and "rtol = 1e-05" in text
    assert "easy_iterations {2: 7, 3: 6}" in text  # the values used where the option is None


def test_profiles_figure_leaves_out_suspect_results_as_the_other_figures_do(tmp_path, monkeypatch):
    # a suspect case (here a law far out of its range: 250 MPa at the bone) was drawn in Fig. 10
    # like any result, unmarked, while Figs. 11-13 and metrics_vs_thickness leave it out; on the
    # shared y axis it also flattened the ok profiles to a line at zero
    s = np.linspace(0, 8, 81)
    recs, rows = [], []
    for mat, pk, summary in (("silicone", 0.3, {}), ("polyurethane", 250.0, {"max_abs_stress_mpa": 300.0})):
        for ind in ("flat", "curved"):
            p = pk * np.exp(-s ** 2)
            recs.append(CaseRecord(Scene(thickness=1.0, material=mat, indenter=ind), s, p, summary, Path(".")))
            rows.append(dict(status="ok" if not summary else "suspect: stress", material=mat, thickness_mm=1.0,
                             indenter=ind, braille_text="", peak_mpa=pk, span_mm=1.0, auc_mpa_mm=pk))
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.all_figures(recs, rows, tmp_path)
    lines = [ln for ax in got["fig10_profiles"].axes for ln in ax.lines if ln.get_label() in ("flat", "curved")]
    assert len(lines) == 2
    assert max(float(np.max(ln.get_ydata())) for ln in lines) == pytest.approx(0.3)


def _one_thickness_2d_3d():
    s = np.linspace(0, 8, 81)
    recs, rows = [], []
    for ind, dim, pk in (("flat", 2, 0.3), ("curved", 2, 0.2), ("braille", 2, 0.1), ("braille", 3, 0.04)):
        p = pk * np.exp(-s ** 2)
        recs.append(CaseRecord(Scene(thickness=1.0, material="silicone", indenter=ind), s, p, {}, Path(".")))
        rows.append(dict(status="ok", material="silicone", thickness_mm=1.0, indenter=ind, braille_text="",
                         dim=dim, peak_mpa=pk, span_mm=1.0, auc_mpa_mm=pk))
    return recs, rows


def test_bars_of_the_2d_ridge_and_the_3d_dots_look_different(tmp_path, monkeypatch):
    # `--braille-dim both`: the 'braille 2d' and 'braille 3d' bars had one colour and no hatch,
    # so the legend could not tell which bar is which model
    recs, rows = _one_thickness_2d_3d()
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.all_figures(recs, rows, tmp_path)
    for stem in ("fig11_peak", "fig12_span", "fig13_auc"):
        ax = got[stem].axes[0]
        style = {c.get_label(): (c.patches[0].get_facecolor(), c.patches[0].get_hatch()) for c in ax.containers}
        assert style["braille 2d"] != style["braille 3d"], stem
    figures._plt().close("all")


def test_sweep_figures_keep_their_title_and_legend_inside_the_image(tmp_path, monkeypatch):
    # one thickness and material: a one-panel figure 3.2 in wide clipped its suptitle
    # ('face mean pressure along the bone (cf. paper') and its legend ('bra' for 'braille 3d')
    recs, rows = _one_thickness_2d_3d()
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.all_figures(recs, rows, tmp_path)
    for stem, fig in got.items():
        fig.canvas.draw()
        r = fig.canvas.get_renderer()
        W, H = fig.bbox.width, fig.bbox.height
        for artist in [fig._suptitle, *fig.legends]:
            if artist is None:
                continue
            bb = artist.get_window_extent(r)
            assert bb.x0 >= -1 and bb.x1 <= W + 1 and bb.y0 >= -1 and bb.y1 <= H + 1, (stem, bb, W)
    figures._plt().close("all")


def test_report_states_geometry_files_that_are_not_the_shipped_ones(tmp_path, monkeypatch):
    # with TACTILESKIN_GEOMETRY naming an edited fingertip.toml the cache keyed the results by
    # it, but report.md said nothing: the paper checks read as if on the shipped fingertip
    import shutil

    from tactileskin import params
    from tactileskin.report.markdown import build_report

    scenes = [Scene(thickness=1.0, material="silicone", indenter="flat")]
    rows = [dict(case="t1", status="ok", material="silicone", thickness_mm=1.0, indenter="flat", braille_text="",
                 depth_mm=0.2, peak_mpa=0.3, span_mm=2.0, auc_mpa_mm=0.4, reaction_n_per_mm=0.5)]
    plain = build_report(rows, [], [], [], [], 1.0, scenes=scenes)
    assert "TACTILESKIN_GEOMETRY" not in plain
    geo = tmp_path / "geo"
    shutil.copytree(params._packaged_dir(), geo)
    monkeypatch.setenv("TACTILESKIN_GEOMETRY", str(geo))
    assert "the same bytes as the shipped" in "\n".join(run_settings(scenes))
    f = geo / "fingertip.toml"
    f.write_text(f.read_text().replace("half_width = 8.0", "half_width = 8.4"))
    md = build_report(rows, [], [], [], [], 1.0, scenes=scenes)
    assert md.count("fingertip.toml differs from the shipped files") == 2  # run settings and the paper section
    assert str(geo) in md


def test_profiles_legend_names_every_series_not_only_the_first_panels(tmp_path, monkeypatch):
    # the legend was taken from the first panel (silicone, t = 1): with its flat case failed or
    # suspect (left out), 'flat' was drawn at t = 3 but missing from the legend
    s = np.linspace(0, 8, 81)
    recs = [CaseRecord(Scene(thickness=t, material="silicone", indenter=ind), s, 0.3 * np.exp(-s ** 2), {}, Path("."))
            for t, inds in ((1.0, ("curved", "braille")), (3.0, ("flat", "curved", "braille"))) for ind in inds]
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.profiles_figure(recs, tmp_path)
    fig = got["fig10_profiles"]
    assert [t.get_text() for leg in fig.legends for t in leg.get_texts()] == ["flat", "curved", "braille"]
    figures._plt().close("all")


def test_profiles_figure_shows_a_two_sided_profile_whole(tmp_path, monkeypatch):
    # a whole model's profile runs across the centre (a full-width pad under Braille 'ab': s from
    # -10 to 10, peak 0.0883 at s = -3.0 at t = 2): the s axis was fixed to 0-8 mm, so half the
    # profile and the reported peak were off the figure; the fingertip's profiles keep 0-8 mm
    s = np.linspace(0, 13.5, 136)
    tip = CaseRecord(Scene(thickness=1.0, material="silicone", indenter="flat"), s, 0.3 * np.exp(-(s / 1.5) ** 2),
                     {}, Path("."))
    s2 = np.linspace(-10, 10, 201)
    whole = CaseRecord(Scene(thickness=2.0, material="silicone", indenter="flat"), s2,
                       0.09 * np.exp(-((s2 + 3) / 0.8) ** 2) + 0.08 * np.exp(-((s2 - 3) / 0.8) ** 2), {}, Path("."))
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.profiles_figure([tip], tmp_path)
    assert got.pop("fig10_profiles").axes[0].get_xlim() == (0.0, 8.0)
    figures.profiles_figure([tip, whole], tmp_path)
    for ax in got["fig10_profiles"].axes:
        lo, hi = ax.get_xlim()
        assert lo <= -4.0 and hi >= 8.0
    figures._plt().close("all")


def test_bar_legends_name_only_series_with_an_ok_case_and_no_case_ok_draws_no_figure(tmp_path, monkeypatch):
    # sweep -t 1 -m lock2.toml,silicone -i flat,curved --depth 0.2,0.6: every d0.6 case failed or
    # suspect, yet Figs. 11-13 listed 'flat d0.6' and 'curved d0.6' in their legends with no bar
    # anywhere; sweep -t 1,3 --mesh-size 3 (all six suspect) wrote empty bar and
    # metrics-against-thickness figures (y from -0.04 to 0.04, a legend of three series)
    recs, rows = _one_thickness_2d_3d()
    rows[3] = dict(rows[3], status="suspect: mesh coarser")
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [stem])
    figures.all_figures(recs[:3], rows, tmp_path)
    for stem in ("fig11_peak", "fig12_span", "fig13_auc"):
        assert [t.get_text() for leg in got[stem].legends for t in leg.get_texts()] == ["flat 2d", "curved 2d", "braille 2d"]
    got.clear()
    assert figures.all_figures([], [dict(r, status="suspect: x") for r in rows], tmp_path) == [] and not got
    from tactileskin.report.markdown import build_report

    sus = [dict(r, status="suspect: x", case=f"c{i}", depth_mm=0.2, reaction_n_per_mm=0.1) for i, r in enumerate(rows)]
    md = build_report(sus, recs, [], [], [], 1.0, scenes=[r.scene for r in recs])
    assert "No figures: no case is ok" in md and "The figures show" not in md
    figures._plt().close("all")


def test_profiles_figure_labels_s_by_what_it_is_on_the_figures_skins(tmp_path, monkeypatch):
    # Fig. 10 said "distance along bone s" and "along the bone" for a pad too, which has no bone:
    # its s is x on the board (skins.pad); the fingertip keeps the paper's label
    s = np.linspace(0, 8, 81)
    p = 0.3 * np.exp(-s ** 2)
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.profiles_figure([CaseRecord(Scene(thickness=2.0, skin="pad"), s, p, {}, Path("."))], tmp_path)
    fig = got.pop("fig10_profiles")
    assert fig.axes[0].get_xlabel() == "distance across the pad s = x (mm)"
    assert "board" in fig._suptitle.get_text() and "bone" not in fig._suptitle.get_text()
    figures.profiles_figure([CaseRecord(Scene(thickness=2.0), s, p, {}, Path("."))], tmp_path)
    fig = got.pop("fig10_profiles")
    assert fig.axes[0].get_xlabel() == "distance along bone s (mm)"
    assert "along the bone" in fig._suptitle.get_text()
    figures._plt().close("all")


def test_run_settings_say_elastic_for_a_material_without_prony_terms(tmp_path):
    """A fitted material has no Prony terms, so its scenes are solved elastic although
    `viscoelastic` defaults to True: the run settings read "yes". They now say no, and why."""
    from tactileskin.cli import main

    lam = np.linspace(0.8, 1.5, 8)
    (tmp_path / "t.csv").write_text("stretch,nominal_stress_mpa\n" + "".join(
        f"{float(a)!r},{float(0.04 * (a - a ** -2))!r}\n" for a in lam))
    gel = tmp_path / "gel.toml"
    assert main(["material", "fit", str(tmp_path / "t.csv"), "-o", str(gel), "--law", "neo_hookean"]) == 0
    fitted, paper = Scene(thickness=1.0, material=str(gel)), Scene(thickness=1.0)
    assert fitted.viscoelastic and paper.viscoelastic
    text = "\n".join(run_settings([fitted, paper, paper.replace(viscoelastic=False)]))
    rows = [ln for ln in text.splitlines() if ln.startswith("| 2D |")]
    cells = sorted(ln.split(" | ")[-3] for ln in rows)
    assert cells == ["no", "no (the material has no Prony terms)", "yes"], rows


def test_bar_figures_of_three_materials_show_no_empty_fourth_panel(tmp_path, monkeypatch):
    """Three materials on a 2 x 2 grid: the spare panel was hidden per row (row[3:], always
    empty), so Figs. 11-13 showed a fourth, empty panel with a 0-1 axis beside the third."""
    rows = [dict(status="ok", material=m, thickness_mm=t, indenter=ind, braille_text="",
                 peak_mpa=0.1, span_mm=1.0, auc_mpa_mm=0.1)
            for m in ("gel.toml", "polyurethane", "silicone") for t in (1.0, 3.0) for ind in ("flat", "curved")]
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.metric_figure(rows, "peak_mpa", "peak P (MPa)", "fig11_peak", "Peak", tmp_path)
    shown = [ax.get_title() for ax in got["fig11_peak"].axes if ax.get_visible()]
    assert shown == ["gel.toml", "polyurethane", "silicone"]


def test_a_figure_saved_twice_has_the_same_bytes(tmp_path):
    """A cached rerun gave byte-identical CSVs but new SVG / PDF figures: matplotlib stamps
    them with the date and salts the SVG's ids with a random hash. Saved alike now."""
    from tactileskin.report import figures

    plt = figures._plt()  # the figures' own settings (SVG text as text)
    got = []
    for k in range(2):
        fig, ax = plt.subplots()
        ax.plot([0, 1], [0, 2])
        ax.set_title("P (MPa)")
        out = tmp_path / str(k)
        out.mkdir()
        got.append({p.name: p.read_bytes() for p in figures._save(fig, out, figures.DESIGN_STEMS[0])})
    assert sorted(got[0]) == ["metrics_vs_thickness.pdf", "metrics_vs_thickness.png", "metrics_vs_thickness.svg"]
    assert got[0] == got[1]


def test_every_format_of_a_figure_has_the_constrained_layout_of_the_first(tmp_path, monkeypatch):
    """The layout is computed once, for the first format, and kept for the others (it was
    recomputed per savefig, ~30 % of the figures' time): the axes of every format sit where
    constrained layout put them, with a long label kept inside, not at matplotlib's defaults."""
    from tactileskin.report import figures

    plt = figures._plt()
    fig, ax = plt.subplots(figsize=(3.0, 2.5), constrained_layout=True)
    ax.plot([0, 1], [0, 2])
    ax.set_ylabel("a long label of the mean pressure P (MPa)")
    pos = []
    real = figures.save_reproducibly
    monkeypatch.setattr(figures, "save_reproducibly",
                        lambda f, buf, fmt, dpi: (real(f, buf, fmt, dpi), pos.append(f.axes[0].get_position().bounds)))
    figures._save(fig, tmp_path, figures.DESIGN_STEMS[0])
    assert len(pos) == 3
    assert all(p == pos[0] for p in pos), pos
    default = plt.rcParams["figure.subplot.left"]
    assert abs(pos[0][0] - default) > 0.02  # constrained layout moved the axes for the label


def _small_grid():
    recs, rows = [], []
    s = np.linspace(0, 8, 41)
    for t in (1.0, 3.0):
        for ind, pk in (("flat", 0.5), ("curved", 0.4)):
            p = pk / (1 + t) * np.exp(-(s / (1 + t / 2)) ** 2)
            recs.append(CaseRecord(Scene(thickness=t, material="silicone", indenter=ind), s, p, {}, Path(".")))
            rows.append(dict(status="ok", material="silicone", thickness_mm=t, indenter=ind, braille_text="",
                             peak_mpa=float(p.max()), span_mm=1.0 + t, auc_mpa_mm=float(np.trapezoid(p, s))))
    return recs, rows


def _drawn(monkeypatch):
    """Count figure_jobs' calls (the drawing) while it still draws."""
    calls = []
    real = figures.figure_jobs
    monkeypatch.setattr(figures, "figure_jobs", lambda *a: (calls.append(1), real(*a))[1])
    return calls


def test_a_rerun_with_the_same_inputs_writes_the_kept_figures_without_drawing(tmp_path, monkeypatch):
    """A cached rerun drew every figure again (3.4 s of a preview sweep's ~11 s): the files are
    kept in the cache under their inputs' digest and copied, byte for byte, in the same order."""
    from tactileskin.cache import ResultCache
    from tactileskin.report import outputs

    recs, rows = _small_grid()
    cache = ResultCache(tmp_path / "cache")
    calls = _drawn(monkeypatch)
    first = outputs._figures(recs, rows, tmp_path / "a", cache)
    again = outputs._figures(recs, rows, tmp_path / "b", cache)
    assert len(calls) == 1  # drawn once
    assert [p.name for p in again] == [p.name for p in first] and len(first) == 11
    assert all(p.parent == tmp_path / "b" for p in again)
    assert [p.read_bytes() for p in again] == [p.read_bytes() for p in first]


def test_a_changed_input_or_a_damaged_kept_figure_is_drawn_again(tmp_path, monkeypatch):
    from tactileskin.cache import ResultCache
    from tactileskin.report import outputs

    calls = []

    def drawn(records, rows):  # a stand-in for the drawing: files that follow the inputs
        calls.append(1)

        def peak(out):
            (out / "fig11_peak.png").write_text(repr([r["peak_mpa"] for r in rows]))
            return [out / "fig11_peak.png"]

        def profiles(out):
            (out / "fig10_profiles.png").write_text(repr([r.pressure.tolist() for r in records]))
            return [out / "fig10_profiles.png"]
        return [peak, profiles]

    monkeypatch.setattr(figures, "figure_jobs", drawn)
    recs, rows = _small_grid()
    cache = ResultCache(tmp_path / "cache")
    first = {p.name: p.read_bytes() for p in outputs._figures(recs, rows, tmp_path / "a", cache)}
    outputs._figures(recs, rows, tmp_path / "a2", cache)
    assert len(calls) == 1
    # one number of one row changed: another key, the figures drawn again and differing
    rows2 = [dict(r) for r in rows]
    rows2[0]["peak_mpa"] *= 1.5
    changed = {p.name: p.read_bytes() for p in outputs._figures(recs, rows2, tmp_path / "b", cache)}
    assert len(calls) == 2 and changed["fig11_peak.png"] != first["fig11_peak.png"]
    # a profile point changed (the records, not the rows): drawn again
    recs2 = [CaseRecord(r.scene, r.s, r.pressure * (1.1 if k == 0 else 1.0), r.summary, r.path)
             for k, r in enumerate(recs)]
    outputs._figures(recs2, rows, tmp_path / "c", cache)
    assert len(calls) == 3
    # the kept copy of the first figures damaged: not used, drawn again as they were
    kept = cache.root / f"figures-{figures.figures_key(recs, rows)}" / "fig11_peak.png"
    kept.write_bytes(kept.read_bytes()[:-1] + b"!")
    again = {p.name: p.read_bytes() for p in outputs._figures(recs, rows, tmp_path / "d", cache)}
    assert len(calls) == 4 and again == first


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork() is Linux-only here")
def test_the_first_figures_are_drawn_in_a_second_process_to_the_same_bytes(tmp_path, monkeypatch):
    """The sweep's figures took ~3 s after its last solve on 2 cores; the first
    BACKGROUND_JOBS figures are drawn in a fork()ed child meanwhile. The files, their order
    and their bytes are all_figures' own."""
    from tactileskin import threads
    from tactileskin.cache import ResultCache
    from tactileskin.report import outputs

    monkeypatch.setattr(threads, "other_threads", list)  # pytest-xdist's own threads
    recs, rows = _small_grid()
    serial = figures.all_figures(recs, rows, tmp_path / "serial")
    pids = {}
    real = figures.figure_jobs

    def jobs(records, rows):  # each job notes the process that ran it beside its files
        def noted(job, k):
            def run(out):
                (out / f"pid{k}").write_text(str(os.getpid()))
                return job(out) + [out / f"pid{k}"]
            return run
        return [noted(job, k) for k, job in enumerate(real(records, rows))]

    monkeypatch.setattr(figures, "figure_jobs", jobs)
    rendered = []
    split = outputs._figures(recs, rows, tmp_path / "split", ResultCache(tmp_path / "cache"),
                             meanwhile=lambda: rendered.append(os.getpid()))
    for p in split:
        if p.name.startswith("pid"):
            pids[int(p.name[3:])] = int(p.read_text())
    drawn = [p for p in split if not p.name.startswith("pid")]
    assert [p.name for p in drawn] == [p.name for p in serial]
    assert [p.read_bytes() for p in drawn] == [p.read_bytes() for p in serial]
    here = os.getpid()
    assert rendered == [here]
    assert [pids[k] != here for k in sorted(pids)] == [True] * outputs.BACKGROUND_JOBS + [False] * (
        len(pids) - outputs.BACKGROUND_JOBS)


def test_the_tables_are_written_while_the_second_process_draws(tmp_path, monkeypatch):
    """The second process had the longer share of the drawing (~0.1 s waited for it); the
    tables (CSV, Parquet: ~0.05-0.2 s with pyarrow's import) were written before it was
    started. They are written after, with the renders, and are the same files."""
    from tactileskin import threads
    from tactileskin.cache import ResultCache
    from tactileskin.report import background, outputs

    monkeypatch.setattr(threads, "other_threads", list)  # pytest-xdist's own threads
    recs, rows = _small_grid()
    for k, r in enumerate(rows):
        r.update(case=f"c{k}", key=f"k{k}", dim=2, variant="")
    for k, r in enumerate(recs):
        r.case = f"c{k}"
    monkeypatch.setattr(outputs, "collect", lambda outcomes, cache: (recs, rows, []))
    events = []
    enter, parquet = background.Background.__enter__, outputs._write_parquet

    def entered(self):
        got = enter(self)
        events.append(("child", self.pid is not None))
        return got

    monkeypatch.setattr(background.Background, "__enter__", entered)
    monkeypatch.setattr(outputs, "_write_parquet", lambda path, *a: events.append(path.name) or parquet(path, *a))
    import tactileskin.report.markdown as markdown

    monkeypatch.setattr(markdown, "build_report", lambda *a, **k: "report")
    outputs._write_outputs(tmp_path, [], ResultCache(tmp_path / "cache"), 1.0, render=True, figures=True)
    assert events == [("child", True), "results.parquet", "profiles.parquet"]
    names = {p.name for p in tmp_path.iterdir()}
    assert {"results.csv", "results.parquet", "profiles.csv", "profiles.parquet", "fig11_peak.png"} <= names


def test_the_figures_key_does_not_import_pyplot():
    """A cached rerun draws nothing, but reading rcParams["backend"] for the key imported
    pyplot (~0.5 s of the rerun's ~2 s)."""
    import subprocess
    import sys

    code = ("import sys; from tactileskin.report import figures; figures.drawing_digest(); "
            "print('matplotlib.pyplot' in sys.modules)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stdout.strip() == "False"


def test_a_resolved_case_with_the_same_results_keeps_its_figures(tmp_path):
    """The figures' key hashed every row and summary field, the solve's wall time among them:
    a case solved again (its cache entry lost, another cache) with the same numbers drew
    every figure again (~3.4 s of a preview sweep). No figure draws a wall time (the
    drawings are byte-identical), so it is not in the key; a number the figures draw is."""
    recs, rows = _small_grid()

    def timed(wall):
        rs = [CaseRecord(r.scene, r.s, r.pressure, {**r.summary, "wall_s": wall + k}, r.path)
              for k, r in enumerate(recs)]
        return rs, [dict(r, wall_s=wall + k) for k, r in enumerate(rows)]

    a, b = timed(1.0), timed(7.5)
    assert figures.figures_key(*a) == figures.figures_key(*b)
    drawn_a = {p.name: p.read_bytes() for p in figures.all_figures(*a, tmp_path / "a")}
    drawn_b = {p.name: p.read_bytes() for p in figures.all_figures(*b, tmp_path / "b")}
    assert drawn_a == drawn_b and len(drawn_a) == 11
    peak = [dict(r) for r in a[1]]
    peak[0]["peak_mpa"] *= 1.001
    assert figures.figures_key(a[0], peak) != figures.figures_key(*a)
    summ = [CaseRecord(r.scene, r.s, r.pressure, {**r.summary, "peak_mpa": 0.1}, r.path) if k == 0 else r
            for k, r in enumerate(a[0])]
    assert figures.figures_key(summ, a[1]) != figures.figures_key(*a)


def test_run_settings_give_the_numbers_of_each_material(tmp_path):
    """A material file edited between two sweeps (mu 0.010 -> 0.012 MPa in a copy of silicone)
    re-solved every case and moved every number (t = 1 mm flat peak 0.315 -> 0.340 MPa), but the
    two report.md's Run settings, which state what produced the numbers, read alike: the material
    was its path only. They now give each material's law and numbers, as the cache keys them."""
    toml = ("[hyperfoam]\nmu = [0.080, {mu}]\nalpha = [0.001, 15.5]\nnu = 0.49\n"
            "[prony]\ng = [0.015, 0.044, 0.029]\ntau = [0.025, 0.150, 0.300]\n")
    mat = tmp_path / "mysil.toml"
    mat.write_text(toml.format(mu="0.010"))
    scenes = [Scene(thickness=1.0, material=str(mat)), Scene(thickness=1.0, material="polyurethane")]
    before = "\n".join(run_settings(scenes))
    assert "`mysil` (mysil.toml): hyperfoam alpha = [0.001, 15.5], mu = [0.08, 0.01], nu = 0.49; " \
           "Prony g = [0.015, 0.044, 0.029], tau = [0.025, 0.15, 0.3] s" in before
    assert "`polyurethane`: hyperfoam alpha = [5.5, 8.25], mu = [0.1, 0.063], nu = 0.47; " in before
    mat.write_text(toml.format(mu="0.012"))
    after = "\n".join(run_settings(scenes))
    assert after != before and "mu = [0.08, 0.012]" in after


def test_the_drawing_digest_follows_the_font_files_bytes(tmp_path, monkeypatch):
    """The kept figures were named by each font file's path and size: a font replaced by
    another of the same size (its time stamp kept, touch -r) drew other glyphs, but a rerun
    copied the figures drawn with the old one. The font's bytes are hashed now."""
    import os

    from matplotlib import font_manager

    real = font_manager.findfont(font_manager.FontProperties(family=["DejaVu Sans"]))
    font = tmp_path / "font.ttf"
    font.write_bytes(Path(real).read_bytes())
    monkeypatch.setattr(font_manager, "findfont", lambda *a, **k: str(font))
    before, st = figures.drawing_digest(), font.stat()
    data = bytearray(font.read_bytes())
    data[len(data) // 2] ^= 0xFF
    font.write_bytes(bytes(data))
    os.utime(font, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert font.stat().st_size == st.st_size and font.stat().st_mtime_ns == st.st_mtime_ns
    assert figures.drawing_digest() != before
