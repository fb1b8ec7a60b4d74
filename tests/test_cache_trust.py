"""The result cache can be trusted: its key covers the material and geometry files, damaged
entries are recomputed with a warning (never used), and two runs share one case's work."""

import json
import logging
import os
import shutil
import threading
import time
import tomllib

import numpy as np
import pytest
import tomli_w

from tactileskin import params
from tactileskin.cache import ResultCache, cache_key
from tactileskin.materials import get_material
from tactileskin.report.outputs import collect
from tactileskin.results import Result
from tactileskin.scene import Scene
from tactileskin.sweep import run_sweep

COARSE = dict(thickness=1.0, mesh_size=1.0, refinement=2.0)


def _material_file(path, mu_scale=1.0):
    d = get_material("polyurethane").to_dict()
    d["hyperfoam"]["mu"] = [m * mu_scale for m in d["hyperfoam"]["mu"]]
    d.pop("name")
    path.write_text(tomli_w.dumps(d))
    return path


@pytest.fixture
def geometry(tmp_path, monkeypatch):
    """A private copy of the geometry parameter files, used by this process."""
    folder = tmp_path / "geometry"
    shutil.copytree(params.geometry_dir(), folder)
    monkeypatch.setenv("TACTILESKIN_GEOMETRY", str(folder))
    return folder


def _set_radius(folder, radius):
    p = folder / "indenters.toml"
    text = p.read_text()
    assert "radius = 12.0" in text
    p.write_text(text.replace("radius = 12.0", f"radius = {radius}"))


# --- the key ---------------------------------------------------------------------------------

def test_key_follows_material_content_not_its_path(tmp_path):
    a = _material_file(tmp_path / "pu.toml")
    k = cache_key(Scene(material=str(a)))
    b = tmp_path / "renamed.toml"
    a.rename(b)
    assert cache_key(Scene(material=str(b))) == k            # renaming alone: same result
    _material_file(b, mu_scale=10.0)
    assert cache_key(Scene(material=str(b))) != k            # mu x10: another result
    assert cache_key(Scene(material="polyurethane")) != cache_key(Scene(material="silicone"))


def test_an_elastic_key_ignores_the_prony_series_it_does_not_solve_with(tmp_path):
    # editing g of a material re-solved its elastic cases (viscoelastic = false), whose solve
    # never reads the Prony series; the viscoelastic cases' key still follows it
    p = _material_file(tmp_path / "pu.toml")
    elastic, visco = Scene(material=str(p), viscoelastic=False), Scene(material=str(p))
    ke, kv = cache_key(elastic), cache_key(visco)
    d = tomllib.loads(p.read_text())
    d["prony"]["g"][0] *= 1.01
    p.write_text(tomli_w.dumps(d))
    assert cache_key(elastic) == ke and cache_key(visco) != kv
    d["hyperfoam"]["mu"][0] *= 1.01
    p.write_text(tomli_w.dumps(d))
    assert cache_key(elastic) != ke


def test_key_ignores_the_mold_file_no_solve_reads(geometry):
    # molds.toml (the casting mold, `build` only) was hashed into every key: widening the mold
    # wall re-solved every cached case of a sweep; a Braille dimension still changes the key
    sc = Scene(indenter="braille")
    k = cache_key(sc)
    f = geometry / "molds.toml"
    text = f.read_text()
    assert "wall = 4.0 " in text
    f.write_text(text.replace("wall = 4.0 ", "wall = 4.5 "))
    assert cache_key(sc) == k
    b = geometry / "braille.toml"
    text = b.read_text()
    assert "height = 0.48" in text
    b.write_text(text.replace("height = 0.48", "height = 0.5"))
    assert cache_key(sc) != k


def test_code_digest_leaves_out_the_shipped_mold_file(tmp_path):
    # the packaged data/geometry/*.toml are also package files: editing the shipped molds.toml in
    # place (the one source of truth, README) changed code_digest, so every case re-solved anyway
    from tactileskin.cache import code_digest

    pkg = tmp_path / "pkg"
    (pkg / "data" / "geometry").mkdir(parents=True)
    (pkg / "data" / "geometry" / "molds.toml").write_text("wall = 4.0\n")
    (pkg / "data" / "geometry" / "braille.toml").write_text("height = 0.48\n")
    d0 = code_digest(pkg)
    (pkg / "data" / "geometry" / "molds.toml").write_text("wall = 4.5\n")
    code_digest.cache_clear()
    assert code_digest(pkg) == d0
    (pkg / "data" / "geometry" / "braille.toml").write_text("height = 0.5\n")
    code_digest.cache_clear()
    assert code_digest(pkg) != d0  # a file a solve reads still counts
    code_digest.cache_clear()


def test_key_and_loads_follow_geometry_files_within_a_process(geometry):
    sc = Scene(indenter="curved")
    k = cache_key(sc)
    assert params.load("indenters")["curved"]["radius"] == 12.0
    _set_radius(geometry, 20)
    assert params.load("indenters")["curved"]["radius"] == 20.0   # not served from a stale memo
    assert cache_key(sc) != k
    f = geometry / "indenters.toml"
    f.write_text(f.read_text().replace("radius = 20", "radius = 12.0"))  # undone: the old key again
    assert cache_key(sc) == k


