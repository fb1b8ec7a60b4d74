"""The result cache of sweeps: one folder per case, keyed by everything that can change it.

Key. `Scene.key()` hashes the scene's own fields only (it names a scene, e.g. to drop
duplicates from a grid). A cached result also depends on files and code the scene merely
names, so the cache is keyed by `cache_key(scene)`, the SHA-256 of
- the scene's fields except the material's name or path;
- the material's law name and numbers (its parameters, and its Prony terms for a viscoelastic scene:
  an elastic solve ignores them), read from the preset table or the
  user's material file: editing the file changes the key, renaming or moving it does not;
- the values of every geometry parameter file a solve reads (`params.geometry_digest()`, parsed, so
  a comment does not change the key: fingertip, indenters, Braille standards; not molds.toml, read
  by `build` alone; the shipped files are package data, hashed by their bytes with the code);
- the bytes of files the indenter kind reads (`Indenter.cache_content`: a user's STL) and the
  skin reads (`Skin.cache_content`: a user's .msh or STEP), not their paths;
- `scene.SCHEMA_VERSION`, the package version and `code_digest()`: the bytes of the package's
  own source and data files (but the shipped molds.toml) and the versions of the libraries that mesh and solve (gmsh,
  scikit-fem, numpy, scipy, numba, mkl, meshio, trimesh, build123d, OCP; and the API version of the gmsh.py Python
  imports, which a gmsh SDK on PYTHONPATH provides), so a result computed by other code (an update of
  tactileskin, a changed mesher) is never reused; a .pyc Python runs instead of its edited source
  (same size and time stamp, or an unchecked-hash .pyc, PEP 552) adds its code (`_stale_bytecode`). The .py files are hashed as this
  process first imported them (`tactileskin._IMPORTED_SOURCES`, kept by importlib.reload), not as they are on disk at key time.
While the package's .py files on disk differ from those it imported (a `git pull` in a running
notebook kernel: the old code runs, or old and new mixed as modules load), the process neither
stores nor reuses entries and its cases fail (`code_changes`: a WARNING names the files and says
to restart Python); a Dask worker started after the change imports the new code, whose key
differs from the sweep's, so it refuses the case.
Every caller that identifies a cached result (the cache itself, run_sweep, results.csv's
`key` column) uses this key. Files are hashed on every call (a few kB), never memoised by
time stamp, so an edit within the same second is not missed.

Entry. `<cache>/<key>/` holds the files `Result.write` writes (profile.csv,
summary.json, contact.csv, result.vtu; 3D also bone_map.csv, profile_max_z.csv), scene.toml, and cache.json (schema, key, package
version, and the SHA-256 of every other file of the entry). It is staged beside its final
name and renamed into place when complete, so a killed run leaves no half-written entry.
Loading validates it: cache.json names this key and schema, every file it lists is there
with its bytes unchanged (a profile.csv cut at a line end, a missing result.vtu, an edited
number: each read as a valid entry before), summary.json is an object with finite
peak/span/auc, profile.csv has >= 2 finite rows with increasing s, scene.toml describes this
scene. A damaged entry (truncated,
empty, corrupt, non-finite, foreign) is logged as a WARNING naming its path, removed, and
recomputed; it is never used.

Lock. `<cache>/<key>.lock` is taken with flock by the run computing the case, so two
sweeps into one cache do not compute the same case twice; the lock goes with the process
(a killed run leaves no stale lock). Without fcntl (Windows) there is no lock.
"""

from __future__ import annotations

import csv
import hashlib
import json
import logging
import math
import os
import re
import shutil
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from tactileskin import __version__, fileio, params, staging
from tactileskin.errors import TactileSkinError
from tactileskin.ownership import open_lock_file
from tactileskin.scene import SCHEMA_VERSION, Scene

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None

log = logging.getLogger(__name__)


class CacheError(TactileSkinError):
    """A cache entry that should be valid is missing or damaged."""


