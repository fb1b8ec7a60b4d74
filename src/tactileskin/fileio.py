"""Safe file output: every file and folder the toolkit writes goes through here.

Rules (issue #12, "never destroy user data"):
- A file is written to a temporary sibling and renamed over its target (atomic on one
  filesystem), so a crash leaves either the old file or the new one, never a partial one.
- Files get mode 0o666 and folders 0o777, less the user's umask (mkstemp and mkdtemp
  would leave 0600 / 0700).
- A temporary name carries the writer's pid (`.NAME.tsk<pid>-XXXX.tmp`), so that the next
  run can remove the leftovers of a killed one (`clean_stale`) without touching the files
  of a writer that is still alive.
- An OSError becomes an `OutputError` that names the path and the cause in one line.

Which existing files a write may replace is decided beside this module, which writes
wherever it is told: the output folder's marker (outdir), the record of the files the
toolkit wrote (ownership), and the moves of a whole result into place (staging).
"""

from __future__ import annotations

import contextlib
import errno
import functools
import json
import os
import re
import shutil
import tempfile
import time
from pathlib import Path
from typing import Iterator

from tactileskin.errors import TactileSkinError

# `.NAME.tskPID[hHOST]-XXXX[.suffix]`: HOST names the writer's host and PID namespace (`_host`)
_TMP_RE = re.compile(r"^\..+\.tsk(\d+)(?:h([0-9a-f]{8}))?-[A-Za-z0-9_]+(\.[A-Za-z0-9]+)?$")  # any suffix
_TMP_NAME_RE = re.compile(r"^\.(.+)\.tsk\d+(?:h[0-9a-f]{8})?-[A-Za-z0-9_]+(\.[A-Za-z0-9]+)?$")  # group 1: the target
# a temporary of another host or PID namespace (a cluster node or a container writing to the
# same shared folder) cannot be judged by its PID: it is stale only this long after its last change
FOREIGN_STALE_S = 24 * 3600.0
# the name staged_files' staging folders are made from (`.tactileskin-staging.tskPID-X.partial`):
# it stands for the output folder itself, never for a file in it (see user_path)
STAGING = "tactileskin-staging"


class OutputError(TactileSkinError):
    """An output could not be written (permissions, no space, a file in the way, ...)."""

    def __init__(self, path, cause: str):
        self.path = user_path(path)
        super().__init__(f"cannot write {self.path}: {cause}")


def user_path(path) -> str:
    """`path` as the user knows it: our temporaries in it named by their targets, and the
    staging folders of staged_files (they stand for the output folder) left out. A write that
    fails inside staging then names the destination, not `.x.tsk123-abc.partial/...`."""
    parts = []
    for part in Path(path).parts:
        m = _TMP_NAME_RE.match(part)
        if m is None:
            parts.append(part)
        elif m.group(1) != STAGING:
            parts.append(m.group(1))
    return str(Path(*parts)) if parts else str(path)


def umask() -> int:
    """The process umask, read without changing it where the OS allows."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    old = os.umask(0o022)  # not thread-safe, hence the /proc read above
    os.umask(old)
    return old


def file_mode() -> int:
    return 0o666 & ~umask()


def dir_mode() -> int:
    return 0o777 & ~umask()


def _cause(e: OSError) -> str:
    if e.errno == errno.ENOSPC:
        return "no space left on the device"
    if e.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return "permission denied (read-only folder?)"
    if e.errno == errno.ENOTDIR:
        return "a part of the path is a file, not a folder"
    if e.errno == errno.EISDIR:
        return "it is a folder"
    if e.errno == errno.EEXIST:
        return "a file is in the way where a folder is needed"
    return e.strerror or type(e).__name__


@contextlib.contextmanager
def os_errors(path, *, own_name: bool = True) -> Iterator[None]:
    """Turn an OSError raised inside into an OutputError naming `path`, or with own_name the
    error's own file if it has one (not for our temporaries: the user gave `path`)."""
    try:
        yield
    except OutputError:
        raise
    except OSError as e:
        named = e.filename if own_name and e.filename and not is_temporary(Path(str(e.filename)).name) else path
        raise OutputError(named, _cause(e)) from e


def tmp_prefix(path: Path) -> str:
    # the name cut short: a name near the file system's 255-byte limit is valid, its
    # temporary (about 35 characters longer) would not be
    return f".{path.name.encode()[:64].decode('utf-8', 'ignore')}.tsk{os.getpid()}h{_host()}-"


@functools.lru_cache(maxsize=1)
def _host() -> str:
    """8 hex digits naming this host and PID namespace: a PID means a process only there."""
    import hashlib
    import socket

    try:
        ns = os.stat("/proc/self/ns/pid").st_ino
    except OSError:
        ns = 0
    return hashlib.sha256(f"{socket.gethostname()}\0{ns}".encode()).hexdigest()[:8]


