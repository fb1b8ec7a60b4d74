"""An output folder's earlier result is what tactileskin recorded writing there
(`.tactileskin-files.json`): a user's file stays whatever its name, and a file the user
edited is not overwritten. The CLI runs in-process; solves are faked (files, not numbers)."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

import tactileskin.fe
from tactileskin import fileio, outdir, ownership, staging
from tactileskin.cli import main

from test_output_safety import CHEAP, _err, _temporaries, fake_result


@pytest.fixture
def fake_solve(monkeypatch):
    monkeypatch.setattr(tactileskin.fe, "solve", lambda scene, **kw: fake_result())


def _record(folder: Path) -> dict:
    return json.loads((folder / ownership.OWNED_FILES).read_text())


def test_users_files_with_our_names_stay_in_a_solve_folder(tmp_path, capsys, fake_solve):
    d = tmp_path / "s1"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    assert set(_record(d)) == {"profile.csv", "contact.csv", "summary.json", "result.vtu"}
    (d / "sensors.csv").write_text("mine\n")
    (d / "history.csv").write_text("mine\n")
    (d / "section_2d").mkdir()
    (d / "section_2d" / "profile.csv").write_text("keep\n")
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    assert (d / "sensors.csv").read_text() == "mine\n" and (d / "history.csv").read_text() == "mine\n"
    assert (d / "section_2d" / "profile.csv").read_text() == "keep\n"
    assert "sensors.csv" not in _record(d) and _temporaries(d) == []


def test_a_users_file_the_new_result_would_replace_is_refused(tmp_path, capsys, fake_solve):
    d = tmp_path / "s1"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    rec = _record(d)
    del rec["contact.csv"]  # as if the user had put it there
    (d / ownership.OWNED_FILES).write_text(json.dumps(rec))
    (d / "contact.csv").write_text("mine\n")
    before = {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()}
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    err = _err(capsys)
    assert "contact.csv" in err and "did not write" in err and len(err.strip().splitlines()) == 1
    assert {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()} == before  # nothing written


def test_an_edited_report_is_not_overwritten(tmp_path, capsys, fake_solve):
    d = tmp_path / "s1"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    (d / "summary.json").write_text('{"mine": 1}\n')
    before = {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()}
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    err = _err(capsys)
    assert str(d / "summary.json") in err and "changed since" in err and len(err.strip().splitlines()) == 1
    assert {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()} == before


def test_an_edited_result_file_is_refused_before_the_solve(tmp_path, capsys, monkeypatch):
    # the refusal came after the solve, whose result (minutes of a 3D solve) was thrown away
    calls = []
    monkeypatch.setattr(tactileskin.fe, "solve", lambda scene, **kw: calls.append(1) or fake_result())
    d = tmp_path / "s1"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    (d / "profile.csv").write_text("s_mm,pressure_mpa\n0,1\n")
    (d / "contact.csv").unlink()  # a file of ours the user removed is no obstacle
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    err = _err(capsys)
    assert str(d / "profile.csv") in err and "changed since" in err and len(err.strip().splitlines()) == 1
    assert calls == [1]  # not solved again
    (d / "profile.csv").unlink()
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0 and calls == [1, 1]
    # a 3D solve's own files are checked too (a map edited after a 3D run); a 2D solve, which
    # does not write a map, leaves the edited one where it is
    (d / "bone_map.csv").write_text("s_mm,z_mm,pressure_mpa\n0,0,1\n")
    assert main(["solve", "--dim", "3", "-i", "braille", *CHEAP, "--out", str(d)]) == 2
    assert "bone_map.csv" in _err(capsys) and calls == [1, 1]
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0 and calls == [1, 1, 1]
    assert (d / "bone_map.csv").read_text().endswith("0,0,1\n")


def test_an_edited_history_does_not_block_a_force_solve_which_writes_none(tmp_path, capsys, fake_solve):
    # history.csv comes of [[loading]] segments only; a --force ramp writes none, yet its
    # solve was refused (exit 2, "changed since") over an edited history.csv of an earlier run
    d = tmp_path / "s1"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    (d / "history.csv").write_text("t_s,travel_mm\n0,0\n")
    ownership.record_file(d / "history.csv")  # as an earlier indent-hold-release run left it
    (d / "history.csv").write_text("t_s,travel_mm\n0,0\n1,0.2\n")  # then edited
    assert main(["solve", *CHEAP, "--force", "0.1", "--out", str(d)]) == 0, _err(capsys)
    assert (d / "history.csv").read_text().endswith("1,0.2\n")


def test_the_solve_table_lists_the_2d_comparison_it_wrote(tmp_path, capsys, fake_solve):
    # the "files" row left out compare_2d.json and section_2d/ of --compare-2d
    d = tmp_path / "s3"
    assert main(["solve", "--dim", "3", "-i", "braille", "--compare-2d", *CHEAP, "--out", str(d)]) == 0
    assert (d / "compare_2d.json").is_file() and (d / "section_2d" / "profile.csv").is_file()
    out = " ".join(capsys.readouterr().out.split())
    assert "compare_2d.json" in out and "section_2d" in out, out


def test_staged_files_in_a_marked_folder_replace_only_recorded_files(tmp_path):
    d = outdir.claim_dir(tmp_path / "d", "test")
    own = ("a.csv", "fig9_*.png", "sub/x_*.csv")
    with staging.staged_files(d, own) as tmp:
        (tmp / "a.csv").write_text("1")
        (tmp / "fig9_case.png").write_text("1")
    (d / "fig9_my_notes.png").write_text("mine")
    (d / "sub").mkdir()
    (d / "sub" / "x_mine.csv").write_text("mine")
    with staging.staged_files(d, own) as tmp:
        (tmp / "a.csv").write_text("2")  # no figure this time: the recorded one goes
    assert not (d / "fig9_case.png").exists() and (d / "a.csv").read_text() == "2"
    assert (d / "fig9_my_notes.png").read_text() == "mine" and (d / "sub" / "x_mine.csv").read_text() == "mine"
    assert set(_record(d)) == {"a.csv"}
    # an edited file of ours that the new result does not write is the user's now: it stays
    with staging.staged_files(d, own) as tmp:
        (tmp / "a.csv").write_text("3")
        (tmp / "fig9_case.png").write_text("3")
    (d / "fig9_case.png").write_text("edited")
    with staging.staged_files(d, own) as tmp:
        (tmp / "a.csv").write_text("4")
    assert (d / "fig9_case.png").read_text() == "edited"  # its entry stays: a rewrite says "changed since"


def test_a_sweep_leaves_a_users_figure_of_its_pattern(tmp_path, capsys, monkeypatch):
    import tactileskin.sweep as sw
    from tactileskin.errors import ConvergenceError

    def fail(scene):
        raise ConvergenceError("not solved in this test", {})

    monkeypatch.setattr(sw, "solve_case", fail)
    out = tmp_path / "out"
    argv = ["sweep", "-t", "1", "-m", "silicone", "-i", "flat", "--serial", "--no-render", "--out", str(out)]
    assert main(argv) == 1
    (out / "fig9_my_notes.png").write_bytes(b"mine")
    assert main(argv) == 1
    assert (out / "fig9_my_notes.png").read_bytes() == b"mine"
    (out / "report.md").write_text("my edits\n")
    assert main(argv) == 2
    assert "report.md" in _err(capsys) and (out / "report.md").read_text() == "my edits\n"


@pytest.fixture
def failing_solves(monkeypatch):
    """Every case's solve fails at once; the list of the thicknesses it was asked to solve."""
    import tactileskin.sweep as sw
    from tactileskin.errors import ConvergenceError

    calls = []

    def fail(scene):
        calls.append(scene.thickness)
        raise ConvergenceError("not solved in this test", {})

    monkeypatch.setattr(sw, "solve_case", fail)
    return calls