def _floats(x):
    if isinstance(x, dict):
        return {k: _floats(v) for k, v in sorted(x.items())}
    if isinstance(x, (list, tuple)):
        return [_floats(v) for v in x]
    return float(x)


def material_content(material: str) -> dict:
    """The numbers of a material (preset name or .toml path) that enter a solve."""
    from tactileskin.materials import get_material

    m = get_material(material)
    # the law's name is the key of its numbers: a change of law or of any parameter changes
    # the cache key (hyperfoam materials keep the key they always had)
    return {m.law_name: _floats(m.law.to_dict()), "prony": _floats(m.prony.to_dict())}


# the libraries whose version can change a mesh or a solve (distribution names): trimesh
# reads a user's STL indenter and its gaps, build123d and OCP (OpenCascade) tessellate a STEP
SOLVER_LIBRARIES = ("gmsh", "scikit-fem", "numpy", "scipy", "numba", "mkl", "meshio", "trimesh",
                    "build123d", "cadquery-ocp-novtk", "cadquery-ocp")


@lru_cache(maxsize=1)
def code_digest(root: Path | None = None) -> str:
    """SHA-256 of the code that produces a result: the names and bytes of every .py, .json and
    .toml file of the package (`root`, default the installed package's folder; sorted by path)
    and the installed versions of SOLVER_LIBRARIES; plus the code of any .pyc Python runs in place
    of its source (_stale_bytecode). Computed once per process (~130 files, ~20 ms). For the
    installed package the .py files are those this process imported (their hashes at import,
    tactileskin._IMPORTED_SOURCES), not the files on disk now: after a `git pull` in a running
    kernel the disk's were the new code's, while the old code ran (see code_changes)."""
    from importlib import metadata

    import tactileskin

    imported = tactileskin._IMPORTED_SOURCES if root is None else None
    root = Path(__file__).resolve().parent if root is None else Path(root)
    h = hashlib.sha256()
    try:
        # the shipped geometry files no solve reads (params.NOT_SOLVED: molds.toml) stay out here
        # too, or editing data/geometry/molds.toml in place re-solved every case all the same
        skip = {f"data/geometry/{n}" for n in params.NOT_SOLVED}
        paths = sorted(p for p in root.rglob("*") if p.suffix in (".py", ".json", ".toml") and p.is_file()
                       and "__pycache__" not in p.parts and p.relative_to(root).as_posix() not in skip
                       and not (imported is not None and p.suffix == ".py"))
        for p in paths:
            data = p.read_bytes()
            h.update(p.relative_to(root).as_posix().encode() + b"\0" + str(len(data)).encode() + b"\0" + data)
            if p.suffix == ".py" and (old := _stale_bytecode(p, data)) is not None:
                h.update(b"stale bytecode\0" + old)  # results of the code that runs, not of the file
        for rel, digest in sorted((imported or {}).items()):
            h.update(f"{rel}\0{digest}\0".encode())
            try:
                data = (root / rel).read_bytes()
            except OSError:
                continue  # removed since: code_changes() keeps the cache closed
            if hashlib.sha256(data).hexdigest() == digest and (old := _stale_bytecode(root / rel, data)) is not None:
                h.update(b"stale bytecode\0" + old)
    except OSError as e:  # an unreadable install: the version alone names the code
        log.warning("package files not readable (%s); cache keys use the version %s only", e, __version__)
        h.update(b"unreadable")
    for name in SOLVER_LIBRARIES:
        try:
            v = metadata.version(name)
        except metadata.PackageNotFoundError:
            v = "-"
        h.update(f"{name}={v}\0".encode())
    h.update(f"gmsh module={_gmsh_api_version()}\0".encode())
    return h.hexdigest()