def test_a_comment_in_a_geometry_file_keeps_the_keys(geometry):
    """The key hashed the geometry files' bytes: a comment added to the user's indenters.toml
    (TACTILESKIN_GEOMETRY), or its lines re-spaced, re-solved every cached case with the same
    numbers. It hashes what the file says (its parsed values); a value still changes it."""
    sc = Scene(indenter="curved")
    k = cache_key(sc)
    f = geometry / "indenters.toml"
    text = f.read_text()
    f.write_text("# my notes: the curved radius is the paper's\n" + text.replace("radius = 12.0", "radius   =   12.0"))
    assert cache_key(sc) == k
    f.write_text(text.replace("radius = 12.0", "radius = 12.5"))
    assert cache_key(sc) != k
    f.write_text(text.replace("radius = 12.0", "radius = 12"))  # an integer: not the same TOML value
    assert cache_key(sc) != k
    f.write_text("[[[not toml")  # unreadable: keyed by its bytes, the solve names the error
    assert cache_key(sc) != k


def test_key_follows_schema_and_version(monkeypatch):
    import tactileskin.cache as cache_mod

    sc = Scene()
    k = cache_key(sc)
    monkeypatch.setattr(cache_mod, "SCHEMA_VERSION", cache_mod.SCHEMA_VERSION + 1)
    k2 = cache_key(sc)
    monkeypatch.setattr(cache_mod, "__version__", "99.0")
    assert len({k, k2, cache_key(sc)}) == 3


def test_key_follows_the_code_that_computes(tmp_path, monkeypatch):
    """Another tactileskin (an update, an edited solver) or another mesher version never reuses
    a result: the key covers the package's files and the solving libraries' versions."""
    from tactileskin.cache import code_digest

    pkg = tmp_path / "pkg"
    (pkg / "fe").mkdir(parents=True)
    (pkg / "fe" / "solver.py").write_text("RTOL = 1e-8\n")
    (pkg / "data.json").write_text("{}")
    d0 = code_digest(pkg)
    (pkg / "__pycache__").mkdir()
    (pkg / "__pycache__" / "solver.cpython-311.pyc").write_bytes(b"\0compiled")
    (pkg / "notes.txt").write_text("not code")
    code_digest.cache_clear()
    assert code_digest(pkg) == d0                      # byte-code and other files do not count
    (pkg / "fe" / "solver.py").write_text("RTOL = 1e-6\n")
    code_digest.cache_clear()
    d1 = code_digest(pkg)
    assert d1 != d0                                    # one changed constant: another key
    (pkg / "fe" / "solver.py").rename(pkg / "solver.py")
    code_digest.cache_clear()
    assert code_digest(pkg) not in (d0, d1)            # a moved module is other code too

    code_digest.cache_clear()
    sc = Scene()
    k = cache_key(sc)
    from importlib import metadata

    real = metadata.version
    monkeypatch.setattr(metadata, "version", lambda name: "0.0-other" if name == "gmsh" else real(name))
    code_digest.cache_clear()
    assert cache_key(sc) != k                          # another gmsh meshes differently
    monkeypatch.undo()
    code_digest.cache_clear()
    assert cache_key(sc) == k


def test_key_follows_the_gmsh_that_python_imports(tmp_path):
    """A gmsh SDK's lib folder on PYTHONPATH (as its docs say to set up) shadows the pip gmsh:
    its own gmsh.py and libgmsh mesh, while the key named the pip distribution's version, so
    upgrading the SDK reused the old mesher's results. The key has the API version of the
    gmsh.py that `import gmsh` loads (read from it: libgmsh is not loaded for a key)."""
    import subprocess
    import sys
    from pathlib import Path

    import tactileskin

    src = Path(tactileskin.__file__).parent.parent
    code = ("from tactileskin.cache import cache_key; from tactileskin.scene import Scene; "
            "import sys; print(cache_key(Scene())); assert 'gmsh' not in sys.modules")

    def key(*path):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(map(str, (*path, src))))
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
        assert r.returncode == 0, r.stderr
        return r.stdout.split()[-1]

    sdk = tmp_path / "gmsh-sdk" / "lib"
    sdk.mkdir(parents=True)
    (sdk / "gmsh.py").write_text('GMSH_API_VERSION = "4.11.1"\n')
    old = key(sdk)
    (sdk / "gmsh.py").write_text('GMSH_API_VERSION = "4.13.0"\n')      # the SDK upgraded
    assert key(sdk) != old
    assert key() not in (old, key(sdk))                                 # the pip gmsh, unshadowed


def test_stale_bytecode_is_keyed_as_the_code_it_runs(tmp_path, caplog):
    """Python takes a .pyc while it names its source's mtime (whole seconds) and size: a same-size
    edit with the time stamp set back (touch -d, cp -p) or within the second the .pyc was compiled
    in runs the old code. Its results took the new source's key and were reused as the new code's
    once the .pyc was refreshed (a results.py printing 10 digits stood for one printing 12)."""
    import importlib.util
    import py_compile

    from tactileskin.cache import code_digest

    pkg = tmp_path / "pkg"
    pkg.mkdir()
    mod = pkg / "rtol.py"
    mod.write_text("RTOL = 1e-8\n")
    st = mod.stat()
    pyc = importlib.util.cache_from_source(str(mod))

    def compile_pyc():
        py_compile.compile(str(mod), cfile=pyc, doraise=True,
                           invalidation_mode=py_compile.PycInvalidationMode.TIMESTAMP)

    compile_pyc()
    mod.write_text("RTOL = 1e-6\n")                    # same size, time stamp set back
    os.utime(mod, ns=(st.st_atime_ns, st.st_mtime_ns))
    spec = importlib.util.spec_from_file_location("rtol_stale", mod)
    ran = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ran)
    assert ran.RTOL == 1e-8                            # the premise: Python runs the old code
    code_digest.cache_clear()
    with caplog.at_level(logging.WARNING, logger="tactileskin.cache"):
        stale = code_digest(pkg)
    os.remove(pyc)                                     # refreshed: the file's own code runs
    code_digest.cache_clear()
    fresh = code_digest(pkg)
    assert stale != fresh                              # the old code's results are not the new code's
    assert "rtol.py" in caplog.text and "earlier version" in caplog.text
    compile_pyc()                                      # a .pyc that matches its source changes nothing
    code_digest.cache_clear()
    assert code_digest(pkg) == fresh
    code_digest.cache_clear()


