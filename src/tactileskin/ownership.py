"""The record of the files the toolkit wrote into a folder (`.tactileskin-files.json`), kept
so that a rerun replaces its own files and never a user's.

A single output file of the CLI replaces an existing file only if the record lists it with
its current contents (`claim_file` before the work, `written_file` around the write); staging keeps
the record of a result's files in a marked output folder (outdir). Every read-modify-write
of the record holds an flock on `.tactileskin-files.lock` beside it (`record_lock`).
"""

from __future__ import annotations

import contextlib
import errno
import json
import logging
import os
from pathlib import Path
from typing import Iterator

from tactileskin.fileio import OutputError, atomic_path, atomic_write_json, file_sha256, is_open_file, os_errors

log = logging.getLogger(__name__)

# Beside single files the CLI writes (a deck, a mesh, a calibration, a plot), the folder's
# record of them: name -> sha256 of the contents written. An existing file is replaced only
# if the record lists it with its current contents, i.e. the toolkit wrote it and nobody has
# changed it since; a user's file of the same name (or the command's own input) is refused.
OWNED_FILES = ".tactileskin-files.json"


def read_record(folder: Path) -> dict:
    """The folder's OWNED_FILES (name -> entry); {} without one or for an unreadable one."""
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
    if path.name in (OWNED_FILES, RECORD_LOCK):  # the write's own record replaced the output
        raise OutputError(path, f"that is tactileskin's record of the folder's files: give {what} another file name")
    if path.exists() or path.is_symlink():
        try:
            ours = (not path.is_symlink() and path.is_file()
                    and is_recorded(read_record(path.parent).get(path.name), file_sha256(path)))
        except OSError:
            ours = False
        if not ours:
            raise OutputError(path, "the file exists and tactileskin did not write it (or it was changed since); "
                                    f"refusing to overwrite it: give {what} a new file name")
    check_writable(path)
    return path


def check_writable(path: Path) -> None:
    """OutputError now if the file `path` could not be written where it is named (a file in
    the way of its folder, a folder where no file can be made, a linked record lock): before
    the work, not after it (a mesh, a fit). Nothing is left behind."""
    import tempfile

    from tactileskin.fileio import tmp_prefix

    folder = path.parent
    # the folder, or the deepest one of its path that exists (written_file makes the rest)
    there = next((d for d in [folder, *folder.parents] if d.exists() or d.is_symlink()), Path("."))
    if there.is_symlink() and not there.exists():
        raise OutputError(there, "it is a broken symbolic link")
    if not there.is_dir():
        raise OutputError(there, "a part of the path is a file, not a folder")
    if there == folder:
        check_lock_name(folder, RECORD_LOCK)
    with os_errors(there, own_name=False):
        fd, probe = tempfile.mkstemp(prefix=tmp_prefix(path), dir=there)
        try:
            os.close(fd)
        finally:  # removed even on a Ctrl-C here: the user's folder keeps no trace
            os.unlink(probe)


def check_lock_name(folder: Path, name: str) -> None:
    """OutputError now if `folder / name`, a lock file the run will take, is a symbolic link
    (open_lock_file refuses it when taking the lock: after the work) or not a file."""
    lock = folder / name
    if lock.is_symlink():
        raise OutputError(lock, LINKED_LOCK)
    if lock.exists() and not lock.is_file():
        raise OutputError(lock, "it is not a file (tactileskin's lock file of that folder): remove it")


def record_file(path) -> None:
    """Note in the folder's OWNED_FILES that the toolkit wrote `path` as it is now."""
    path = Path(path)
    with os_errors(path):
        digest = file_sha256(path)
    _set_entry(path, lambda old: digest)


def _set_entry(path: Path, entry) -> None:
    """Set `path`'s entry in its folder's OWNED_FILES to entry(the current one)."""
    with record_lock(path.parent):  # two writers into one folder must not lose an entry
        rec = {k: v for k, v in read_record(path.parent).items() if (path.parent / k).is_file()}
        rec[path.name] = entry(rec.get(path.name))
        atomic_write_json(path.parent / OWNED_FILES, rec)


