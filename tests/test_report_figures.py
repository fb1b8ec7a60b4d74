"""Sweep figures that scale to the grid, the metrics-against-thickness figure, report settings."""

from __future__ import annotations

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


def test_a_suspect_profile_is_marked_in_fig10(tmp_path, monkeypatch):
    """A suspect case's profile (here: no contact) was drawn and labelled as any other."""
    s = np.linspace(0, 8, 81)
    ok = {"peak_mpa": 0.3, "contact_points": 5, "reaction_n_per_mm": 0.5, "min_J": 0.95, "max_abs_stress_mpa": 0.4}
    none = {**ok, "peak_mpa": 0.0, "contact_points": 0, "reaction_n_per_mm": 0.0}
    recs = [CaseRecord(Scene(thickness=3.0, indenter="flat"), s, 0.3 * np.exp(-s ** 2), ok, Path(".")),
            CaseRecord(Scene(thickness=3.0, indenter="curved"), s, 0 * s, none, Path("."))]
    got = {}
    monkeypatch.setattr(figures, "_save", lambda fig, out, stem: got.setdefault(stem, fig) and [])
    figures.profiles_figure(recs, tmp_path)
    fig = got["fig10_profiles"]
    labels = [ln.get_label() for ln in fig.axes[0].lines if not ln.get_label().startswith("_")]
    assert labels == ["flat", "curved (suspect)"]
    assert "suspect" in fig._suptitle.get_text() and "curved" in fig._suptitle.get_text()