def _gmsh_api_version() -> str:
    """GMSH_API_VERSION of the gmsh.py `import gmsh` loads, read from its source (a key does not
    load libgmsh): a gmsh SDK's lib folder on PYTHONPATH shadows the pip gmsh with its own
    gmsh.py and libgmsh, which the pip distribution's version does not name. "-" if none."""
    import importlib.util
    import re

    try:
        origin = importlib.util.find_spec("gmsh").origin
        text = Path(origin).read_text(encoding="utf-8", errors="replace")
    except (ImportError, AttributeError, TypeError, ValueError, OSError):
        return "-"
    found = re.search(r'^GMSH_API_VERSION\s*=\s*"([^"]*)"', text, re.M)
    return found.group(1) if found else "-"


_WARNED_CHANGES: set[tuple[str, ...]] = set()


def code_changes() -> list[str]:
    """The package's .py files (paths in it) whose bytes on disk are not those this process
    imported: edited, added or removed since (a `git pull` in a running kernel). While there are
    any, the process runs other code than the files say (the old, or old and new mixed as modules
    load), so the cache neither stores nor reuses entries. Each new list is logged once as a
    WARNING. Hashes the files on every call (~130 files, 3-8 ms), as the geometry files are."""
    import tactileskin

    now, then = tactileskin._source_hashes(), tactileskin._IMPORTED_SOURCES
    changed = sorted(k for k in now.keys() | then.keys() if now.get(k) != then.get(k))
    if changed and tuple(changed) not in _WARNED_CHANGES:
        _WARNED_CHANGES.add(tuple(changed))
        log.warning("%s (a notebook's kernel, a Dask cluster's workers): until then it runs the code it imported, "
                    "and no result is cached or taken from the cache", changed_code_message(changed))
    return changed


def changed_code_message(changed: list[str]) -> str:
    names = ", ".join(changed[:5]) + (f" and {len(changed) - 5} more" if len(changed) > 5 else "")
    return f"tactileskin's sources changed since this Python imported them ({names}): restart Python to run them"


def _stale_bytecode(p: Path, source: bytes) -> bytes | None:
    """The body of p's .pyc when Python runs it instead of p's code, else None. Python takes a
    time-stamp .pyc while it names the source's mtime in whole seconds and its size, so a same-size
    edit within the second the .pyc was compiled in, or with the time stamp set back (touch -d,
    cp -p), still runs the old code; and it takes an unchecked-hash .pyc (PEP 552) whatever the
    source says (a checked-hash one is recompiled when the source's hash differs). Compiled (~3 ms)
    and compared only when p changed after the .pyc was written (their ctimes, which no tool sets
    back): other .pyc files cost a 16-byte read."""
    import _imp
    import importlib.util
    import marshal
    import types
    import warnings

    try:
        with open(importlib.util.cache_from_source(str(p)), "rb") as fh:
            head, written, st = fh.read(16), os.fstat(fh.fileno()).st_ctime_ns, p.stat()
            flags, check = int.from_bytes(head[4:8], "little"), _imp.check_hash_based_pycs
            if flags == 0:  # time stamp
                taken = (int.from_bytes(head[8:12], "little") == int(st.st_mtime) & 0xFFFFFFFF
                         and int.from_bytes(head[12:16], "little") == st.st_size & 0xFFFFFFFF)
            else:  # source hash: unchecked (1), or checked (3) under --check-hash-based-pycs never
                taken = check != "always" and (flags == 1 or (flags == 3 and check == "never"))
            if len(head) < 16 or head[:4] != importlib.util.MAGIC_NUMBER or not taken or st.st_ctime_ns < written:
                return None  # none, not one Python takes, or compiled after p's last change
            body = fh.read()
        code = marshal.loads(body)
    except (OSError, NotImplementedError, ValueError, EOFError, TypeError):
        return None  # no .pyc Python can run
    if not isinstance(code, types.CodeType):
        return None  # Python refuses it (ImportError)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the source's own SyntaxWarnings: Python shows them itself
            if code == compile(source, code.co_filename, "exec", dont_inherit=True):
                return None
    except (SyntaxError, ValueError):
        pass  # the source does not compile: the .pyc's code is all the more not the source's
    log.warning("Python runs %s, compiled from an earlier version of %s (%s): results are cached as that "
                "code's; delete the .pyc to run the file's code", importlib.util.cache_from_source(str(p)), p,
                "changed within the second it was compiled in, or its time stamp set back" if flags == 0
                else "an unchecked-hash .pyc, which Python runs without looking at the source")
    return body


