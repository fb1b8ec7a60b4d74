"""Never destroy user data: output folders are claimed or refused, files are written
atomically under the umask, killed writers leave nothing behind, file errors are one line.
The CLI runs in-process; solves are faked where the test is about files, not numbers."""

from __future__ import annotations

import fnmatch
import json
import os
import signal
import stat
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import numpy as np
import pytest

import tactileskin
import tactileskin.fe
import tactileskin.sweep as sw
from tactileskin import fileio, outdir, ownership, params, staging
from tactileskin.cli import main
from tactileskin.results import Result

CHEAP = ["--mesh-size", "1", "--refinement", "5", "-t", "1", "--elastic"]  # the preview sizes
REPO = Path(__file__).resolve().parents[1]


def fake_result(scene=None) -> Result:
    """A tiny complete Result (with fields, so result.vtu is written)."""
    return Result(s=np.array([0.0, 1.0, 2.0]), pressure=np.array([0.1, 0.3, 0.0]),
                  contact_x=np.array([0.0, 0.5]), contact_pressure=np.array([0.2, 0.1]), reaction=0.4,
                  stats={"dofs": 6}, fields={"points": [[0, 0], [1, 0], [0, 1]], "cells": [[0, 1, 2]],
                                             "cell_type": "triangle", "point_data": {"pressure": [0, 1, 2]}})


@pytest.fixture
def fake_solve(monkeypatch):
    calls = []

    def solve(scene, **kw):
        calls.append(scene)
        return fake_result()

    monkeypatch.setattr(tactileskin.fe, "solve", solve)
    return calls


def _err(capsys) -> str:
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err + cap.out
    return cap.err


def _temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*") if ".tsk" in p.name or ".old" in p.name
                  or p.name.endswith(".partial"))


def _as_written_by_us(path: Path) -> None:
    """Record `path` in its folder's record as a file tactileskin wrote (an earlier run's)."""
    rec = ownership.read_record(path.parent)
    rec[path.name] = fileio.file_sha256(path)
    (path.parent / ownership.OWNED_FILES).write_text(__import__("json").dumps(rec))


# --- solve --out ------------------------------------------------------------------------

def test_solve_refuses_a_folder_holding_a_user_file_and_keeps_it(tmp_path, capsys, fake_solve):
    d = tmp_path / "d"
    d.mkdir()
    (d / "notes.txt").write_text("mine")
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    err = _err(capsys)
    assert str(d) in err and "notes.txt" in err and len(err.strip().splitlines()) == 1
    assert fake_solve == []  # refused before solving
    assert [p.name for p in d.iterdir()] == ["notes.txt"] and (d / "notes.txt").read_text() == "mine"


def test_solve_rewrites_its_own_folder_and_refuses_unmarked_lookalikes(tmp_path, capsys, fake_solve):
    d = tmp_path / "d"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0  # marked as ours: rewritten
    assert sorted(p.name for p in d.iterdir()) == [".tactileskin", ownership.OWNED_FILES, ownership.RECORD_LOCK,
                                                  outdir.RUN_LOCK, "contact.csv", "profile.csv", "result.vtu",
                                                  "summary.json"]
    # without our marker, files with solve's names are the user's: refused, left as they are
    user = tmp_path / "user"
    user.mkdir()
    (user / "summary.json").write_text("MY DATA")
    (user / "profile.csv").write_text("x\n")
    assert main(["solve", *CHEAP, "--out", str(user)]) == 2
    assert "did not write" in capsys.readouterr().err
    assert (user / "summary.json").read_text() == "MY DATA" and (user / "profile.csv").read_text() == "x\n"
    assert sorted(p.name for p in user.iterdir()) == ["profile.csv", "summary.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d", "user"]  # no staging siblings


def test_a_failed_solve_write_leaves_the_earlier_result_whole(tmp_path, capsys, fake_solve, monkeypatch):
    import errno

    import tactileskin.results as results

    d = tmp_path / "d"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    (d / "notes.txt").write_text("mine")  # a user's file in our folder stays whatever happens
    before = {p.name: p.read_bytes() for p in d.iterdir()}

    def full_disk(path, *a, **k):
        with fileio.os_errors(path):  # as atomic_path turns it
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(results, "_write_vtu", full_disk)  # fails after profile.csv and contact.csv
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    assert "no space left" in _err(capsys)
    assert {p.name: p.read_bytes() for p in d.iterdir()} == before  # the old result, whole
    assert _temporaries(d) == [] and sorted(p.name for p in tmp_path.iterdir()) == ["d"]


