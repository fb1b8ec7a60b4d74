"""Sweeps: grid expansion, a crash-safe result cache keyed by Scene hash, Dask execution.

The cache is a folder per case, `<cache>/<scene key>/` holding profile.csv, summary.json,
result.vtu and scene.toml, i.e. the same files `tactileskin solve` writes, so every cached
case can be opened by hand. A case is staged in a temporary folder and renamed into place
only when complete (rename is atomic on one filesystem), so a sweep killed midway leaves
no half-written case and a rerun recomputes only what is missing. (diskcache or
joblib.Memory would store opaque pickles and add nothing the atomic rename does not give.)

Execution uses dask.distributed: an embedded LocalCluster of single-threaded worker
processes by default (gmsh is not thread-safe), or any running scheduler by address.
Workers return results to the client, which writes the cache, so remote workers need no
shared filesystem.
"""

from __future__ import annotations

import csv
import itertools
import json
import logging
import os
import shutil
import tempfile
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Sequence

import numpy as np

from tactileskin.errors import ParameterError, TactileSkinError
from tactileskin.scene import IndenterKind, Scene

log = logging.getLogger(__name__)

PAPER_THICKNESSES = (1.0, 3.0, 5.0)
PAPER_MATERIALS = ("silicone", "polyurethane")
PAPER_INDENTERS = ("flat", "curved", "braille")


def parse_values(text: str, name: str) -> list[float]:
    """'1,3,5' or a range 'start:stop:step' (stop inclusive) -> floats."""
    out: list[float] = []
    for part in str(text).split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if ":" in part:
                a, b, c = (float(x) for x in part.split(":"))
                if not all(np.isfinite((a, b, c))) or c <= 0 or b < a:
                    raise ValueError
                n = int(np.floor((b - a) / c + 1e-9)) + 1
                if n > 1000:
                    raise ParameterError(name, text, "at most 1000 values")
                out.extend(round(a + i * c, 10) for i in range(n))
            else:
                out.append(float(part))
                if not np.isfinite(out[-1]):
                    raise ValueError
        except ValueError:
            raise ParameterError(name, text, "comma-separated finite numbers or start:stop:step with step > 0") from None
    if not out:
        raise ParameterError(name, text, "at least one value")
    return out


# ~30 h of 2D solves at ~10 s each on one core: beyond that a grid is surely a typo (a range
# step of 0.001), and building its scenes alone would take minutes
MAX_CASES = 10_000


def expand_grid(
    thicknesses: Sequence[float] = PAPER_THICKNESSES,
    materials: Sequence[str] = PAPER_MATERIALS,
    indenters: Sequence[str] = PAPER_INDENTERS,
    depths: Sequence[float | None] = (None,),
    braille_texts: Sequence[str] = ("",),
    base: Scene | None = None,
) -> list[Scene]:
    """Cartesian product of the sweep axes; Braille texts apply to Braille indenters only."""
    base = base or Scene()
    for name, axis in (("thicknesses", thicknesses), ("materials", materials), ("indenters", indenters),
                       ("depths", depths), ("braille_texts", braille_texts)):
        if isinstance(axis, (str, bytes)):  # would iterate as one-letter values
            raise ParameterError(name, axis, "a sequence of values, not a string")
    n = len(thicknesses) * len(materials) * len(indenters) * len(depths) * max(len(braille_texts), 1)
    if n > MAX_CASES:
        raise ParameterError("sweep grid", f"{n} cases", f"at most {MAX_CASES} cases",
                             "split the sweep; every case is a separate solve")
    scenes: list[Scene] = []
    seen: set[str] = set()
    for t, m, ind, d in itertools.product(thicknesses, materials, indenters, depths):
        kind = base.replace(thickness=t, indenter=ind).indenter  # validates the name
        texts = braille_texts if kind is IndenterKind.BRAILLE else ("",)
        for text in texts:
            s = base.replace(thickness=t, material=m, indenter=ind, depth=d, braille_text=text)
            if s.key() not in seen:
                seen.add(s.key())
                scenes.append(s)
    check_materials(s.material for s in scenes)
    return scenes


def check_materials(names: Iterable[str]) -> None:
    """Resolve every material (preset name or .toml file) now, so a bad one fails before
    any worker starts rather than in every case."""
    from tactileskin.materials import get_material

    for name in sorted(set(names)):
        get_material(name)


MAX_AXIS_VALUES = 1000  # values per sweep axis, as parse_values allows
_SPEC_LISTS = {"thicknesses": "numbers", "depths": "numbers", "materials": "strings",
               "indenters": "strings", "braille_texts": "strings"}