def test_unchecked_hash_bytecode_is_keyed_as_the_code_it_runs(tmp_path, caplog):
    """A PEP 552 unchecked-hash .pyc (`py_compile --invalidation-mode unchecked-hash`: distro
    packages, reproducible builds) runs whatever its source now says; only time-stamp .pyc files
    were compared, so an edited source's key was given to the old code's results. A checked-hash
    .pyc is recompiled from a changed source: it changes nothing."""
    import importlib.util
    import py_compile

    from tactileskin.cache import code_digest

    pkg = tmp_path / "pkg"
    pkg.mkdir()
    mod = pkg / "rtol.py"
    pyc = importlib.util.cache_from_source(str(mod))

    def compile_pyc(mode):
        py_compile.compile(str(mod), cfile=pyc, doraise=True, invalidation_mode=mode)

    def digest():
        code_digest.cache_clear()
        return code_digest(pkg)

    mod.write_text("RTOL = 1e-8\n")
    compile_pyc(py_compile.PycInvalidationMode.UNCHECKED_HASH)
    mod.write_text("RTOL = 1e-06\n")                   # edited: another size and time stamp
    spec = importlib.util.spec_from_file_location("rtol_unchecked", mod)
    ran = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ran)
    assert ran.RTOL == 1e-8                            # the premise: Python runs the old code
    with caplog.at_level(logging.WARNING, logger="tactileskin.cache"):
        stale = digest()
    os.remove(pyc)
    fresh = digest()
    assert stale != fresh                              # the old code's results are not the new code's
    assert "rtol.py" in caplog.text and "earlier version" in caplog.text
    compile_pyc(py_compile.PycInvalidationMode.UNCHECKED_HASH)   # compiled from this source: the same code
    assert digest() == fresh
    mod.write_text("RTOL = 1e-8\n")
    compile_pyc(py_compile.PycInvalidationMode.CHECKED_HASH)
    mod.write_text("RTOL = 1e-06\n")                   # Python sees the hash differ and compiles the source
    assert digest() == fresh
    code_digest.cache_clear()


# A long-lived Python (a notebook kernel) on a copy of the package: it imports tactileskin, then
# `git pull` edits a module it already ran, then it runs a serial sweep (its solve stubbed: quick)
_SESSION = """
import json, sys
import numpy as np
import tactileskin.sweep as sw
from pathlib import Path
from tactileskin.cache import ResultCache, cache_key
from tactileskin.results import Result
from tactileskin.scene import Scene

sc = Scene(thickness=1.0, mesh_size=1.0, refinement=2.0)
src = Path(sw.__file__).parent / "results.py"
src.write_text(src.read_text() + "\\nEDITED = True\\n")   # the pull
s = np.linspace(0.0, 5.0, 11)
sw.solve_case = lambda scene: Result(s=s, pressure=np.exp(-s ** 2), contact_x=s[:3], contact_pressure=s[:3],
                                     reaction=0.5, stats={"dofs": 10, "increments": 1, "newton_iterations": 2})
outs = [sw.run_sweep([sc], ResultCache(sys.argv[1]), serial=True)[0] for _ in range(2)]
print(json.dumps({"key": cache_key(sc), "status": [o.status for o in outs], "error": outs[0].error}))
"""

_FRESH = """
import json, sys
import tactileskin.sweep as sw
from tactileskin.cache import ResultCache, cache_key
from tactileskin.scene import Scene

sc = Scene(thickness=1.0, mesh_size=1.0, refinement=2.0)
sw.solve_case = lambda scene: None   # a Dask worker of the session's sweep: must not get this far
ran = sw._run_one_safely(sc, sys.argv[2])
print(json.dumps({"key": cache_key(sc), "found": ResultCache(sys.argv[1]).lookup(sc) is not None,
                  "worker": ran[0], "worker_error": ran[3]}))
"""


def _run_python(pkg, code, *args):
    import subprocess
    import sys

    env = dict(os.environ, PYTHONPATH=str(pkg))
    r = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.splitlines()[-1]), r.stderr