def test_staged_files_undo_a_move_that_fails_halfway(tmp_path, monkeypatch):
    import errno

    d = tmp_path / "d"
    own = ("a.csv", "b.csv", "c.csv", "summary.json")
    with staging.staged_files(d, own, last="summary.json") as tmp:
        for name in own:
            (tmp / name).write_text("old")
    before = {p.name: p.read_text() for p in d.iterdir()}
    real, calls = os.replace, []

    def flaky(src, dst):
        calls.append(dst)
        if len(calls) == 4:  # after summary.json aside and a.csv swapped: mid-way through b.csv
            raise OSError(errno.EIO, "I/O error", str(dst))
        return real(src, dst)

    monkeypatch.setattr(os, "replace", flaky)
    with pytest.raises(fileio.OutputError), staging.staged_files(d, own, last="summary.json") as tmp:
        for name in own:
            (tmp / name).write_text("new")
    monkeypatch.setattr(os, "replace", real)
    assert {p.name: p.read_text() for p in d.iterdir()} == before and _temporaries(d) == []


def test_temporaries_of_long_names_fit_the_file_system(tmp_path):
    name = "a" * 240 + ".inp"  # valid (244 bytes); its temporary must be too
    fileio.atomic_write_text(tmp_path / name, "x")
    assert (tmp_path / name).read_text() == "x"


def test_a_new_solve_removes_the_earlier_2d_comparison(tmp_path, capsys, fake_solve):
    d = tmp_path / "d"
    assert main(["solve", "--dim", "3", *CHEAP, "--compare-2d", "--out", str(d)]) == 0
    assert (d / "compare_2d.json").is_file() and (d / "section_2d" / "summary.json").is_file()
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0  # another result: its comparison goes with it
    assert not (d / "compare_2d.json").exists() and not (d / "section_2d").exists()


def test_a_failed_2d_comparison_keeps_the_3d_result(tmp_path, capsys, monkeypatch):
    from tactileskin.errors import ConvergenceError

    def solve(scene, **kw):
        if scene.dim == 2:
            raise ConvergenceError("no convergence in this test", {})
        return fake_result()

    monkeypatch.setattr(tactileskin.fe, "solve", solve)
    d = tmp_path / "d"
    assert main(["solve", "--dim", "3", *CHEAP, "--compare-2d", "--out", str(d)]) == 0
    assert (d / "summary.json").is_file() and not (d / "compare_2d.json").exists()
    assert "2D section could not be solved" in capsys.readouterr().out


def test_staged_files_replace_one_result_with_the_next(tmp_path):
    d = tmp_path / "d"
    with staging.staged_files(d, ("a.csv", "map.csv", "steps/s_*.vtu", "summary.json"), last="summary.json") as tmp:
        for name in ("a.csv", "map.csv", "summary.json"):
            (tmp / name).write_text("1")
        (tmp / "steps").mkdir()
        (tmp / "steps" / "s_0.vtu").write_text("1")
    (d / "steps" / "mine.txt").write_text("mine")
    with staging.staged_files(d, ("a.csv", "map.csv", "steps/s_*.vtu", "summary.json"), last="summary.json") as tmp:
        (tmp / "a.csv").write_text("2")  # no map, no steps this time
        (tmp / "summary.json").write_text("2")
    assert sorted(f.relative_to(d).as_posix() for f in d.rglob("*")) == ["a.csv", "steps", "steps/mine.txt",
                                                                       "summary.json"]
    assert (d / "a.csv").read_text() == "2" and (d / "summary.json").read_text() == "2"
    with pytest.raises(RuntimeError), staging.staged_files(d, ("a.csv", "summary.json")) as tmp:
        (tmp / "a.csv").write_text("3")
        raise RuntimeError("the body failed")
    assert (d / "a.csv").read_text() == "2" and _temporaries(d) == []
    with pytest.raises(ValueError, match="other.txt"), staging.staged_files(d, ("a.csv",)) as tmp:
        (tmp / "other.txt").write_text("x")  # only owned names are moved in
    assert not (d / "other.txt").exists()
    # a link where a subfolder of ours goes: refused, nothing written through it
    (tmp_path / "users").mkdir()
    (d / "steps" / "mine.txt").unlink()
    (d / "steps").rmdir()
    (d / "steps").symlink_to(tmp_path / "users")
    with pytest.raises(fileio.OutputError, match="link"), \
            staging.staged_files(d, ("a.csv", "steps/s_*.vtu")) as tmp:
        (tmp / "a.csv").write_text("4")
        (tmp / "steps").mkdir()
        (tmp / "steps" / "s_0.vtu").write_text("4")
    assert list((tmp_path / "users").iterdir()) == [] and (d / "a.csv").read_text() == "2"