def cache_key(scene: Scene) -> str:
    """Hash of everything that can change `scene`'s result (see the module docstring)."""
    fields = _scene_fields(scene)
    material = material_content(scene.material)
    if not scene.viscoelastic:  # fe.solve leaves the Prony series out: its edit must not re-solve
        material.pop("prony")
    payload = {"scene": fields, "material": material,
               "geometry": params.geometry_digest(), "schema": SCHEMA_VERSION, "version": __version__,
               "code": code_digest()}
    files = scene.indenter_kind.cache_content(scene)
    if files:  # only kinds that read files add the key (the others' keys stay as they were)
        payload["indenter_files"] = files
    skin_files = scene.skin_kind.cache_content(scene)
    if skin_files:  # likewise a user's skin file (skins.file)
        payload["skin_files"] = skin_files
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:24]


@dataclass
class CaseRecord:
    """One finished case as stored in the cache (validated)."""

    scene: Scene
    s: np.ndarray
    pressure: np.ndarray
    summary: dict
    path: Path
    case: str = ""      # the case id within its sweep (sweep.case_ids), set by the report
    variant: str = ""   # the id's suffix naming the fields that tell it apart ("d0.2-r2")
    variant_label: str = ""  # the same as legends name it, with units ("d = 0.2 mm, rate 2 mm/s")
    material_label: str = ""  # the material as tables and figures name it (scene.material_labels)


def material_of(rec) -> str:
    """A record's material as tables and figures name it: its label, else the scene's material."""
    return getattr(rec, "material_label", "") or rec.scene.material


def read_profile(path: Path) -> tuple[np.ndarray, np.ndarray]:
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    s = np.array([float(r["s_mm"]) for r in rows])
    p = np.array([float(r["pressure_mpa"]) for r in rows])
    return s, p


def _plain(d: dict) -> dict:
    """As TOML reads it back (tuples as lists)."""
    return json.loads(json.dumps(d))


def _stored_fields(path: Path, scene: Scene) -> dict:
    """The fields an entry's scene.toml records, without those whose file contents are in the
    key (as _scene_fields). Read as written, not rebuilt into a Scene: rebuilding would read
    the files it names, and a moved or renamed file (same bytes, same key) would read as a
    damaged entry."""
    from tactileskin.params import read_toml

    d = read_toml(path, "cache entry scene.toml")
    d.pop("material", None)
    for name in (*scene.indenter_kind.cache_content(scene), *scene.skin_kind.cache_content(scene)):
        d.pop(name, None)
    return _plain(d)


def _scene_fields(scene: Scene) -> dict:
    d = scene.to_dict()
    d.pop("material")  # its content is in the key; the file may have been renamed
    for name in scene.indenter_kind.cache_content(scene):
        d.pop(name, None)  # likewise an indenter file: its bytes are in the key, not its path
    for name in scene.skin_kind.cache_content(scene):
        d.pop(name, None)  # and a skin file
    return d


class CaseLock:
    """An exclusive flock on `<cache>/<key>.lock`, held until release() or process exit."""

    def __init__(self, path: Path, fd: int | None):
        self.path, self._fd = path, fd

    def release(self) -> None:
        if self._fd is not None:
            try:
                fcntl.flock(self._fd, fcntl.LOCK_UN)
            finally:
                os.close(self._fd)
                self._fd = None