def test_sources_edited_after_import_are_neither_keyed_nor_stored_as_the_new_code(tmp_path):
    """The key hashed the package's files on disk at its first use: after a `git pull` in a
    running kernel, the old code's result was stored under the new code's key, and every fresh
    process (new code) reused it. The key names the code this process imported; while the
    sources on disk differ from it, no entry is stored or reused (a WARNING names the file)."""
    from pathlib import Path

    import tactileskin

    pkg = tmp_path / "src"
    shutil.copytree(Path(tactileskin.__file__).parent, pkg / "tactileskin",
                    ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "cache"
    session, log_text = _run_python(pkg, _SESSION, cache)
    # the session's key names the code it runs: the unedited package's (this process's)
    assert session["key"] == cache_key(Scene(**COARSE))
    assert session["status"] == ["failed", "failed"] and "restart" in session["error"]
    assert log_text.count("results.py") == 1 and "restart" in log_text   # warned once, naming the file
    assert not [p for p in cache.iterdir() if p.is_dir()]                # nothing stored
    fresh, _ = _run_python(pkg, _FRESH, cache, session["key"])
    assert fresh["key"] != session["key"]          # the new code: another key
    assert not fresh["found"]                       # the old code's result is not reused as the new code's
    # a worker started after the pull runs the new code: it refuses the sweep's (old code's) key
    assert fresh["worker"] == "failed" and "differ from the sweep's" in fresh["worker_error"]


def test_reloading_the_package_keeps_the_sources_it_imported(tmp_path):
    """importlib.reload(tactileskin) (to pick up a `git pull`) re-ran the package's snapshot of
    its sources: the edited results.py read as imported while the module already loaded still
    ran the old code, so the old code's result was stored under the new code's key, which every
    fresh process (the new code) reuses. The snapshot stays the first import's."""
    from pathlib import Path

    import tactileskin

    pkg = tmp_path / "src"
    shutil.copytree(Path(tactileskin.__file__).parent, pkg / "tactileskin",
                    ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "cache"
    code = _SESSION.replace("# the pull\n", "# the pull\nimport importlib, tactileskin; importlib.reload(tactileskin)\n")
    assert code != _SESSION
    session, log_text = _run_python(pkg, code, cache)
    assert session["key"] == cache_key(Scene(**COARSE))                  # the code it runs: the old
    assert session["status"] == ["failed", "failed"] and "restart" in session["error"]
    assert "results.py" in log_text
    assert not [p for p in cache.iterdir() if p.is_dir()]                # nothing stored


_CLI_PULL_MID_RUN = """
import sys
import numpy as np
import tactileskin.sweep as sw
from pathlib import Path
from tactileskin.cli import main
from tactileskin.results import Result

def solve_then_pull(scene):   # the first case's solve ends as `git pull` edits a module
    src = Path(sw.__file__).parent / "results.py"
    src.write_text(src.read_text() + "\\nEDITED = True\\n")
    s = np.linspace(0.0, 5.0, 11)
    return Result(s=s, pressure=np.exp(-s ** 2), contact_x=s[:3], contact_pressure=s[:3], reaction=0.5,
                  stats={"dofs": 10, "increments": 1, "newton_iterations": 2})

sw.solve_case = solve_then_pull
sys.exit(main(["sweep", "-t", "1,2", "-i", "flat", "-m", "polyurethane", "--quality", "preview", "--serial",
               "--no-render", "-o", sys.argv[1], "--cache", sys.argv[2]]))
"""


def test_cli_sweep_warns_once_when_the_sources_change_mid_run(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    import tactileskin

    pkg = tmp_path / "src"
    shutil.copytree(Path(tactileskin.__file__).parent, pkg / "tactileskin",
                    ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "cache"
    r = subprocess.run([sys.executable, "-c", _CLI_PULL_MID_RUN, str(tmp_path / "out"), str(cache)],
                       capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(pkg), COLUMNS="400"))
    text = r.stdout + r.stderr
    assert r.returncode == 1, text                                    # both cases failed
    assert text.count("WARNING") == 1 and "restart Python" in text    # one warning, not one per case
    assert "not stored" in text and "not solved" in text              # solved before the pull; after it not
    assert not [p for p in cache.iterdir() if p.is_dir()]


def test_unchecked_hash_bytecode_of_the_package_is_keyed_apart(tmp_path):
    """As above, in a copy of the package itself (the key of a fresh process importing it)."""
    import importlib.util
    import py_compile
    from pathlib import Path

    import tactileskin

    pkg = tmp_path / "src"
    shutil.copytree(Path(tactileskin.__file__).parent, pkg / "tactileskin",
                    ignore=shutil.ignore_patterns("__pycache__"))
    mod = pkg / "tactileskin" / "results.py"
    pyc = importlib.util.cache_from_source(str(mod))
    py_compile.compile(str(mod), cfile=pyc, doraise=True, invalidation_mode=py_compile.PycInvalidationMode.UNCHECKED_HASH)
    mod.write_text(mod.read_text() + "\nEDITED = True\n")
    code = ("import json, tactileskin.results as r; from tactileskin.cache import cache_key; "
            "from tactileskin.scene import Scene; print(json.dumps({'key': cache_key(Scene()), "
            "'edited': hasattr(r, 'EDITED')}))")
    stale, log_text = _run_python(pkg, code)
    assert not stale["edited"]                          # the premise: the .pyc's old code runs
    assert "results.py" in log_text and "unchecked-hash" in log_text
    os.remove(pyc)
    fresh, _ = _run_python(pkg, code)
    assert fresh["edited"] and fresh["key"] != stale["key"]


def test_edited_material_file_is_recomputed(tmp_path):
    mat = _material_file(tmp_path / "pu.toml")
    sc = Scene(material=str(mat), indenter="curved", **COARSE)
    cache = ResultCache(tmp_path / "cache")
    first = run_sweep([sc], cache, serial=True)[0]
    assert first.status == "done"
    assert run_sweep([sc], cache, serial=True)[0].status == "cached"
    _material_file(mat, mu_scale=10.0)
    again = run_sweep([sc], cache, serial=True)[0]
    assert again.status == "done"
    assert again.record.summary["peak_mpa"] > 1.5 * first.record.summary["peak_mpa"]


def test_edited_curved_radius_is_recomputed(tmp_path, geometry):
    sc = Scene(material="polyurethane", indenter="curved", **COARSE)
    cache = ResultCache(tmp_path / "cache")
    r12 = run_sweep([sc], cache, serial=True)[0]
    assert r12.status == "done"
    _set_radius(geometry, 20)
    r20 = run_sweep([sc], cache, serial=True)[0]
    assert r20.status == "done"
    # a flatter cylinder spreads the same indentation: the profile changes
    assert r20.record.summary["span_mm"] != pytest.approx(r12.record.summary["span_mm"], rel=1e-3)


# --- damaged entries -------------------------------------------------------------------------

def _result(peak=0.4):
    s = np.linspace(0.0, 5.0, 11)
    p = peak * np.exp(-s ** 2)
    return Result(s=s, pressure=p, contact_x=s[:3], contact_pressure=p[:3], reaction=0.5,
                  stats={"dofs": 10, "increments": 1, "newton_iterations": 2, "wall_s": 0.1})


def _damage(entry, kind):
    prof, summ = entry / "profile.csv", entry / "summary.json"
    if kind == "truncated profile":
        prof.write_bytes(prof.read_bytes()[:25])
    elif kind == "empty summary":
        summ.write_text("")
    elif kind == "corrupt summary":
        summ.write_bytes(b"\x00\xff{not json")
    elif kind == "summary a list":
        summ.write_text("[1, 2]")
    elif kind == "NaN peak":
        d = json.loads(summ.read_text())
        d["peak_mpa"] = float("nan")
        summ.write_text(json.dumps(d))
    elif kind == "NaN in profile":
        lines = prof.read_text().splitlines()
        lines[3] = lines[3].split(",")[0] + ",nan"
        prof.write_text("\n".join(lines) + "\n")
    elif kind == "s not increasing":
        lines = prof.read_text().splitlines()
        lines[2], lines[3] = lines[3], lines[2]
        prof.write_text("\n".join(lines) + "\n")
    elif kind == "no cache.json":
        (entry / "cache.json").unlink()
    elif kind == "old schema":
        d = json.loads((entry / "cache.json").read_text())
        d["schema"] -= 1
        (entry / "cache.json").write_text(json.dumps(d))
    elif kind == "foreign scene":
        Scene(thickness=5.0).to_toml(entry / "scene.toml")
    elif kind == "profile cut at a line end":  # still a valid-looking profile of 4 rows
        prof.write_text("\n".join(prof.read_text().splitlines()[:5]) + "\n")
    elif kind == "missing contact.csv":
        (entry / "contact.csv").unlink()
    elif kind == "edited peak":  # a plausible number that the profile does not have
        d = json.loads(summ.read_text())
        d["peak_mpa"] = 99.0
        summ.write_text(json.dumps(d))
    elif kind == "no file list":
        d = json.loads((entry / "cache.json").read_text())
        del d["files"]
        (entry / "cache.json").write_text(json.dumps(d))
    elif kind == "entry is a file":
        shutil.rmtree(entry)
        entry.write_text("x")
    else:
        raise AssertionError(kind)


DAMAGE = ["truncated profile", "empty summary", "corrupt summary", "summary a list", "NaN peak",
          "NaN in profile", "s not increasing", "no cache.json", "old schema", "foreign scene",
          "profile cut at a line end", "missing contact.csv", "edited peak", "no file list", "entry is a file"]


@pytest.mark.parametrize("kind", DAMAGE)
def test_damaged_entry_is_warned_removed_and_never_used(tmp_path, caplog, kind):
    cache = ResultCache(tmp_path / "cache")
    sc = Scene(**COARSE)
    entry = cache.store(sc, _result())
    assert cache.lookup(sc) is not None
    _damage(entry, kind)
    with caplog.at_level(logging.WARNING, logger="tactileskin.cache"):
        assert cache.lookup(sc) is None
    assert any(str(entry) in r.getMessage() and r.levelno == logging.WARNING for r in caplog.records)
    assert not entry.exists()
    assert not any(p.name.endswith(".partial") for p in cache.root.iterdir())
    cache.store(sc, _result(peak=0.7))
    assert cache.load(sc).summary["peak_mpa"] == pytest.approx(0.7)


@pytest.mark.parametrize("kind", ["NaN in profile", "truncated profile", "empty summary"])
def test_sweep_recomputes_a_damaged_case_and_reports_it(tmp_path, caplog, kind):
    cache = ResultCache(tmp_path / "cache")
    sc = Scene(material="polyurethane", **COARSE)
    good = run_sweep([sc], cache, serial=True)[0]
    _damage(good.record.path, kind)
    with caplog.at_level(logging.WARNING):
        again = run_sweep([sc], cache, serial=True)[0]
    assert again.status == "done"
    assert any(str(good.record.path) in r.getMessage() for r in caplog.records if r.levelno == logging.WARNING)
    records, rows, _ = collect([again], cache)
    assert rows[0]["peak_mpa"] == pytest.approx(good.record.summary["peak_mpa"], rel=1e-9)
    assert np.all(np.isfinite(records[0].pressure))
    assert run_sweep([sc], cache, serial=True)[0].status == "cached"


# --- two runs, one cache ---------------------------------------------------------------------

def _counting_solver(monkeypatch):
    import tactileskin.sweep as sw

    real, calls = sw.solve_case, []
    one_at_a_time = threading.Lock()  # gmsh is not thread-safe; the runs' threads take turns

    def counted(scene):
        calls.append(scene)
        with one_at_a_time:
            return real(scene)

    monkeypatch.setattr(sw, "solve_case", counted)
    return calls


# a guard against a hang only, not a speed check: a clean clone's first solve in a process
# compiles the numba kernels (~11 s of CPU; 215 s wall at a load of 14 on 2 cores)
HANG_S = 600.0


def _wait_for(pred, timeout=HANG_S):
    t0 = time.monotonic()
    while not pred():
        assert time.monotonic() - t0 < timeout, "timed out"
        time.sleep(0.02)


@pytest.mark.parametrize("other_run_stores", [True, False])
def test_case_locked_by_another_run_is_waited_for(tmp_path, monkeypatch, caplog, other_run_stores):
    """The test holds one case's lock, as another sweep computing it would. The sweep does its
    other case first, waits, then reuses the other run's result (or computes the case itself
    when the other run ended without storing it)."""
    cache = ResultCache(tmp_path / "cache")
    mine = Scene(material="polyurethane", indenter="flat", **COARSE)
    theirs = Scene(material="polyurethane", indenter="curved", **COARSE)
    lock = cache.lock(cache.key(theirs), blocking=False)
    assert lock is not None
    calls = _counting_solver(monkeypatch)
    out = {}
    caplog.set_level(logging.WARNING, logger="tactileskin.sweep")
    th = threading.Thread(target=lambda: out.update(r=run_sweep([theirs, mine], cache, serial=True)))
    th.start()
    try:
        _wait_for(lambda: any("waiting" in r.getMessage() for r in caplog.records))
        assert calls == [mine] and th.is_alive()   # our own case first, then it waits
        if other_run_stores:
            cache.store(theirs, _result(peak=0.123))
    finally:
        lock.release()
    th.join(HANG_S)
    assert not th.is_alive()
    first, second = out["r"]
    assert second.status == "done"
    if other_run_stores:
        assert first.status == "cached" and calls == [mine]
        assert first.record.summary["peak_mpa"] == pytest.approx(0.123)
    else:
        assert first.status == "done" and calls == [mine, theirs]


def test_two_concurrent_sweeps_solve_each_case_once(tmp_path, monkeypatch):
    cache = ResultCache(tmp_path / "cache")
    scenes = [Scene(material="polyurethane", indenter=i, **COARSE) for i in ("flat", "curved")]
    calls = _counting_solver(monkeypatch)
    results = [None, None]

    def run(k):
        results[k] = run_sweep(scenes if k == 0 else scenes[::-1], cache, serial=True)

    threads = [threading.Thread(target=run, args=(k,)) for k in (0, 1)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(HANG_S)
        assert not th.is_alive()
    assert sorted(sc.indenter.value for sc in calls) == ["curved", "flat"]  # each solved once
    for res in results:
        assert all(o.status in ("done", "cached") for o in res)
    peaks = [{o.scene.indenter.value: o.record.summary["peak_mpa"] for o in res} for res in results]
    assert peaks[0] == peaks[1]


@pytest.mark.slow
def test_dask_sweep_waits_for_a_locked_case_then_reuses_it(tmp_path, caplog):
    cache = ResultCache(tmp_path / "cache")
    mine = Scene(material="polyurethane", indenter="flat", **COARSE)
    theirs = Scene(material="polyurethane", indenter="curved", **COARSE)
    lock = cache.lock(cache.key(theirs), blocking=False)
    out = {}
    caplog.set_level(logging.WARNING, logger="tactileskin.sweep")
    th = threading.Thread(target=lambda: out.update(r=run_sweep([mine, theirs], cache, workers=1)))
    th.start()
    try:
        _wait_for(lambda: any("waiting" in r.getMessage() for r in caplog.records))
        assert cache.has(mine) and not cache.has(theirs)
        cache.store(theirs, _result(peak=0.321))
    finally:
        lock.release()
    th.join(HANG_S)
    assert not th.is_alive()
    assert [o.status for o in out["r"]] == ["done", "cached"]
    assert out["r"][1].record.summary["peak_mpa"] == pytest.approx(0.321)


def test_geometry_edited_during_a_solve_is_not_stored(tmp_path, geometry, monkeypatch):
    import tactileskin.sweep as sw

    real = sw.solve_case

    def edit_then_solve(scene):
        _set_radius(geometry, 20)   # the user edits the file while the case is being solved
        return real(scene)

    monkeypatch.setattr(sw, "solve_case", edit_then_solve)
    sc = Scene(material="polyurethane", indenter="curved", **COARSE)
    cache = ResultCache(tmp_path / "cache")
    (oc,) = run_sweep([sc], cache, serial=True)
    assert oc.status == "failed" and "changed during the solve" in oc.error
    assert not [p for p in cache.root.iterdir() if p.is_dir()]   # stored under neither key


def test_results_key_column_names_the_entry_its_numbers_came_from(tmp_path, monkeypatch):
    """results.csv's key was recomputed from the files at report time: a material file edited
    during the sweep (its new case failed, the cached one reported) gave the cached row the
    key of the new content, an entry that does not hold its numbers (or one solved later)."""
    import tactileskin.sweep as sw

    mat = _material_file(tmp_path / "pu.toml")
    a = Scene(material=str(mat), indenter="flat", **COARSE)
    b = a.replace(indenter="curved")
    cache = ResultCache(tmp_path / "cache")
    run_sweep([a], cache, serial=True)
    real = sw.solve_case

    def edit_then_solve(scene):
        _material_file(mat, mu_scale=10.0)   # the user edits the file while b is solved
        return real(scene)

    monkeypatch.setattr(sw, "solve_case", edit_then_solve)
    outcomes = run_sweep([a, b], cache, serial=True)
    assert [o.status for o in outcomes] == ["cached", "failed"]
    _, rows, _ = collect(outcomes, cache)
    assert rows[0]["key"] == outcomes[0].record.path.name != cache_key(a)
    assert rows[1]["key"] == outcomes[1].key == cache_key(a.replace(indenter="curved", material="polyurethane"))


def test_one_entry_shared_by_equal_cases_is_solved_once(tmp_path, monkeypatch):
    calls = _counting_solver(monkeypatch)
    cache = ResultCache(tmp_path / "cache")
    mat = _material_file(tmp_path / "pu_copy.toml")   # the preset's numbers under another name
    a = Scene(material="polyurethane", **COARSE)
    b = a.replace(material=str(mat))
    outcomes = run_sweep([a, b], cache, serial=True)
    assert [o.status for o in outcomes] == ["done", "cached"] and calls == [a]
    assert outcomes[1].record.summary == outcomes[0].record.summary


def test_a_damaged_vtu_reads_as_an_error_not_an_exit(tmp_path):
    """meshio's VTU reader calls sys.exit on a file it cannot parse: read_vtu raises ValueError
    (a truncated cached result.vtu ended every later sweep with exit 1 and no report)."""
    from tactileskin.results import read_vtu

    path = tmp_path / "r.vtu"
    path.write_text('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1">\n<Unstr')
    with pytest.raises(ValueError, match="r.vtu"):
        read_vtu(path)


def test_an_editor_lock_file_in_the_package_is_not_code(tmp_path):
    """Emacs marks a buffer with unsaved edits by a dangling symlink `.#name.py` beside the file.
    The import-time snapshot of the package's .py files took it in (digest None; code_digest's
    rglob had skipped it, not a file): a fresh process's key then changed while an editor held
    such a buffer, and every case was solved again under that key."""
    from pathlib import Path

    import tactileskin

    pkg = tmp_path / "src"
    shutil.copytree(Path(tactileskin.__file__).parent, pkg / "tactileskin",
                    ignore=shutil.ignore_patterns("__pycache__"))
    lock = pkg / "tactileskin" / ".#results.py"
    code = ("import json, sys, os; from tactileskin.cache import cache_key, code_changes; "
            "from tactileskin.scene import Scene; key = cache_key(Scene()); "
            "len(sys.argv) > 1 and os.symlink('user@host.1234:1700000000', sys.argv[1]); "
            "print(json.dumps({'key': key, 'changes': code_changes()}))")
    plain, _ = _run_python(pkg, code, lock)   # the lock appears after the import
    assert plain["changes"] == []
    held, _ = _run_python(pkg, code)          # imported while the lock is there
    lock.unlink()
    assert held["key"] == plain["key"] and held["changes"] == []


def test_a_date_in_a_geometry_file_is_refused_naming_its_key_and_keys_apart_from_its_text(geometry):
    """tomllib reads `radius = 2024-01-01` as a date; the key dumped it with default=str, the
    same as the string "2024-01-01"; a solve met float(date): a TypeError traceback. No geometry
    value is a date or time: the file is refused naming the key, and keyed by its bytes."""
    from tactileskin.errors import ParameterError

    sc = Scene(indenter="curved")
    f = geometry / "indenters.toml"
    text = f.read_text()
    keys = set()
    for value in ('"2024-01-01"', "2024-01-01", "'12:00:00'", "12:00:00", "2024-01-01T12:00:00Z"):
        f.write_text(text.replace("radius = 12.0", f"radius = {value}"))
        keys.add(cache_key(sc))
        if '"' not in value and "'" not in value:
            with pytest.raises(ParameterError, match=r"indenters.toml: curved.radius=.* is invalid; valid: a finite "
                                                     r"number"):
                params.load("indenters")
    assert len(keys) == 5


@pytest.mark.parametrize("old, new, key", [
    ("radius = 12.0", 'radius = "12.0"', r"curved.radius"),
    ("radius = 12.0", "radius = nan", r"curved.radius"),
    ("radius = 12.0", "radius = true", r"curved.radius"),
    ("radius = 12.0", "radius = [12.0]", r"curved.radius"),
    ("radius = 12.0", "radius = {r = 12.0}", r"curved.radius"),
    ("radius = 12.0", "radius = 1" + "0" * 400, r"curved.radius"),  # no float has it: OverflowError
])
def test_a_geometry_value_of_the_wrong_type_is_refused_naming_its_key(geometry, old, new, key):
    """A user's geometry file with text, nan, a boolean or a table where the shipped file has a
    number ended in a ValueError or TypeError traceback (float('abc')) or in a nan geometry;
    it is refused naming the file and the key. An integer is a number (radius = 12 solves)."""
    from tactileskin.errors import ParameterError

    f = geometry / "indenters.toml"
    text = f.read_text()
    assert old in text
    f.write_text(text.replace(old, new))
    with pytest.raises(ParameterError, match=rf"^indenters.toml: {key}=.* is invalid; valid: a finite number"):
        params.load("indenters")
    params.geometry_digest()  # keyed by its bytes, as other refused files
    f.write_text(text.replace(old, "radius = 12"))
    assert params.load("indenters")["curved"]["radius"] == 12


def test_a_key_missing_from_a_geometry_file_is_refused_naming_it(geometry):
    """A user's geometry file without a value its reader needs (curved.radius) ended in a
    KeyError traceback at the solve; it is now a ParameterError naming the file and the key,
    and the CLI says so in one line with exit 2, writing nothing. An optional key read with
    .get() is unchanged."""
    import subprocess
    import sys

    from tactileskin.errors import ParameterError
    from tactileskin.geometry.indenters import indenter_for_scene

    f = geometry / "indenters.toml"
    text = f.read_text()
    f.write_text("\n".join(ln for ln in text.splitlines() if not ln.startswith("radius = 12.0")) + "\n")
    with pytest.raises(ParameterError, match=r"^indenters.toml: curved.radius=None is invalid"):
        indenter_for_scene(Scene(indenter="curved", thickness=1.0))
    assert params.load("indenters")["curved"].get("radius") is None
    out = geometry.parent / "out"
    run = subprocess.run([sys.executable, "-m", "tactileskin", "solve", "--indenter", "curved", "-t", "1",
                          "--quality", "preview", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr[-800:]
    assert "indenters.toml: curved.radius" in run.stderr + run.stdout and not out.exists()

def test_an_integer_past_pythons_digit_limit_is_an_invalid_toml_file(geometry, tmp_path):
    """tomllib's int() of a 5000-digit integer raises ValueError (Python's 4300-digit limit),
    not TOMLDecodeError: a geometry file holding one ended in a traceback from params.load and
    from geometry_digest (every solve's cache key), a scene or material file from read_toml."""
    from tactileskin.errors import ParameterError

    f = geometry / "indenters.toml"
    f.write_text(f.read_text().replace("radius = 12.0", "radius = 1" + "0" * 5000))
    with pytest.raises(ParameterError, match=r"valid TOML"):
        params.load("indenters")
    params.geometry_digest()
    g = tmp_path / "scene.toml"
    g.write_text("depth = 1" + "0" * 5000 + "\n")
    with pytest.raises(ParameterError, match=r"valid TOML"):
        params.read_toml(g, "scene file")


def test_a_date_where_a_number_belongs_is_told_a_number_not_text(geometry):
    """`radius = 2024-01-01` was told 'valid: a number or text, not a TOML date or time; quote
    it if it is text': quoted, the radius was refused again ('a finite number'). Where the
    shipped file has a number the error says a finite number; a date in a key of the user's own
    (no shipped value) keeps the date message."""
    from tactileskin.errors import ParameterError

    f = geometry / "indenters.toml"
    text = f.read_text()
    f.write_text(text.replace("radius = 12.0", "radius = 2024-01-01"))
    with pytest.raises(ParameterError, match=r"^indenters.toml: curved.radius=.* is invalid; valid: a finite number"):
        params.load("indenters")
    f.write_text(text.replace("radius = 12.0", "radius = 12.0\nmeasured = 2024-01-01"))
    with pytest.raises(ParameterError, match=r"^indenters.toml: curved.measured=.* is invalid; valid: a number or "
                                             r"text, not a TOML date"):
        params.load("indenters")


def test_a_sweep_checks_the_code_once_per_stored_case_and_still_validates_it(tmp_path, monkeypatch):
    """run_sweep's finish stored a case (store: the code check) and read it back with lookup,
    which hashed the package's sources again (~3.4 ms, 18 x in a preview sweep's main
    process): the entry just written under that check is read back by the cache's validation
    alone. A result that does not pass it is still a failed case, its entry removed."""
    import tactileskin.cache as cache_mod
    import tactileskin.sweep as sw

    scenes = [Scene(thickness=1.0), Scene(thickness=3.0)]
    class Bad:  # written, but "s is not increasing": not a valid entry
        def write_owned(self, directory):
            (directory / "profile.csv").write_text("s_mm,pressure_mpa\n1.0,0.1\n0.0,0.2\n")
            (directory / "summary.json").write_text('{"peak_mpa": 0.2, "span_mm": 1.0, "auc_mpa_mm": 0.1}')

    bad = Bad()
    monkeypatch.setattr(sw, "solve_case", lambda sc: _result() if sc.thickness == 1.0 else bad)
    calls = []
    real = cache_mod.code_changes
    monkeypatch.setattr(cache_mod, "code_changes", lambda: calls.append(1) or real())
    cache = ResultCache(tmp_path / "cache")
    outcomes = run_sweep(scenes, cache, serial=True)
    checks = len(calls)
    assert [o.status for o in outcomes] == ["done", "failed"]
    assert "validation" in outcomes[1].error
    assert outcomes[0].record is not None and outcomes[0].record.summary["peak_mpa"] == pytest.approx(0.4)
    assert cache.has(scenes[0]) and not (cache.root / outcomes[1].key).exists()
    # per case: the scan's lookup, the claim's lookup under the lock, store; not a 4th in the read-back
    assert checks == 3 * len(scenes), checks
