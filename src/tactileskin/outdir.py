"""Output folders: a command writes into a folder only if it is new, empty, or marked as
the toolkit's by an earlier run of the same command.

`claim_dir` writes the marker `.tactileskin`, whose kind names the command; a folder holding
files we did not write is refused, never emptied, and one marked by another command is
refused naming that command. `claimed` removes again a folder it created for a run that
failed; `adopt_dir` marks a folder that a version before the marker wrote. Which files in a
marked folder are ours is the folder's record (ownership); staging moves results in.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path
from typing import Iterable, Iterator

from tactileskin.fileio import (STAGING, OutputError, atomic_write_json, clean_stale, is_temporary, make_dirs,
                                os_errors, tmp_prefix)
from tactileskin.ownership import OWNED_FILES, RECORD_LOCK, check_lock_name, folder_lock, record_file

MARKER = ".tactileskin"
# held (flock) by the run writing into the folder: a second run into it is refused, as its
# result would replace the first's files while the first reports them written
RUN_LOCK = ".tactileskin-run.lock"
BOOKKEEPING = (OWNED_FILES, RECORD_LOCK, RUN_LOCK)


def _is_ours(folder: Path, kind: str | None) -> bool:
    """Whether `folder` carries our marker (of `kind`, if given). A folder without it is not
    ours, whatever its file names: a user's summary.json or report.md looks like ours."""
    marker = folder / MARKER
    if not marker.is_file():
        return False
    if kind is None:
        return True
    try:
        return json.loads(marker.read_text()).get("kind") in (kind, None)
    except (OSError, ValueError, AttributeError):
        return False


def marker_kind(folder) -> str | None:
    """The kind our marker in `folder` names ("solve", "film-analyze", ...): "" for a marker
    without a readable one, None without a marker."""
    folder = Path(folder)
    if not (folder / MARKER).is_file():
        return None
    try:
        kind = json.loads((folder / MARKER).read_text()).get("kind")
    except (OSError, ValueError, AttributeError):
        kind = None
    return kind if isinstance(kind, str) else ""


def written_by(kind: str) -> str:
    """`kind` as the message of a refused folder names it: the command (`film analyze`)."""
    return f"`{kind.replace('-', ' ')}`" if kind else "of an unknown kind"


def claim_dir(folder, kind: str, *, what: str = "out") -> Path:
    """Make `folder` the toolkit's output folder of `kind`, or refuse it.

    Accepted: a missing or empty folder, or a folder with our marker of the same kind.
    Anything else raises OutputError and nothing is written. Stale temporaries of killed runs
    are removed.
    """
    folder = Path(folder)
    if folder.is_symlink() and not folder.is_dir():
        raise OutputError(folder, "it is a broken symbolic link")
    if folder.exists() and not folder.is_dir():
        raise OutputError(folder, f"{what} must be a folder, and this is a file")
    if folder.is_dir():
        with os_errors(folder):
            entries = [p for p in folder.iterdir() if not is_temporary(p.name)
                       and p.name not in BOOKKEEPING]  # our bookkeeping of single files
        if entries and not _is_ours(folder, kind):
            other = marker_kind(folder)
            if other is not None:  # ours, but another command's: say so, not "did not write"
                raise OutputError(folder, f"the folder was written by another tactileskin command "
                                          f"({written_by(other)}); "
                                          f"refusing to write into it: give {what} a new or empty folder")
            shown = ", ".join(sorted(p.name for p in entries)[:3]) + (", ..." if len(entries) > 3 else "")
            raise OutputError(folder, f"the folder holds files tactileskin did not write ({shown}); "
                                      f"refusing to write into it: give {what} a new or empty folder")
    if folder.is_dir():  # refused now, not when the result's files are recorded (after a solve)
        for name in (RECORD_LOCK, RUN_LOCK):
            check_lock_name(folder, name)
    make_dirs(folder)
    clean_stale(folder)
    if not (folder / MARKER).is_file():
        atomic_write_json(folder / MARKER, marker_doc(kind))
    else:  # nothing written yet: a read-only folder is refused now, not after the work (a solve)
        with os_errors(folder, own_name=False):
            fd, probe = tempfile.mkstemp(prefix=tmp_prefix(folder / STAGING), dir=folder)
            os.close(fd)
            os.unlink(probe)
    return folder


