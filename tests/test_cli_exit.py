"""cli.run, the console script: ends without Python's teardown, but after the exit handlers
and the streams' flush, with main's exit code."""

import subprocess
import sys

import pytest


def _run(args, extra=""):
    code = ("import atexit, sys\n"
            "atexit.register(lambda: print('exit handler ran', file=sys.stderr))\n"
            f"{extra}\n"
            f"sys.argv = ['tactileskin'] + {args!r}\n"
            "from tactileskin.cli import run\n"
            "run()\n")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)


def test_help_is_printed_whole_and_the_exit_handlers_run():
    r = _run(["--help"])
    assert r.returncode == 0
    assert "Usage: tactileskin" in r.stdout and "sweep" in r.stdout
    assert "exit handler ran" in r.stderr


@pytest.mark.parametrize("args, code", [(["sweep", "--thickness", "-1", "--out", "/nonexistent/x"], 2),
                                        (["no-such-command"], 2)])
def test_the_exit_code_is_mains(args, code):
    r = _run(args)
    assert r.returncode == code, r.stderr
    assert "exit handler ran" in r.stderr and "Traceback" not in r.stderr


def test_buffered_output_is_flushed_before_the_end():
    """A large stdout buffer (a pipe is block-buffered) must reach the reader whole."""
    r = _run(["--help"], extra="print('x' * 100000, end='')")
    assert r.stdout.startswith("x" * 100000) and "Usage: tactileskin" in r.stdout


def test_a_running_thread_gets_the_normal_exit_which_waits_for_it():
    extra = ("import threading, time\n"
             "def late():\n"
             "    time.sleep(0.5)\n"
             "    print('thread finished', file=sys.stderr)\n"
             "threading.Thread(target=late).start()")
    r = _run(["--help"], extra=extra)
    assert r.returncode == 0 and "thread finished" in r.stderr and "exit handler ran" in r.stderr


@pytest.mark.parametrize("fd", [1, 2])
def test_a_closed_standard_stream_is_not_a_failed_flush(fd):
    """`tactileskin ... >&-` (or 2>&-, a service without streams): Python starts with that
    sys.stdout / sys.stderr None and exits 0 after a successful run; run() counted the None
    stream's flush (AttributeError) as a failed one and exited 120."""
    import os

    code = "import sys\nsys.argv = ['tactileskin', '--version']\nfrom tactileskin.cli import run\nrun()\n"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                       preexec_fn=lambda: os.close(fd))
    assert r.returncode == 0, (r.returncode, r.stderr)
