"""A second pair of hands for drawing: `Background(fn)` runs fn(folder) in a fork()ed child
while this process goes on, and `files()` returns the (name, bytes) of the files fn wrote
into its private folder (fn returns their paths). The sweep draws half its figures there,
half here (2 cores: the figures and renders of the 18-case preview 2.05 -> 1.09 s wall, idle;
benchmarks/results/figure_split.md).

The child writes nothing the user sees: only a private temporary folder, which this process
removes. Whatever goes wrong there (no fork() here, the child crashed, was killed or hung,
its bytes did not arrive) fn runs here instead, so results and errors are those of drawing
here. Log records the child made are handed to this process's loggers (a child writing to
the terminal could meet a lock held by the progress bar's thread at the fork)."""

from __future__ import annotations

import logging
import os
import pickle
import select
import shutil
import signal
import sys
import tempfile
import threading
import time
from pathlib import Path

log = logging.getLogger(__name__)

# how long to wait for the child beyond the time this process spent on its own share; a
# child past it is killed and its share drawn here (a hang costs that much, never the result)
GRACE_S = 60.0


def can_fork() -> bool:
    """fork() is safe here: Linux, and no thread of this process runs code of its own
    (threads.other_threads: a lock it holds as fork() copies the process stays held)."""
    from tactileskin.threads import other_threads

    # Background._fork sets Python handlers of SIGINT and SIGTERM: the main thread's to set,
    # and to put back (getsignal None: a handler not set from Python, which cannot be)
    return (sys.platform.startswith("linux") and threading.current_thread() is threading.main_thread()
            and all(signal.getsignal(s) is not None for s in (signal.SIGINT, signal.SIGTERM))
            and not other_threads())


def _read_files(paths) -> list[tuple[str, bytes]]:
    return [(Path(p).name, Path(p).read_bytes()) for p in paths]


class _Keep(logging.Handler):
    """Keeps the child's log records, made picklable (message formatted, no traceback object)."""

    def __init__(self) -> None:
        super().__init__()
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        record.msg, record.args = record.getMessage(), None
        record.exc_info, record.exc_text, record.stack_info = None, None, None
        self.records.append(record)


_PR_SET_PDEATHSIG = 1  # linux/prctl.h


def _end_with(parent: int, folder: Path) -> None:
    """End this child, its folder removed, when `parent` ends: a parent SIGKILLed mid-sweep
    left it drawing on (seconds), holding the output lock's descriptor, and its folder in /tmp
    for good. The kernel sends SIGTERM at the parent's death (PR_SET_PDEATHSIG); a parent gone
    before that was asked shows as another parent pid."""
    def end(signum, frame):
        shutil.rmtree(folder, ignore_errors=True)
        os._exit(1)

    signal.signal(signal.SIGTERM, end)
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
    except (ImportError, OSError, AttributeError):  # no ctypes or prctl: the child ends when its share is drawn
        pass
    if os.getppid() != parent:
        end(None, None)


def _in_child(fn, folder: Path, fd: int, other_end: int, parent: int) -> None:
    """Run fn(folder), send ("ok", files, records) or ("error", text, records), and end the
    process without its parent's exit handlers (os._exit: they close the parent's cluster,
    release its locks)."""
    code = 1
    try:
        os.close(other_end)
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
        _end_with(parent, folder)  # SIGTERM too ends the child, its folder removed
        # new file objects on the standard streams: the ones copied may be the progress bar's
        # proxies, or hold a lock another thread had taken as the process was copied
        sys.stdout = open(1, "w", closefd=False)  # noqa: SIM115 - for the child's short life
        sys.stderr = open(2, "w", closefd=False)  # noqa: SIM115
        keep = _Keep()
        root = logging.getLogger()
        root.handlers = [keep]
        for lg in list(logging.Logger.manager.loggerDict.values()):
            if isinstance(lg, logging.Logger):
                lg.handlers = []
        logging.captureWarnings(True)  # a warning too reaches the parent (as a py.warnings record)
        try:
            payload = ("ok", _read_files(fn(folder)), keep.records)
        except BaseException as e:  # noqa: BLE001 - reported to the parent, which draws again
            payload = ("error", f"{type(e).__name__}: {e}", keep.records)
        data = pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL)
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
        code = 0
    finally:
        os._exit(code)


