"""Result.plot() (matplotlib) and Result.to_pyvista() (the content of result.vtu)."""

from __future__ import annotations

import sys

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import dataclasses  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from tactileskin.errors import MissingDependency, ParameterError  # noqa: E402
from tactileskin.fe import solve  # noqa: E402
from tactileskin.planner import with_quality  # noqa: E402
from tactileskin.results import BoneMap, Result  # noqa: E402
from tactileskin.scene import Scene  # noqa: E402

SCENE = with_quality(Scene(thickness=1.0, material="silicone", indenter="flat"), "preview")


@pytest.fixture(scope="module")
def res():
    return solve(SCENE)


def test_plot_draws_the_profile_and_writes_nothing_unless_asked(res, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    fig, ax = res.plot()
    s, p = res._profile()
    np.testing.assert_array_equal(ax.lines[0].get_xdata(), s)
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), p)
    assert "(mm)" in ax.get_xlabel() and "(MPa)" in ax.get_ylabel()
    assert list(tmp_path.iterdir()) == []
    plt.close(fig)
    fig, ax = res.plot(tmp_path / "p.pdf")
    assert (tmp_path / "p.pdf").read_bytes()[:5] == b"%PDF-"
    plt.close(fig)
    with pytest.raises(ParameterError, match="suffix"):
        res.plot(tmp_path / "p.jpeg")
    assert not (tmp_path / "p.jpeg").exists()


def test_plot_labels_s_by_what_it_is_on_the_results_skin(res):
    # a pad has no bone: its s is x across the board (the label said "s along the bone" for every skin)
    fig, ax = res.plot()
    assert ax.get_xlabel() == "distance along bone s (mm)"
    plt.close(fig)
    pad = dataclasses.replace(res, scene={**res.scene, "skin": "pad"})
    fig, ax = pad.plot()
    assert ax.get_xlabel() == "distance across the pad s = x (mm)"
    plt.close(fig)


def test_plot_into_the_callers_axes(res):
    fig, ax = plt.subplots()
    f2, a2 = res.plot(ax=ax)
    assert f2 is fig and a2 is ax and len(ax.lines) == 1
    plt.close(fig)


def test_plot_of_a_3d_result_has_the_map_panel():
    s, z = np.linspace(0, 4, 9), np.linspace(-1, 1, 5)
    P = np.outer(1 + z ** 2, np.exp(-s))  # largest at |z| = 1: the maximum over z is 2 exp(-s)
    bm = BoneMap(s, z, P, section_z=0.0)
    r = Result(s=s, pressure=P[2], contact_x=np.zeros(0), contact_pressure=np.zeros(0), reaction=-1.0,
               stats={"profile_plane_z": 0.0}, bone_map=bm)
    fig, axes = r.plot()
    assert len(axes) == 2
    np.testing.assert_allclose(axes[0].lines[1].get_ydata(), 2 * np.exp(-s))
    assert fig.axes[-1].get_ylabel() == "P (MPa)"  # the colour bar
    with pytest.raises(ParameterError, match="ax"):
        r.plot(ax=axes[0])
    plt.close(fig)


def test_to_pyvista_is_the_reference_mesh_with_fields_and_names(res):
    pytest.importorskip("pyvista")
    grid = res.to_pyvista()
    X = res.fields["points"]
    u = res.fields["point_data"]["displacement_mm"]
    assert grid.n_points == len(X)
    np.testing.assert_array_equal(grid.points[:, :2], X)
    np.testing.assert_array_equal(grid.point_data["pressure_MPa"], res.fields["point_data"]["pressure_MPa"])
    # Warp By Vector on the active vectors gives the deformed skin (reference + u)
    np.testing.assert_allclose(grid.warp_by_vector().points[:, :2], X + u)
    bid = grid.cell_data["boundary_id"]
    assert np.count_nonzero(bid == 0) == len(res.fields["cells"])
    names = {k: int(np.asarray(grid.field_data[k]).ravel()[0]) for k in grid.field_data.keys()}
    assert set(names) == set(res.fields["boundaries"])
    for name, (_, conn) in res.fields["boundaries"].items():
        assert np.count_nonzero(bid == names[name]) == len(conn)


def test_to_pyvista_without_pyvista_names_the_extra(res, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyvista", None)  # import pyvista -> ImportError
    with pytest.raises(MissingDependency, match=r"pip install 'tactileskin\[render\]'"):
        res.to_pyvista()
