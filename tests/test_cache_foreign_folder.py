"""--cache DIR took any folder: a user's folder of their own files got case entries, .lock files
and figure/render entries written among them (--out refuses such a folder). A non-empty folder
that is not a tactileskin cache is refused naming --cache and what it must be, before any case
and with nothing written; a new, an empty, and an existing cache (shared between sweeps: the
option's purpose) are taken."""

from __future__ import annotations

import pytest
from test_output_safety import fake_solve  # noqa: F401 - the fixture: a result without solving

from tactileskin.cli import main

SWEEP = ["sweep", "-t", "1", "-m", "silicone", "-i", "flat", "--serial", "--no-render"]


def _tree(folder):
    return sorted((p.relative_to(folder).as_posix(), p.read_bytes() if p.is_file() else None)
                  for p in folder.rglob("*"))


@pytest.mark.parametrize("command", [SWEEP, ["array", "--set", "paper", "-t", "1", "--pitch", "1"]])
def test_a_folder_of_the_users_files_is_refused_as_cache(tmp_path, capsys, fake_solve, command):
    users = tmp_path / "users"
    (users / "photos").mkdir(parents=True)
    (users / "notes.txt").write_text("mine")
    (users / "photos" / "a.jpg").write_bytes(b"\xff\xd8")
    before = _tree(users)
    out = tmp_path / "out"
    assert main([*command, "--out", str(out), "--cache", str(users)]) == 2
    cap = capsys.readouterr()
    err = cap.err.strip()
    assert "Traceback" not in cap.err + cap.out and len(err.splitlines()) == 1, err
    assert str(users) in err and "--cache" in err and "new or empty folder, or a cache made by tactileskin" in err
    assert "notes.txt" in err
    assert _tree(users) == before and fake_solve == [] and not out.exists()


def test_a_cache_is_shared_between_sweeps_and_a_new_or_empty_folder_taken(tmp_path, capsys, fake_solve):
    shared = tmp_path / "shared"
    assert main([*SWEEP, "--out", str(tmp_path / "a"), "--cache", str(shared)]) in (0, 3)
    assert len(fake_solve) == 1 and any(p.is_dir() for p in shared.iterdir())
    assert main([*SWEEP, "--out", str(tmp_path / "b"), "--cache", str(shared)]) in (0, 3)  # the cache's own files
    assert len(fake_solve) == 1  # taken from the shared cache, not solved again
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main([*SWEEP, "--out", str(tmp_path / "c"), "--cache", str(empty)]) in (0, 3)
    assert len(fake_solve) == 2


def test_the_api_refuses_a_users_folder_as_cache(tmp_path, fake_solve):
    import tactileskin as ts
    from tactileskin.fileio import OutputError

    users = tmp_path / "users"
    users.mkdir()
    (users / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match=r"cache must be a new or empty folder, or a cache made by tactileskin"):
        ts.sweep({"thickness": [1.0], "material": ["silicone"], "indenter": ["flat"]}, cache=users, serial=True)
    assert sorted(p.name for p in users.iterdir()) == ["notes.txt"] and fake_solve == []


def test_a_users_folder_named_by_tactileskin_cache_is_refused_too(tmp_path, monkeypatch, fake_solve):
    # TACTILESKIN_CACHE is the user's choice of folder, as cache= is: the same rule, naming it
    import tactileskin as ts
    from tactileskin.array.chart import result_cache
    from tactileskin.fileio import OutputError

    users = tmp_path / "users"
    users.mkdir()
    (users / "notes.txt").write_text("mine")
    monkeypatch.setenv("TACTILESKIN_CACHE", str(users))
    for call in (lambda: ts.sweep({"thickness": [1.0], "material": ["silicone"], "indenter": ["flat"]},
                                  serial=True, report=False),
                 lambda: result_cache(None)):
        with pytest.raises(OutputError, match=r"TACTILESKIN_CACHE must be a new or empty folder"):
            call()
    assert sorted(p.name for p in users.iterdir()) == ["notes.txt"] and fake_solve == []
    monkeypatch.setenv("TACTILESKIN_CACHE", str(tmp_path / "new"))
    ts.sweep({"thickness": [1.0], "material": ["silicone"], "indenter": ["flat"]}, serial=True, report=False)
    assert len(fake_solve) == 1 and any((tmp_path / "new").iterdir())


@pytest.mark.parametrize("clutter", [".DS_Store", ".nfs000000000012a4c600000001", "Thumbs.db", "desktop.ini"])
def test_a_cache_with_the_file_systems_own_files_is_still_a_cache(tmp_path, capsys, fake_solve, clutter):
    # Finder's .DS_Store (a cache opened by hand), NFS's .nfsXXXX (a lock unlinked while another
    # client held it open) and Windows' Thumbs.db / desktop.ini are written by the system, not the
    # user: a shared cache holding one was refused as "not a cache" and could not be used again
    shared = tmp_path / "shared"
    assert main([*SWEEP, "--out", str(tmp_path / "a"), "--cache", str(shared)]) in (0, 3)
    (shared / clutter).write_bytes(b"\0")
    assert main([*SWEEP, "--out", str(tmp_path / "b"), "--cache", str(shared)]) in (0, 3), capsys.readouterr().err
    assert len(fake_solve) == 1


def test_a_cache_entry_without_its_cache_json_is_named_as_such(tmp_path, capsys, fake_solve):
    # a shared cache copied by a cut-short cp/rsync holds key-named entries without cache.json:
    # still refused (lookup would remove the folder), but the error said the cache held "other
    # files", as for a folder of the user's own, with nothing to say what to do
    shared = tmp_path / "shared"
    assert main([*SWEEP, "--out", str(tmp_path / "a"), "--cache", str(shared)]) in (0, 3)
    entry = next(p for p in shared.iterdir() if p.is_dir() and (p / "cache.json").is_file())
    (entry / "cache.json").unlink()
    capsys.readouterr()
    assert main([*SWEEP, "--out", str(tmp_path / "b"), "--cache", str(shared)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and entry.name in err, err
    assert "other files" not in err and "no cache.json" in err and "remove" in err, err
    assert entry.is_dir() and len(fake_solve) == 1
