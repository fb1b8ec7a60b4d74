"""Run every script in examples/ and check the numbers it reports.

Convention for examples (every script in examples/*.py must follow it):

- It runs as `python examples/<name>.py OUT_DIR` and writes any files under OUT_DIR (the
  test passes a fresh temporary folder; without the argument the script uses its own
  temporary folder). It exits with code 0 on success.
- It prints one line `RESULT <name>=<value>` per number it checks (value: a float).
- Its module docstring declares the accepted range of each result on a line of its own:
  `EXPECT <name> <lo> <hi>` (inclusive), best with a sentence on where the range comes from.
- Every RESULT must have an EXPECT and vice versa; values must be finite.
- It should run in well under a minute (heavy studies belong in benchmarks/).
"""

from __future__ import annotations

import ast
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))
TIMEOUT_S = 300

_EXPECT = re.compile(r"^\s*EXPECT\s+(\w+)\s+(\S+)\s+(\S+)\s*$", re.M)
_RESULT = re.compile(r"^RESULT\s+(\w+)=(\S+)\s*$", re.M)


def expectations(path: Path) -> dict[str, tuple[float, float]]:
    doc = ast.get_docstring(ast.parse(path.read_text())) or ""
    return {name: (float(lo), float(hi)) for name, lo, hi in _EXPECT.findall(doc)}


def test_examples_exist():
    assert {p.name for p in EXAMPLES} >= {"braille_word_indenter.py", "skin_2mm_with_mold.py"}


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_and_reports_expected_numbers(script, tmp_path):
    expect = expectations(script)
    assert expect, f"{script.name}: no `EXPECT <name> <lo> <hi>` line in the module docstring"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run([sys.executable, str(script), str(tmp_path / "out")], capture_output=True,
                          text=True, timeout=TIMEOUT_S, env=env, cwd=tmp_path)
    assert proc.returncode == 0, f"{script.name} exited {proc.returncode}:\n{proc.stdout}\n{proc.stderr}"
    results = {name: float(v) for name, v in _RESULT.findall(proc.stdout)}
    assert set(results) == set(expect), f"{script.name}: RESULT {sorted(results)} vs EXPECT {sorted(expect)}"
    for name, value in results.items():
        lo, hi = expect[name]
        assert math.isfinite(value) and lo <= value <= hi, f"{script.name}: {name}={value} not in [{lo}, {hi}]"