def test_solve_out_dot_works_when_empty_and_refuses_cleanly_otherwise(tmp_path, capsys, monkeypatch, fake_solve):
    empty = tmp_path / "empty"
    empty.mkdir()
    monkeypatch.chdir(empty)
    assert main(["solve", *CHEAP, "--out", "."]) == 0
    assert (empty / "summary.json").is_file()
    user = tmp_path / "user"
    user.mkdir()
    (user / "thesis.tex").write_text("x")
    monkeypatch.chdir(user)
    assert main(["solve", *CHEAP, "--out", "."]) == 2
    assert "thesis.tex" in _err(capsys)
    assert [p.name for p in user.iterdir()] == ["thesis.tex"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty", "user"]  # no `..old.*` left


def test_a_path_under_a_file_is_a_one_line_error(tmp_path, capsys, fake_solve):
    f = tmp_path / "file.txt"
    f.write_text("x")
    assert main(["solve", *CHEAP, "--out", str(f / "sub")]) == 2
    err = _err(capsys)
    assert str(f) in err and "is a file" in err and len(err.strip().splitlines()) == 1
    assert main(["mesh", "-t", "1", "--mesh-size", "1", "--refinement", "2", "--out", str(f / "m.vtu")]) == 2
    assert str(f) in _err(capsys)
    assert main(["sweep", "-t", "1", "--out", str(f / "sweep"), "--serial"]) == 2
    assert str(f) in _err(capsys)
    assert f.read_text() == "x"


def test_a_full_disk_is_a_one_line_error_without_leftovers(tmp_path, capsys, monkeypatch, fake_solve):
    def full(fd):
        raise OSError(28, os.strerror(28))

    monkeypatch.setattr(os, "fsync", full)
    d = tmp_path / "d"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    err = _err(capsys)
    assert "no space left" in err and str(d) in err and len(err.strip().splitlines()) == 1
    assert _temporaries(tmp_path) == []


def test_a_stray_os_error_is_one_line(tmp_path, capsys, monkeypatch):
    def boom(scene, **kw):
        raise PermissionError(13, "Permission denied", "/some/place")

    monkeypatch.setattr(tactileskin.fe, "solve", boom)
    assert main(["solve", *CHEAP, "--out", str(tmp_path / "d")]) == 2
    err = _err(capsys)
    assert "/some/place" in err and "Permission denied" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "d").exists()  # the folder it created for nothing is removed again


def test_solve_outputs_have_umask_permissions(tmp_path, capsys):
    old = os.umask(0o022)
    try:
        d = tmp_path / "d"
        assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    finally:
        os.umask(old)
    assert stat.S_IMODE(d.stat().st_mode) == 0o755
    files = [p for p in d.iterdir()]
    assert {p.name for p in files} >= {"profile.csv", "contact.csv", "summary.json", "result.vtu"}
    assert {p.name: stat.S_IMODE(p.stat().st_mode) for p in files} == {p.name: 0o644 for p in files}


# --- killed writers ----------------------------------------------------------------------

_KILLED = textwrap.dedent("""
    import os, signal, sys, time
    import numpy as np
    import tactileskin.fe, tactileskin.results as r
    from tactileskin import fileio
    from tactileskin.cli import main
    sys.path.insert(0, {tests!r})
    from test_output_safety import fake_result

    def dying_vtu(path, fields, *args, **kwargs):
        with fileio.atomic_path(path) as tmp:
            tmp.write_text("half a file")
            os.kill(os.getpid(), signal.{sig})
            time.sleep(30)

    tactileskin.fe.solve = lambda scene, **kw: fake_result()
    r._write_vtu = dying_vtu
    sys.exit(main(["solve", "-t", "1", "--out", {out!r}]))
""")


def _run_killed(out: Path, sig: str) -> int:
    code = _KILLED.format(tests=str(Path(__file__).parent), out=str(out), sig=sig)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120).returncode


def test_sigterm_unwinds_and_removes_the_temporary(tmp_path):
    out = tmp_path / "d"
    assert _run_killed(out, "SIGTERM") == 128 + signal.SIGTERM
    assert _temporaries(tmp_path) == [] and not (out / "result.vtu").exists()


