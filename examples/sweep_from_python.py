"""A thickness sweep from Python: a pandas DataFrame back, files for the report beside it.

Three silicone skins (1, 2 and 3 mm) under the flat plate at the `preview` quality, on a
local Dask cluster of two worker processes. The script has no `if __name__ == "__main__":`
guard around the sweep on purpose: tactileskin.sweep() does not need one. Writes
results.csv/.parquet, profiles.csv/.parquet, the figures (metrics_vs_thickness.png: the
figure to choose a thickness from) and report.md into OUT_DIR (default: a temporary
folder), with the result cache in OUT_DIR/cache.

- cases: the rows of the DataFrame, and of results.parquet read back.
EXPECT cases 3 3
EXPECT parquet_rows 3 3
- peak_t3_over_t1: the peak bone pressure falls as the skin thickens (paper Fig. 11): the
  t = 1 and 2 mm preview values are 0.315 and 0.188 MPa, so t = 3 mm is well under half.
EXPECT peak_t3_over_t1 0.25 0.5
- span_grows: 1 when the span rises with the thickness at every step (the load spreads).
EXPECT span_grows 1 1

    python examples/sweep_from_python.py [OUT_DIR]
"""

import sys
import tempfile
from pathlib import Path

import pandas as pd

import tactileskin as ts

tmp = None
if len(sys.argv) > 1:
    out = Path(sys.argv[1])
else:
    tmp = tempfile.TemporaryDirectory()
    out = Path(tmp.name) / "sweep"

df, profiles = ts.sweep({"thickness": [1.0, 2.0, 3.0], "material": "silicone", "indenter": "flat"},
                        quality="preview", workers=2, out=out, profiles=True)
print(df[["case", "status", "peak_mpa", "span_mm", "auc_mpa_mm"]].to_string(index=False))
print(f"{len(profiles)} profile points in long form; report: {out / 'report.md'}")

peak = df.set_index("thickness_mm").peak_mpa
span = df.sort_values("thickness_mm").span_mm.to_numpy()
print(f"RESULT cases={len(df)}")
print(f"RESULT parquet_rows={len(pd.read_parquet(out / 'results.parquet'))}")
print(f"RESULT peak_t3_over_t1={peak[3.0] / peak[1.0]:.6g}")
print(f"RESULT span_grows={int(all(a < b for a, b in zip(span, span[1:])))}")
if tmp is not None:
    tmp.cleanup()