# the list of a derived entry's files (load_files), not cache.json: a folder holding a
# cache.json is a solved case's entry
DERIVED_MANIFEST = "files.json"


def out_cache(out) -> Path:
    """`out`/cache, the default cache of a command writing into `out`. A symbolic link there
    is refused (OutputError naming it): followed, it put the case entries and locks outside
    `out`, or read a user's folder as the cache. A shared cache is named explicitly (--cache)."""
    from tactileskin.fileio import OutputError

    path = Path(out) / "cache"
    if path.is_symlink():
        try:
            target = os.readlink(path)
        except OSError:
            target = "?"
        raise OutputError(path, f"it is a symbolic link (to {target}), and the out folder's cache is its own; "
                                "to share a cache folder, name it with --cache (cache= in Python)")
    return path


# the names a cache holds: case entries (cache_key), derived entries (figures-, render-: the
# sweep's report), their .lock files; anything else in a folder means it is not a cache
_ENTRY_NAME = re.compile(r"^(?:figures-|render-)?[0-9a-f]{24}$")
# what the system writes into any folder, a cache too: Finder's .DS_Store and ._ companions (a
# cache opened by hand, one on a network or exFAT volume), NFS's .nfsXXXX (a file unlinked
# while another client holds it open: a lock), Windows' Thumbs.db and desktop.ini, a mount
# point's lost+found
_SYSTEM_NAME = re.compile(r"^(?:\.DS_Store|\._.+|\.nfs[0-9a-f]+|Thumbs\.db|desktop\.ini|lost\+found)$")


def open_cache(root, what: str = "--cache") -> "ResultCache":
    """The cache in `root`, a folder the user named (`what`: the option or parameter): refused
    (OutputError, nothing written) unless it is new, empty, or holds a cache's files only: its
    entries (each with its cache.json or files.json) and locks. A folder of the user's own files
    would get entries and locks among them, and lookup's removal of a damaged entry is for the
    cache's own folders."""
    from tactileskin.fileio import OutputError

    root = Path(root)
    if root.is_dir():
        with fileio.os_errors(root):
            names = sorted(p.name for p in root.iterdir() if not fileio.is_temporary(p.name)
                           and not _SYSTEM_NAME.match(p.name) and not _cache_file(root / p.name))
        if names:
            shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
            if all(_ENTRY_NAME.match(n) and (root / n).is_dir() and not (root / n).is_symlink()
                   for n in names):  # a cache's entries, their manifests lost
                raise OutputError(root, f"its entries {shown} have no cache.json or files.json (damaged, as by "
                                        f"a copy cut short), so {what} is not taken for a cache tactileskin "
                                        "made; remove them (their cases are solved again)")
            raise OutputError(root, f"{what} must be a new or empty folder, or a cache made by tactileskin; "
                                    f"this one holds other files ({shown})")
    elif root.exists() or root.is_symlink():
        raise OutputError(root, f"{what} must be a folder (new or empty, or a cache made by tactileskin), "
                                "and this is not")
    return ResultCache(root)


def _cache_file(p: Path) -> bool:
    if p.is_symlink():
        return False
    if p.suffix == ".lock":
        return _ENTRY_NAME.match(p.stem) is not None and p.is_file()
    return (_ENTRY_NAME.match(p.name) is not None and p.is_dir()
            and ((p / "cache.json").is_file() or (p / DERIVED_MANIFEST).is_file()))