def test_a_killed_writers_temporary_is_removed_by_the_next_run(tmp_path, capsys, fake_solve):
    out = tmp_path / "d"
    assert _run_killed(out, "SIGKILL") == -signal.SIGKILL
    assert any(".tsk" in p.name for p in out.iterdir())  # the kill left its temporary
    assert main(["solve", *CHEAP, "--out", str(out)]) == 0
    assert _temporaries(tmp_path) == [] and (out / "result.vtu").is_file()


# --- sweep --out -------------------------------------------------------------------------

@pytest.fixture
def counted_cases(monkeypatch):
    """Every case fails at once (no solving); the list records which were attempted."""
    from tactileskin.errors import ConvergenceError

    calls = []

    def fail(scene):
        calls.append(scene)
        raise ConvergenceError("not solved in this test", {})

    monkeypatch.setattr(sw, "solve_case", fail)
    return calls


def _hold_run_lock(folder: Path):
    """Hold `folder`'s run lock as another process's run would (flock: a second open file
    description conflicts even within one process)."""
    import fcntl

    fd = os.open(folder / outdir.RUN_LOCK, os.O_RDWR | os.O_CREAT, 0o666)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    return fd


def test_a_second_run_into_a_folder_in_use_is_refused_and_changes_nothing(tmp_path, capsys, fake_solve):
    d = tmp_path / "d"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    before = {p.name: p.read_bytes() for p in d.iterdir()}
    fd, fd2 = _hold_run_lock(d), None   # the first run still writing (a long sweep into the same --out)
    try:
        assert main(["solve", *CHEAP, "-t", "2", "--out", str(d)]) == 2
        err = _err(capsys)
        assert str(d) in err and "another tactileskin run" in err and len(err.strip().splitlines()) == 1
        assert len(fake_solve) == 1   # refused before solving
        assert {p.name: p.read_bytes() for p in d.iterdir()} == before
        new = tmp_path / "new"        # the holder's new folder: the refused run removes nothing
        new.mkdir()
        fd2 = _hold_run_lock(new)
        assert main(["solve", *CHEAP, "--out", str(new)]) == 2
        assert sorted(p.name for p in new.iterdir()) == [".tactileskin", outdir.RUN_LOCK]  # the holder's
    finally:
        os.close(fd)
        if fd2 is not None:
            os.close(fd2)
    assert main(["solve", *CHEAP, "-t", "2", "--out", str(d)]) == 0   # released: a run may go on


def _in_the_lock_window(monkeypatch, then):
    """Run `then` once, between a taker's open of a lock file and its flock: the instant another
    run removes the file (deterministic, not timed)."""
    import fcntl

    real = fcntl.flock

    def flock(fd, op):
        monkeypatch.setattr(fcntl, "flock", real)
        then()
        return real(fd, op)

    monkeypatch.setattr(fcntl, "flock", flock)


def test_a_run_locking_the_lock_file_a_failed_run_removed_does_not_go_on(tmp_path, monkeypatch):
    # run A created `out` and failed: it removed the folder, its lock file too, still holding the
    # lock; run B had opened that file and took the lock once A let go: B went on, holding a lock
    # on a removed file, into a folder that no longer exists
    out = tmp_path / "out"
    a = outdir.claimed(out, "solve")
    a.__enter__()
    _in_the_lock_window(monkeypatch, lambda: a.__exit__(RuntimeError, RuntimeError("run A failed"), None))
    with pytest.raises(fileio.OutputError):
        with outdir.run_lock(out):
            pass
    assert not out.exists()  # A's cleanup stands; B wrote nothing


def test_a_run_lock_taken_on_a_removed_lock_file_is_taken_again(tmp_path, monkeypatch):
    # the folder stays, the lock file goes in B's window: B must hold the file a third run opens,
    # else both "hold" the folder (the third created a new lock file and locked it)
    d = tmp_path / "d"
    d.mkdir()
    _in_the_lock_window(monkeypatch, lambda: (d / outdir.RUN_LOCK).unlink())
    with outdir.run_lock(d):
        assert (d / outdir.RUN_LOCK).is_file()
        with pytest.raises(fileio.OutputError, match="another tactileskin run"):
            with outdir.run_lock(d):
                pass