def is_temporary(name: str) -> bool:
    """Whether a file name is one of our temporaries (`.NAME.tskPID-XXXX.tmp`)."""
    return bool(_TMP_RE.match(name))


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def clean_stale(folder) -> list[Path]:
    """Remove our temporary files/folders in `folder` whose writer process is gone."""
    folder = Path(folder)
    removed = []
    try:
        entries = list(folder.iterdir())
    except OSError:
        return removed
    for p in entries:
        m = _TMP_RE.match(p.name)
        if m and m.group(2) not in (None, _host()):  # another host's: its PID says nothing here
            try:
                stale = time.time() - p.lstat().st_mtime > FOREIGN_STALE_S
            except OSError:
                continue
        else:
            stale = m is not None and not _pid_alive(int(m.group(1)))
        if stale:
            with contextlib.suppress(OSError):
                if p.is_dir() and not p.is_symlink():
                    shutil.rmtree(p)
                else:
                    p.unlink()
                removed.append(p)
    return removed


def make_dirs(path) -> Path:
    """mkdir -p under the umask; a file in the way is an OutputError."""
    path = Path(path)
    with os_errors(path):
        path.mkdir(parents=True, exist_ok=True)
    return path


@contextlib.contextmanager
def atomic_path(path, *, suffix: str = ".tmp") -> Iterator[Path]:
    """Yield a temporary path beside `path`; on success it is renamed over `path` with
    normal permissions. For writers that want a file name (meshio, savefig, OCP)."""
    path = Path(path)
    make_dirs(path.parent)
    clean_stale(path.parent)
    with os_errors(path, own_name=False):
        fd, tmp = tempfile.mkstemp(prefix=tmp_prefix(path), suffix=suffix, dir=path.parent)
        os.close(fd)
    tmp = Path(tmp)
    try:
        yield tmp
        with os_errors(path, own_name=False):
            os.chmod(tmp, file_mode())
            os.replace(tmp, path)
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()


def atomic_write_bytes(path, data: bytes) -> Path:
    path = Path(path)
    with atomic_path(path) as tmp, os_errors(path, own_name=False):
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return path


def atomic_write_text(path, text: str) -> Path:
    """Write `text` (UTF-8, newlines as given) to `path` atomically."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path, obj) -> Path:
    """Strict JSON (NaN and infinity are refused, not written as invalid tokens)."""
    try:
        text = json.dumps(obj, indent=2, allow_nan=False)
    except ValueError as e:
        raise OutputError(path, f"non-finite number in the data ({e})") from None
    return atomic_write_text(path, text + "\n")


def is_open_file(fd: int, path) -> bool:
    """Whether `path` still names the file open as `fd`. A lock taken on a lock file that was
    removed (a failed run removing its new folder) meanwhile locks nothing the next run opens:
    the taker retries on the path's file. False only if the path is gone or another file."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return False
    except OSError:  # cannot tell: as before the check
        return True
    f = os.fstat(fd)
    return (st.st_dev, st.st_ino) == (f.st_dev, f.st_ino)


def file_sha256(path: Path) -> str:
    """The hex SHA-256 of a file's bytes: the digests of the record of written files
    (ownership) and of the cache's entries."""
    import hashlib

    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_unchanged(read, path, digest: str, digest_of, name: str, valid: str):
    """read(path) for a memo keyed by `digest`, the file's digest (digest_of) taken before the
    read; refused (ParameterError naming `name`) if the file no longer has it afterwards: an
    edit in between would keep another file's contents under this digest, and so under its
    cache key, for the life of the process."""
    from tactileskin.errors import ParameterError

    changed = "it changed while it was read; run again once it is written"
    try:
        out = read(path)
    except Exception as e:  # a half-written file fails to parse (any error): say what happened
        if _digest_or_none(digest_of, path) != digest:
            raise ParameterError(name, str(path), valid, changed) from e
        raise
    if digest_of(path) != digest:
        raise ParameterError(name, str(path), valid, changed)
    return out


def _digest_or_none(digest_of, path):
    """digest_of(path), or None if the file cannot be read now (removed meanwhile: changed too)."""
    from tactileskin.errors import ParameterError

    try:
        return digest_of(path)
    except (OSError, ParameterError):
        return None


def fix_tree_modes(root) -> None:
    """Give files written by third-party code inside a staging folder normal permissions."""
    fm, dm = file_mode(), dir_mode()
    for dirpath, dirnames, filenames in os.walk(root):
        os.chmod(dirpath, dm)
        for f in filenames:
            p = os.path.join(dirpath, f)
            if not os.path.islink(p):
                os.chmod(p, fm)