def test_a_sweep_refuses_an_edited_result_file_before_solving(tmp_path, capsys, failing_solves):
    # the refusal came after every case was solved (exit 2, documented as "before any case ran")
    calls = failing_solves
    out = tmp_path / "out"
    argv = ["sweep", "-m", "silicone", "-i", "flat", "--serial", "--no-render", "--out", str(out)]
    assert main([*argv, "-t", "1"]) == 1 and calls == [1.0]
    for name in ("report.md", "results.csv"):
        kept = (out / name).read_bytes()
        (out / name).write_text("my edits\n")
        assert main([*argv, "-t", "2"]) == 2
        err = _err(capsys)
        assert str(out / name) in err and "changed since" in err and len(err.strip().splitlines()) == 1
        assert calls == [1.0] and (out / name).read_text() == "my edits\n"
        (out / name).write_bytes(kept)
    assert main([*argv, "-t", "2"]) == 1 and calls == [1.0, 2.0]


def test_ts_sweep_refuses_an_edited_result_file_before_solving(tmp_path, failing_solves):
    # 80f0cc8 moved the refusal before the solves for the command only: ts.sweep(out=...) still
    # solved every case and then refused the edited report.md
    import tactileskin as ts
    from tactileskin.fileio import OutputError

    calls = failing_solves
    out = tmp_path / "out"
    grid = {"materials": ["silicone"], "indenters": ["flat"]}
    ts.sweep({**grid, "thicknesses": [1.0]}, out=out, serial=True, report=False)
    assert calls == [1.0]
    (out / "report.md").write_text("my edits\n")
    with pytest.raises(OutputError, match="changed since"):
        ts.sweep({**grid, "thicknesses": [2.0]}, out=out, serial=True, report=False)
    assert calls == [1.0] and (out / "report.md").read_text() == "my edits\n"