def test_a_case_lock_taken_on_a_removed_lock_file_is_taken_again(tmp_path, monkeypatch):
    # outdir's cleanup of a failed sweep's new folder removes its free case locks: a sweep that
    # opened one just before must not compute the case beside a third that locked the new file
    from tactileskin.cache import ResultCache

    rc = ResultCache(tmp_path / "cache")
    rc.root.mkdir()
    (rc.root / "k.lock").touch()
    _in_the_lock_window(monkeypatch, lambda: (rc.root / "k.lock").unlink())
    lock = rc.lock("k", blocking=True)
    try:
        assert rc.lock("k", blocking=False) is None
    finally:
        lock.release()


def test_the_api_sweep_refuses_a_folder_in_use(tmp_path, counted_cases):
    from tactileskin import api
    from tactileskin.fileio import OutputError

    out = tmp_path / "out"
    out.mkdir()
    fd = _hold_run_lock(out)
    try:
        with pytest.raises(OutputError, match="another tactileskin run"):
            api.sweep({"thickness": [1], "material": ["silicone"], "indenter": ["flat"]}, out=out, serial=True,
                      report=False)
    finally:
        os.close(fd)
    assert counted_cases == []


def test_a_sweep_replaces_its_outputs_whole_and_leaves_a_users_file(tmp_path, capsys, counted_cases):
    out = tmp_path / "out"
    argv = ["sweep", "-t", "1", "-m", "silicone", "-i", "flat", "--serial", "--no-render", "--out", str(out)]
    assert main(argv) == 1  # the (faked) case failed; the outputs are written
    (out / "fig9_t5-silicone-flat-2d.png").write_bytes(b"a render of an earlier sweep")
    _as_written_by_us(out / "fig9_t5-silicone-flat-2d.png")
    (out / "notes.txt").write_text("mine")
    assert main(argv) == 1
    assert not (out / "fig9_t5-silicone-flat-2d.png").exists()  # not this sweep's: it would mislead
    assert (out / "notes.txt").read_text() == "mine" and (out / "report.md").is_file()
    assert _temporaries(out) == []


def test_sweep_refuses_a_foreign_folder_before_solving(tmp_path, capsys, counted_cases):
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.csv").write_text("mine")
    (out / "data.xlsx").write_text("mine too")
    assert main(["sweep", "-t", "1", "-m", "silicone", "-i", "flat", "--serial", "--no-render",
                 "--out", str(out)]) == 2
    assert "data.xlsx" in _err(capsys)
    assert counted_cases == []
    assert sorted(p.name for p in out.iterdir()) == ["data.xlsx", "results.csv"]
    assert (out / "results.csv").read_text() == "mine"


def test_sweep_refuses_an_unmarked_folder_of_lookalike_names(tmp_path, capsys, counted_cases):
    out = tmp_path / "out"
    (out / "cache").mkdir(parents=True)
    for name in ("results.csv", "profiles.csv", "report.md", "fig11_peak.svg", "fig9_t1-silicone-flat-2d.png"):
        (out / name).write_text("mine")
    argv = ["sweep", "-t", "1", "-m", "silicone", "-i", "flat", "--serial", "--no-render", "--out", str(out)]
    assert main(argv) == 2
    assert "did not write" in capsys.readouterr().err and counted_cases == []  # refused before solving
    assert all((out / n).read_text() == "mine" for n in ("results.csv", "report.md", "fig11_peak.svg"))
    assert not (out / outdir.MARKER).exists()


# --- build --------------------------------------------------------------------------------

def test_build_output_has_umask_permissions_and_writes_into_its_folder(tmp_path, capsys, monkeypatch):
    out = tmp_path / "parts"
    old = os.umask(0o022)
    try:
        assert main(["build", "-t", "2", "--indenter", "none", "--no-molds", "--out", str(out)]) == 0
    finally:
        os.umask(old)
    assert stat.S_IMODE(out.stat().st_mode) == 0o755
    modes = {p.name: stat.S_IMODE(p.stat().st_mode) for p in out.iterdir()}
    assert "manifest.json" in modes and "skin.stl" in modes and outdir.MARKER in modes
    assert modes == {n: 0o644 for n in modes}
    assert [p.name for p in tmp_path.iterdir()] == ["parts"]
    capsys.readouterr()
    # the folder itself is kept (its mode bits, group, ACLs; a mount point; the shell's folder)
    os.chmod(out, 0o2775)
    inode = out.stat().st_ino
    (out / "notes.txt").write_text("mine")
    (out / "my.stl").write_text("mine too")  # a build's pattern, not a build's file
    monkeypatch.chdir(out)
    assert main(["build", "-t", "2", "--indenter", "none", "--no-molds", "--out", "."]) == 0
    monkeypatch.chdir(tmp_path)
    assert out.stat().st_ino == inode and stat.S_IMODE(out.stat().st_mode) == 0o2775
    assert (out / "notes.txt").read_text() == "mine" and (out / "my.stl").read_text() == "mine too"
    assert set(p.name for p in out.iterdir()) == set(modes) | {"notes.txt", "my.stl"}
    assert [p.name for p in tmp_path.iterdir()] == ["parts"] and _temporaries(out) == []
    capsys.readouterr()
    # an edited part is the user's now: refused, nothing written
    (out / "skin.stl").write_bytes(b"edited")
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert main(["build", "-t", "2", "--indenter", "none", "--no-molds", "--out", str(out)]) == 2
    err = _err(capsys)
    assert "skin.stl" in err and "changed since" in err and len(err.strip().splitlines()) == 1
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before