def load_spec(path: str | Path) -> dict:
    """A sweep TOML: [sweep] thicknesses/materials/indenters/depths/braille_texts lists,
    optional [scene] base fields. Unknown tables or keys and values of the wrong type
    (`materials = "silicone"`, a string, not a list) are ParameterErrors."""
    from tactileskin import validate
    from tactileskin.params import read_toml

    data = read_toml(path, "sweep file")
    validate.known_keys(data, ("sweep", "scene"), "sweep file table")
    sw = validate.table(data.get("sweep", {}), "[sweep]")
    validate.known_keys(sw, _SPEC_LISTS, "sweep")
    spec: dict = {}
    for k, v in sw.items():
        name = f"sweep.{k}"
        if _SPEC_LISTS[k] == "numbers":
            spec[k] = validate.number_list(v, name, MAX_AXIS_VALUES, min_len=1)
        else:
            spec[k] = validate.string_list(v, name, MAX_AXIS_VALUES, min_len=1)
    if "scene" in data:
        spec["base"] = Scene.from_dict(validate.table(data["scene"], "[scene]"))
    return spec


# --- cache -------------------------------------------------------------------------------

@dataclass
class CaseRecord:
    """One finished case as stored in the cache."""

    scene: Scene
    s: np.ndarray
    pressure: np.ndarray
    summary: dict
    path: Path


class ResultCache:
    def __init__(self, root: str | Path):
        self.root = Path(root)

    def path(self, scene: Scene) -> Path:
        return self.root / scene.key()

    def has(self, scene: Scene) -> bool:
        p = self.path(scene)
        return (p / "summary.json").is_file() and (p / "profile.csv").is_file()

    def load(self, scene: Scene) -> CaseRecord:
        p = self.path(scene)
        s, pr = read_profile(p / "profile.csv")
        summary = json.loads((p / "summary.json").read_text())
        return CaseRecord(scene, s, pr, summary, p)

    def store(self, scene: Scene, result) -> Path:
        """Write `result` (has .write(dir)) under the scene key, atomically."""
        self.root.mkdir(parents=True, exist_ok=True)
        final = self.path(scene)
        staging_root = Path(tempfile.mkdtemp(prefix=".staging-", dir=self.root))
        try:
            staging = staging_root / "case"
            result.write(staging)
            scene.to_toml(staging / "scene.toml")
            if final.exists():  # a concurrent writer finished first: identical content by key
                return final
            os.replace(staging, final)
        finally:
            shutil.rmtree(staging_root, ignore_errors=True)
        return final


def read_profile(path: Path) -> tuple[np.ndarray, np.ndarray]:
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    s = np.array([float(r["s_mm"]) for r in rows])
    p = np.array([float(r["pressure_mpa"]) for r in rows])
    return s, p


# --- execution ------------------------------------------------------------------------------

SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
SCHEDULER_TIMEOUT_S = 10.0  # a running scheduler answers in well under a second


def check_scheduler(address: str) -> str:
    """A Dask scheduler address [scheme://]host:port, checked for form (not reachability)."""
    import re

    valid = "an address such as tcp://host:8786 (schemes: " + ", ".join(SCHEDULER_SCHEMES) + ")"
    m = re.fullmatch(r"(?:([a-z]+)://)?(\[[0-9a-fA-F:.]+\]|[A-Za-z0-9_.-]+):([0-9]{1,5})/?", str(address))
    if not m or (m.group(1) or "tcp") not in SCHEDULER_SCHEMES or not 0 < int(m.group(3)) < 65536:
        raise ParameterError("--scheduler", address, valid)
    return str(address)


def connect(address: str):
    """A dask Client on a running scheduler; an unreachable one is a ParameterError after
    SCHEDULER_TIMEOUT_S, not a traceback."""
    from dask.distributed import Client

    check_scheduler(address)
    try:
        return Client(address, timeout=SCHEDULER_TIMEOUT_S)
    except (OSError, TimeoutError, ValueError) as e:
        raise ParameterError("--scheduler", address, "the address of a running Dask scheduler",
                             f"no connection within {SCHEDULER_TIMEOUT_S:g} s: {type(e).__name__}: "
                             f"{str(e).splitlines()[0] if str(e) else ''}".rstrip(": ")) from None

@dataclass
class CaseOutcome:
    scene: Scene
    status: str                 # "cached" | "done" | "failed"
    seconds: float = 0.0
    error: str = ""
    diagnosis: dict = field(default_factory=dict)