def test_an_api_result_written_into_a_cli_solve_folder_replaces_its_whole_result(tmp_path, capsys, fake_solve):
    d = tmp_path / "s"
    assert main(["solve", "--dim", "3", *CHEAP, "--compare-2d", "--out", str(d)]) == 0
    assert (d / "compare_2d.json").is_file() and (d / "section_2d" / "summary.json").is_file()
    (d / "notes.txt").write_text("mine")
    fake_result().write(d)  # Result.write: the same files as `solve`
    assert not (d / "compare_2d.json").exists() and not (d / "section_2d").exists()
    assert (d / "notes.txt").read_text() == "mine" and (d / "summary.json").is_file()
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0  # and the CLI replaces the API's


def _write_and_record(path: str) -> None:
    fileio.atomic_write_text(path, "deck\n")
    ownership.record_file(path)


def test_parallel_single_file_writes_into_one_folder_keep_every_record(tmp_path):
    import multiprocessing

    names = [str(tmp_path / f"d{i}.inp") for i in range(16)]
    with multiprocessing.get_context("fork").Pool(8) as pool:
        pool.map(_write_and_record, names)
    assert set(_record(tmp_path)) == {Path(n).name for n in names}  # none lost to a race
    for n in names:
        ownership.claim_file(n)  # each may be rewritten


def test_an_unreachable_scheduler_is_refused_before_the_folder_is_claimed(tmp_path, capsys):
    import socket

    out = tmp_path / "X"
    with socket.socket() as s:  # a port nobody listens on: bound, not listening
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        assert main(["sweep", "--scheduler", f"tcp://127.0.0.1:{port}", "-t", "1", "-m", "silicone", "-i", "flat",
                     "--no-render", "--out", str(out)]) == 2
    err = _err(capsys)
    assert "--scheduler" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
    from tactileskin.sweep import check_reachable

    with socket.socket() as s:  # something listening passes the check
        s.bind(("127.0.0.1", 0))
        s.listen()
        check_reachable(f"tcp://127.0.0.1:{s.getsockname()[1]}")


def test_a_write_failing_inside_staging_names_the_destination(tmp_path, capsys, fake_solve, monkeypatch):
    import errno

    import tactileskin.results as results

    def too_large(path, *a, **k):
        with fileio.atomic_path(path) as tmp, fileio.os_errors(path):
            raise OSError(errno.EFBIG, "File too large", str(tmp))

    monkeypatch.setattr(results, "_write_vtu", too_large)
    d = tmp_path / "uf1"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    err = _err(capsys)
    assert f"cannot write {d / 'result.vtu'}: File too large" in err and ".tsk" not in err
    assert fileio.user_path(d / ".x.csv.tsk12-ab.tmp") == str(d / "x.csv")


