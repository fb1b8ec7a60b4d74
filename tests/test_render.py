"""The Fig. 9-style render (report.render): mm axes, scale bar, indenter outline at full
depth resting on the deformed skin, viridis, colour bar with the unit."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar  # noqa: E402

from tactileskin.fe import solve  # noqa: E402
from tactileskin.planner import with_quality  # noqa: E402
from tactileskin.report.render import render_case, render_figure, scale_bar_length  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402


@pytest.fixture(scope="module", params=["flat", "curved"])
def case(request, tmp_path_factory):
    sc = with_quality(Scene(thickness=1.0, material="polyurethane", indenter=request.param), "preview")
    out = solve(sc).write(tmp_path_factory.mktemp("r") / "r")
    return sc, out / "result.vtu"


def test_render_axes_scale_bar_colour_bar_and_outline(case, tmp_path):
    sc, vtu = case
    fig = render_figure(vtu, "t", sc)
    try:
        ax = fig.axes[0]
        assert ax.get_xlabel() == "x (mm)" and ax.get_ylabel() == "y (mm)"
        assert ax.get_aspect() == 1.0
        assert ax.collections[0].get_cmap().name == "viridis"
        assert "(MPa)" in fig.axes[1].get_ylabel()  # the colour bar
        bars = [a for a in ax.artists if isinstance(a, AnchoredSizeBar)]
        assert len(bars) == 1
        # the indenter's face at full depth: its lowest point is the undeformed top moved down
        # by the indentation, and it rests on the deformed skin (the top node's y) to within
        # the contact tolerance (1e-4 mm penetration) and the solver's tolerance
        poly = next(p for p in ax.patches if isinstance(p, Polygon)).get_xy()
        face_y = poly[:200, 1]
        top0 = sc.section().top
        assert face_y.min() == pytest.approx(top0 - sc.indentation, abs=1e-9)
        import meshio

        m = meshio.read(vtu)
        y = m.points[:, 1] + m.point_data["displacement_mm"][:, 1]
        i = np.argmax(m.points[:, 1])  # the skin's top at x = 0
        assert y[i] == pytest.approx(top0 - sc.indentation, abs=5e-4)
    finally:
        plt.close(fig)
    png = render_case(vtu, tmp_path / "fig9.png", title="t", scene=sc)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("extent, bar", [(12.0, 2.0), (30.0, 5.0), (4.0, 0.5), (0.9, 0.1)])
def test_scale_bar_is_a_round_fifth(extent, bar):
    assert scale_bar_length(extent) == pytest.approx(bar)


def test_a_2d_render_is_kept_in_the_cache_and_copied_on_a_rerun(case, tmp_path):
    """A cached rerun rendered the Fig. 9 cases again (~0.8 s of a preview sweep): the render
    is kept under the digest of its result.vtu, scene, title and name, and copied, with the
    bytes a fresh render has; another result is rendered anew."""
    import meshio

    from tactileskin.cache import CaseRecord, ResultCache
    from tactileskin.report import outputs

    sc, vtu = case
    rec = CaseRecord(sc, np.zeros(2), np.zeros(2), {}, vtu.parent, case="c")
    cache = ResultCache(tmp_path / "cache")
    calls = []

    def counted(*a, **kw):
        calls.append(1)
        return render_case(*a, **kw)

    first = outputs._render(counted, vtu, tmp_path / "a" / "fig9_c.png", rec, cache)
    again = outputs._render(counted, vtu, tmp_path / "b" / "fig9_c.png", rec, cache)
    fresh = render_case(vtu, tmp_path / "fresh.png", title="c", scene=sc)
    assert len(calls) == 1 and again.parent == tmp_path / "b"
    assert again.read_bytes() == first.read_bytes() == fresh.read_bytes()
    m = meshio.read(vtu)
    m.point_data["displacement_mm"] = 0.5 * m.point_data["displacement_mm"]
    other = tmp_path / "other" / "result.vtu"
    other.parent.mkdir()
    m.write(other)
    changed = outputs._render(counted, other, tmp_path / "c" / "fig9_c.png", rec, cache)
    assert len(calls) == 2 and changed.read_bytes() != first.read_bytes()


def test_a_force_case_draws_the_indenter_at_the_travel_it_reached(tmp_path, monkeypatch):
    """Force control: the sweep's Fig. 9 drew the indenter 'at full depth (0.2 mm)', the
    scene's default 20 % of t, on a skin pressed 0.056 mm (F = 0.03 N/mm): the outline floated
    inside the skin and its legend named a depth the case never had. It is drawn at the travel
    of the result's state (summary loading.profile_travel_mm) and says so."""
    from tactileskin.cli import main
    from tactileskin.report import render

    seen = []
    real = render.render_case

    def spy(vtu, png, **kw):
        seen.append(kw)
        return real(vtu, png, **kw)

    monkeypatch.setattr(render, "render_case", spy)
    out = tmp_path / "o"
    assert main(["sweep", "-t", "1", "-m", "polyurethane", "-i", "flat", "--force", "0.03", "--quality",
                 "preview", "--serial", "--out", str(out)]) == 0
    assert len(seen) == 1
    travel = seen[0]["depth"]
    assert 0.01 < travel < 0.15  # not the scene's 0.2 mm
    sc = seen[0]["scene"]
    fig = render_figure(next((out / "cache").rglob("result.vtu")), "t", sc, depth=travel)
    try:
        ax = fig.axes[0]
        poly = next(p for p in ax.patches if isinstance(p, Polygon))
        assert poly.get_xy()[:200, 1].min() == pytest.approx(sc.section().top - travel, abs=1e-9)
        assert poly.get_label() == f"indenter at the travel reached ({travel:.3g} mm)"
    finally:
        plt.close(fig)
