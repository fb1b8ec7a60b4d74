"""A serial sweep killed (SIGKILL) mid-run resumes: finished cases come from the cache, the
rest are computed, and the outputs equal those of an uninterrupted run."""

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import tactileskin
from tactileskin.cli import main

ARGS = ["--thickness", "1", "--depth", "0.1,0.2", "--material", "polyurethane", "--indenter", "flat,curved",
        "--mesh-size", "1", "--refinement", "5", "--serial", "--no-render"]
SAME = ("case", "key", "status", "depth_mm", "peak_mpa", "span_mm", "auc_mpa_mm", "reaction_n_per_mm",
        "dofs", "increments", "newton_iterations")


def _finished(cache: Path) -> list[Path]:
    # an entry is written in a staging folder (.KEY.tsk<pid>-*.partial) and renamed whole: a
    # cache.json inside a staging folder is not a finished case (counting it made the test
    # kill the sweep before anything was stored, on a loaded machine)
    return sorted(p for p in cache.glob("*/cache.json") if not p.parent.name.startswith(".")) \
        if cache.is_dir() else []


def _rows(out: Path):
    with open(out / "results.csv") as fh:
        return [{k: r[k] for k in SAME} for r in csv.DictReader(fh)]


@pytest.mark.slow
def test_killed_sweep_resumes_with_identical_results(tmp_path, capsys):
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(Path(tactileskin.__file__).parents[1]))
    cmd = [sys.executable, "-m", "tactileskin", "sweep", "--out", str(out), *ARGS]
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        t0 = time.monotonic()
        while not _finished(out / "cache"):
            assert proc.poll() is None, "the sweep ended before its first case was cached"
            assert time.monotonic() - t0 < 120, "no case cached within 120 s"
            time.sleep(0.01)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait()
    done_before = len(_finished(out / "cache"))
    assert 1 <= done_before < 4, "the kill came after the last case; nothing to resume"
    assert not (out / "results.csv").exists()

    assert main(["sweep", "--out", str(out), *ARGS]) == 0
    text = capsys.readouterr().out
    assert text.count("cached") == done_before
    assert text.count("done ") == 4 - done_before
    # the killed run's staging folder is gone, every case is stored once
    assert not [p for p in (out / "cache").iterdir() if p.name.endswith((".partial", ".tmp"))]
    assert len(_finished(out / "cache")) == 4

    ref = tmp_path / "ref"
    assert main(["sweep", "--out", str(ref), *ARGS]) == 0
    resumed = _rows(out)
    assert [r["status"] for r in resumed] == ["ok"] * 4
    assert resumed == _rows(ref)
    assert (out / "profiles.csv").read_text() == (ref / "profiles.csv").read_text()