def test_another_commands_folder_is_refused_naming_that_command(tmp_path, capsys, fake_solve):
    d = outdir.claim_dir(tmp_path / "sw", "sweep")
    (d / "cache").mkdir()
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    err = " ".join(_err(capsys).split())
    assert "written by another tactileskin command (`sweep`)" in err and "did not write" not in err


def test_a_run_stopped_before_its_first_case_leaves_no_folder(tmp_path):
    """A sweep interrupted before any case finished left its new folder holding the marker and
    cache/*.lock alone; a folder that held anything else, or existed before, is kept."""
    from tactileskin.outdir import MARKER, claimed

    out = tmp_path / "new"
    with pytest.raises(KeyboardInterrupt):
        with claimed(out, "sweep"):
            (out / "cache").mkdir()
            (out / "cache" / "abc.lock").write_text("")
            raise KeyboardInterrupt
    assert not out.exists()
    with pytest.raises(KeyboardInterrupt):
        with claimed(out, "sweep"):
            (out / "cache").mkdir()
            (out / "cache" / "abc.lock").write_text("")
            (out / "cache" / "key1").mkdir()  # a finished case: kept for the rerun
            raise KeyboardInterrupt
    assert (out / MARKER).is_file() and (out / "cache" / "key1").is_dir()


def test_a_stopped_run_keeps_the_cache_locks_another_sweep_holds(tmp_path):
    """A second sweep started on the same new folder holds a case lock: removing that file
    would let a third run compute the same case again; the lock and the folder stay."""
    fcntl = pytest.importorskip("fcntl")
    from tactileskin.outdir import claimed

    out = tmp_path / "new"
    with pytest.raises(KeyboardInterrupt):
        with claimed(out, "sweep"):
            (out / "cache").mkdir()
            for k in ("held", "free"):
                (out / "cache" / f"{k}.lock").write_text("")
            fd = os.open(out / "cache" / "held.lock", os.O_RDONLY)  # another open file: another run's lock
            fcntl.flock(fd, fcntl.LOCK_EX)
            raise KeyboardInterrupt
    try:
        assert sorted(p.name for p in (out / "cache").iterdir()) == ["held.lock"]
    finally:
        os.close(fd)


def test_a_write_stopped_during_its_moves_leaves_a_folder_the_next_run_accepts(tmp_path, monkeypatch):
    """The record is written before the moves with both versions of each replaced file: a run
    killed between two renames (old and new files mixed) does not make the next run refuse
    its own files as 'changed since'."""
    d = tmp_path / "o"
    outdir.claim_dir(d, "solve")
    for text in ("1", "2"):
        with staging.staged_files(d, ("a.csv", "b.csv")) as tmp:
            (tmp / "a.csv").write_text("a" + text)
            (tmp / "b.csv").write_text("b" + text)
    real, calls = os.replace, []

    def dying(src, dst):  # the process "dies" at the third rename: no undo runs
        calls.append(dst)
        if len(calls) == 3:
            raise SystemExit(137)
        return real(src, dst)

    monkeypatch.setattr(staging.os, "replace", dying)
    monkeypatch.setattr(staging.contextlib, "suppress", lambda *e: (_ for _ in ()).throw(SystemExit(137)))
    for text in ("3", "3b"):  # twice: the second run's record keeps the first's digests
        calls.clear()
        with pytest.raises(SystemExit):
            with staging.staged_files(d, ("a.csv", "b.csv")) as tmp:
                (tmp / "a.csv").write_text("a" + text)
                (tmp / "b.csv").write_text("b" + text)
    monkeypatch.undo()
    with pytest.raises(KeyboardInterrupt):  # and a run undone cleanly puts the record back too
        with staging.staged_files(d, ("a.csv", "b.csv")) as tmp:
            (tmp / "a.csv").write_text("a5")
            raise KeyboardInterrupt
    with staging.staged_files(d, ("a.csv", "b.csv")) as tmp:  # accepted, whatever mix is there
        (tmp / "a.csv").write_text("a4")
        (tmp / "b.csv").write_text("b4")
    assert (d / "a.csv").read_text() == "a4" and (d / "b.csv").read_text() == "b4"


