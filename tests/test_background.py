"""report.background: drawing in a fork()ed child, and drawing here whenever the child fails."""

import logging
import os
import sys
import time
from pathlib import Path

import pytest

from tactileskin import threads
from tactileskin.report import background
from tactileskin.report.background import Background

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork() is Linux-only here")


@pytest.fixture(autouse=True)
def no_other_threads(monkeypatch):
    monkeypatch.setattr(threads, "other_threads", list)  # pytest-xdist's own threads


def write_pids(folder):
    """Two files, the second first in name order: the order fn returns must be kept."""
    b = Path(folder) / "b.txt"
    a = Path(folder) / "a.txt"
    b.write_text(str(os.getpid()))
    a.write_text("a")
    return [b, a]


def test_runs_in_a_child_and_keeps_the_order():
    with Background(write_pids) as bg:
        assert bg.pid is not None
        folder = bg.folder
        files = bg.files()
    assert [n for n, _ in files] == ["b.txt", "a.txt"]
    assert not folder.exists()  # the child's private folder is removed
    assert int(files[0][1]) != os.getpid()


def test_without_fork_it_draws_here(monkeypatch):
    monkeypatch.setattr(threads, "other_threads", lambda: ["a user's thread"])
    with Background(write_pids) as bg:
        assert bg.pid is None
        files = bg.files()
    assert int(files[0][1]) == os.getpid()


def test_a_failing_child_is_redone_here():
    parent = os.getpid()

    def fails_in_child(folder):
        if os.getpid() != parent:
            raise RuntimeError("child broke")
        return write_pids(folder)

    with Background(fails_in_child) as bg:
        files = bg.files()
    assert int(files[0][1]) == parent


def test_a_child_that_dies_is_redone_here():
    parent = os.getpid()

    def dies(folder):
        if os.getpid() != parent:
            os._exit(3)
        return write_pids(folder)

    with Background(dies) as bg:
        files = bg.files()
    assert int(files[0][1]) == parent


def test_a_hung_child_is_killed_and_redone_here(monkeypatch):
    monkeypatch.setattr(background, "GRACE_S", 0.5)
    parent = os.getpid()

    def hangs(folder):
        if os.getpid() != parent:
            time.sleep(60)
        return write_pids(folder)

    t0 = time.perf_counter()
    with Background(hangs) as bg:
        pid = bg.pid
        files = bg.files()
    assert time.perf_counter() - t0 < 30
    assert int(files[0][1]) == parent
    with pytest.raises(ChildProcessError):  # reaped: no zombie left
        os.waitpid(pid, os.WNOHANG)


def test_leaving_the_block_early_kills_the_child():
    parent = os.getpid()

    def slow(folder):
        if os.getpid() != parent:
            time.sleep(60)
        return []

    with pytest.raises(KeyboardInterrupt):
        with Background(slow) as bg:
            pid, folder = bg.pid, bg.folder
            raise KeyboardInterrupt
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)
    assert not folder.exists()


def test_the_childs_log_records_reach_this_process(caplog):
    def logs(folder):
        logging.getLogger("tactileskin.report.figures").warning("drawn in %d", os.getpid())
        return write_pids(folder)

    with caplog.at_level(logging.WARNING):
        with Background(logs) as bg:
            files = bg.files()
    msgs = [r.getMessage() for r in caplog.records if r.name == "tactileskin.report.figures"]
    assert msgs == [f"drawn in {int(files[0][1])}"]
    assert int(files[0][1]) != os.getpid()


def test_the_childs_warnings_reach_this_process_as_records(caplog):
    import warnings

    def warns(folder):
        warnings.warn(f"odd axis in {os.getpid()}", UserWarning)
        return write_pids(folder)

    with caplog.at_level(logging.WARNING):
        with Background(warns) as bg:
            files = bg.files()
    assert int(files[0][1]) != os.getpid()
    assert any(f"odd axis in {int(files[0][1])}" in r.getMessage() for r in caplog.records if r.name == "py.warnings")


def test_a_signal_just_after_the_fork_never_runs_this_process_code_in_the_child(tmp_path):
    """Ctrl-C reaching the child between fork() and its own handlers raised KeyboardInterrupt
    in the child, which then unwound through its parent's code (the sweep's `finally` blocks,
    main's 'interrupted', the exit handlers): signals are held across fork()."""
    import subprocess

    script = tmp_path / "race.py"
    script.write_text(
        "import os, signal\n"
        "from tactileskin import threads\n"
        "threads.other_threads = list\n"
        "from tactileskin.report import background\n"
        "from tactileskin.report.background import Background\n"
        "real_fork = os.fork\n"
        "def fork():\n"
        "    pid = real_fork()\n"
        "    if pid == 0:\n"
        "        os.kill(os.getpid(), signal.SIGINT)\n"
        "        for _ in range(1000):\n"
        "            pass\n"
        "    return pid\n"
        "background.os.fork = fork\n"
        "def draw(folder):\n"
        "    p = os.path.join(folder, 'a.txt')\n"
        "    open(p, 'w').write(str(os.getpid()))\n"
        "    return [p]\n"
        "me = os.getpid()\n"
        "try:\n"
        "    with Background(draw) as bg:\n"
        "        files = bg.files()\n"
        "    print('drawn in', 'parent' if int(files[0][1]) == me else 'child', flush=True)\n"
        "except KeyboardInterrupt:\n"
        "    print('KeyboardInterrupt in', 'parent' if os.getpid() == me else 'child', flush=True)\n")
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120,
                       env={**os.environ, "PYTHONPATH": str(Path(background.__file__).parents[2])})
    assert r.stdout.splitlines() == ["drawn in child"], r.stdout + r.stderr


