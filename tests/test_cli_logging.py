"""What the CLI shows on stderr: nothing routine by default; the solver's cut-backs under -v
(tactileskin's INFO), the libraries' info lines and every increment only under -vv."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[1] / "src")
# 1 mm silicone at 40 % indentation: the step control cuts back 4 times (preview, ~4 s)
SOLVE = ["solve", "-t", "1", "-m", "silicone", "-i", "flat", "--depth", "0.4", "--quality", "preview"]


def _stderr(tmp_path, *flags) -> str:
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}
    r = subprocess.run([sys.executable, "-m", "tactileskin", *flags, *SOLVE, "-o", str(tmp_path / "o")],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    return r.stderr


@pytest.mark.slow
def test_default_stderr_is_quiet_and_v_shows_the_cutbacks(tmp_path):
    quiet = _stderr(tmp_path)
    assert quiet.strip() == "", quiet  # off a terminal the progress line is not drawn either
    verbose = _stderr(tmp_path, "-v")
    assert "cutting back" in verbose
    assert "INFO tactileskin.fe:" in verbose  # the solve's one-line summary
    assert "Initializing finished" not in verbose  # scikit-fem's own info: -vv
    assert not re.search(r"increment \d+: t =", verbose)  # each increment: -vv
