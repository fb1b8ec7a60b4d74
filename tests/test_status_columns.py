"""Every CSV a solve writes carries the result's status on every row (the `status` column,
summary.json's text, as the sweep's sensors.csv): a suspect result's profile.csv, contact.csv,
sensors.csv, bone map and history read like an ok one's before. Readers take the column, and
files written before it."""

import csv
import json

import numpy as np
import pytest

from tactileskin import quality
from tactileskin.cli import main
from tactileskin.results import BoneMap, Result, read_bone_map
from tactileskin.scene import Scene
from tactileskin.sensors import COLUMNS, SensorReadings, read_sensors_csv

SENSORS_TOML = '[[sensors]]\nkind = "points"\ns = [0.0, 1.0]\ndepth = 0.5\n'
# coarser than the preview preset (suspect, with contact points: contact.csv has rows), ~4 s
COARSE_2D = ["-t", "3", "-i", "curved", "--mesh-size", "2", "--refinement", "2"]
# the same flag in 3D on a thin flat-pressed skin (~2000 dofs, ~6 s)
COARSE_3D = ["--dim", "3", "-t", "1", "-i", "flat", "--mesh-size", "4", "--refinement", "2", "--depth", "0.1",
             "--elastic"]


def csv_statuses(folder) -> dict:
    """{relative path: (header, [status of each row])} of every CSV under `folder`."""
    out = {}
    for f in sorted(folder.rglob("*.csv")):
        with open(f, newline="", encoding="utf-8") as fh:
            rd = csv.DictReader(fh)
            rows = list(rd)
        assert all(None not in r for r in rows), f  # no row longer than its header (a quoted status)
        out[f.relative_to(folder).as_posix()] = (rd.fieldnames, [r.get("status") for r in rows])
    return out


def assert_status_everywhere(folder, expected: str, names) -> None:
    got = csv_statuses(folder)
    assert set(got) == set(names), sorted(got)
    for name, (header, statuses) in got.items():
        assert header[-1] == "status", (name, header)
        assert statuses and all(s == expected for s in statuses), (name, statuses[:3], expected)


def _readings(n=2):
    return SensorReadings(ids=[f"L0-{i}" for i in range(n)], layout=["L0"] * n,
                          xyz=np.c_[np.arange(n), np.full(n, 6.0), np.zeros(n)], s=np.arange(n, dtype=float),
                          depth=np.full(n, 0.5), normal=np.tile([0.0, 1.0, 0.0], (n, 1)),
                          pressure=np.full(n, 0.1), sigma_nn=np.full(n, -0.1), tau_1=np.zeros(n),
                          tau_2=np.zeros(n), taxel_points=np.ones(n, int), normal_depth=np.full(n, 0.5))


def _result(stress: float) -> Result:
    """A 3D-like result with every optional file: contact points, a map, sensors, a history."""
    s = np.linspace(0.0, 2.0, 5)
    p = 0.2 * np.exp(-s)
    z = np.linspace(0.0, 1.0, 3)
    hist = [{"t": 0.5, "d": 0.05, "reaction": 0.1, "peak_mpa": 0.1, "segment": 0},
            {"t": 1.0, "d": 0.1, "reaction": 0.2, "peak_mpa": 0.2, "segment": 0}]
    return Result(s=s, pressure=p, contact_x=np.array([0.0, 0.5, 1.0]), contact_pressure=np.array([0.3, 0.2, 0.1]),
                  contact_points=np.c_[[0.0, 0.5, 1.0], [7.0, 7.0, 7.0], [0.0, 0.0, 0.0]], reaction=0.5,
                  stats={"min_J": 0.99, "max_abs_stress_mpa": stress}, history=hist,
                  scene={"dim": 3}, bone_map=BoneMap(s, z, np.tile(p, (3, 1)), 0.0), sensors=_readings(),
                  loading={"control": "depth", "profile_t_s": 1.0, "final": {"t_s": 1.0}})


ALL_FILES = ["profile.csv", "contact.csv", "bone_map.csv", "profile_max_z.csv", "sensors.csv", "history.csv"]


