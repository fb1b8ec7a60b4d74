"""Staging: a result is written into a temporary folder, then moved into place whole, so a
failed or killed write leaves the earlier result, never part of the new one.

- `staged_dir` replaces a folder the toolkit owns entirely (a cache entry); the old folder
  is removed only once the new one is in place.
- `staged_files` moves one result's files into an output folder that may hold other files.
  In a folder marked as ours (outdir.claim_dir) the folder's record (ownership) lists the
  earlier result's files: a rerun replaces or removes only those, so a user's file stays
  whatever its name, and a file of ours the user edited is refused, not overwritten.

Apart from fileio because it reads and updates the marker and the record, which fileio's
plain writes know nothing of.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterable, Iterator

from tactileskin.fileio import (
    STAGING,
    OutputError,
    atomic_write_json,
    clean_stale,
    dir_mode,
    file_sha256,
    is_temporary,
    make_dirs,
    os_errors,
    tmp_prefix,
)
from tactileskin.outdir import BOOKKEEPING, MARKER, is_legacy, marker_doc
from tactileskin.ownership import OWNED_FILES, entry_digests, is_recorded, read_record, record_lock


@contextlib.contextmanager
def staged_dir(final) -> Iterator[Path]:
    """Yield a new, empty staging folder beside `final`; on success it replaces `final`.

    For folders the toolkit owns entirely (a cache entry, a result folder inside one).
    `final`, if it exists, must be ours: callers check (claim_dir, or a cache layout).
    The old folder is moved aside and removed only after the new one is in place.
    """
    final = Path(final)
    make_dirs(final.parent)
    clean_stale(final.parent)
    with os_errors(final):
        tmp = Path(tempfile.mkdtemp(prefix=tmp_prefix(final), suffix=".partial", dir=final.parent))
        os.chmod(tmp, dir_mode())
    try:
        yield tmp
        with os_errors(final):
            if final.exists():
                old = Path(tempfile.mkdtemp(prefix=tmp_prefix(final), suffix=".partial", dir=final.parent))
                try:  # `old` removed however a move fails (it leaked when the first one did)
                    os.replace(final, old / "old")
                    try:
                        os.replace(tmp, final)
                    except BaseException:
                        os.replace(old / "old", final)
                        raise
                finally:
                    shutil.rmtree(old, ignore_errors=True)
            else:
                os.replace(tmp, final)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


def _files(root: Path, subfolders=None) -> list[str]:
    """Paths (relative, with "/") of the files under `root`, our temporaries left out; with
    `subfolders`, only those top-level folders are entered (not a sweep's cache)."""
    out = []
    for dirpath, dirnames, filenames in os.walk(root):
        rel = Path(dirpath).relative_to(root)
        dirnames[:] = [d for d in dirnames if not is_temporary(d)
                       and (subfolders is None or rel != Path(".") or d in subfolders)]
        out += [(rel / f).as_posix() for f in filenames if not is_temporary(f)]
    return out


def _check_owned(folder: Path, old: list[str], new: list[str], rec: dict) -> list[str]:
    """Of the pattern-matching files `old` in a marked `folder`, those the toolkit recorded
    writing and nobody changed since (to replace or remove). A file the new result would
    replace that is not one of them is refused: it is the user's (not recorded) or the user
    edited ours. Any other is left where it is."""
    ours = []
    for rel in old:
        p = folder / rel
        try:
            same = rel in rec and not p.is_symlink() and is_recorded(rec[rel], file_sha256(p))
        except OSError:
            same = False
        if same:
            ours.append(rel)
        elif rel in new:
            why = ("tactileskin wrote it but it was changed since" if rel in rec
                   else "the file exists and tactileskin did not write it")
            raise OutputError(p, f"{why}; refusing to overwrite it: move it away, or write to a new folder")
    for rel in new:  # a name the earlier result did not use, held by a folder or link of the user's
        p = folder / rel
        if rel not in old and (p.exists() or p.is_symlink()):
            raise OutputError(p, "something tactileskin did not write is in the way; refusing to "
                                 "replace it: move it away, or write to a new folder")
    return ours


def check_replaceable(folder, names: Iterable[str]) -> None:
    """Before the work: OutputError if a run that will write `names` (paths relative to the
    folder) into the marked `folder` would be refused by staged_files when it moves them in
    (a file of ours the user edited, a user's file or folder of that name), so that a long
    solve is not done to be thrown away. A name that is not there is no obstacle."""
    folder = Path(folder)
    if not (folder / MARKER).is_file() or is_legacy(folder):
        return
    names = list(names)
    old = [n for n in names if (folder / n).is_file()]
    _check_owned(folder, old, names, read_record(folder))


@contextlib.contextmanager
def staged_files(folder, own: Iterable[str], *, last: str | None = None) -> Iterator[Path]:
    """Yield an empty staging folder inside `folder` for the body to write one result into.

    On success the result replaces the folder's earlier one: every file the body wrote moves
    into place, and every file of the earlier result that matches an `own` pattern (fnmatch on
    the path relative to `folder`: "summary.json", "result_steps/step_*.vtu") but was not
    written this time is removed, so no file of an earlier result outlives it. In a folder
    marked as ours (claim_dir) the earlier result is what the folder's OWNED_FILES records
    (the record is updated with the new files): a user's file stays even if its name matches
    a pattern, and one the new result would replace (or a file of ours the user edited) is
    refused (OutputError) before anything moves. An unmarked folder is the caller's entirely
    (a cache entry, a staging folder): there every matching file is the earlier result's.
    Other files are left alone, and a folder is removed only once empty. `last` is removed
    first and moved in last, so a folder holding it holds a complete result. On failure
    nothing in `folder` changes (a full disk fails while staging, before the first move).
    """
    import fnmatch

    own = tuple(own)
    folder = make_dirs(folder)
    clean_stale(folder)
    with os_errors(folder, own_name=False):
        tmp = Path(tempfile.mkdtemp(prefix=tmp_prefix(folder / STAGING), suffix=".partial", dir=folder))
        os.chmod(tmp, dir_mode())
    try:
        yield tmp
        new = _files(tmp)
        stray = [f for f in new if not any(fnmatch.fnmatchcase(f, p) for p in own)]
        if stray:
            raise ValueError(f"staged files not in the owned patterns: {stray}")
        marked = (folder / MARKER).is_file()
        with os_errors(folder):  # the digests the record will hold, before anything moves
            digests = {rel: file_sha256(tmp / rel) for rel in new} if marked else {}
        with record_lock(folder) if marked else contextlib.nullcontext():
            _replace_files(folder, tmp, own, new, last, digests if marked else None)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _replace_files(folder: Path, tmp: Path, own: tuple, new: list[str], last, digests: dict | None) -> None:
    """staged_files' moves: the earlier result aside, the new one in (and, with `digests`,
    the folder's record updated), undone in reverse if any step fails."""
    import fnmatch

    tops = {p.split("/")[0] for p in own if "/" in p}
    old = [f for f in _files(folder, tops) if any(fnmatch.fnmatchcase(f, p) for p in own)]
    rec = None
    legacy = digests is not None and is_legacy(folder)
    if legacy:
        # marked by a version before the record of results (2026-11-26): its pattern-matching
        # files are the earlier result, as that version took them; the record starts here
        rec = read_record(folder)  # single files (mesh -o, export -o) that version did record
    elif digests is not None:
        rec = read_record(folder)
        old = _check_owned(folder, old, new, rec)
    for rel in new:  # a linked subfolder would take our files into a folder we do not own
        for parent in list(Path(rel).parents)[:-1]:
            if (folder / parent).is_symlink() or ((folder / parent).exists() and not (folder / parent).is_dir()):
                raise OutputError(folder / parent, "it is a link or a file where tactileskin writes a folder "
                                                   "of its own; move it away")
    with os_errors(folder, own_name=False):
        trash = Path(tempfile.mkdtemp(prefix=tmp_prefix(folder / STAGING), suffix=".partial", dir=folder))
    aside, moved_in = [], []  # (where it was, where it is): undone in reverse on a failure
    try:
        with os_errors(folder):
            if rec is not None:  # a kill during the moves leaves either version of each file: both ours
                atomic_write_json(folder / OWNED_FILES, {**rec, **{k: entry_digests(rec.get(k)) + [v]
                                                                   for k, v in digests.items()}})
            order = sorted(set(new) | set(old), key=lambda f: f == last)
            if last in old:
                os.replace(folder / last, trash / "last")
                aside.append((folder / last, trash / "last"))
            for i, rel in enumerate(order):
                dst = folder / rel
                if rel in old and rel != last:
                    os.replace(dst, trash / f"{i}")
                    aside.append((dst, trash / f"{i}"))
                if rel in new:
                    make_dirs(dst.parent)
                    os.replace(tmp / rel, dst)
                    moved_in.append((tmp / rel, dst))
            if rec is not None:  # entries of files gone or replaced dropped, the new ones added
                keep = {k: v for k, v in rec.items() if k not in old and (folder / k).is_file()}
                if legacy:  # the earlier version's files of its other commands are ours too (a
                    # film folder's analyze files, upgraded by a compare that writes only its own)
                    subs = {p.name for p in folder.iterdir() if p.is_dir() and not p.is_symlink() and p.name != "cache"}
                    keep.update({rel: file_sha256(folder / rel) for rel in _files(folder, subs)
                                 if rel not in digests and rel not in keep and rel not in (MARKER, *BOOKKEEPING)
                                 and (folder / rel).is_file() and not (folder / rel).is_symlink()})
                atomic_write_json(folder / OWNED_FILES, {**keep, **digests})  # the last step: no undo
                if legacy:
                    with contextlib.suppress(OSError, ValueError, AttributeError):
                        kind = json.loads((folder / MARKER).read_text()).get("kind")
                        atomic_write_json(folder / MARKER, marker_doc(kind))
    except BaseException:
        for src, dst in reversed(moved_in):  # the earlier result back as it was
            with contextlib.suppress(OSError):
                os.replace(dst, src)
        for orig, parked in reversed(aside):
            with contextlib.suppress(OSError):
                os.replace(parked, orig)
        if rec is not None:  # and the record that describes it
            with contextlib.suppress(OSError):
                atomic_write_json(folder / OWNED_FILES, rec)
        raise
    finally:
        shutil.rmtree(trash, ignore_errors=True)
    # folders of the earlier result that are empty now (deepest first)
    for rel in sorted({Path(f).parent for f in old} - {Path(".")}, key=lambda d: -len(d.parts)):
        with contextlib.suppress(OSError):
            (folder / rel).rmdir()