def test_a_build_folder_from_before_the_marker_is_adopted(tmp_path, capsys):
    out = tmp_path / "parts"
    argv = ["build", "-t", "2", "--indenter", "none", "--no-molds", "--out", str(out)]
    assert main(argv) == 0
    for n in (outdir.MARKER, ownership.OWNED_FILES, ownership.RECORD_LOCK):
        (out / n).unlink()  # as an earlier version left it: the manifest's files only
    assert main(argv) == 0
    assert (out / outdir.MARKER).is_file() and "skin.stl" in ownership.read_record(out)


def test_staged_dir_leaves_no_temporary_when_the_first_move_fails(tmp_path, monkeypatch):
    import errno

    final = tmp_path / "entry"
    with staging.staged_dir(final) as tmp:
        (tmp / "a").write_text("1")
    real = os.replace

    def busy(src, dst):
        if Path(src) == final:
            raise OSError(errno.EBUSY, "Device or resource busy", str(src))
        return real(src, dst)

    monkeypatch.setattr(os, "replace", busy)
    with pytest.raises(fileio.OutputError), staging.staged_dir(final) as tmp:
        (tmp / "a").write_text("2")
    assert [p.name for p in tmp_path.iterdir()] == ["entry"] and (final / "a").read_text() == "1"


def test_build_refuses_another_commands_folder_naming_it(tmp_path, capsys, fake_solve):
    d = tmp_path / "s"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    capsys.readouterr()
    assert main(["build", "-t", "2", "--indenter", "none", "--no-molds", "--out", str(d)]) == 2
    err = " ".join(_err(capsys).split())
    assert "another tactileskin command (`solve`)" in err and "did not write" not in err


# --- single output files -------------------------------------------------------------------

