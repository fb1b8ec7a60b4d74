"""Safe file output: every file and folder the toolkit writes goes through here.

Rules (issue #12, "never destroy user data"):
- A file is written to a temporary sibling and renamed over its target (atomic on one
  filesystem), so a crash leaves either the old file or the new one, never a partial one.
- Files get mode 0o666 and folders 0o777, less the user's umask (mkstemp and mkdtemp
  would leave 0600 / 0700).
- A temporary name carries the writer's pid (`.NAME.tsk<pid>-XXXX.tmp`), so that the next
  run can remove the leftovers of a killed one (`clean_stale`) without touching the files
  of a writer that is still alive.
- An output folder is written into only if it is new, empty, or marked as the toolkit's
  (`outdir.claim_dir` writes the marker `.tactileskin`); a folder holding files we did not write
  is refused, never emptied.
- A single output file of the CLI replaces an existing file only if the toolkit wrote it and
  nobody changed it since (`claim_file`, `record_file`: the folder's `.tactileskin-files.json`).
  The same record lists the files of a result in a marked output folder (`staging.staged_files`): a
  rerun replaces or removes only those, so a user's file stays whatever its name, and a file
  of ours the user edited is refused, not overwritten.
- An OSError becomes an `OutputError` that names the path and the cause in one line.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import json
import logging
import os
import re
import shutil
import tempfile
import time
from pathlib import Path
from typing import Iterator

from tactileskin.errors import TactileSkinError

log = logging.getLogger(__name__)

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


# --- single output files ------------------------------------------------------------------

# Beside single files the CLI writes (a deck, a mesh, a calibration, a plot), the folder's
# record of them: name -> sha256 of the contents written. An existing file is replaced only
# if the record lists it with its current contents, i.e. the toolkit wrote it and nobody has
# changed it since; a user's file of the same name (or the command's own input) is refused.
OWNED_FILES = ".tactileskin-files.json"


def file_sha256(path: Path) -> str:
    import hashlib

    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_record(folder: Path) -> dict:
    try:
        rec = json.loads((folder / OWNED_FILES).read_text())
        return rec if isinstance(rec, dict) else {}
    except (OSError, ValueError):
        return {}


def entry_digests(entry) -> list:
    """The digests of a record entry (a digest, a list of them, or none)."""
    return list(entry) if isinstance(entry, list) else [entry] if isinstance(entry, str) else []


def is_recorded(entry, digest: str) -> bool:
    """Whether a record entry (a digest, or [old, new] while a result is being moved in) has
    `digest`."""
    return digest == entry or (isinstance(entry, list) and digest in entry)


def claim_file(path, what: str = "--out") -> Path:
    """Refuse `path` as an output file unless it is new or a file the toolkit wrote there and
    nobody changed since (OWNED_FILES); call before the work, `record_file` after writing."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(path, f"{what} must be a file name, and this is a folder")
    if path.exists() or path.is_symlink():
        try:
            ours = (not path.is_symlink() and path.is_file()
                    and is_recorded(read_record(path.parent).get(path.name), file_sha256(path)))
        except OSError:
            ours = False
        if not ours:
            raise OutputError(path, "the file exists and tactileskin did not write it (or it was changed since); "
                                    f"refusing to overwrite it: give {what} a new file name")
    return path


def has_any_record(folder) -> bool:
    """Whether `folder` has an OWNED_FILES record (this version's writes leave one)."""
    return (Path(folder) / OWNED_FILES).exists()


def record_file(path) -> None:
    """Note in the folder's OWNED_FILES that the toolkit wrote `path` as it is now."""
    path = Path(path)
    with os_errors(path):
        digest = file_sha256(path)
    with record_lock(path.parent):  # two writers into one folder must not lose an entry
        rec = {k: v for k, v in read_record(path.parent).items() if (path.parent / k).is_file()}
        rec[path.name] = digest
        atomic_write_json(path.parent / OWNED_FILES, rec)


# The record is replaced by a rename, so it cannot be locked itself: a lock file beside it,
# left in place (removing it would race with the next writer's open).
RECORD_LOCK = ".tactileskin-files.lock"


@contextlib.contextmanager
def record_lock(folder: Path) -> Iterator[None]:
    """Hold an exclusive flock on the folder's RECORD_LOCK around a read-modify-write of its
    OWNED_FILES (waits for another writer into the same folder). Without flock (no fcntl, a
    file system without locks) there is no lock, as in the cache."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    # opened for writing (NFS emulates flock by byte-range locks, which need it), else read-only:
    # a group-shared folder's lock file (0644 under umask 022) must open for the other users too
    with os_errors(folder / OWNED_FILES, own_name=False):
        try:
            fd = os.open(folder / RECORD_LOCK, os.O_RDWR | os.O_CREAT, 0o666)  # open applies the umask
        except PermissionError:
            fd = os.open(folder / RECORD_LOCK, os.O_RDONLY | os.O_CREAT, 0o666)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError as e:
            if e.errno not in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL, errno.EBADF):
                with os_errors(folder / OWNED_FILES, own_name=False):
                    raise
            log.warning("no file locks in %s (%s): its record is written without one", folder, e.strerror)
        yield
    finally:
        os.close(fd)  # releases the lock


def fix_tree_modes(root) -> None:
    """Give files written by third-party code inside a staging folder normal permissions."""
    fm, dm = file_mode(), dir_mode()
    for dirpath, dirnames, filenames in os.walk(root):
        os.chmod(dirpath, dm)
        for f in filenames:
            p = os.path.join(dirpath, f)
            if not os.path.islink(p):
                os.chmod(p, fm)
