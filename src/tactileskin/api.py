"""The Python API a notebook user finds at the top level: `tactileskin.solve`, `tactileskin.sweep`.

    import tactileskin as ts
    r = ts.solve(ts.Scene(thickness=1, material="polyurethane"), quality="preview")
    df = ts.sweep({"thickness": [1, 2, 3], "indenter": ["flat", "braille"]}, quality="preview")

`sweep` caches every case (cache.py: keyed by everything that produced it), so rerunning a
cell reuses the finished cases. The cache is `out/cache` when `out` is given, else
`default_cache_dir()`: $TACTILESKIN_CACHE, else $XDG_CACHE_HOME/tactileskin (~/.cache/tactileskin).
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
import time
from pathlib import Path

from tactileskin import validate
from tactileskin.errors import ParameterError

# sweep(grid) keys: a Scene field (one value or a list) or a sweep list name
_GRID_ALIASES = {"thickness": "thicknesses", "material": "materials", "indenter": "indenters",
                 "depth": "depths", "braille_text": "braille_texts", "braille_dim": "braille_dims",
                 "force": "forces"}


def _axis_values(name: str, v) -> list:
    """One grid axis: a single value or a list / tuple / range / 1-D array of values."""
    import numpy as np

    if isinstance(v, (str, int, float)) or v is None:
        return [v]
    if isinstance(v, np.ndarray) and v.ndim == 1:
        return v.tolist()
    if isinstance(v, (list, tuple, range)):
        return list(v)
    raise ParameterError(name, repr(v), "a value or a list of values (not a dict, set or bytes)")


def default_cache_dir() -> Path:
    """Where `sweep` caches results when no `out` or `cache` is given."""
    env = os.environ.get("TACTILESKIN_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "tactileskin"


def default_cache():
    """The ResultCache of default_cache_dir(). A TACTILESKIN_CACHE folder is the user's choice, like
    `cache=`: refused unless new, empty or a cache (cache.open_cache)."""
    from tactileskin.cache import ResultCache, open_cache

    if os.environ.get("TACTILESKIN_CACHE"):
        return open_cache(default_cache_dir(), "TACTILESKIN_CACHE")
    return ResultCache(default_cache_dir())


def solve(scene=None, *, quality: str | None = None, history: bool = False, progress=None, **fields):
    """Solve one scene and return its Result (profile, metrics, fields; .write(folder) saves it).

    scene: a Scene, a scene/one-case sweep TOML path, or None (Scene fields from **fields).
    quality: 'preview', 'default' or 'fine' mesh preset (explicit mesh_size/refinement win).
    history: keep per-increment records (and write result.pvd, a time series, with .write).
    """
    from tactileskin import scenefile
    from tactileskin.fe import solve as fe_solve

    validate.boolean(history, "history")
    if progress is not None and not callable(progress):
        raise ParameterError("progress", repr(progress), "a callable taking an IncrementInfo, or None")
    sc, file_quality, mesh = _scene(scene, fields)
    if quality or file_quality:
        sc = scenefile.apply_quality(sc, quality or file_quality, mesh)
    return fe_solve(sc, history=history, progress=progress)


def _scene(scene, fields: dict):
    """(Scene, file's quality, explicit mesh fields) of solve()'s arguments."""
    from tactileskin import scenefile
    from tactileskin.scene import Scene

    quality, mesh = None, {}
    if isinstance(scene, Scene):
        base = scene
    elif scene is None:
        base = Scene()
    elif isinstance(scene, (str, os.PathLike)):
        sf = scenefile.read(scene)
        quality = sf.quality
        base = Scene.from_dict(scenefile.single_scene_fields(sf, "tactileskin.solve"))
        # the file's mesh sizes go over the quality preset, as `tactileskin solve --scene` takes them
        mesh = {k: sf.fields[k] for k in scenefile.MESH_FIELDS if k in sf.fields}
    else:
        raise ParameterError("scene", type(scene).__name__, "a Scene, a TOML file path or None")
    mesh.update({k: fields[k] for k in scenefile.MESH_FIELDS if fields.get(k) is not None})
    return (base.replace(**fields) if fields else base), quality, mesh


def scenes(grid=None, *, quality: str | None = None, base=None) -> list:
    """The Scenes of a sweep grid (see `sweep`)."""
    from tactileskin import scenefile
    from tactileskin.scene import Scene
    from tactileskin.sweep import expand_grid

    if base is not None and not isinstance(base, Scene):
        raise ParameterError("base", repr(base), "a Scene or None")
    if isinstance(grid, (list, tuple)) and len(grid) == 0:
        raise ParameterError("grid", "[]", "at least one Scene (or a dict of axes, a TOML path, None)")
    if isinstance(grid, (list, tuple)) and all(isinstance(s, Scene) for s in grid):
        if quality is None:
            return list(grid)
        return [scenefile.apply_quality(s, quality, {}) for s in grid]
    axes, fields, file_quality = {}, {}, None
    if isinstance(grid, (str, os.PathLike)):
        sf = scenefile.read(grid)
        fields, axes, file_quality = dict(sf.fields), dict(sf.axes), sf.quality
        for f, ax in scenefile.AXES.items():
            if f in fields:
                axes[ax] = (fields.pop(f),)
    elif isinstance(grid, dict):
        for k, v in grid.items():
            if not isinstance(k, str):
                raise ParameterError("grid key", repr(k), "a name: " + ", ".join(_GRID_ALIASES) + " or a Scene field")
            ax = _GRID_ALIASES.get(k, k)
            if ax in _GRID_ALIASES.values():
                axes[ax] = _axis_values(k, v)
            else:
                fields[k] = v  # a Scene field, the same in every case
    elif grid is not None:
        raise ParameterError("grid", type(grid).__name__,
                             "a dict of axes (thickness=[...], material=[...], ...), a list of Scenes, "
                             "a sweep/scene TOML path, or None (the paper's grid)")
    mesh = {k: fields.pop(k) for k in scenefile.MESH_FIELDS if k in fields}
    b = base if base is not None else Scene()
    if any(fields.get(f) is not None for f in scenefile.INDENTER_FIELDS):  # else `base` keeps its indenter
        fields = scenefile.with_base_indenter(fields, axes.get("indenters"))  # as the CLI: its own fields
    b = b.replace(**fields) if fields else b
    if "dim" in fields and "braille_dims" not in axes:  # a dim asked for: the Braille cases' too
        axes["braille_dims"] = (b.dim,)
    return expand_grid(base=b, quality=quality or file_quality, overrides=mesh or None, **axes)


def sweep(grid=None, *, quality: str | None = None, out=None, cache=None, workers: int | None = None,
          serial: bool = False, scheduler: str | None = None, profiles: bool = False,
          report: bool = True, base=None):
    """Run a cached sweep and return its metrics as a pandas DataFrame (one row per case:
    case, status, thickness_mm, material, indenter, ..., peak_mpa, span_mm, auc_mpa_mm, ...).

    grid: {"thickness": [1, 3, 5], "material": [...], "indenter": [...], "depth": [...],
      "braille_text": [...], "braille_dim": [2, 3]} (any subset; other Scene fields such as
      rate=2 or dim=3 apply to every case), a list of Scenes, a scene/sweep TOML path, or
      None (the paper's 18 cases; 24 at the default quality). Without "braille_dim" (or "dim")
      the Braille cases are both the 2D ridge and the 3D dots at the default quality
      (sweep.default_braille_dims), else 2D.
    quality: mesh preset of each case's dimension ('preview', 'default', 'fine').
    out: also write the folder the `tactileskin sweep` command writes (results.csv and
      .parquet, profiles.csv and .parquet, figures with the Fig. 9 renders, report.md);
      `report=False` skips figures, renders and report. cache: the result cache folder (default out/cache, else default_cache_dir()).
    workers / serial / scheduler: as the command (default: a local Dask cluster, one worker
      process per core). A script needs no `if __name__ == "__main__":` guard.
    profiles: return (metrics, profiles), profiles in long form (case, status, s_mm, pressure_mpa).
    A case that failed is a row with status 'failed: ...' and its error; nothing is raised.
    """
    import pandas as pd

    from tactileskin.cache import ResultCache, open_cache, out_cache
    from tactileskin.report.outputs import PROFILE_COLUMNS, profile_rows

    for name, value in (("out", out), ("cache", cache)):
        if value is not None:
            validate.path(value, name, "a folder path (str or os.PathLike) or None")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ParameterError("workers", repr(workers), "a whole number >= 1, or None (one per core)")
    for name, value in (("serial", serial), ("profiles", profiles), ("report", report)):
        validate.boolean(value, name)  # serial="no" is truthy: it ran serially
    scs = scenes(grid, quality=quality, base=base)
    if cache is None:
        rc = ResultCache(out_cache(out)) if out is not None else default_cache()
    else:  # the user's folder: refused unless new, empty or a cache
        rc = open_cache(cache, "cache")
    if out is None:
        records, rows = _sweep_rows(scs, rc, scheduler, workers, serial, None, report)
    else:
        from tactileskin.outdir import claimed

        with claimed(Path(out), "sweep", what="out"):  # a second run into `out` is refused
            from tactileskin import staging
            from tactileskin.report.outputs import SWEEP_ALWAYS_WRITTEN

            # as the command (cli.sweep): an edited report.md is refused now, not after every case
            staging.check_replaceable(Path(out), SWEEP_ALWAYS_WRITTEN)
            records, rows = _sweep_rows(scs, rc, scheduler, workers, serial, Path(out), report)
    from tactileskin.report.outputs import FLOAT_COLUMNS, RESULT_COLUMNS

    # the columns of results.csv / .parquet, all of them: a column no row filled (error when
    # none failed, the target forces without force control) was missing from the DataFrame
    metrics = pd.DataFrame(rows).reindex(columns=RESULT_COLUMNS + ["dim", "variant"])
    for c in FLOAT_COLUMNS:  # a value a case has not (a 2D case's reaction_n, a failed case): NaN
        metrics[c] = pd.to_numeric(metrics[c], errors="coerce").astype(float)
    if not profiles:
        return metrics
    prof = pd.DataFrame(profile_rows(records), columns=PROFILE_COLUMNS)
    return metrics, prof


def _sweep_rows(scs, rc, scheduler, workers, serial, out, report):
    """Run the sweep; write the `sweep` command's folder into `out` (if given); (records, rows)."""
    from tactileskin.report.outputs import collect
    from tactileskin.sweep import run_sweep

    t0 = time.perf_counter()
    with _script_not_rerun():
        outcomes = run_sweep(scs, rc, scheduler=scheduler, workers=workers, serial=serial)
    failed = [oc for oc in outcomes if oc.status == "failed"]
    if failed:  # the rows say which and why; a notebook user should not miss that some did
        logging.getLogger(__name__).warning("%d of %d cases failed (status and error columns): %s",
                                            len(failed), len(outcomes), ", ".join(oc.case for oc in failed))
    if out is None:
        records, rows, _ = collect(outcomes, rc)
        return records, rows
    from tactileskin.report.outputs import write_outputs

    # as the command writes it: the wall time, and (with report) the Fig. 9 renders
    res = write_outputs(out, outcomes, rc, time.perf_counter() - t0, render=report, figures=report)
    return res["records"], res["rows"]


@contextlib.contextmanager
def _script_not_rerun():
    """Worker processes start by `spawn`, which re-runs the main script (the reason for the
    usual `if __name__ == "__main__":` guard; without it each worker would start a sweep of
    its own). The workers need nothing from the script (cases are Scenes, solved by
    tactileskin functions), so while the sweep runs, __main__ does not name its file."""
    main = sys.modules.get("__main__")
    saved = {k: main.__dict__[k] for k in ("__file__", "__spec__") if main is not None and k in main.__dict__}
    if main is None or "__file__" not in saved:
        yield
        return
    try:
        del main.__file__
        main.__spec__ = None
        yield
    finally:
        main.__dict__.update(saved)
