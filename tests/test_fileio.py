"""fileio, outdir, staging: atomic writes under the umask, owned output folders, stale temporaries."""

import os
import stat
import subprocess
import sys
import time

import pytest

from tactileskin import fileio, outdir, staging
from tactileskin.fileio import OutputError


def _mode(p):
    return stat.S_IMODE(os.stat(p).st_mode)


def test_files_and_folders_follow_the_umask(tmp_path):
    old = os.umask(0o027)
    try:
        f = fileio.atomic_write_text(tmp_path / "a" / "b.txt", "x")
        assert _mode(f) == 0o640
        assert _mode(tmp_path / "a") == 0o750
        with staging.staged_dir(tmp_path / "case") as d:
            (d / "f").write_text("y")
        assert _mode(tmp_path / "case") == 0o750
    finally:
        os.umask(old)
    old = os.umask(0o022)
    try:
        assert _mode(fileio.atomic_write_text(tmp_path / "c.txt", "x")) == 0o644
    finally:
        os.umask(old)


def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("old")
    with pytest.raises(RuntimeError):
        with fileio.atomic_path(p) as tmp:
            tmp.write_text("half")
            raise RuntimeError("killed")
    assert p.read_text() == "old"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["r.csv"]


def test_strict_json_refuses_nan(tmp_path):
    with pytest.raises(OutputError, match="non-finite"):
        fileio.atomic_write_json(tmp_path / "x.json", {"a": float("nan")})
    assert not (tmp_path / "x.json").exists()


def test_claim_refuses_a_folder_of_user_files_and_keeps_them(tmp_path):
    d = tmp_path / "d"
    d.mkdir()
    (d / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="notes.txt"):
        outdir.claim_dir(d, "solve")
    assert (d / "notes.txt").read_text() == "mine"
    assert not (d / outdir.MARKER).exists()


def test_claim_accepts_new_empty_and_own_folders_only(tmp_path):
    outdir.claim_dir(tmp_path / "new", "solve")
    assert (tmp_path / "new" / outdir.MARKER).is_file()
    (tmp_path / "empty").mkdir()
    outdir.claim_dir(tmp_path / "empty", "solve")
    (tmp_path / "new" / "user.txt").write_text("later")  # our folder stays ours
    outdir.claim_dir(tmp_path / "new", "solve")
    with pytest.raises(OutputError):  # but not for another command's kind
        outdir.claim_dir(tmp_path / "new", "sweep")
    # no marker: a user's summary.json is not ours, however much it looks like a solve output
    user = tmp_path / "user"
    user.mkdir()
    (user / "summary.json").write_text("MY DATA")
    with pytest.raises(OutputError, match="summary.json"):
        outdir.claim_dir(user, "solve")
    assert (user / "summary.json").read_text() == "MY DATA" and not (user / outdir.MARKER).exists()


def test_claim_refuses_a_file_and_a_path_under_a_file(tmp_path):
    f = tmp_path / "f"
    f.write_text("x")
    with pytest.raises(OutputError, match="is a file"):
        outdir.claim_dir(f, "solve")
    with pytest.raises(OutputError, match=str(f)):
        outdir.claim_dir(f / "sub", "solve")


@pytest.mark.skipif(os.geteuid() == 0, reason="root ignores folder permissions")
def test_read_only_folder_is_a_one_line_error(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        with pytest.raises(OutputError, match="permission denied"):
            fileio.atomic_write_text(ro / "x.txt", "x")
    finally:
        ro.chmod(0o700)


def test_stale_temporaries_of_a_dead_writer_are_removed_live_ones_kept(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    stale = tmp_path / f".r.csv.tsk{dead}-abc.tmp"
    stale.write_text("half")
    stale_dir = tmp_path / f".case.tsk{dead}-xyz.partial"
    stale_dir.mkdir()
    live = tmp_path / f".r.csv.tsk{os.getpid()}-def.tmp"
    live.write_text("being written")
    user = tmp_path / ".hidden.tmp"
    user.write_text("user's")
    fileio.atomic_write_text(tmp_path / "r.csv", "new")
    assert not stale.exists() and not stale_dir.exists()
    assert live.exists() and user.exists()


def test_another_hosts_temporaries_are_kept_until_a_day_old(tmp_path):
    """A temporary of another host or PID namespace (a cluster node, a container on the same
    shared folder) names a PID that means nothing here: it was removed as a dead writer's while
    that run was writing into it."""
    ours = fileio.tmp_prefix(tmp_path / "r.csv")
    assert fileio.is_temporary(ours + "abc.tmp")
    other = "0" * 8 if fileio._host() != "0" * 8 else "1" * 8
    fresh = tmp_path / f".case.tsk1h{other}-xyz.partial"
    fresh.mkdir()
    old = tmp_path / f".r.csv.tsk1h{other}-abc.tmp"
    old.write_text("half")
    day = time.time() - fileio.FOREIGN_STALE_S - 60
    os.utime(old, (day, day))
    dead_here = tmp_path / f".r.csv.tsk{2 ** 22 + 7}h{fileio._host()}-def.tmp"  # beyond pid_max
    dead_here.write_text("half")
    fileio.clean_stale(tmp_path)
    assert fresh.exists() and not old.exists() and not dead_here.exists()


@pytest.mark.parametrize("err, cause", [(28, "no space left"), (13, "permission denied")])
def test_full_disk_and_denied_write_name_the_path_and_keep_the_old_file(tmp_path, monkeypatch, err, cause):
    p = tmp_path / "r.csv"
    p.write_text("old")

    def refuse(*a, **k):
        raise OSError(err, os.strerror(err))

    monkeypatch.setattr(os, "fsync", refuse)
    with pytest.raises(OutputError, match=cause) as e:
        fileio.atomic_write_text(p, "new")
    assert str(p) in str(e.value) and "\n" not in str(e.value)
    monkeypatch.undo()
    assert p.read_text() == "old"
    assert sorted(x.name for x in tmp_path.iterdir()) == ["r.csv"]


def test_a_temporary_with_its_own_suffix_is_also_cleaned(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    stale = tmp_path / f".m.vtu.tsk{dead}-k2j_9.vtu"
    stale.write_text("half")
    with fileio.atomic_path(tmp_path / "m.vtu", suffix=".vtu") as tmp:
        assert fileio._TMP_RE.match(tmp.name)
        tmp.write_text("whole")
    assert not stale.exists() and (tmp_path / "m.vtu").read_text() == "whole"