def test_the_record_lock_opens_read_only_where_it_cannot_be_written(tmp_path, monkeypatch):
    # a group-shared folder's lock file is 0644 under umask 022: another user cannot open it for
    # writing ("permission denied" refused every rerun); flock needs no write access
    real, flags = os.open, []

    def opener(p, f, *a):
        flags.append(f)
        if str(p).endswith(ownership.RECORD_LOCK) and f & os.O_RDWR:
            raise PermissionError(13, "Permission denied")
        return real(p, f, *a)

    monkeypatch.setattr(ownership.os, "open", opener)
    (tmp_path / "x.inp").write_text("x")
    ownership.record_file(tmp_path / "x.inp")
    assert any(f & (os.O_WRONLY | os.O_RDWR) == 0 for f in flags)
    assert "x.inp" in json.loads((tmp_path / ownership.OWNED_FILES).read_text())


def test_a_legacy_folder_upgraded_by_one_command_keeps_the_others_files(tmp_path):
    """A film folder of an earlier version: `film compare` (its own files only) upgraded the
    marker, and the next `film analyze` refused the earlier analyze files as not ours."""
    d = tmp_path / "f"
    outdir.claim_dir(d, "film-analyze")
    marker = json.loads((d / outdir.MARKER).read_text())
    del marker["record"]
    (d / outdir.MARKER).write_text(json.dumps(marker))
    (d / "profile.csv").write_text("old analyze")
    (d / "comparison.json").write_text("old compare")
    with staging.staged_files(d, ("comparison.json",)) as tmp:
        (tmp / "comparison.json").write_text("new compare")
    with staging.staged_files(d, ("profile.csv", "comparison.json")) as tmp:
        (tmp / "profile.csv").write_text("new analyze")
        (tmp / "comparison.json").write_text("newer compare")
    assert (d / "profile.csv").read_text() == "new analyze"


def test_a_folder_of_our_bookkeeping_alone_is_empty(tmp_path):
    d = tmp_path / "d"
    d.mkdir()
    (d / "deck.msh").write_text("x")
    ownership.record_file(d / "deck.msh")
    (d / "deck.msh").unlink()
    outdir.claim_dir(d, "solve")  # was refused: "holds files tactileskin did not write (.tactileskin-files.json, ...)"


def test_removing_free_locks_removes_nothing_but_lock_files(tmp_path):
    """claimed()'s clean-up checks that a new folder's cache holds only locks, then removes
    them: a file another run wrote in between is not one of them (it was unlinked too)."""
    from tactileskin.outdir import _remove_free_locks

    (tmp_path / "a.lock").write_text("")
    (tmp_path / "case.json").write_text("another run's")
    assert _remove_free_locks(tmp_path) is False
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.json"]


def test_a_single_file_whose_record_cannot_be_written_is_replaced_by_the_rerun(tmp_path, capsys, monkeypatch):
    """`material fit -o` (as mesh, export, film calibrate) wrote the file, then its record: a
    disk that filled in between left the new file unrecorded, and every rerun refused it as
    the user's ("tactileskin did not write it"). Now the record lists the new digest before the
    file is replaced: the failed run leaves the earlier file, and the rerun replaces it."""
    import numpy as np

    lam = np.linspace(0.8, 1.5, 8)
    (tmp_path / "t.csv").write_text("stretch,nominal_stress_mpa\n" + "".join(
        f"{float(a)!r},{float(0.04 * (a - a ** -2))!r}\n" for a in lam))  # neo-Hookean, mu = 0.04 MPa
    out = tmp_path / "fit" / "gel.toml"
    argv = ["material", "fit", str(tmp_path / "t.csv"), "-o", str(out), "--law"]
    assert main(argv + ["neo_hookean"]) == 0
    earlier = out.read_text()
    real = ownership.atomic_write_json

    def full_disk(path, obj):
        raise fileio.OutputError(path, "no space left on the device")

    monkeypatch.setattr(ownership, "atomic_write_json", full_disk)
    capsys.readouterr()
    assert main(argv + ["mooney_rivlin"]) == 2
    assert "cannot write" in _err(capsys) and out.read_text() == earlier  # not a new file unrecorded
    monkeypatch.setattr(ownership, "atomic_write_json", real)
    assert main(argv + ["mooney_rivlin"]) == 0, _err(capsys)
    assert 'law = "mooney_rivlin"' in out.read_text()
    assert _record(out.parent)["gel.toml"] == fileio.file_sha256(out)