@contextlib.contextmanager
def written_file(path) -> Iterator[Path]:
    """Yield a temporary path beside `path` for a writer (same suffix); then the record lists its
    digest beside the earlier file's, it replaces `path`, and the record keeps it alone. A
    failure at any step (a full disk) leaves the earlier file and a record that covers the file
    that is there: a rerun replaces it. (Writing `path`, then `record_file`, left the new file
    unrecorded when the record's write failed: every rerun refused it as a user's file.)"""
    path = Path(path)
    new_dirs = _missing_dirs(path.parent)
    try:
        with atomic_path(path, suffix=path.suffix or ".tmp") as tmp:
            yield path.with_name(tmp.name)  # as the user named the folder (mkstemp's is absolute)
            with os_errors(path, own_name=False):
                digest = file_sha256(tmp)
            _set_entry(path, lambda old: entry_digests(old) + [digest])
    except BaseException:
        _remove_new_dirs(new_dirs)
        raise
    try:  # in place; the [old, new] entry already covers it if this write fails
        _set_entry(path, lambda old: digest)
    except OutputError as e:
        log.warning("%s", e)


def _missing_dirs(folder: Path) -> list[Path]:
    """The folders of `folder`'s path that do not exist yet, deepest first."""
    missing = []
    for d in [folder, *folder.parents]:
        if d.exists() or d.is_symlink():
            break
        missing.append(d)
    return missing


def _remove_new_dirs(dirs: list[Path]) -> None:
    """After a failed write, remove the folders it created (deepest first) while they hold
    nothing but the record of files and its lock, which no other writer holds: a failed
    `mesh -o new/m.msh` left an empty `new`."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        fcntl = None
    for d in dirs:
        try:
            names = {p.name for p in d.iterdir()}
            if not names <= {OWNED_FILES, RECORD_LOCK} or any(
                    (d / n).is_symlink() or not (d / n).is_file() for n in names):
                return
            if OWNED_FILES in names and any((d / k).exists() for k in read_record(d)):
                return
            if RECORD_LOCK in names:
                fd = os.open(d / RECORD_LOCK, os.O_RDONLY)
                try:  # a writer holding it is using the folder
                    if fcntl is not None:
                        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    for n in names:
                        (d / n).unlink()
                finally:
                    os.close(fd)
            else:
                for n in names:
                    (d / n).unlink()
            d.rmdir()
        except OSError:
            return


# The record is replaced by a rename, so it cannot be locked itself: a lock file beside it,
# left in place (removing it would race with the next writer's open).
RECORD_LOCK = ".tactileskin-files.lock"


@contextlib.contextmanager
def record_lock(folder: Path) -> Iterator[None]:
    """Hold an exclusive flock on the folder's RECORD_LOCK around a read-modify-write of its
    OWNED_FILES (waits for another writer into the same folder). Without flock (no fcntl, a
    file system without locks) there is no lock, as in the cache."""
    with folder_lock(folder, RECORD_LOCK, folder / OWNED_FILES):
        yield


NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)  # not on every OS
LINKED_LOCK = "it is a symbolic link, which tactileskin does not follow: remove it"


def open_lock_file(path: Path, mode: int) -> int:
    """os.open of a lock file (created, 0o666 less the umask) that does not follow a symlink of
    its name: O_CREAT would make the link's target, outside the folder. A link is refused
    naming it."""
    try:
        return os.open(path, mode | os.O_CREAT | NOFOLLOW, 0o666)
    except OSError as e:
        if e.errno == errno.ELOOP:
            raise OutputError(path, LINKED_LOCK) from None
        raise


@contextlib.contextmanager
def folder_lock(folder: Path, name: str, about: Path, blocking: bool = True) -> Iterator[None]:
    """Hold an exclusive flock on `folder / name` (created, left in place) for the body; errors
    name `about`. blocking=False: BlockingIOError at once if another process holds it. Without
    flock (no fcntl, a file system without locks) there is no lock, with a warning."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    while True:
        # opened for writing (NFS emulates flock by byte-range locks, which need it), else read-only:
        # a group-shared folder's lock file (0644 under umask 022) must open for the other users too
        with os_errors(about, own_name=False):
            try:
                fd = open_lock_file(folder / name, os.O_RDWR)
            except PermissionError:
                fd = open_lock_file(folder / name, os.O_RDONLY)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | (0 if blocking else fcntl.LOCK_NB))
        except BlockingIOError:
            os.close(fd)
            raise
        except OSError as e:
            if e.errno not in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL, errno.EBADF):
                os.close(fd)
                with os_errors(about, own_name=False):
                    raise
            log.warning("no file locks in %s (%s): %s is written without one", folder, e.strerror, about.name)
            break
        if is_open_file(fd, folder / name):
            break
        # the holder removed the lock file before releasing it (a failed run removing its new
        # folder): a lock on the removed file excludes no one who opens the path now
        os.close(fd)
    try:
        yield
    finally:
        os.close(fd)  # releases the lock