def solve_case(scene: Scene):
    """Worker entry point: solve one scene and return its Result (or raise)."""
    from tactileskin.fe import solve

    return solve(scene)


def _cost_rank(scene: Scene) -> float:
    """A rough relative cost of solving a scene, for scheduling only: 3D far above 2D, then
    the skin thickness (dofs and Newton iterations grow with it: benchmarks/paper_sweep.py,
    t = 5 mm cases 3-10x the t = 1 mm ones), Braille (more increments) above the rest."""
    return (100.0 if scene.dim == 3 else 0.0) + scene.thickness + (0.5 if scene.indenter == IndenterKind.BRAILLE else 0.0)


def _run_one_safely(scene: Scene):
    """Runs on a worker: never raises, so one failure cannot stop the sweep."""
    t0 = time.perf_counter()
    try:
        return ("done", solve_case(scene), time.perf_counter() - t0, "", {})
    except TactileSkinError as e:
        return ("failed", None, time.perf_counter() - t0, str(e), getattr(e, "diagnosis", {}) or {})
    except Exception as e:  # noqa: BLE001 - a bug in one case is reported, the rest go on
        return ("failed", None, time.perf_counter() - t0, f"{type(e).__name__}: {e}",
                {"traceback": traceback.format_exc()})


def run_sweep(
    scenes: Iterable[Scene],
    cache: ResultCache,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    serial: bool = False,
    on_event: Callable[[CaseOutcome], None] | None = None,
) -> list[CaseOutcome]:
    """Solve every scene not yet in the cache; returns one outcome per scene, in order.

    scheduler: address of a running dask scheduler; None starts a LocalCluster.
    workers: LocalCluster worker processes (default: number of cores).
    serial: run in this process without Dask (debugging, profiling).
    """
    scenes = list(scenes)
    outcomes: dict[str, CaseOutcome] = {}
    todo: list[Scene] = []
    for sc in scenes:
        if cache.has(sc):
            outcomes[sc.key()] = CaseOutcome(sc, "cached")
            on_event and on_event(outcomes[sc.key()])
        else:
            todo.append(sc)

    def finish(sc: Scene, packed) -> None:
        status, result, secs, err, diag = packed
        if status == "done":
            try:
                cache.store(sc, result)
            except TactileSkinError as e:
                status, err = "failed", str(e)
        oc = CaseOutcome(sc, status, secs, err, diag)
        if status == "failed":
            log.error("case %s failed: %s", sc.label(), err)
        outcomes[sc.key()] = oc
        on_event and on_event(oc)

    if todo and serial:
        for sc in todo:
            finish(sc, _run_one_safely(sc))
    elif todo:
        from dask.distributed import Client, LocalCluster, as_completed

        cluster = None
        if not log.isEnabledFor(logging.INFO):  # dask's scheduler logs at INFO by default
            for name in ("distributed", "distributed.scheduler", "distributed.nanny", "distributed.core",
                         "distributed.http.proxy", "distributed.worker"):
                logging.getLogger(name).setLevel(logging.ERROR)
        if scheduler:
            client = connect(scheduler)
        else:
            if workers is not None and workers < 1:
                raise ParameterError("workers", workers, ">= 1 (or use serial)")
            n = workers or os.cpu_count() or 1
            n = max(1, min(n, len(todo)))
            import dask

            # dask sets MALLOC_TRIM_THRESHOLD_=65536 in its workers, which also switches off
            # glibc's adaptive mmap threshold: every numpy temporary over 128 KiB is then
            # mmapped and unmapped, and a solve spent ~30 % of its time in the kernel (t1
            # silicone curved: 2.0 s in a worker, 1.0 s in a plain process; 1.4 s without it).
            # The statistical profiler samples every 10 ms; nobody reads it here.
            with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
                                  "distributed.worker.profile.enabled": False}):
                cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
            client = Client(cluster)
        try:
            # longest cases first, so that no long case starts last and runs alone
            futs = {client.submit(_run_one_safely, sc, pure=False, key=f"case-{sc.key()}",
                                  priority=_cost_rank(sc)): sc
                    for sc in todo}
            for fut in as_completed(futs):
                sc = futs[fut]
                try:
                    packed = fut.result()
                except Exception as e:  # worker died etc.
                    packed = ("failed", None, 0.0, f"{type(e).__name__}: {e}", {})
                finish(sc, packed)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    return [outcomes[sc.key()] for sc in scenes]