def test_a_read_only_result_folder_is_refused_before_the_solve(tmp_path, capsys, monkeypatch):
    """A rerun into an earlier result's folder that has become read-only solved in full (a 3D
    solve: minutes) and then failed to write; the marker is there, so the claim wrote nothing.
    (Root ignores folder modes: no new file can be made in `d` stands for read-only.)"""
    import errno
    import tempfile

    calls = []
    monkeypatch.setattr(tactileskin.fe, "solve", lambda scene, **kw: calls.append(1) or fake_result())
    d = tmp_path / "s"
    assert main(["solve", *CHEAP, "--out", str(d)]) == 0
    before = {p.name: p.read_bytes() for p in d.iterdir()}
    real = {n: getattr(tempfile, n) for n in ("mkstemp", "mkdtemp")}

    def read_only(name):
        def make(*a, dir=None, **kw):
            if dir is not None and Path(dir) == d:
                raise PermissionError(errno.EACCES, "Permission denied", str(dir))
            return real[name](*a, dir=dir, **kw)
        return make

    for n in real:
        monkeypatch.setattr(tempfile, n, read_only(n))
    calls.clear()
    capsys.readouterr()
    assert main(["solve", *CHEAP, "--out", str(d)]) == 2
    assert "permission denied" in _err(capsys) and calls == []  # was: solved, then refused
    assert {p.name: p.read_bytes() for p in d.iterdir()} == before


@pytest.mark.parametrize("fail_at", ["writer", "record"])
def test_a_failed_single_file_write_leaves_no_folder_it_created(tmp_path, capsys, monkeypatch, fail_at):
    """`material fit -o new/sub/gel.toml` (as mesh, export, film calibrate) on a full disk left
    the empty folders `new/sub` it had created (solve and film analyze removed theirs). Now a
    failed write removes the folders it created, which hold only its bookkeeping; a folder that
    was there stays, and so does the user's file."""
    import numpy as np

    lam = np.linspace(0.8, 1.5, 8)
    (tmp_path / "t.csv").write_text("stretch,nominal_stress_mpa\n" + "".join(
        f"{float(a)!r},{float(0.04 * (a - a ** -2))!r}\n" for a in lam))
    real = ownership.atomic_write_json

    def full_disk(path, obj):
        raise fileio.OutputError(path, "no space left on the device")

    def failing_writer(path, text):
        raise fileio.OutputError(path, "no space left on the device")

    if fail_at == "record":
        monkeypatch.setattr(ownership, "atomic_write_json", full_disk)
    else:
        monkeypatch.setattr(fileio, "atomic_write_text", failing_writer)
    out = tmp_path / "new" / "sub" / "gel.toml"
    argv = ["material", "fit", str(tmp_path / "t.csv"), "-o", str(out), "--law", "neo_hookean"]
    assert main(argv) == 2
    assert "Traceback" not in _err(capsys)
    assert not (tmp_path / "new").exists()
    (tmp_path / "kept").mkdir()
    (tmp_path / "kept" / "mine.txt").write_text("user")
    assert main(argv[:4] + [str(tmp_path / "kept" / "sub" / "gel.toml")] + argv[5:]) == 2
    assert sorted(p.name for p in (tmp_path / "kept").iterdir()) == ["mine.txt"]
    monkeypatch.setattr(ownership, "atomic_write_json", real)
