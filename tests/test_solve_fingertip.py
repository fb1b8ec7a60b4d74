"""The whole pipeline on the 2D fingertip: scene -> mesh -> solve -> Result -> files / CLI."""

import csv
import json

import numpy as np
import pytest

from tactileskin.cli import main
from tactileskin.fe import solve
from tactileskin.scene import Scene


@pytest.fixture(scope="module")
def flat_1mm():
    # a coarser mesh than the default keeps this a smoke test (~2 s); physics checks below
    # do not depend on the resolution
    return solve(Scene(thickness=1.0, material="silicone", indenter="flat", mesh_size=0.4), history=True)


def test_fingertip_flat_converges_with_a_finite_positive_peak_under_the_indenter(flat_1mm):
    r = flat_1mm
    assert np.all(np.isfinite(r.pressure)) and r.s.size > 20
    assert r.peak > 0
    # the flat plate presses the pulp around x = 0: the peak sits near s = 0 and P decays
    # far along the bone (the nail end, ~13.6 mm, is unloaded)
    assert r.s[np.argmax(r.pressure)] < 1.0
    assert abs(r.pressure[-1]) < 0.05 * r.peak
    # the vertical reaction on the bone equals the indenter load: both from the solution
    assert r.reaction > 0
    assert r.stats["increments"] >= 1 and r.stats["newton_iterations"] >= r.stats["increments"]
    # the contact zone is centred on the symmetry line
    assert r.contact_x.min() < 0.2 and np.all(r.contact_pressure > 0)


def test_history_follows_the_indenter(flat_1mm):
    h = flat_1mm.history
    t = np.array([r["t"] for r in h])
    d = np.array([r["d"] for r in h])
    f = np.array([r["reaction"] for r in h])
    assert len(h) == flat_1mm.stats["increments"]
    assert np.all(np.diff(t) > 0) and t[-1] == pytest.approx(0.2)   # 0.2 mm at 1 mm/s
    np.testing.assert_allclose(d, 1.0 * t)
    assert np.all(np.diff(f) > 0) and f[-1] == pytest.approx(flat_1mm.reaction)


def test_result_write_is_complete(flat_1mm, tmp_path):
    out = flat_1mm.write(tmp_path / "res")
    names = sorted(p.name for p in out.iterdir())
    # solved with history=True: also the time series result.pvd over result_steps/; the marker
    # of the folder Result.write claimed, with its record of the files written (and its lock)
    assert names == [".tactileskin", ".tactileskin-files.json", ".tactileskin-files.lock", ".tactileskin-run.lock",
                     "contact.csv",
                     "profile.csv", "result.pvd", "result.vtu", "result_steps", "summary.json"]
    rows = list(csv.reader(open(out / "profile.csv")))
    assert rows[0] == ["s_mm", "pressure_mpa", "status"]
    s = np.array([float(a) for a, _, _ in rows[1:]])
    assert np.all(np.diff(s) > 0)
    summ = json.loads((out / "summary.json").read_text())
    for k in ("peak_mpa", "span_mm", "auc_mpa_mm", "reaction_n_per_mm", "dofs", "newton_iterations",
              "increments", "wall_s"):
        assert k in summ
    assert summ["peak_mpa"] == pytest.approx(flat_1mm.peak)
    import meshio

    vtu = meshio.read(out / "result.vtu")
    assert vtu.cells[0].type == "triangle6"
    for k in ("pressure_MPa", "displacement_mm", "sxx_MPa", "syy_MPa", "szz_MPa", "sxy_MPa"):
        assert np.all(np.isfinite(vtu.point_data[k]))
    # the bone nodes of the profile are among the mesh nodes, with the same pressure
    assert vtu.point_data["pressure_MPa"].max() >= flat_1mm.peak - 1e-12
    # rewriting replaces the folder without leaving temporary siblings
    flat_1mm.write(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["res"]


def test_cli_solve_writes_the_same_numbers_as_the_api(tmp_path, capsys):
    rc = main(["solve", "--thickness", "1", "--material", "silicone", "--indenter", "flat",
               "--mesh-size", "0.4", "--out", str(tmp_path / "cli")])
    assert rc == 0
    assert "peak bone pressure" in capsys.readouterr().out
    summ = json.loads((tmp_path / "cli" / "summary.json").read_text())
    api = solve(Scene(thickness=1.0, mesh_size=0.4))
    assert summ["peak_mpa"] == pytest.approx(api.peak, rel=1e-9)


def test_cli_rejects_bad_thickness_without_output(tmp_path, capsys):
    rc = main(["solve", "--thickness", "9", "--out", str(tmp_path / "o")])
    assert rc == 2 and "thickness" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