def marker_doc(kind: str) -> dict:
    # "record": its results are in OWNED_FILES (a marker without it is an earlier version's)
    return {"kind": kind, "record": 1, "note": "written by tactileskin; its commands may replace their "
                                                "own files here"}


def is_legacy(folder: Path) -> bool:
    """Whether our marker in `folder` is from a version before the record of written files:
    then the folder's pattern-matching files are its earlier result, as that version took them."""
    try:
        return json.loads((folder / MARKER).read_text()).get("record") != 1
    except (OSError, ValueError, AttributeError):
        return True


@contextlib.contextmanager
def claimed(folder, kind: str, *, what: str = "out") -> Iterator[Path]:
    """claim_dir `folder` for the body, holding its RUN_LOCK (OutputError if another run holds
    it); if the body fails and the folder was created here and holds nothing but our marker
    (and locks), remove it again: a refused or failed run leaves no empty folder behind."""
    folder = Path(folder)
    existed = folder.exists() or folder.is_symlink()
    claim_dir(folder, kind, what=what)
    with run_lock(folder, what):
        try:
            yield folder
        except BaseException:
            _remove_if_new(folder, existed)
            raise


@contextlib.contextmanager
def run_lock(folder: Path, what: str = "out") -> Iterator[None]:
    """Hold the folder's RUN_LOCK for a run writing into it; OutputError at once if another
    process holds it (a second run into one folder would replace the first's files)."""
    with contextlib.ExitStack() as stack:
        try:  # only the taking of the lock: a BlockingIOError of the body is the body's
            stack.enter_context(folder_lock(folder, RUN_LOCK, folder, blocking=False))
        except BlockingIOError:
            raise OutputError(folder, "another tactileskin run is writing into this folder now; wait for it "
                                      f"to finish, or give {what} another folder") from None
        yield


def check_free(folder, what: str = "out") -> None:
    """OutputError now if another run holds `folder`'s RUN_LOCK (a command that works long
    before it claims its folder: build's CAD); the run takes the lock itself when it writes."""
    folder = Path(folder)
    if (folder / RUN_LOCK).is_file() and not (folder / RUN_LOCK).is_symlink():
        with run_lock(folder, what):
            pass


def _remove_if_new(folder: Path, existed: bool) -> None:
    """Remove `folder` if this run created it and it holds nothing but our bookkeeping."""
    if existed:
        return
    with contextlib.suppress(OSError):
        names = {p.name for p in folder.iterdir()}
        cache = folder / "cache"  # a sweep stopped before its first case: locks only
        if "cache" in names and cache.is_dir() and not cache.is_symlink() and all(
                p.suffix == ".lock" and p.is_file() for p in cache.iterdir()) \
                and _remove_free_locks(cache):
            cache.rmdir()
            names.discard("cache")
        if MARKER in names and names <= {MARKER, *BOOKKEEPING}:
            for n in names:
                (folder / n).unlink()
            folder.rmdir()


def _remove_free_locks(folder: Path) -> bool:
    """Remove the lock files in `folder` that no process holds (each taken before it goes: a
    sweep started on the same new folder keeps its duplicate-work guard); True if all went."""
    try:
        import fcntl
    except ImportError:  # no flock (Windows): no lock is held by anyone
        fcntl = None
    every = True
    for p in list(folder.iterdir()):
        if p.suffix != ".lock" or p.is_symlink() or not p.is_file():
            # the caller saw only locks, but a run sharing the folder may have written since
            every = False
            continue
        try:
            fd = os.open(p, os.O_RDONLY)
        except OSError:
            every = False
            continue
        try:
            if fcntl is not None:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            p.unlink()
        except OSError:  # held by another run (BlockingIOError) or not ours to remove
            every = False
        finally:
            os.close(fd)
    return every


def adopt_dir(folder, kind: str, names: Iterable[str]) -> None:
    """Mark `folder` as ours of `kind`, recording `names` in it as files we wrote, as they are
    now: for a folder an earlier version wrote without the marker and record (the caller has
    made sure those files are the toolkit's, e.g. listed in its manifest)."""
    folder = Path(folder)
    for n in names:
        if (folder / n).is_file() and not (folder / n).is_symlink():
            record_file(folder / n)
    if not (folder / MARKER).is_file():
        atomic_write_json(folder / MARKER, marker_doc(kind))
