"""The figures of one result say when it is suspect, as summary.json does: Result.plot() (the
profile, 3D with its map) and the render of a result.vtu (report.render) were titled as an
ok result's. The note is summary.json's status text (quality.suspect_title)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from tactileskin import quality  # noqa: E402
from tactileskin.fe import solve  # noqa: E402
from tactileskin.planner import with_quality  # noqa: E402
from tactileskin.results import BoneMap, Result  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402

OK = with_quality(Scene(thickness=3.0, indenter="curved"), "preview")
# no contact: the depth is far below the contact tolerance (test_result_status)
NO_CONTACT = with_quality(Scene(thickness=3.0, indenter="curved", depth=1e-6), "preview")


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    out = {}
    for name, sc in (("ok", OK), ("suspect", NO_CONTACT)):
        res = solve(sc)
        out[name] = (res, res.write(tmp_path_factory.mktemp(name) / "r"))
    assert quality.kind(out["suspect"][0].status) == "suspect" and out["ok"][0].status == "ok"
    return out


def _fits(fig, text_artist) -> bool:
    fig.canvas.draw()
    box = text_artist.get_window_extent(fig.canvas.get_renderer())
    return box.x0 >= -1 and box.x1 <= fig.bbox.width + 1


def test_result_plot_of_a_suspect_result_says_so(solved):
    for name, (res, _) in solved.items():
        fig, ax = res.plot()
        title = ax.get_title(loc="left")
        assert ("SUSPECT: no contact" in title) == (name == "suspect"), title
        assert _fits(fig, ax._left_title)
        plt.close(fig)


def test_result_plot_of_a_suspect_3d_result_says_so():
    s, z = np.linspace(0, 4, 9), np.linspace(-1, 1, 5)
    P = np.outer(1 + z ** 2, np.exp(-s))
    for stress in (0.3, 1e5):
        r = Result(s=s, pressure=P[2], contact_x=np.array([0.0, 0.5]), contact_pressure=np.array([0.3, 0.2]),
                   reaction=-1.0, stats={"profile_plane_z": 0.0, "max_abs_stress_mpa": stress},
                   scene={"dim": 3}, bone_map=BoneMap(s, z, P, section_z=0.0))
        fig, axes = r.plot()
        title = axes[0].get_title(loc="left")
        assert ("SUSPECT: stress" in title) == (stress > quality.MAX_ABS_STRESS_MPA), title
        assert _fits(fig, axes[0]._left_title)
        plt.close(fig)


def test_the_render_of_a_suspect_result_says_so(solved):
    from tactileskin.report.render import render_figure

    for name, (res, out) in solved.items():
        fig = render_figure(out / "result.vtu", "t3 curved")
        title = fig.axes[0].get_title(loc="left")
        assert title.startswith("t3 curved")
        assert ("SUSPECT: no contact" in title) == (name == "suspect"), title
        plt.close(fig)


def test_the_note_is_the_summarys_status():
    why = "no contact (no contact point): the indenter pressed no contact point"
    assert quality.suspect_title("x", "ok") == "x"
    t = quality.suspect_title("x", "suspect: " + why, width=40)
    assert t.startswith("x\nSUSPECT: no contact") and " ".join(t.split("\n")[1:]) == "SUSPECT: " + why
    assert quality.suspect_title("x", None) == "x"  # a file without a status (written before)


def test_the_3d_render_of_a_suspect_result_says_so(tmp_path, monkeypatch):
    """The pyvista render's title text (coarse-mesh 3D pad of test_status_columns, ~10 s)."""
    pv = pytest.importorskip("pyvista")
    from tactileskin.report.render import render_case

    texts = []
    add_text = pv.Plotter.add_text
    monkeypatch.setattr(pv.Plotter, "add_text", lambda self, text, **kw: texts.append(text) or add_text(self, text, **kw))
    res = solve(Scene(dim=3, thickness=1.0, indenter="flat", mesh_size=4.0, refinement=2, depth=0.1,
                      viscoelastic=False))
    assert res.status.startswith("suspect: mesh coarser")
    out = res.write(tmp_path / "r")
    assert render_case(out / "result.vtu", tmp_path / "r.png", title="t1 flat 3d").is_file()
    assert len(texts) == 1 and texts[0].startswith("t1 flat 3d\nSUSPECT: mesh coarser"), texts
