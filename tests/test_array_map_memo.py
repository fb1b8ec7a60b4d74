"""The maps a chart reads at a sensor depth are kept beside the cached solve (chart.MEMO_DIR in
its cache entry): a rerun reads them instead of locating every grid point in result.vtu again
(2-3 s per 3D map), and a memo that does not match what made it is never used."""

import json
from types import SimpleNamespace

import numpy as np
import pytest
from test_array_sensor_depth import _linear_pad

from tactileskin import cache as cache_mod
from tactileskin.array import chart
from tactileskin.cache import CaseRecord, ResultCache
from tactileskin.scene import Scene

COARSE = dict(thickness=3.0, indenter="curved", mesh_size=0.5, refinement=2)  # about 1 s, as test_array_sensor_depth


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """A coarse 2D solve stored in a result cache, as the chart's solve_cached finds it."""
    from tactileskin.fe import solve

    sc = Scene(**COARSE)
    c = ResultCache(tmp_path_factory.mktemp("cache"))
    c.store(sc, solve(sc))
    return c, sc


@pytest.fixture
def counted(monkeypatch):
    """The calls of chart._at_depth (the map read from result.vtu)."""
    calls = []
    real = chart._at_depth

    def spy(rec, s, z, depth):
        calls.append(depth)
        return real(rec, s, z, depth)

    monkeypatch.setattr(chart, "_at_depth", spy)
    return calls


def _memos(rec):
    d = rec.path / chart.MEMO_DIR
    return sorted(d.iterdir()) if d.is_dir() else []


def test_a_rerun_reads_the_map_at_depth_from_its_memo_and_the_entry_stays_valid(stored, counted):
    c, sc = stored
    rec = c.lookup(sc)
    first = chart.profile_of(rec, 1.25)
    again = chart.profile_of(c.lookup(sc), 1.25)  # a rerun: a new lookup of the same entry
    assert counted == [1.25]  # not read from result.vtu again
    assert np.array_equal(again[0], first[0]) and np.array_equal(again[1], first[1])
    assert len(_memos(rec)) == 1
    assert c.lookup(sc, repair=False) is not None  # the memo does not make the entry read as damaged
    chart.profile_of(rec, 1.0)  # another depth is another map
    assert counted == [1.25, 1.0] and len(_memos(rec)) == 2
    # a record that is no cache entry (no key to name a memo by) is read as before, nothing kept
    plain = SimpleNamespace(scene=sc, s=rec.s, pressure=rec.pressure, path=rec.path)
    assert np.array_equal(chart.profile_of(plain, 1.25)[1], first[1])
    assert counted == [1.25, 1.0, 1.25] and len(_memos(rec)) == 2


def test_a_damaged_or_foreign_memo_is_recomputed_never_an_error(stored, counted, monkeypatch, caplog):
    c, sc = stored
    rec = c.lookup(sc)
    ref = chart.profile_of(rec, 2.0)
    (memo,) = [p for p in _memos(rec) if p.name.startswith(chart._memo_key(rec, rec.s, None, 2.0))]
    n = len(counted)

    def reread():
        s, P = chart.profile_of(rec, 2.0)
        assert np.array_equal(s, ref[0]) and np.array_equal(P, ref[1])

    import io

    npy = io.BytesIO()
    np.save(npy, ref[1])  # a bare .npy under the memo's name: np.load gives an array, not an archive
    for bad in (b"", b"not a zip", memo.read_bytes()[:-40], npy.getvalue()):  # empty, garbage, cut short, .npy
        memo.write_bytes(bad)
        reread()
        assert len(counted) == n + 1, bad  # recomputed ...
        n += 1
        reread()
        assert len(counted) == n  # ... and kept again
    # a well-formed memo whose numbers were altered, and another depth's memo under this name
    with np.load(memo) as f:
        s, P, tag = f["s"], f["P"], f["memo"]
    np.savez(memo, s=s, P=P * 1.01, memo=tag)
    reread()
    assert len(counted) == n + 1
    n += 1
    chart.profile_of(rec, 1.5)
    n += 1
    other = next(p for p in _memos(rec) if p.name.startswith(chart._memo_key(rec, rec.s, None, 1.5)))
    memo.write_bytes(other.read_bytes())
    reread()
    assert len(counted) == n + 1
    n += 1
    assert "is damaged" in caplog.text
    # other code (the key's code digest) names another memo: not trusted
    monkeypatch.setattr(cache_mod, "code_digest", lambda: "other code")
    reread()
    assert len(counted) == n + 1
    n += 1
    # a memo that cannot be written (a read-only cache): the map is still read
    from tactileskin import fileio

    def refuse(path, data):
        raise OSError("read-only file system")

    monkeypatch.setattr(fileio, "atomic_write_bytes", refuse)
    chart.profile_of(rec, 0.75)
    assert len(counted) == n + 1


def test_a_3d_map_at_depth_is_kept_per_entry_key(tmp_path, counted):
    """raw_map_of of a 3D entry: the (z, s) map comes back from the memo as computed, and an
    entry of another key (cache.json) does not read it."""
    rec3, _ = _linear_pad(tmp_path, 1.0)
    (tmp_path / "cache.json").write_text(json.dumps({"key": "a" * 24, "files": {"result.vtu": "x"}}), encoding="utf-8")
    rec = CaseRecord(rec3.scene, np.zeros(2), np.zeros(2), {}, tmp_path)
    first = chart.raw_map_of(rec, 0.3)
    again = chart.raw_map_of(rec, 0.3)
    assert counted == [0.3] and np.array_equal(first.pressure, again.pressure) and first.pressure.ndim == 2
    (tmp_path / "cache.json").write_text(json.dumps({"key": "b" * 24, "files": {"result.vtu": "x"}}), encoding="utf-8")
    chart.raw_map_of(rec, 0.3)
    assert counted == [0.3, 0.3]


def test_an_entry_removed_while_its_map_is_read_is_not_brought_back_by_the_memo(stored, tmp_path, monkeypatch):
    """Another process may discard the entry (found damaged) while this one reads a map from
    it: the memo's write made its folders again (mkdir -p), a key folder with no cache.json
    that the next lookup warns of as a damaged entry. The memo is skipped instead."""
    import shutil

    c, sc = stored
    mine = ResultCache(tmp_path / "cache")
    shutil.copytree(c.lookup(sc).path, mine.path(sc), ignore=shutil.ignore_patterns(chart.MEMO_DIR))
    rec = mine.lookup(sc)
    real = chart._at_depth

    def read_then_discarded(r, s, z, depth):
        out = real(r, s, z, depth)
        shutil.rmtree(r.path)  # as ResultCache._discard in another process
        return out

    monkeypatch.setattr(chart, "_at_depth", read_then_discarded)
    s, P = chart.profile_of(rec, 1.25)
    assert P.shape == s.shape and np.all(np.isfinite(P))
    assert not rec.path.exists(), sorted(p.relative_to(tmp_path) for p in rec.path.rglob("*"))