class Background:
    """`with Background(fn) as bg: ...; files = bg.files()`: fn(folder) drawn in a child, or
    here when files() finds the child's work missing, into `here` (the caller's output folder:
    files and errors as drawing in one process) or else a private temporary folder. Leaving
    the block kills a child not collected (an error or Ctrl-C here) and removes its folder."""

    def __init__(self, fn, here: Path | None = None) -> None:
        self.fn = fn
        self.here = here
        self.pid: int | None = None
        self.fd: int | None = None
        self.folder: Path | None = None
        self.started = time.perf_counter()

    def __enter__(self) -> "Background":
        if can_fork():
            try:
                self._fork()
            except OSError as e:  # no folder, no pipe or fork() refused (EAGAIN): draw here
                log.debug("no second process for drawing (%s); drawing here", e)
            except BaseException:  # Ctrl-C as the child started: no `with` block to end it
                self._end_child()
                raise
            finally:
                if self.pid is None:  # no child: its folder is not wanted
                    self._end_child()
        self.started = time.perf_counter()
        return self

    def _fork(self) -> None:
        self.folder = Path(tempfile.mkdtemp(prefix="tactileskin-draw-"))
        r, w = os.pipe()
        # Ctrl-C / SIGTERM only noted across fork() and the child's start: a handler raising in
        # the child before _in_child set its own unwound through this process's code there, and
        # one raising here before self.pid was set left the child unended (masking the signals
        # is not enough: another thread takes them and this one runs the handler)
        held: list[int] = []
        previous = {s: signal.signal(s, lambda signum, frame: held.append(signum))
                    for s in (signal.SIGINT, signal.SIGTERM)}
        parent = os.getpid()
        try:
            try:
                pid = os.fork()
            except OSError:
                os.close(r)
                os.close(w)
                raise
            if pid == 0:
                _in_child(self.fn, self.folder, w, r, parent)
            os.close(w)
            self.pid, self.fd = pid, r
        finally:
            for s, h in previous.items():
                signal.signal(s, h)
        for s in held[:1]:
            signal.raise_signal(s)  # now, with this process's handlers (and its child known)

    def _receive(self, deadline: float) -> bytes | None:
        chunks = []
        while True:
            left = deadline - time.perf_counter()
            if left <= 0 or not select.select([self.fd], [], [], left)[0]:
                return None
            chunk = os.read(self.fd, 1 << 20)
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)

    def files(self) -> list[tuple[str, bytes]]:
        """The (name, bytes) of the files fn returned, in its order: the child's, or fn's run here."""
        if self.pid is not None:
            data = self._receive(time.perf_counter() + GRACE_S + (time.perf_counter() - self.started))
            self._end_child()
            try:
                status, value, records = pickle.loads(data) if data else ("error", "no answer", [])
            except Exception as e:  # noqa: BLE001 - a cut message: draw here
                status, value, records = "error", f"unreadable answer ({e})", []
            if status == "ok":
                for rec in records:
                    logging.getLogger(rec.name).handle(rec)
                return value
            # a failed child's records are not handed on: fn, run again here, logs its own
            log.debug("drawing in a second process failed (%s); drawing here", value)
        if self.here is not None:
            return _read_files(self.fn(self.here))
        folder = Path(tempfile.mkdtemp(prefix="tactileskin-draw-"))
        try:
            return _read_files(self.fn(folder))
        finally:
            shutil.rmtree(folder, ignore_errors=True)

    def _reap(self) -> None:
        try:
            os.kill(self.pid, signal.SIGKILL)  # done already (os._exit) or to be given up
        except ProcessLookupError:
            pass
        os.waitpid(self.pid, 0)
        os.close(self.fd)
        self.pid = self.fd = None

    def _end_child(self) -> None:
        try:
            if self.pid is not None:
                self._reap()
        finally:  # a second Ctrl-C while the child is ended still removes its folder
            if self.folder is not None:
                shutil.rmtree(self.folder, ignore_errors=True)
                self.folder = None

    def __exit__(self, *exc) -> None:
        self._end_child()
