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


def test_a_title_with_more_reasons_than_lines_says_how_many_more():
    """At most three status lines: the fourth reason and those after it were cut without a word
    ('...' in the middle of the third line). The title now ends with '(+N more)', N the reasons
    it leaves out, and shows whole reasons only (the first is cut when it alone is too long)."""
    reasons = [f"reason {k} " + "x" * 40 for k in range(1, 6)]  # 49 characters each
    t = quality.suspect_title("x", "suspect: " + "; ".join(reasons), width=72)
    lines = t.split("\n")
    assert len(lines) <= 4 and all(len(ln) <= 72 for ln in lines[1:]), lines
    body = " ".join(lines[1:])
    shown = [r for r in reasons if r in body]
    assert len(shown) >= 2 and body.endswith(f"(+{len(reasons) - len(shown)} more)"), body
    assert [r for r in reasons if r.split()[1] in body.split()] == shown  # no reason cut in two
    long = "y" * 400
    t = quality.suspect_title("x", f"suspect: {long}; short one", width=40).split("\n")
    assert len(t) == 4 and t[-1].endswith("... (+1 more)") and all(len(ln) <= 40 for ln in t[1:]), t
    assert quality.suspect_title("x", f"suspect: {long}", width=40).split("\n")[-1].endswith("y...")


def test_no_reason_holds_the_separator_of_the_status():
    """'; ' parts the status's reasons (a title counts them): no reason may hold it."""
    summaries = [dict(peak_mpa=0.1, profile_min_mpa=-1.0, reaction_n_per_mm=1.0, contact_points=5),
                 dict(peak_mpa=0.1, reaction_n=1.0, max_abs_stress_mpa=3.0, material_mu0_mpa=0.09),
                 dict(element_order=1, material_nu0=0.49),
                 dict(profile_plane_from_map=True, peak_map_edge_mpa=1.0, peak_map_edge_s_mm=1.0,
                      peak_map_edge_z_mm=1.0, profile_plane_z=0.0),
                 dict(peak_mpa=0.1, peak_interior_mpa=0.05, peak_edge_s_mm=3.0, peak_interior_s_mm=0.0),
                 dict(indenter_cap={"contact_mm": 1.0, "face_half_mm": 0.5, "axis": "x"}),
                 dict(indenter_cap={"travel_mm": 1.0, "cap_mm": 0.5}),
                 dict(buckling={"strain": 0.2, "euler_strain": 0.03})]
    found = [f for s in summaries for f in quality.flags(s)]
    assert {f.code for f in found} >= {"tensile_bone", "stress_range", "locking", "edge_peak", "indenter_cap",
                                       "buckling"}
    assert not [f.reason for f in found if "; " in f.reason]
    # a reason holding the separator would count as two: it is mended, not raised on (a solve's
    # end must not fail on a status text)
    assert quality.Flag("x", "a; b; c").reason == "a, b, c"
    assert quality.status_of([quality.Flag("x", "a; b"), quality.Flag("y", "c")]).split(quality.SEPARATOR) == \
        ["suspect: a, b", "c"]