def test_a_failed_fork_draws_here(monkeypatch, tmp_path):
    """fork() refused (EAGAIN: the process limit) is one more case of drawing here, not an
    error of the sweep, and leaves no private folder behind."""
    import tempfile

    def refuse():
        raise BlockingIOError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(background.os, "fork", refuse)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    with Background(write_pids) as bg:
        assert bg.pid is None
        files = bg.files()
    assert int(files[0][1]) == os.getpid()
    assert list(tmp_path.iterdir()) == []


def test_a_failed_childs_log_records_are_not_repeated_by_the_drawing_here(caplog):
    """A child whose fn logged and then raised is redone here, which logs the same again: the
    child's records were re-emitted as well, every warning of that figure shown twice."""
    from tactileskin.errors import TactileSkinError

    def logs_and_fails(folder):
        logging.getLogger("tactileskin.report.figures").warning("odd axis")
        raise TactileSkinError("figure broke")

    with caplog.at_level(logging.WARNING):
        with pytest.raises(TactileSkinError, match="figure broke"):
            with Background(logs_and_fails) as bg:
                assert bg.pid is not None
                bg.files()
    assert [r.getMessage() for r in caplog.records if r.name == "tactileskin.report.figures"] == ["odd axis"]


def test_drawing_here_writes_into_the_callers_folder_not_a_temporary_one(monkeypatch, tmp_path):
    """With `here` (the sweep's output folder) fn run in this process writes there, as drawing
    in one process did: a temporary folder that cannot be made or written (a full or read-only
    /tmp) failed the sweep, which had never needed it, and an error named a file in a
    temporary folder already removed."""
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "no-such-dir"))
    out = tmp_path / "out"
    out.mkdir()
    with Background(write_pids, here=out) as bg:
        assert bg.pid is None  # no private folder: no child
        files = bg.files()
    assert [n for n, _ in files] == ["b.txt", "a.txt"] and int(files[0][1]) == os.getpid()

    def refused(folder):
        raise PermissionError(13, "Permission denied", str(Path(folder) / "fig.png"))

    monkeypatch.setattr(threads, "other_threads", lambda: ["a user's thread"])
    with pytest.raises(PermissionError) as e:
        with Background(refused, here=out) as bg:
            bg.files()
    assert e.value.filename == str(out / "fig.png")


def _gone(pid: int) -> bool:
    """The process has ended (a zombie counts: an init that does not reap leaves it)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except FileNotFoundError:
        return True


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's")
@pytest.mark.parametrize("late", [False, True])
def test_the_child_ends_with_its_parent_and_removes_its_folder(tmp_path, late):
    """A sweep SIGKILLed while its figure child drew left the child drawing on (its share's
    time, seconds), holding the output folder's lock descriptor, and its /tmp folder for good.
    The child now ends with its parent and removes the folder; `late`: the parent dies before
    the child has asked to (the child finds it reparented)."""
    import signal
    import subprocess

    script = tmp_path / "orphan.py"
    script.write_text(
        "import os, sys, time\n"
        "from tactileskin import threads\n"
        "threads.other_threads = list\n"
        "from tactileskin.report import background\n"
        "from tactileskin.report.background import Background\n"
        "parent = os.getpid()\n"
        "real_fork = os.fork\n"
        "def fork():\n"
        "    pid = real_fork()\n"
        f"    if pid == 0 and {late}:\n"
        "        while os.getppid() == parent:\n"
        "            time.sleep(0.01)\n"
        "    return pid\n"
        "background.os.fork = fork\n"
        "def draw(folder):\n"
        "    p = os.path.join(folder, 'a.txt')\n"
        "    open(p, 'w').write('x')\n"
        "    for _ in range(3000):\n"
        "        time.sleep(0.01)\n"
        "    return [p]\n"
        "with Background(draw) as bg:\n"
        "    print(bg.pid, bg.folder, flush=True)\n"
        "    time.sleep(120)\n")
    p = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True,
                         env={**os.environ, "PYTHONPATH": str(Path(background.__file__).parents[2])})
    pid = None
    try:
        pid, folder = p.stdout.readline().split()
        pid = int(pid)
        if not late:
            deadline = time.monotonic() + 30
            while not (Path(folder) / "a.txt").exists() and time.monotonic() < deadline:
                time.sleep(0.01)  # the child is drawing
        p.send_signal(signal.SIGKILL)
        p.wait(timeout=30)
        deadline = time.monotonic() + 20  # the child draws for 30 s: well apart under load
        while not (_gone(pid) and not Path(folder).exists()) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert _gone(pid), "the child outlived its parent"
        assert not Path(folder).exists(), "the child's folder outlived it"
    finally:
        p.kill()
        p.wait()
        if pid is not None and not _gone(pid):
            os.kill(pid, signal.SIGKILL)


@pytest.mark.parametrize("broken", ["no ctypes", "no prctl"])
def test_a_python_without_ctypes_or_prctl_still_draws_in_the_child(monkeypatch, broken):
    """The child's PR_SET_PDEATHSIG is a nicety: a Python built without _ctypes (import
    ctypes: ImportError) ended the child before drawing (exit 1, 'no answer'), every figure
    drawn here instead; it draws there, as without prctl."""
    if broken == "no ctypes":
        monkeypatch.setitem(sys.modules, "ctypes", None)  # import ctypes: ImportError
    else:
        import ctypes

        monkeypatch.setattr(ctypes, "CDLL", lambda *a, **k: object())  # no prctl: AttributeError
    with Background(write_pids) as bg:
        files = bg.files()
    assert int(files[0][1]) != os.getpid()
