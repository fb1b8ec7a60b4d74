"""The sweep's Parquet tables: built without pyarrow importing pandas (pa.array of a list
does, ~0.2 s CPU of the sweep command's main process), with the same arrays and the same
file bytes as pa.array's inference gives."""

from __future__ import annotations

import io
import math
import subprocess
import sys

import numpy as np
import pytest

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

from tactileskin.report.arrow import column  # noqa: E402
from tactileskin.report.outputs import FLOAT_COLUMNS, PROFILE_COLUMNS, RESULT_COLUMNS, _write_parquet  # noqa: E402

CASES = [
    [], [None], [None, None],
    ["a", None, "", "gel-ä ✓"], ["x"],
    [1, None, 3], [2 ** 62, -5], [2 ** 63],  # the last: past int64, pyarrow's own error or type
    [1.5, None, math.nan, -0.0], [1, 2.5, None], [math.inf], [2 ** 53 + 1, 0.5], [2 ** 53 + 1], [2 ** 53, 0.5],
    [np.float64(1.5), 2.0], [np.int64(3), 4], [np.int32(3)], [np.float32(1.5)],
    [True, False, None], [True, 1], ["a", 1], [1, "a"], [b"raw"],
    ["\ud800"],  # a lone surrogate: not UTF-8, pyarrow's own error
]


def _reference(values, type_=None):
    try:
        return pa.array(values, type=type_)
    except Exception as e:  # noqa: BLE001 - compared with column's error below
        return type(e)


@pytest.mark.parametrize("values", CASES, ids=repr)
@pytest.mark.parametrize("type_", [None, "float64", "string"])
def test_column_is_pa_array_of_the_list(values, type_):
    t = {None: None, "float64": pa.float64(), "string": pa.string()}[type_]
    want = _reference(values, t)
    if isinstance(want, type):
        with pytest.raises(want):
            column(values, t)
        return
    got = column(values, t)
    assert got.type == want.type
    assert got.null_count == want.null_count
    # NaN != NaN in equals: compared as Python values, NaN by its bits
    assert [repr(x) for x in got.to_pylist()] == [repr(x) for x in want.to_pylist()]


def _rows():
    ok = dict(case="t1-silicone-flat-2d", key="k1", status="ok", thickness_mm=1.0, material="silicone",
              indenter="flat", braille_text=None, depth_mm=0.2, rate_mm_s=1.0, peak_mpa=0.3, span_mm=2.0,
              auc_mpa_mm=0.4, reaction_n_per_mm=0.5, reaction_n=None, min_J=0.99, max_abs_stress_mpa=0.3,
              dofs=2060, increments=4, newton_iterations=20, wall_s=1.0, dim=2, variant="")
    braille = {**ok, "case": "t3-pu-braille[,a,]-2d", "indenter": "braille", "braille_text": "a", "thickness_mm": 3}
    failed = dict(case="t5-gel-ä-flat-2d", key="k3", status="failed: no convergence", thickness_mm=5.0,
                  material="gel-ä", indenter="flat", braille_text=None, depth_mm=None, rate_mm_s=1.0,
                  error="SolverError: no convergence", dim=2, variant="F0.03")
    return [ok, braille, failed]


def _old_write(path, columns, rows):
    """report.outputs._write_parquet as it was: pa.array of every column list."""
    data = {c: [r[i] if isinstance(r, tuple) else r.get(c) for r in rows] for i, c in enumerate(columns)}
    types = {**dict.fromkeys(FLOAT_COLUMNS + ("s_mm", "pressure_mpa"), pa.float64()), "error": pa.string()}
    pq.write_table(pa.table({c: pa.array(v, type=types.get(c)) for c, v in data.items()}), path)


def test_sweep_tables_have_the_bytes_of_pa_array(tmp_path):
    cols = RESULT_COLUMNS + ["dim", "variant"]
    prof = [("t1-silicone-flat-2d", "ok", float(s), float(np.sin(s))) for s in np.linspace(0, 8, 200)]
    prof += [("t5-gel-ä-flat-2d", "suspect: no contact", 0.0, math.nan)]
    for name, columns, rows in (("results", cols, _rows()), ("profiles", PROFILE_COLUMNS, prof)):
        _write_parquet(tmp_path / f"{name}.parquet", columns, rows)
        _old_write(tmp_path / f"{name}-old.parquet", columns, rows)
        assert (tmp_path / f"{name}.parquet").read_bytes() == (tmp_path / f"{name}-old.parquet").read_bytes(), name


def test_writing_the_sweep_tables_does_not_import_pandas(tmp_path):
    """The sweep command's process has no other use for pandas: its import was ~0.2 s CPU
    on the path to the report."""
    code = f"""
import sys
sys.path[:0] = {sys.path!r}
from pathlib import Path
from tactileskin.report.outputs import RESULT_COLUMNS, PROFILE_COLUMNS, _write_parquet
out = Path({str(tmp_path)!r})
_write_parquet(out / "r.parquet", RESULT_COLUMNS + ["dim", "variant"], {_rows()!r})
_write_parquet(out / "p.parquet", PROFILE_COLUMNS, [("c", "ok", 0.0, 1.0), ("c", "ok", 0.5, 0.25)])
print("pandas" in sys.modules)
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split()[-1] == "False", done.stdout + done.stderr
    assert pq.read_table(tmp_path / "p.parquet").column("pressure_mpa").to_pylist() == [1.0, 0.25]


def test_a_column_written_reads_back_as_written():
    buf = io.BytesIO()
    pq.write_table(pa.table({"s": column(["a", None, "é"]), "x": column([1.0, None, 2.0], pa.float64()),
                             "n": column([2, None, 4])}), buf)
    t = pq.read_table(io.BytesIO(buf.getvalue()))
    assert t.column("s").to_pylist() == ["a", None, "é"] and t.column("x").to_pylist() == [1.0, None, 2.0]
    assert t.column("n").to_pylist() == [2, None, 4]