def test_single_file_outputs_replace_only_their_own_unchanged_files(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    deck = ["export", *CHEAP, "--out", "deck.inp"]
    Path("deck.inp").write_text("MY DECK")  # a user's file of that name: refused, kept
    assert main(deck) == 2
    assert "did not write" in _err(capsys) and Path("deck.inp").read_text() == "MY DECK"
    Path("deck.inp").unlink()
    assert main(deck) == 0 and main(deck) == 0  # ours, unchanged: replaced
    assert Path("deck.inp").read_text().startswith("*")
    with open("deck.inp", "a") as fh:  # the user edited it since: no longer replaced
        fh.write("** my edit\n")
    assert main(deck) == 2 and Path("deck.inp").read_text().endswith("** my edit\n")
    capsys.readouterr()
    Path("notes.vtu").write_text("MINE")
    assert main(["mesh", *CHEAP[:4], "--out", "notes.vtu"]) == 2 and Path("notes.vtu").read_text() == "MINE"
    assert "did not write" in _err(capsys)
    # film calibrate: a plot over its own input CSV is refused before anything is written
    cal = "force_n,area_mm2,gray\n30,100,40\n17,100,120\n2,100,220\n"
    Path("cal.csv").write_text(cal)
    assert main(["film", "calibrate", "cal.csv", "-o", "c.json", "--plot", "cal.csv"]) == 2
    assert Path("cal.csv").read_text() == cal and not Path("c.json").exists()
    assert "--plot" in _err(capsys)
    assert main(["film", "calibrate", "cal.csv", "-o", "c.json", "--plot", "c.png"]) == 0
    assert main(["film", "calibrate", "cal.csv", "-o", "c.json", "--plot", "c.png"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        ".tactileskin-files.json", ".tactileskin-files.lock", "c.json", "c.png", "cal.csv", "deck.inp", "notes.vtu"]


# --- install --------------------------------------------------------------------------------

def test_geometry_files_are_package_data_and_read_from_the_package(monkeypatch):
    monkeypatch.delenv("TACTILESKIN_GEOMETRY", raising=False)
    names = {"fingertip.toml", "indenters.toml", "braille.toml", "molds.toml"}
    pkg = Path(tactileskin.__file__).parent
    assert params.geometry_dir().resolve() == (pkg / "data" / "geometry").resolve()
    assert names <= {p.name for p in params.geometry_dir().iterdir()}
    pyproject = REPO / "pyproject.toml"
    if not pyproject.is_file():
        pytest.skip("not a source checkout")
    # every TOML file inside the package is matched by a package-data glob, so the wheel ships it
    data = tomllib.loads(pyproject.read_text())["tool"]["setuptools"]["package-data"]
    src = REPO / "src"
    for f in (src / "tactileskin").rglob("*.toml"):
        rel = f.relative_to(src)
        owners = [(pkg_name, globs) for pkg_name, globs in data.items()
                  if rel.parent.as_posix().startswith(pkg_name.replace(".", "/"))]
        assert any(fnmatch.fnmatch(rel.relative_to(Path(*n.split("."))).as_posix(), g)
                   for n, globs in owners for g in globs), f"{rel} is not package data"
    assert not list(REPO.glob("geometry/*.toml"))  # one source of truth


def test_geometry_override_still_works(tmp_path, monkeypatch):
    (tmp_path / "fingertip.toml").write_text("[x]\ny = 1\n")
    monkeypatch.setenv("TACTILESKIN_GEOMETRY", str(tmp_path))
    assert params.geometry_dir() == tmp_path
    assert params.read_toml(params.geometry_dir() / "fingertip.toml", "p") == {"x": {"y": 1}}


def test_result_write_refuses_a_users_folder(tmp_path):
    user = tmp_path / "user"
    (user / "result_steps").mkdir(parents=True)
    (user / "summary.json").write_text("MY DATA")
    (user / "result_steps" / "step_0001.vtu").write_text("MINE")
    with pytest.raises(fileio.OutputError, match="did not write"):
        fake_result().write(user)
    assert (user / "summary.json").read_text() == "MY DATA"
    assert (user / "result_steps" / "step_0001.vtu").read_text() == "MINE"
    out = fake_result().write(tmp_path / "new")  # a new folder: claimed, written, rewritten
    assert fake_result().write(out) == out and (out / "summary.json").is_file()


@pytest.mark.skipif(not Path("/proc/self/status").is_file(), reason="reads the signal mask from /proc")
def test_meshing_keeps_the_sigterm_handler_that_unwinds_the_cli():
    # gmsh's initialize installs C-level handlers over Python's: a SIGTERM then killed the
    # process in place, leaving its staging folder behind
    from tactileskin.mesh import build_mesh
    from tactileskin.scene import Scene

    def caught() -> bool:
        line = next(x for x in open("/proc/self/status") if x.startswith("SigCgt:"))
        return bool(int(line.split()[1], 16) & (1 << (signal.SIGTERM - 1)))

    previous = signal.signal(signal.SIGTERM, lambda *a: None)
    try:
        build_mesh(Scene(thickness=1.0, mesh_size=1.0, refinement=2.0))
        assert caught()
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_a_suspect_case_gets_no_render(tmp_path, capsys, monkeypatch):
    # a no-contact (suspect) flat case was rendered as the sweep's Fig. 9, unmarked
    import tactileskin.report.render as render

    rendered = []
    monkeypatch.setattr(render, "render_case", lambda vtu, png, **kw: rendered.append(png) or png)

    def no_contact(scene):
        r = fake_result()
        r.pressure, r.contact_x, r.contact_pressure, r.reaction = np.zeros(3), np.zeros(0), np.zeros(0), 0.0
        return r

    monkeypatch.setattr(sw, "solve_case", no_contact)
    out = tmp_path / "out"
    assert main(["sweep", "-t", "1", "-m", "silicone", "-i", "flat", "--serial", "--out", str(out)]) == 3
    assert rendered == [] and not list(out.glob("fig9_*"))


def test_a_folder_an_earlier_version_wrote_without_the_record_is_rerun(tmp_path):
    """Before the record of results, a marked folder's pattern-matching files were the earlier
    result: a rerun into such a folder (yesterday's ./dev run) replaces them as that version did
    and starts the record, instead of refusing every file as not ours; also when that version
    recorded a single file there (mesh -o); a folder this version claimed keeps the record's rule."""
    d = tmp_path / "old"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    marker = json.loads((d / ".tactileskin").read_text())
    assert marker.get("record") == 1
    del marker["record"]  # as the earlier version wrote it
    (d / ".tactileskin").write_text(json.dumps(marker))
    (d / ".tactileskin-files.json").write_text(json.dumps({"deck.msh": "0" * 64}))
    (d / "profile.csv").write_text("s_mm,pressure_mpa\n0,1\n1,0\n")  # the old result's
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    assert len((d / "profile.csv").read_text().splitlines()) > 3
    rec = json.loads((d / ".tactileskin-files.json").read_text())
    assert "profile.csv" in rec and "deck.msh" not in rec  # deck.msh is not there
    assert json.loads((d / ".tactileskin").read_text())["record"] == 1
    # from now on the record's rule: a user's file of a result's name is refused, not replaced
    (d / ".tactileskin-files.json").write_text(json.dumps({k: v for k, v in rec.items() if k != "contact.csv"}))
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2


@pytest.mark.parametrize("t, words", [("1", "reads 2.6x the peak of the 3D dots measured"), ("2", "1.9-3.1x the peak")])
def test_a_2d_braille_solve_says_it_is_the_ridge_not_the_dots(tmp_path, capsys, fake_solve, t, words):
    # the ridge's 0.0997 MPa at t = 1 silicone read as a plain 'ok' answer for a dot 2.6x lower
    assert main(["solve", "-i", "braille", "-t", t, "--elastic", "--out", str(tmp_path / "o")]) == 0
    out = " ".join(capsys.readouterr().out.replace("│", " ").split())
    assert "the paper's 2D ridge" in out and words in out and "--dim 3 solves the dots" in out
    assert main(["solve", "-i", "flat", "-t", t, "--elastic", "--out", str(tmp_path / "o")]) == 0
    assert "2D ridge" not in capsys.readouterr().out


def test_build_refuses_a_folder_in_use_before_its_cad(tmp_path, capsys, monkeypatch):
    # build took the folder's run lock only when it wrote, after minutes of CAD
    import tactileskin.geometry.parts as gp

    monkeypatch.setattr(gp, "build_parts", lambda *a, **k: (_ for _ in ()).throw(AssertionError("CAD started")))
    out = tmp_path / "parts"
    out.mkdir()
    fd = _hold_run_lock(out)
    try:
        assert main(["build", "-t", "1", "--no-molds", "-i", "none", "--out", str(out)]) == 2
    finally:
        os.close(fd)
    assert "another tactileskin run" in _err(capsys)


def test_result_write_refuses_a_folder_another_run_is_writing_into(tmp_path):
    from tactileskin.fileio import OutputError

    d = fake_result().write(tmp_path / "r")
    before = {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()}
    fd = _hold_run_lock(d)
    try:
        with pytest.raises(OutputError, match="another tactileskin run"):
            fake_result().write(d)
    finally:
        os.close(fd)
    assert {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()} == before
    fake_result().write(d)


@pytest.mark.parametrize("lock", [outdir.RUN_LOCK, ownership.RECORD_LOCK])
def test_a_lock_file_that_is_a_symlink_is_not_followed(tmp_path, capsys, fake_solve, lock):
    """A dangling symlink named like a lock file made the run create its target outside --out
    (open(O_CREAT) follows it); a link to a user's file was opened and locked."""
    d = tmp_path / "d"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    before = {p.name: p.read_bytes() for p in d.iterdir() if p.name != lock}
    (d / lock).unlink()
    (d / lock).symlink_to(tmp_path / "elsewhere")
    assert main(["solve", *CHEAP, "-t", "2", "--out", str(d)]) == 2
    err = _err(capsys)
    assert len(err.strip().splitlines()) == 1 and "symbolic link" in err and str(d) in err
    assert not (tmp_path / "elsewhere").exists()
    assert {p.name: p.read_bytes() for p in d.iterdir() if p.name != lock} == before
    assert len(fake_solve) == 1  # refused before the solve (the record's lock as the run lock)


def test_a_case_lock_that_is_a_symlink_is_not_followed(tmp_path):
    from tactileskin.cache import ResultCache

    cache = ResultCache(tmp_path / "cache")
    cache.root.mkdir()
    (cache.root / "abc.lock").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(fileio.OutputError, match="symbolic link"):
        cache.lock("abc", blocking=False)
    assert not (tmp_path / "elsewhere").exists()