@pytest.mark.parametrize("stress", [0.3, 1e5])
def test_every_csv_of_a_result_carries_its_status(tmp_path, stress):
    r = _result(stress)
    status = r.summary()["status"]
    assert (status == "ok") == (stress < quality.MAX_ABS_STRESS_MPA)
    out = r.write(tmp_path / "o")
    assert json.loads((out / "summary.json").read_text())["status"] == status
    assert_status_everywhere(out, status, ALL_FILES)


def test_the_numbers_and_other_columns_are_unchanged(tmp_path):
    r = _result(1e5)
    out = r.write(tmp_path / "o")
    with open(out / "profile.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [k for k in rows[0]] == ["s_mm", "pressure_mpa", "status"]
    np.testing.assert_array_equal([float(x["pressure_mpa"]) for x in rows], [float(f"{v:.10g}") for v in r.pressure])
    # the numeric columns read by position, as before (usecols: the status is last)
    prof = np.loadtxt(out / "profile.csv", delimiter=",", skiprows=1, usecols=(0, 1))
    np.testing.assert_allclose(prof[:, 0], r.s)
    # readers take the new files ...
    bm = read_bone_map(out / "bone_map.csv")
    np.testing.assert_allclose(bm.pressure, r.bone_map.pressure, rtol=1e-9)
    rd = read_sensors_csv(out / "sensors.csv")
    np.testing.assert_allclose(rd.pressure, r.sensors.pressure)
    # ... and those written before the status column
    old = tmp_path / "old"
    old.mkdir()
    (old / "bone_map.csv").write_text("s_mm,z_mm,pressure_mpa\n0,0,1\n1,0,2\n")
    assert read_bone_map(old / "bone_map.csv").pressure.tolist() == [[1.0, 2.0]]
    (old / "sensors.csv").write_text(",".join(COLUMNS) + "\nL0-0,L0,0,6,0,0,0.5,0.1,-0.1,0,0,1,0,1,0,0.5\n")
    assert read_sensors_csv(old / "sensors.csv").pressure.tolist() == [0.1]


def test_cli_solve_2d_suspect_and_ok(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(SENSORS_TOML)
    names = ["profile.csv", "contact.csv", "sensors.csv"]
    for args, rc in ((COARSE_2D, 3), (["-t", "3", "-i", "curved", "--quality", "preview"], 0)):
        out = tmp_path / f"o{rc}"
        assert main(["solve", *args, "--sensors", str(tmp_path / "s.toml"), "--out", str(out)]) == rc
        status = json.loads((out / "summary.json").read_text())["status"]
        assert (status == "ok") == (rc == 0)
        assert_status_everywhere(out, status, names)


def test_cli_solve_3d_suspect(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(SENSORS_TOML)
    out = tmp_path / "o"
    assert main(["solve", *COARSE_3D, "--sensors", str(tmp_path / "s.toml"), "--out", str(out)]) == 3
    status = json.loads((out / "summary.json").read_text())["status"]
    assert status.startswith("suspect: mesh coarser")
    assert_status_everywhere(out, status, ["profile.csv", "contact.csv", "bone_map.csv", "profile_max_z.csv",
                                           "sensors.csv"])


def test_a_cached_suspect_case_stays_suspect_in_every_file(tmp_path):
    """A sweep rerun from the cache: the entry's CSVs (written once) and the sweep's
    sensors.csv still say suspect, with one status column (the sweep's, recomputed)."""
    from tactileskin.cache import ResultCache
    from tactileskin.report.outputs import write_outputs
    from tactileskin.sweep import run_sweep

    lays = [{"name": "bone", "kind": "line", "s": [0, 2], "pitch": 1.0, "height": 0.0}]
    sc = Scene(thickness=3.0, indenter="curved", mesh_size=2.0, refinement=2, sensors=lays)
    cache = ResultCache(tmp_path / "cache")
    first = run_sweep([sc], cache, serial=True)
    again = run_sweep([sc], cache, serial=True)
    assert again[0].status == "cached", again[0].status
    res = write_outputs(tmp_path / "o", again, cache, 1.0, render=False, figures=False)
    (rec,) = res["records"]
    status = quality.status(rec.summary)
    assert status.startswith("suspect: mesh coarser") and first[0].key == again[0].key
    assert_status_everywhere(rec.path, status, ["profile.csv", "contact.csv", "sensors.csv"])
    with open(tmp_path / "o" / "sensors.csv", newline="") as fh:
        rd = csv.DictReader(fh)
        rows = list(rd)
    assert rd.fieldnames == ["case", "status", *COLUMNS]
    assert len(rows) == 3 and all(r["status"] == status for r in rows)
    # the sweep's long-form profiles too (they read like an ok case's): its status on every row
    with open(tmp_path / "o" / "profiles.csv", newline="") as fh:
        rd = csv.DictReader(fh)
        prof = list(rd)
    assert rd.fieldnames == ["case", "status", "s_mm", "pressure_mpa"]
    assert len(prof) == len(rec.s) and all(p["status"] == status for p in prof)
    import pyarrow.parquet as pq

    table = pq.read_table(tmp_path / "o" / "profiles.parquet")
    assert table.column_names == ["case", "status", "s_mm", "pressure_mpa"]
    assert set(table.column("status").to_pylist()) == {status}


@pytest.mark.parametrize("name", ["L\u2028a", "L\x0cb", "L\x85c", "L\x1ed"])
def test_a_layout_name_with_a_line_separator_other_than_newline_keeps_its_rows(tmp_path, name):
    """A layout name may hold any character but a comma, a quote, CR or LF (sensors.py); str.
    splitlines also breaks at U+2028, form feed, NEL and the \\x1c-\\x1e separators, which cut
    such a sensors.csv's rows in two around the status (CSV rows end at CR / LF only)."""
    n = 2
    r = _result(0.3)
    r.sensors.ids[:] = [f"{name}-{i}" for i in range(n)]
    r.sensors.layout[:] = [name] * n
    out = r.write(tmp_path / "o")
    assert_status_everywhere(out, "ok", ALL_FILES)
    rd = read_sensors_csv(out / "sensors.csv")
    assert list(rd.ids) == [f"{name}-{i}" for i in range(n)]
    assert list(rd.layout) == [name] * n
    np.testing.assert_allclose(rd.pressure, r.sensors.pressure)


def test_a_no_contact_results_contact_csv_says_why(tmp_path, capsys):
    """contact.csv of a result without contact held its header alone: a reader (csv, pandas)
    saw no row, so no status, and nothing said why it was empty. It now has one row, its
    numbers empty (no point is invented: pandas reads NaN) and the status saying why."""
    import pandas as pd

    (tmp_path / "s.toml").write_text(SENSORS_TOML)
    out = tmp_path / "o"
    # no contact: the depth is far below the contact tolerance (test_result_status)
    assert main(["solve", "-t", "3", "-i", "curved", "--quality", "preview", "--depth", "1e-6",
                 "--sensors", str(tmp_path / "s.toml"), "--out", str(out)]) == 3
    status = json.loads((out / "summary.json").read_text())["status"]
    assert status.startswith("suspect: no contact")
    assert_status_everywhere(out, status, ["profile.csv", "contact.csv", "sensors.csv"])
    with open(out / "contact.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 1 and {k: v for k, v in rows[0].items() if k != "status"} == \
        {"x_mm": "", "y_mm": "", "contact_pressure_mpa": ""}
    df = pd.read_csv(out / "contact.csv")
    assert df["contact_pressure_mpa"].isna().all() and df["status"].tolist() == [status]
    assert df.drop(columns="status").dropna(how="all").empty  # no contact point


def test_an_ok_tables_rows_are_not_padded():
    from tactileskin.results import with_status

    assert with_status("a,b\n", "ok") == "a,b,status\n"
    assert with_status("a,b\n", "suspect: x, y") == 'a,b,status\n,,"suspect: x, y"\n'
    assert with_status("a,b\n1,2\n", "suspect: x") == "a,b,status\n1,2,suspect: x\n"