class ResultCache:
    def __init__(self, root: str | Path):
        self.root = Path(root)

    def key(self, scene: Scene) -> str:
        return cache_key(scene)

    def path(self, scene: Scene, key: str | None = None) -> Path:
        return self.root / (key or self.key(scene))

    # --- reading ------------------------------------------------------------------------
    def lookup(self, scene: Scene, key: str | None = None, *, repair: bool = True) -> CaseRecord | None:
        """The validated entry of `scene`, or None when there is none or it is damaged.
        With repair, a damaged entry is logged (WARNING, naming its path) and removed."""
        if code_changes():
            return None  # not the code the key names runs here (logged): not reused
        key = key or self.key(scene)
        return self._validated(self.root / key, scene, key, repair)

    def _validated(self, p: Path, scene: Scene, key: str, repair: bool) -> CaseRecord | None:
        """The entry at p through the cache's validation; with repair a damaged one is logged
        (WARNING, naming its path) and removed."""
        rec, problem = self._check(p, scene, key)
        if problem and repair:
            log.warning("cache entry %s is damaged (%s); it is removed and the case recomputed", p, problem)
            self._discard(p)
        return rec

    def has(self, scene: Scene) -> bool:
        return self.lookup(scene) is not None

    def load(self, scene: Scene) -> CaseRecord:
        rec = self.lookup(scene)
        if rec is None:
            raise CacheError(f"no valid cached result for {scene.label()} in {self.root}")
        return rec

    def _check(self, p: Path, scene: Scene, key: str) -> tuple[CaseRecord | None, str | None]:
        if not os.path.lexists(p):
            return None, None
        if p.is_symlink() or not p.is_dir():
            return None, "not a folder"
        name = "cache.json"
        try:
            meta = json.loads((p / name).read_text(encoding="utf-8"))
            if not isinstance(meta, dict):
                raise ValueError("not a JSON object")
            if meta.get("schema") != SCHEMA_VERSION:
                raise ValueError(f"schema {meta.get('schema')!r}, expected {SCHEMA_VERSION}")
            if meta.get("key") != key:
                raise ValueError(f"written for key {meta.get('key')!r}")
            files = meta.get("files")
            if not isinstance(files, dict) or not files:
                raise ValueError("no list of the entry's files")
            for fname, digest in files.items():
                if Path(fname).name != fname or fname == "cache.json":
                    raise ValueError(f"lists {fname!r}")
                if not (p / fname).is_file():
                    raise ValueError(f"{fname} is missing")
                if fileio.file_sha256(p / fname) != digest:
                    raise ValueError(f"the bytes of {fname} changed since the entry was written")
            name = "summary.json"
            summary = json.loads((p / name).read_text(encoding="utf-8"))
            if not isinstance(summary, dict):
                raise ValueError("not a JSON object")
            for k in ("peak_mpa", "span_mm", "auc_mpa_mm"):
                v = summary.get(k)
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise ValueError(f"{k} = {v!r}, expected a finite number")
            name = "profile.csv"
            s, pr = read_profile(p / name)
            if s.size < 2:
                raise ValueError(f"{s.size} rows, expected at least 2")
            if not (np.all(np.isfinite(s)) and np.all(np.isfinite(pr))):
                raise ValueError("non-finite values")
            if np.any(np.diff(s) <= 0):
                raise ValueError("s is not increasing")
            # entries written before the summary had it: quality's tensile-bone check reads it
            summary.setdefault("profile_min_mpa", float(np.min(pr)))
            name = "scene.toml"
            if _stored_fields(p / name, scene) != _plain(_scene_fields(scene)):
                raise ValueError("describes another scene")
        except FileNotFoundError:
            return None, f"{name} is missing"
        except (OSError, ValueError, KeyError, TypeError, TactileSkinError) as e:
            return None, f"{name}: {e}"
        return CaseRecord(scene, s, pr, summary, p), None

    def _discard(self, p: Path) -> None:
        """Remove a damaged entry: it is the cache's own folder (named by a key)."""
        try:
            if p.is_symlink() or not p.is_dir():
                p.unlink()
                return
            aside = p.parent / f"{fileio.tmp_prefix(p)}bad.partial"  # clean_stale finishes it
            os.replace(p, aside)
            shutil.rmtree(aside, ignore_errors=True)
        except OSError as e:
            log.warning("could not remove the damaged cache entry %s: %s", p, e)

    # --- writing ------------------------------------------------------------------------
    def store(self, scene: Scene, result, key: str | None = None) -> Path:
        """Write `result` (has .write_owned(dir)) under the scene's key, atomically."""
        if changed := code_changes():
            raise CacheError(f"not stored: {changed_code_message(changed)}")
        key = key or self.key(scene)
        final = self.root / key
        with fileio.os_errors(final), staging.staged_dir(final) as tmp:
            result.write_owned(tmp)
            scene.to_toml(tmp / "scene.toml")
            files = {f.name: fileio.file_sha256(f) for f in sorted(tmp.iterdir()) if f.is_file()}
            (tmp / "cache.json").write_text(json.dumps(
                {"schema": SCHEMA_VERSION, "key": key, "version": __version__, "files": files}, indent=2) + "\n",
                encoding="utf-8")
            fileio.fix_tree_modes(tmp)
        return final

    def store_record(self, scene: Scene, result, key: str) -> CaseRecord | None:
        """store, then the entry read back through the cache's validation (as lookup: a damaged
        one is logged and removed, None). Without lookup's second code check: the entry is the
        one store just wrote under its own (each check hashes the package's ~130 sources)."""
        return self._validated(self.store(scene, result, key), scene, key, repair=True)

    # --- files derived from entries (a sweep's figures) -------------------------------------
    def load_files(self, name: str) -> list[tuple[str, bytes]] | None:
        """The (file name, bytes) of the derived entry `name` (store_files), in their order, or
        None when there is none or it is damaged (a file missing or its bytes changed: not
        used, and replaced by the next store_files)."""
        if code_changes():
            return None  # not the code the name's digest names (logged): not reused
        p = self.root / name
        try:
            meta = json.loads((p / DERIVED_MANIFEST).read_text(encoding="utf-8"))
            if meta.get("schema") != SCHEMA_VERSION or meta.get("key") != name:
                return None
            out = []
            for fname, digest in meta["files"]:
                if Path(fname).name != fname or fname == DERIVED_MANIFEST:
                    return None
                data = (p / fname).read_bytes()
                if hashlib.sha256(data).hexdigest() != digest:
                    log.warning("cache entry %s is damaged (the bytes of %s changed); not used", p, fname)
                    return None
                out.append((fname, data))
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            return None
        return out or None

    def store_files(self, name: str, paths: list[Path]) -> None:
        """Keep copies of `paths` (files this run wrote) as the derived entry `name`, atomically."""
        if code_changes():
            return  # not the code the name's digest names (logged)
        final = self.root / name
        with fileio.os_errors(final), staging.staged_dir(final) as tmp:
            files = []
            for f in paths:
                data = Path(f).read_bytes()
                (tmp / Path(f).name).write_bytes(data)
                files.append([Path(f).name, hashlib.sha256(data).hexdigest()])
            (tmp / DERIVED_MANIFEST).write_text(json.dumps(
                {"schema": SCHEMA_VERSION, "key": name, "version": __version__, "files": files}, indent=2) + "\n",
                encoding="utf-8")
            fileio.fix_tree_modes(tmp)

    def lock(self, key: str, *, blocking: bool) -> CaseLock | None:
        """Take the case's lock; None if another process holds it and not blocking."""
        path = self.root / f"{key}.lock"
        if fcntl is None:
            return CaseLock(path, None)
        while True:
            fileio.make_dirs(self.root)
            with fileio.os_errors(path):
                fd = open_lock_file(path, os.O_RDWR)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | (0 if blocking else fcntl.LOCK_NB))
                if fileio.is_open_file(fd, path):
                    return CaseLock(path, fd)
            except BlockingIOError:
                os.close(fd)
                return None
            except BaseException:
                os.close(fd)
                raise
            # removed while we waited (outdir's cleanup of a failed sweep's new folder): a lock
            # on the removed file would not keep a third run off the case
            os.close(fd)
