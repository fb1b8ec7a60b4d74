"""What the CLI shows on stderr: nothing routine by default; the solver's cut-backs under -v
(tactileskin's INFO), the libraries' info lines and every increment only under -vv."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
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


@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_signal_whose_exception_was_swallowed_still_ends_the_run(monkeypatch, capsys, signum, code):
    """The handler's exception is lost when it lands in a __del__ or compiled code (the run went
    on to exit 0, ~1 SIGTERM in 8): main ends with the signal's status anyway."""
    import tactileskin.materials as materials
    from tactileskin.cli import main

    real = materials.list_materials

    def swallowing():
        try:
            os.kill(os.getpid(), signum)
            time.sleep(1.0)  # the handler raises in here
        except BaseException:  # noqa: BLE001 - as "Exception ignored in __del__" does
            pass
        return real()

    monkeypatch.setattr(materials, "list_materials", swallowing)
    try:
        rc = main(["material", "list"])
    except SystemExit as e:
        rc = e.code
    assert rc == code
    # the signal was this run's: a later run in another thread (a notebook's) ends normally
    import threading

    monkeypatch.setattr(materials, "list_materials", real)
    later = []
    th = threading.Thread(target=lambda: later.append(main(["material", "list"])))
    th.start()
    th.join()
    assert later == [0]
