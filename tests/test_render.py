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
