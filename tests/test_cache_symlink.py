"""OUT/cache is the out folder's own cache: a symbolic link put in its place (to a shared
folder, or a user's) was followed, so case entries and locks were written outside --out and
a user's folder was read as cache. It is refused naming the path; a shared cache is the
explicit --cache option."""

from __future__ import annotations

import pytest
from test_output_safety import counted_cases  # noqa: F401 - the fixture: every case fails at once

from tactileskin.cli import main
from tactileskin.fileio import OutputError

SWEEP = ["sweep", "-t", "1", "-m", "silicone", "-i", "flat", "--serial", "--no-render"]


def _linked_cache(tmp_path, argv):
    out, elsewhere = tmp_path / "out", tmp_path / "users"
    assert main([*argv, "--out", str(out)]) == 1  # the (faked) case failed; the folder is the sweep's
    (out / "cache").rename(tmp_path / "moved")
    elsewhere.mkdir()
    (elsewhere / "mine.txt").write_text("mine")
    (out / "cache").symlink_to(elsewhere, target_is_directory=True)
    return out, elsewhere


def test_sweep_refuses_a_cache_folder_that_is_a_symlink(tmp_path, capsys, counted_cases):
    out, elsewhere = _linked_cache(tmp_path, SWEEP)
    n = len(counted_cases)
    assert main([*SWEEP, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and str(out / "cache") in err and "symbolic link" in err and "--cache" in err
    assert len(counted_cases) == n  # refused before any case
    assert sorted(p.name for p in elsewhere.iterdir()) == ["mine.txt"]  # nothing written there


def test_an_explicit_shared_cache_is_still_taken(tmp_path, capsys, counted_cases):
    out, elsewhere = _linked_cache(tmp_path, SWEEP)
    shared = tmp_path / "shared"
    assert main([*SWEEP, "--out", str(out), "--cache", str(shared)]) == 1  # runs (the case fails)
    assert shared.is_dir()


def test_array_refuses_a_cache_folder_that_is_a_symlink(tmp_path, capsys, monkeypatch):
    from tactileskin.array import chart

    asked = []
    monkeypatch.setattr(chart, "solve_cached", lambda scenes, *a, **k: asked.append(scenes) or {})
    out, elsewhere = tmp_path / "out", tmp_path / "users"
    elsewhere.mkdir()
    out.mkdir()
    (out / "cache").symlink_to(elsewhere, target_is_directory=True)
    assert main(["array", "--set", "paper", "-t", "1", "--pitch", "1", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(out / "cache") in err and "symbolic link" in err and asked == []


def test_api_sweep_refuses_a_cache_folder_that_is_a_symlink(tmp_path, counted_cases):
    import tactileskin as ts

    out, elsewhere = _linked_cache(tmp_path, SWEEP)
    with pytest.raises(OutputError, match="symbolic link"):
        ts.sweep({"thickness": [1.0], "material": ["silicone"], "indenter": ["flat"]}, out=out, serial=True,
                 report=False)
    assert sorted(p.name for p in elsewhere.iterdir()) == ["mine.txt"]
