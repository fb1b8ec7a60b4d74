"""The top-level Python API: ts.Scene, ts.solve, ts.sweep, lazy imports, Result repr."""

from __future__ import annotations

import csv
import dataclasses
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import tactileskin as ts
from tactileskin import presets
from tactileskin.results import Result


def test_import_tactileskin_loads_no_heavy_library():
    code = ("import sys, tactileskin as ts; ts.__version__; "
            "print(sorted(m for m in ('numpy', 'scipy', 'pandas', 'dask', 'skfem', 'numba', 'matplotlib') "
            "if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stdout.strip() == "[]"


def test_help_of_scene_documents_every_field_with_unit_and_range():
    doc = ts.Scene.__doc__
    for f in dataclasses.fields(ts.Scene):
        line = next((ln for ln in doc.splitlines() if ln.startswith(f"{f.name} (")), None)
        assert line is not None, f.name
        assert "undocumented" not in doc.split(line, 1)[1].splitlines()[1], f.name
    assert "thickness (mm)" in doc and "rate (mm/s)" in doc and "[0.01, 5]" in doc


def test_help_of_result_gives_the_metrics_units():
    """help(r) showed r.peak without a word (span and auc said mm and MPa mm)."""
    for name, unit in (("peak", "(MPa)"), ("span", "(mm)"), ("auc", "(MPa mm)")):
        assert unit in (getattr(Result, name).__doc__ or ""), name


def test_help_and_signature_of_sweep_are_the_api_function():
    """help(ts.sweep) showed the internal module and inspect.signature() the module's
    __call__(grid=None, **kw), not the documented API."""
    import inspect
    import pydoc

    from tactileskin import api

    assert inspect.signature(ts.sweep) == inspect.signature(api.sweep)
    assert {"out", "workers", "serial", "scheduler", "profiles", "report"} <= set(inspect.signature(ts.sweep).parameters)
    text = pydoc.render_doc(ts.sweep, renderer=pydoc.plaintext)
    assert "pandas DataFrame" in text and "profiles: return (metrics, profiles)" in text
    assert "tactileskin.sweep(grid=None, *, quality" in text
    assert callable(ts.sweep.run_sweep) and ts.sweep.__name__ == "tactileskin.sweep"  # still the module


def test_result_repr_is_one_short_line():
    s = np.linspace(0, 8, 2000)
    r = Result(s=s, pressure=np.exp(-s), contact_x=s, contact_pressure=s, reaction=1.5,
               stats={"dofs": 1234}, scene={"thickness": 1.0, "material": "silicone", "indenter": "flat", "dim": 2})
    text = repr(r)
    assert "\n" not in text and len(text) < 300
    assert "t1-silicone-flat-2d" in text and "peak=1 MPa" in text and "2000 profile points" in text
    assert "reaction=1.5 N/mm" in text                   # with its unit (2D: per mm of depth)
    # named as the scene labels itself (the CLI, summary.json): the Braille text too
    braille = Result(s=s, pressure=np.exp(-s), contact_x=s, contact_pressure=s, reaction=1.5, stats={},
                     scene={"thickness": 1.0, "indenter": "braille", "braille_text": "a", "dim": 3})
    assert "t1-silicone-braille[a]-3d" in repr(braille) and "reaction=1.5 N," in repr(braille)


def test_solve_takes_fields_and_a_quality_preset():
    r = ts.solve(thickness=1.0, material="silicone", quality="preview")
    size, ref = presets.mesh(2, "preview")
    assert (r.scene["mesh_size"], r.scene["refinement"]) == (size, ref)
    assert r.peak > 0 and r.status == "ok"


def test_solve_of_a_scene_file_keeps_its_mesh_sizes_over_its_quality(tmp_path, monkeypatch):
    """A scene file's mesh_size / refinement override its quality preset (and the quality
    argument), as `tactileskin solve --scene` takes them: ts.solve put the preset over them
    (q.toml: quality preview, mesh_size 0.5 at t = 1 flat solved at 1.0, 2060 dofs, peak 0.3153
    MPa; the CLI 0.5, 5366 dofs, 0.3174 MPa)."""
    import tactileskin.fe
    from tactileskin.cli._common import scene_from_options

    f = tmp_path / "q.toml"
    f.write_text('quality = "preview"\nthickness = 1.0\nmesh_size = 0.5\nrefinement = 4.0\n')
    seen = []
    monkeypatch.setattr(tactileskin.fe, "solve", lambda sc, **kw: seen.append(sc) or sc)
    cli = scene_from_options({"scene_file": str(f)})
    assert ts.solve(f) == cli and (cli.mesh_size, cli.refinement) == (0.5, 4.0)
    assert ts.solve(f, quality="default") == scene_from_options({"scene_file": str(f), "quality": "default"})
    assert (seen[-1].mesh_size, seen[-1].refinement) == (0.5, 4.0)
    assert ts.solve(f, quality="default", mesh_size=0.8).mesh_size == 0.8  # an argument over the file


def test_sweep_returns_dataframes_equal_to_the_csv_and_parquet_files(tmp_path):
    pd = pytest.importorskip("pandas")
    out = tmp_path / "sw"
    grid = {"thickness": [1.0], "material": "silicone", "indenter": ["flat", "curved"]}
    df, prof = ts.sweep(grid, quality="preview", out=out, serial=True, profiles=True, report=False)
    assert list(df.case) == ["t1-silicone-flat-2d", "t1-silicone-curved-2d"]
    assert (df.status == "ok").all() and (df.peak_mpa > 0).all()
    # numeric columns are numbers: a 2D case's 3D reaction is NaN, not None (object dtype)
    assert df.reaction_n.dtype == float and df.reaction_n.isna().all() and df.reaction_n_per_mm.dtype == float
    with open(out / "results.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [float(r["peak_mpa"]) for r in rows] == pytest.approx(list(df.peak_mpa), rel=1e-12)
    pq = pd.read_parquet(out / "results.parquet")
    assert list(pq.case) == list(df.case) and np.array_equal(pq.peak_mpa, df.peak_mpa)
    pp = pd.read_parquet(out / "profiles.parquet")
    assert len(pp) == len(prof) and np.array_equal(pp.pressure_mpa, prof.pressure_mpa)
    # the peak of each long-form profile is the metric of its row
    for case, g in prof.groupby("case"):
        assert g.pressure_mpa.max() == pytest.approx(float(df.set_index("case").peak_mpa[case]), rel=1e-9)
    # a rerun reads every case from the cache (out/cache) and gives the same numbers
    again = ts.sweep(grid, quality="preview", out=out, serial=True, report=False)
    assert np.array_equal(again.peak_mpa, df.peak_mpa)
    # the report as the command writes it: its wall time measured (it read 0.0 s)
    ts.sweep(grid, quality="preview", out=tmp_path / "fresh", serial=True)  # solved, not read
    wall = float(re.search(r"wall time ([0-9.]+) s", (tmp_path / "fresh" / "report.md").read_text()).group(1))
    assert wall > 0.0


def test_sweep_default_cache_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("TACTILESKIN_CACHE", str(tmp_path / "c"))
    assert ts.default_cache_dir() == tmp_path / "c"
    monkeypatch.delenv("TACTILESKIN_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "x"))
    assert ts.default_cache_dir() == tmp_path / "x" / "tactileskin"


def test_sweep_grid_forms_agree(tmp_path):
    f = tmp_path / "grid.toml"
    f.write_text('quality = "preview"\n[sweep]\nthicknesses = [1.0, 2.0]\nindenters = ["flat"]\n'
                 'materials = ["silicone"]\n')
    from_file = ts.scenes(str(f))
    from_dict = ts.scenes({"thickness": [1.0, 2.0], "indenter": "flat", "material": ["silicone"]},
                          quality="preview")
    assert from_file == from_dict and len(from_file) == 2
    with pytest.raises(ts.ParameterError, match="grid"):
        ts.scenes(42)


@pytest.mark.slow
def test_parallel_sweep_in_a_script_without_main_guard(tmp_path):
    """Dask starts its workers by spawn, which re-runs the main script: without the guard each
    worker would start a sweep of its own. ts.sweep keeps the script from being re-run."""
    script = tmp_path / "noguard.py"
    script.write_text(textwrap.dedent(f"""
        import tactileskin as ts
        df = ts.sweep({{"thickness": [1.0], "indenter": "flat", "material": "silicone"}},
                      quality="preview", workers=1, cache={str(tmp_path / 'cache')!r})
        print("RUNS", len(df), df.status[0])
    """))
    src = str(Path(ts.__file__).resolve().parents[1])  # this checkout's package, from any cwd
    env = {**os.environ, "PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=400,
                       cwd=tmp_path, env=env)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.count("RUNS") == 1 and "RUNS 1 ok" in r.stdout


def test_a_misspelt_grid_key_or_an_empty_axis_is_a_parameter_error_not_a_silent_empty_sweep():
    from tactileskin.errors import ParameterError

    with pytest.raises(ParameterError, match="thick"):
        ts.scenes({"thick": [1]})
    with pytest.raises(ParameterError, match="at least one value"):
        ts.sweep({"thickness": []}, serial=True)
    with pytest.raises(ParameterError, match="scene field"):
        ts.Scene().replace(thick=1.0)


@pytest.mark.parametrize("call, names", [
    (lambda r: ts.scenes({1: [1]}), "grid key"),
    (lambda r: ts.scenes({"thickness": [1]}, base={"thickness": 1}), "base"),
    (lambda r: ts.scenes({"thickness": {1: 2}}), "thickness"),  # was: the dict's keys
    (lambda r: ts.scenes({"thickness": b"1"}), "thickness"),    # was: thickness 49
    (lambda r: ts.sweep([]), "grid"),
    (lambda r: ts.sweep({"thickness": [1]}, workers="x"), "workers"),
    (lambda r: ts.sweep({"thickness": [1]}, cache=5), "cache"),
    # were taken for true ("no" is truthy) or false; the bad thickness ends the old code fast
    (lambda r: ts.sweep({"thickness": [-1]}, serial="no"), "serial"),
    (lambda r: ts.sweep({"thickness": [-1]}, profiles="yes"), "profiles"),
    (lambda r: ts.sweep({"thickness": [-1]}, report="no"), "report"),
    (lambda r: ts.solve(thickness=1, progress=5), "progress"),  # before meshing, not after
    (lambda r: ts.solve(thickness=1, history="yes"), "history"),
    (lambda r: ts.Scene.from_toml(5), "scene file"),            # not read as file descriptor 5
    (lambda r: r.write(5), "directory"),
    (lambda r: r.plot(ax=5), "ax"),
])
def test_api_mistakes_are_parameter_errors_naming_the_argument(call, names):
    from tactileskin.errors import ParameterError

    r = Result(s=np.array([0.0, 1.0]), pressure=np.array([0.2, 0.0]), contact_x=np.zeros(0),
               contact_pressure=np.zeros(0), reaction=0.1, stats={"dofs": 6})
    with pytest.raises(ParameterError, match=names):
        call(r)


def test_the_force_axis_is_a_grid_key():
    scs = ts.scenes({"force": [0.1, 0.2], "thickness": [1], "material": ["silicone"], "indenter": ["flat"]})
    assert [s.force for s in scs] == [0.1, 0.2]


def test_summary_keys_carry_their_units_and_a_3d_reaction_is_in_newtons():
    from tactileskin.quality import reaction_of

    kw = dict(s=np.array([0.0, 1.0]), pressure=np.array([0.2, 0.0]), contact_x=np.zeros(0),
              contact_pressure=np.zeros(0), reaction=0.1, stats={"dofs": 6})
    s2, s3 = Result(**kw, scene={"dim": 2}).summary(), Result(**kw, scene={"dim": 3}).summary()
    assert "reaction_n_per_mm" in s2 and "reaction_n" not in s2  # plane strain: per mm of depth
    assert "reaction_n" in s3 and "reaction_n_per_mm" not in s3  # 3D: the force on the model
    assert reaction_of(s2) == reaction_of(s3) == 0.1 and s2["auc_mpa_mm"] == pytest.approx(0.1)


def test_contact_csv_gives_each_contact_points_position(tmp_path):
    """contact.csv: x, y (and z in 3D) of every contact point, in contact_x's order, and its
    pressure; it had x only, so two 3D points at the same x could not be told apart."""
    s = np.linspace(0, 4, 50)
    pts = np.array([[0.1, 6.8, 0.0], [0.1, 6.8, 0.5], [0.3, 6.79, 0.2]])
    r = Result(s=s, pressure=np.exp(-s), contact_x=pts[:, 0], contact_pressure=np.array([0.3, 0.2, 0.1]),
               reaction=1.0, stats={}, scene={"thickness": 1.0, "dim": 3}, contact_points=pts)
    out = r.write(tmp_path / "o")
    rows = list(csv.DictReader(open(out / "contact.csv", encoding="utf-8")))
    assert list(rows[0]) == ["x_mm", "y_mm", "z_mm", "contact_pressure_mpa", "status"]
    assert [(float(x["z_mm"]), float(x["contact_pressure_mpa"])) for x in rows] == [(0.0, 0.3), (0.5, 0.2), (0.2, 0.1)]


def test_sweep_dataframe_has_the_columns_of_results_csv_and_parquet(tmp_path):
    """The DataFrame dropped the columns no case filled: without a failed case or force
    control it had 22 of results.csv's 25 (no error, target_force_n_per_mm, target_force_n),
    so `df.error` raised where the files had the column."""
    pd = pytest.importorskip("pandas")
    out = tmp_path / "sw"
    df = ts.sweep({"thickness": [1.0], "material": "silicone", "indenter": ["flat"]}, quality="preview",
                  out=out, serial=True, report=False)
    with open(out / "results.csv", newline="") as fh:
        header = next(csv.reader(fh))
    assert list(df.columns) == header == list(pd.read_parquet(out / "results.parquet").columns)
    assert df.error.isna().all() and df.target_force_n_per_mm.isna().all() and df.target_force_n.dtype == float


def test_results_parquet_types_a_column_no_case_filled_as_the_dataframe_does(tmp_path):
    """results.parquet wrote the columns no row filled (a 2D sweep's reaction_n, the target
    forces without force control, error) as type null, read back as object columns of None,
    where ts.sweep's DataFrame has float64 (and a 3D sweep's file double): the files of a 2D
    and a 3D sweep did not share a schema."""
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    from tactileskin.report.outputs import RESULT_COLUMNS, _write_parquet

    cols = RESULT_COLUMNS + ["dim", "variant"]
    row = dict(case="t1-silicone-flat-2d", key="k", status="ok", thickness_mm=1.0, material="silicone",
               indenter="flat", braille_text="", depth_mm=0.2, rate_mm_s=1.0, peak_mpa=0.3, span_mm=2.0,
               auc_mpa_mm=0.4, reaction_n_per_mm=0.5, reaction_n=None, min_J=0.99, max_abs_stress_mpa=0.3,
               dofs=2060, increments=4, newton_iterations=20, wall_s=1.0, dim=2, variant="")
    _write_parquet(tmp_path / "r.parquet", cols, [row])
    schema = pq.read_schema(tmp_path / "r.parquet")
    for c in ("reaction_n", "target_force_n_per_mm", "target_force_n", "peak_mpa", "reaction_n_per_mm"):
        assert schema.field(c).type == pa.float64(), c
    assert schema.field("error").type == pa.string() and schema.field("dofs").type == pa.int64()


@pytest.mark.parametrize("fields", [dict(), dict(depth=0.15)], ids=["depth_fraction", "depth"])
def test_summary_states_the_depth_a_depth_ramp_pressed_to(fields):
    # summary.json gave a force-controlled result's travel (`loading`) but not a depth ramp's:
    # only the scene's depth_fraction, so the depth solved to (mm) could not be read from it
    r = ts.solve(thickness=1.0, material="silicone", indenter="flat", viscoelastic=False, mesh_size=1.0,
                 refinement=5.0, **fields)
    want = fields.get("depth", 0.2 * 1.0)
    assert r.summary()["depth_mm"] == pytest.approx(want, rel=1e-9)


def test_scene_help_gives_the_force_range_and_the_shortest_ramp():
    """Scene's reference said force (0, 10000] while 1e-5 is refused (MIN_FORCE 1e-4), and rate
    [1e-6, 1e6] with nothing of the ramp's shortest time (Scene(rate=1e6) at the default
    0.4 mm depth is refused: 4e-7 s)."""
    from tactileskin import loading
    from tactileskin.errors import ParameterError

    doc = ts.Scene.__doc__
    force = next(ln for ln in doc.splitlines() if ln.startswith("force ("))
    force += doc.split(force, 1)[1].splitlines()[1]
    assert f"[{loading.MIN_FORCE:.4f}, {loading.MAX_FORCE:g}]" in force
    with pytest.raises(ParameterError, match=r"force"):
        ts.Scene(force=loading.MIN_FORCE / 10)
    ts.Scene(force=loading.MIN_FORCE)
    for name in ("rate", "force_rate"):
        line = next(ln for ln in doc.splitlines() if ln.startswith(f"{name} ("))
        nxt = doc.split(line, 1)[1].splitlines()[1]
        assert "at least 1e-6 s" in line + nxt and loading.MIN_RAMP_TIME == 1e-6, name
    with pytest.raises(ParameterError, match=r"^rate="):
        ts.Scene(rate=1e6)
