"""Sweeps: grid expansion, unique case ids, cached Dask execution.

The result cache (tactileskin.cache) holds one validated folder per case, keyed by
`cache_key(scene)`: the scene, the material's numbers, the geometry files and the solver
version. A case is computed under a per-case lock, so two sweeps into one cache share the
work: cases another run holds are waited for after our own, then read from the cache (or
computed, if that run failed). A killed sweep leaves no half-written case; a rerun
computes only what is missing.

Case ids (`case_ids`) extend `Scene.label()` by the fields that tell cases of one sweep
apart (depth, rate, mesh, ...), so every row, profile and bar of a report is one case.

Execution uses dask.distributed: an embedded LocalCluster of single-threaded worker
processes by default (gmsh is not thread-safe), or any running scheduler by address.
Workers return results to the client, which writes the cache, so remote workers need no
shared filesystem.
"""

from __future__ import annotations

import itertools
import logging
import os
import sys
import time
import traceback
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable, Sequence

import numpy as np

from tactileskin.cache import CaseRecord, ResultCache, cache_key, read_profile  # noqa: F401 (API)
from tactileskin.cache import changed_code_message, code_changes
from tactileskin.errors import ParameterError, TactileSkinError
from tactileskin.geometry.indenters.registry import get as get_kind
from tactileskin.scene import Scene
from tactileskin.threads import other_threads as _other_threads  # tests replace it here

log = logging.getLogger(__name__)

PAPER_THICKNESSES = (1.0, 3.0, 5.0)
PAPER_MATERIALS = ("silicone", "polyurethane")
PAPER_INDENTERS = ("flat", "curved", "braille")


def parse_values(text: str, name: str) -> list[float]:
    """'1,3,5' or a range 'start:stop:step' (stop inclusive) -> floats."""
    out: list[float] = []
    for part in str(text).split(","):
        part = part.strip()
        if not part:  # "1,,2": a value left out by mistake, not nothing
            raise ParameterError(name, text, "comma-separated finite numbers, none of them empty")
        try:
            if ":" in part:
                a, b, c = (float(x) for x in part.split(":"))
                if not all(np.isfinite((a, b, c))) or c <= 0 or b < a:
                    raise ValueError
                n = int(np.floor((b - a) / c + 1e-9)) + 1
                if n > MAX_AXIS_VALUES:
                    raise ParameterError(name, text, f"at most {MAX_AXIS_VALUES} values (a larger step)")
                out.extend(round(a + i * c, 10) for i in range(n))
            else:
                out.append(float(part))
                if not np.isfinite(out[-1]):
                    raise ValueError
        except ParameterError:
            raise
        except ValueError:
            raise ParameterError(name, text, "comma-separated finite numbers or start:stop:step with start <= stop and step > 0") from None
    if not out:
        raise ParameterError(name, text, "at least one value")
    return out


# ~30 h of 2D solves at ~10 s each on one core: beyond that a grid is surely a typo (a range
# step of 0.001), and building its scenes alone would take minutes
MAX_CASES = 10_000


BRAILLE_DIMS = (2, 3)


def default_braille_dims(base: Scene, quality: str | None, overrides: dict | None,
                         forced: bool = False) -> tuple[int, ...]:
    """The Braille cases' dimensions when a sweep does not say: at the `default` quality (given,
    or the Scene's own sizes, which are that preset's) both the paper's 2D ridge and the 3D dots
    on a skin that has both models, so that the report sets them side by side and judges the
    paper's claims with the dots, the model that holds (the ridge reads 1.9-3.1x their peak;
    the 18 cases with six 3D dots took 96 s on 2 cores, benchmarks/results/paper_sweep_3d.md).
    Else base.dim: `preview` stays the quick 2D look, `fine` 3D dots take minutes each, explicit
    mesh sizes (overrides, or the base's own) are a 2D mesh's, and `forced` cases (expand_grid's
    test: a force axis, the base's force, a [[loading]] force) press N/mm in 2D but N in 3D.
    expand_grid falls back to base.dim too where a case's 3D scene is refused (a text too long
    for the pad)."""
    from tactileskin.scene import default_mesh

    if overrides or forced or base.dim != 2 or base.skin_kind.fixes_thickness:
        return (base.dim,)
    if (quality or "default") != "default":
        return (base.dim,)
    if quality is None and (base.mesh_size, base.refinement) != default_mesh(2, base.indenter, base.thickness,
                                                                          base.skin):
        return (base.dim,)  # the base's own sizes: a 2D mesh's
    try:
        base.replace(dim=3, indenter="braille", braille_text="")
    except ParameterError:  # a skin without a 3D model
        return (base.dim,)
    return BRAILLE_DIMS


_NONE = object()
_DEFAULT_STANDARD = Scene.__dataclass_fields__["braille_standard"].default


def expand_grid(
    thicknesses: Sequence[float] = PAPER_THICKNESSES,
    materials: Sequence[str] = PAPER_MATERIALS,
    indenters: Sequence[str] = PAPER_INDENTERS,
    depths: Sequence[float | None] = (None,),
    braille_texts: Sequence[str] = ("",),
    base: Scene | None = None,
    braille_dims: Sequence[int] | None = None,
    quality: str | None = None,
    overrides: dict | None = None,
    forces: Sequence[float | None] = (None,),
) -> list[Scene]:
    """Cartesian product of the sweep axes; Braille texts apply to Braille indenters only.

    braille_dims: the dimensions of the Braille cases (2: the paper's ridge section, 3: the
    slab with real dots; both: one case each). Flat and curved cases keep `base.dim`: they
    are uniform along the finger, so the 2D section is exact for them. None:
    `default_braille_dims` (both at the default quality, else base.dim).
    quality: a planner quality preset applied to each scene after its indenter and dim are
    set (planner.with_quality), then `overrides` (Scene fields such as mesh_size, which
    override the preset).
    forces: force-control targets (N, N/mm in 2D; "same press, different skin"), an axis
    instead of depths (None: the depth axis)."""
    base = base or Scene()
    for name, axis in (("thicknesses", thicknesses), ("materials", materials), ("indenters", indenters),
                       ("depths", depths), ("braille_texts", braille_texts), ("braille_dims", braille_dims),
                       ("forces", forces)):
        if isinstance(axis, (str, bytes)):  # would iterate as one-letter values
            raise ParameterError(name, axis, "a sequence of values, not a string")
        if axis is not None and len(axis) == 0:  # would be a sweep of no case, silently
            raise ParameterError(name, list(axis), "at least one value")
        if axis is not None and name != "braille_dims":  # (dims: a set of models, duplicates dropped)
            repeated = next((v for i, v in enumerate(axis) if v in list(axis)[:i]), _NONE)
            if repeated is not _NONE:  # [1, 3, 1] for [1, 3, 5]: ran 2 cases, the repeat dropped silently
                raise ParameterError(name, list(axis), "distinct values",
                                     f"{repeated!r} is listed twice; each value is a set of cases")
    if any(f is not None for f in forces) and any(d is not None for d in depths):
        raise ParameterError("forces", list(forces), "either forces or depths, not both",
                             "a case is pressed to a depth or to a force")
    forced = (any(f is not None for f in forces) or base.force is not None
              or any(g.kind == "force" for g in base.loading))
    chosen = braille_dims is None  # the default, not the caller's: falls back to 2D where 3D is refused
    dims = (check_braille_dims(braille_dims) if braille_dims is not None
            else default_braille_dims(base, quality, overrides, forced))
    if forced and len(set(dims)) > 1 and any(get_kind(i).section_2d == "ridge" for i in indenters):
        raise ParameterError("braille_dims", list(dims), "one dimension under force control",
                             "a force is N/mm of the half section in 2D and N on the whole indenter in 3D: "
                             "the ridge and the dots would not be pressed alike")
    n = (len(thicknesses) * len(materials) * len(indenters) * len(depths) * len(forces)
         * max(len(braille_texts), 1) * len(dims))
    if n > MAX_CASES:
        raise ParameterError("sweep grid", f"{n} cases", f"at most {MAX_CASES} cases",
                             "split the sweep; every case is a separate solve")
    if quality is not None:
        from tactileskin.planner import quality_mesh, with_quality

        quality_mesh(quality, base.indenter)  # an unknown preset fails before any scene
    scenes: list[Scene] = []
    seen: set[str] = set()
    for t, m, ind, d, f in itertools.product(thicknesses, materials, indenters, depths, forces):
        kind = get_kind(ind)  # validates the name
        braille = "braille_text" in kind.scene_params  # the kind reads the texts axis
        own = dims if kind.section_2d == "ridge" else (base.dim,)
        # a [scene] Braille standard is the Braille cases': on a flat or curved case it changed
        # nothing solved but the key (re-solved) and left the case out of the paper checks
        std = {} if "braille_standard" in kind.scene_params else {"braille_standard": _DEFAULT_STANDARD}
        if kind.section_2d is None:
            own = (3,)  # no 2D model of this kind: its cases are 3D
        for text in (braille_texts if braille else ("",)):
            for dim in own:
                fc = {} if f is None else {"force": f}
                try:
                    s = base.replace(thickness=t, material=m, indenter=ind, depth=d, braille_text=text, dim=dim,
                                     **fc, **std)
                except ParameterError as e:
                    # only a Braille case's 3D dots fall back to the ridge; another kind's
                    # refusal (a sphere without a radius) is that case's error
                    if not (chosen and dim == 3 and len(dims) > 1 and kind.section_2d == "ridge"):
                        raise
                    log.warning("the Braille cases stay 2D (the ridge): the 3D dots of %s at t = %g mm are "
                                "refused (%s); --braille-dim 3 asks for them", text or "the dot", t, e)
                    return expand_grid(thicknesses, materials, indenters, depths, braille_texts, base,
                                       (base.dim,), quality, overrides, forces)
                if quality is not None:
                    s = with_quality(s, quality)
                if overrides:
                    s = s.replace(**overrides)
                if s.key() not in seen:
                    seen.add(s.key())
                    scenes.append(s)
    check_materials(s.material for s in scenes)
    return scenes


def check_braille_dims(dims, name: str = "braille_dims") -> tuple[int, ...]:
    """The dimensions of Braille cases: a non-empty list of 2 and/or 3 (duplicates dropped)."""
    from tactileskin import validate

    items = validate.integer_list(dims, name, MAX_AXIS_VALUES, "2 or 3", min_len=1)
    for i, v in enumerate(items):
        if v not in BRAILLE_DIMS:
            raise ParameterError(f"{name}[{i}]", v, "2 or 3")
    return tuple(dict.fromkeys(items))


def check_materials(names: Iterable[str]) -> None:
    """Resolve every material (preset name or .toml file) now, so a bad one fails before
    any worker starts rather than in every case."""
    from tactileskin.materials import get_material

    for name in sorted(set(names)):
        get_material(name)


MAX_AXIS_VALUES = 1000  # values per sweep axis, as parse_values allows
_SPEC_LISTS = {"thicknesses": "numbers", "depths": "numbers", "forces": "numbers", "materials": "strings",
               "indenters": "strings", "braille_texts": "strings", "braille_dims": "dims"}


def load_spec(path: str | Path) -> dict:
    """A sweep TOML: [sweep] thicknesses/materials/indenters/depths/braille_texts/braille_dims
    lists (braille_dims: 2 and/or 3, see expand_grid), optional [scene] base fields. Unknown
    tables or keys and values of the wrong type (`materials = "silicone"`, a string, not a
    list; `braille_dims = [3.0]`, not an integer) are ParameterErrors."""
    from tactileskin import validate
    from tactileskin.params import read_toml

    data = read_toml(path, "sweep file")
    validate.known_keys(data, ("sweep", "scene"), "sweep file table")
    from tactileskin import scenefile
    from tactileskin.scenefile import resolve_paths, sweep_lists

    spec: dict = resolve_paths(sweep_lists(data.get("sweep", {})), path)
    if "scene" in data:
        base = resolve_paths(validate.table(data["scene"], "[scene]"), path)
        # its indenter kind's own fields need that kind there
        spec["base"] = Scene.from_dict(scenefile.with_base_indenter(base, spec.get("indenters")))
    return spec


# --- case ids -----------------------------------------------------------------------------

def _base_id(sc: Scene) -> str:
    # the skin's prefix too ("pad20x20-", "" for the fingertip): results.csv and the report
    # have no skin column, and `solve` names the same scene so
    return sc.label()


# Fields outside the base id that change a result: (value, id suffix, legend text). The
# suffix is short (file names: fig9_...-F0.03.png); the legend text says the unit.
def _force_text(s: Scene) -> str:
    if s.force is None:
        return "depth control"
    return f"F = {s.force:g} " + ("N" if s.dim == 3 else "N/mm")  # 3D: the whole indenter; 2D: per mm


_ID_FIELDS = (
    (lambda s: round(s.indentation, 9), lambda s: f"d{s.indentation:.4g}",
     # under force control the depth is the travel found (an output): the force names the case
     lambda s: "" if s.force is not None else f"d = {s.indentation:.4g} mm"),
    (lambda s: s.force, lambda s: "F" + ("-" if s.force is None else f"{s.force:g}"), _force_text),
    (lambda s: s.rate, lambda s: f"r{s.rate:g}", lambda s: f"rate {s.rate:g} mm/s"),
    (lambda s: s.mesh_size, lambda s: f"h{s.mesh_size:g}", lambda s: f"h = {s.mesh_size:g} mm"),
    (lambda s: s.refinement, lambda s: f"ref{s.refinement:g}", lambda s: f"refinement {s.refinement:g}"),
    (lambda s: s.order, lambda s: f"p{s.order}", lambda s: f"P{s.order}"),
    (lambda s: s.formulation, lambda s: s.formulation.value, lambda s: s.formulation.value),
    (lambda s: s.viscoelastic, lambda s: "visco" if s.viscoelastic else "elastic",
     lambda s: "visco" if s.viscoelastic else "elastic"),
    (lambda s: s.braille_standard, lambda s: s.braille_standard, lambda s: s.braille_standard),
    (lambda s: s.fingertip, lambda s: "ft-" + (",".join(f"{k}={v:g}" for k, v in s.fingertip) or "default"),
     lambda s: "fingertip " + (",".join(f"{k}={v:g}" for k, v in s.fingertip) or "default")),
    # two files, one name: the material's label tells them apart in tables and figures
    (lambda s: s.material, lambda s: "@" + Path(s.material).parent.name, lambda s: ""),
)


def _variants(scenes: list[Scene], which: int) -> list[str]:
    """Per scene, the id suffix (which = 1) or legend text (which = 2) of the fields that
    differ within some group of equal base ids; "" for a scene whose base id is unique."""
    groups = defaultdict(list)
    for i, s in enumerate(scenes):
        groups[_base_id(s)].append(i)
    shared = [g for g in groups.values() if len(g) > 1]
    named = [f for f in _ID_FIELDS if any(len({f[0](scenes[i]) for i in g}) > 1 for g in shared)]
    in_shared = {i for g in shared for i in g}
    sep = "-" if which == 1 else ", "
    variants = [sep.join(t for t in (f[which](s) for f in named) if t) if i in in_shared else ""
                for i, s in enumerate(scenes)]
    suffixes = [v if which == 1 else sep.join(f[1](s) for f in named) for v, s in zip(variants, scenes)]
    ids = [_base_id(s) + (f"-{v}" if v else "") for s, v in zip(scenes, suffixes)]
    n = Counter(ids)
    # still equal: the scenes differ in a field not named above (or are the same scene)
    return [v + ((sep if v else "") + f"k{s.key()[:6]}" if n[i] > 1 else "")
            for v, i, s in zip(variants, ids, scenes)]


def case_variants(scenes: Sequence[Scene]) -> list[str]:
    """Per scene, the suffix that tells it apart from scenes with the same base id (skin, thickness,
    material, indenter, Braille text, dim): "" for a scene whose base id is unique, else the
    values of every field that differs within some group of equal base ids, e.g. "d0.2" or
    "d0.2-r2" (the same fields for all such scenes, so their ids read alike)."""
    return _variants(list(scenes), 1)


def case_variant_labels(scenes: Sequence[Scene]) -> list[str]:
    """case_variants as figure legends name them, with units: "F = 0.03 N/mm" (2D), "F = 0.5 N"
    (3D), "d = 0.2 mm", "rate 2 mm/s"; a force case's depth (its travel, an output) is not named."""
    return _variants(list(scenes), 2)


def case_ids(scenes: Sequence[Scene]) -> list[str]:
    """A unique, readable id per scene of a sweep: Scene.label() (a material file by its
    name) plus "-d0.2"/"-r2"-style suffixes for the fields that differ between cases."""
    scenes = list(scenes)
    return [_base_id(s) + (f"-{v}" if v else "") for s, v in zip(scenes, case_variants(scenes))]


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


def check_reachable(address: str) -> None:
    """ParameterError unless something listens at the scheduler's host:port (a TCP connect
    within SCHEDULER_TIMEOUT_S): checked before the output folder is claimed, so that an
    unreachable scheduler leaves nothing behind. ucx:// is not TCP: left to `connect`."""
    import re
    import socket

    check_scheduler(address)
    m = re.fullmatch(r"(?:([a-z]+)://)?\[?([0-9A-Za-z_.:-]+?)\]?:([0-9]+)/?", address)
    if m is None or (m.group(1) or "tcp") == "ucx":
        return
    try:
        socket.create_connection((m.group(2), int(m.group(3))), timeout=SCHEDULER_TIMEOUT_S).close()
    except OSError as e:
        raise ParameterError("--scheduler", address, "the address of a running Dask scheduler",
                             f"no connection: {e.strerror or type(e).__name__}") from None


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
    case: str = ""              # the case id within the sweep (case_ids)
    record: CaseRecord | None = None  # the validated cache entry, unless failed
    key: str = ""               # the cache key the sweep computed for it (the entry's name)


def solve_case(scene: Scene):
    """Worker entry point: solve one scene and return its Result (or raise)."""
    from tactileskin.fe import solve

    return solve(scene)


def _cost_rank(scene: Scene) -> float:
    """A rough relative cost of solving a scene, for scheduling only: 3D far above 2D, then
    the skin thickness (dofs and Newton iterations grow with it: benchmarks/paper_sweep.py,
    t = 5 mm cases 3-10x the t = 1 mm ones), Braille (more increments) above the rest."""
    return (100.0 if scene.dim == 3 else 0.0) + scene.thickness + (0.5 if scene.indenter_kind.fine_2d_mesh else 0.0)


def _run_one_safely(scene: Scene, key: str | None = None):
    """Runs on a worker: never raises, so one failure cannot stop the sweep. With `key` (the
    client's cache key), a worker whose material/geometry files or version differ, or whose
    files change during the solve, fails the case rather than store it under a wrong key."""
    t0 = time.perf_counter()
    try:
        if key is not None and (changed := code_changes()):  # its result could not be stored
            raise TactileSkinError(f"not solved: {changed_code_message(changed)}")
        if key is not None and cache_key(scene) != key:
            raise TactileSkinError("the material or geometry files, the tactileskin code or the solving "
                                   "libraries' versions seen by the worker differ from the sweep's; not solved")
        result = solve_case(scene)
        if key is not None and cache_key(scene) != key:
            raise TactileSkinError("the material or geometry files changed during the solve; rerun the sweep")
        return ("done", result, time.perf_counter() - t0, "", {})
    except TactileSkinError as e:
        return ("failed", None, time.perf_counter() - t0, str(e), getattr(e, "diagnosis", {}) or {})
    except Exception as e:  # noqa: BLE001 - a bug in one case is reported, the rest go on
        return ("failed", None, time.perf_counter() - t0, f"{type(e).__name__}: {e}",
                {"traceback": traceback.format_exc()})


class _Runner:
    """Runs batches of cases serially or on Dask; the cluster starts with the first batch."""

    def __init__(self, scenes, keys, *, serial, scheduler, workers):
        self.scenes, self.keys = scenes, keys
        self.serial, self.scheduler, self.workers = serial, scheduler, workers
        self.client = self.cluster = None
        self._environ = {}  # this process's values of the nanny's pre-spawn variables
        self._log_levels = {}  # the levels of dask's loggers before the sweep quietened them

    def __call__(self, idx: list[int], finish) -> None:
        if not idx:
            return
        if self.serial:
            for i in idx:
                finish(i, _run_one_safely(self.scenes[i], self.keys[i]))
            return
        from dask.distributed import as_completed

        client = self.client or self._start(len(idx))
        # longest cases first, so that no long case starts last and runs alone
        futs = {client.submit(_run_one_safely, self.scenes[i], self.keys[i], pure=False,
                              key=f"case-{self.keys[i]}-{i}", priority=_cost_rank(self.scenes[i])): i
                for i in idx}
        for fut in as_completed(futs):
            try:
                packed = fut.result()
            except Exception as e:  # worker died etc.
                packed = ("failed", None, 0.0, f"{type(e).__name__}: {e}", {})
            finish(futs[fut], packed)

    def _start(self, ncases: int):
        from dask.distributed import Client, LocalCluster

        if not log.isEnabledFor(logging.INFO):  # dask's scheduler logs at INFO by default
            for name in ("distributed", "distributed.scheduler", "distributed.nanny", "distributed.core",
                         "distributed.http.proxy", "distributed.worker"):
                # for this sweep only (close): the caller's own dask work after it logs as before
                self._log_levels.setdefault(name, logging.getLogger(name).level)
                logging.getLogger(name).setLevel(logging.CRITICAL)
        if self.scheduler:
            self.client = connect(self.scheduler)
            return self.client
        n = max(1, min(self.workers or os.cpu_count() or 1, ncases))
        import dask

        # The nanny sets its other pre-spawn variables (OMP_NUM_THREADS=1, OPENBLAS_NUM_THREADS=1)
        # here too, before each worker starts: the workers keep them (numpy reads them as it
        # loads), this process gets its own values back, or a later lone solve here would take
        # them for the user's thread count (fe.blas_threads) and leave its BLAS unlimited
        self._environ = {k: os.environ.get(k) for k in dask.config.get("distributed.nanny.pre-spawn-environ")}
        # dask sets MALLOC_TRIM_THRESHOLD_=65536 in its workers, which also switches off
        # glibc's adaptive mmap threshold: every numpy temporary over 128 KiB is then
        # mmapped and unmapped, and a solve spent ~30 % of its time in the kernel (t1
        # silicone curved: 2.0 s in a worker, 1.0 s in a plain process; 1.4 s without it).
        # The statistical profiler samples every 10 ms; nobody reads it here. Likewise each
        # server's event-loop tick (every 20 ms) and system monitor (0.5 s), diagnostics for a
        # dashboard the sweep has not, and the nannies' memory checks (0.1 s; 0.5 s still ends
        # a worker that outgrows its memory, its case rerun): ~0.06 -> ~0.01 CPU s per s of
        # sweep on 2 cores (benchmarks/results/sweep_overhead.md).
        # The nanny writes its pre-spawn variables into this process's environment too: the
        # PARDISO threads (read at solve time) go to the workers alone, by `env`, and
        # MKL_NUM_THREADS=1 is not set here, or a later lone solve or sweep in this process
        # would take it for the user's choice
        method = worker_start_method()
        if method == "fork":
            # loaded once here rather than by each spawned worker (numpy, dask, numba, scikit-fem
            # and the package: ~1 s CPU per worker idle, ~2 s loaded; preview sweep ~20 -> ~15 s CPU)
            import tactileskin.fe  # noqa: F401
            import tactileskin.mesh  # noqa: F401
            import multiprocessing.util

            if n > 1:  # loaded once here, not by each worker at its first case
                _load_compiled_loops()

            # loaded here, not by the hook in each child: a terminal's Ctrl-C during that import,
            # before the hook set SIGINT aside, ended a starting worker with a traceback
            import tactileskin.sweep_worker  # noqa: F401

            # in each worker fork()ed while this runner lives (a restarted one too), first thing
            multiprocessing.util.register_after_fork(self, _plain_streams)
        with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
                              "distributed.nanny.pre-spawn-environ.MKL_NUM_THREADS": None,
                              "distributed.worker.profile.enabled": False,
                              "distributed.admin.tick.interval": "1s",
                              "distributed.admin.system-monitor.interval": "5s",
                              "distributed.worker.memory.monitor-interval": "500ms",
                              "distributed.worker.multiprocessing-method": method}):
            # quiet: CRITICAL. On a loaded machine a worker's heartbeat can race the
            # scheduler's shutdown after the last result and log a CommClosedError traceback
            # at ERROR (seen on `./dev run`); a worker that dies during a case still reaches
            # the sweep as its future's exception, recorded as a failed case
            quiet = logging.ERROR if log.isEnabledFor(logging.INFO) else logging.CRITICAL
            from distributed.deploy.spec import SpecCluster

            before = set(SpecCluster._instances)  # a user's own clusters (a notebook) stay
            try:
                # no dashboard; the scheduler's HTTP server still starts, on dask's 8787 unless
                # told: on any free local port, so that a dashboard there (a notebook's own
                # cluster, a second sweep) does not earn every sweep a 4-line "Port 8787 is
                # already in use" UserWarning
                self.cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                            dashboard_address=None, silence_logs=quiet,
                                            scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                                            env={"TACTILESKIN_THREADS": worker_threads(n)})
            except BaseException:
                _close_unfinished_clusters(before)
                raise
            finally:
                _restore_environ(self._environ)
        self.client = Client(self.cluster)
        from tactileskin.sweep_worker import ForkedWorker, IgnoreInterrupts

        self.client.register_plugin(ForkedWorker() if method == "fork" else IgnoreInterrupts())
        return self.client

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()
        _restore_environ(self._environ)  # a worker its nanny restarted set them again
        for name, level in self._log_levels.items():
            logging.getLogger(name).setLevel(level)


# the modules of the compiled loops a 2D or 3D solve calls (numba, cache=True)
COMPILED_MODULES = ("tactileskin.fe._kernels_nb", "tactileskin.fe._sparse_nb", "tactileskin.materials._hyperfoam_nb")


def _load_compiled_loops() -> int:
    """Load, before the workers fork(), every type signature numba's on-disk cache holds of the
    package's serial compiled loops (COMPILED_MODULES): each fork()ed worker loaded them at its
    first case, ~0.24 s CPU each (a preview case 0.60-0.69 -> 0.37-0.47 s in a fork()ed child),
    here once, ~0.25 s (benchmarks/results/sweep_overhead.md). The loops numba compiles in
    parallel (parallel=True) are left to the workers: loaded here they could start numba's
    threads, and a child fork()ed after that solves on one (threads.forked_from_threads).
    Numba's cache index is not public API: where it cannot be read, nothing is loaded and the
    workers load what they call, as before; so is an entry that fails to load (a damaged data
    file). Returns the number of signatures loaded."""
    import importlib

    try:
        from numba.core.dispatcher import Dispatcher
    except ImportError:  # pragma: no cover - numba is a dependency
        return 0
    n = 0
    for name in COMPILED_MODULES:
        for d in vars(importlib.import_module(name)).values():
            # (explicit signatures: compiled as the module loaded, and closed to more)
            if not isinstance(d, Dispatcher) or d.targetoptions.get("parallel") or not d._can_compile:
                continue
            try:
                index = d._cache._cache_file._load_index()
                magic = d.targetctx.codegen().magic_tuple()
                sigs = [key[0] for key in index if key[1] == magic and tuple(key[0]) not in d.overloads]
            except Exception as e:  # noqa: BLE001 - numba's internals moved: the workers load them
                log.debug("numba's cache index of %s not read (%s); not loaded before the workers start", d, e)
                continue
            for sig in sigs:
                misses = sum(d._cache_misses.values())
                try:
                    d.compile(sig)
                except Exception as e:  # noqa: BLE001 - a damaged entry (numba raises as it loads
                    # it), maybe of a loop no case calls: left to the workers, as before
                    log.debug("%s%s not loaded from numba's cache (%s: %s)", d, sig, type(e).__name__, e)
                    continue
                if sum(d._cache_misses.values()) != misses:  # compiled, not loaded: stale entry
                    log.debug("%s%s compiled anew while loading the cache", d, sig)
                n += 1
    return n


def _plain_streams(_runner) -> None:
    """In a fork()ed worker: sys.stdout and sys.stderr the files themselves, as a spawned worker
    has them, not the proxies of the sweep command's progress bar on a terminal (rich's Live),
    which printed each line the worker wrote (a warning) with its own stale copy of the bar,
    and wait on that bar's locks, which another thread may have held as fork() copied them.
    And from the start the signal handling sweep_worker.ForkedWorker sets later (SIGINT ignored,
    SIGTERM Python's default): the nanny terminates a worker still starting when Ctrl-C stops
    the sweep, which in the CLI's handler raised SystemExit inside dask's start-up."""
    from tactileskin.sweep_worker import worker_signals

    worker_signals(default_sigterm=True)
    for name in ("stdout", "stderr"):
        inner = getattr(getattr(sys, name), "rich_proxied_file", None)
        if inner is not None:
            setattr(sys, name, inner)


def worker_start_method() -> str:
    """How the local cluster starts its workers: fork() on Linux, where the package is fork-safe
    (threads.py's fork handler, mesh._gmsh.in_fresh_process) and a worker then needs no imports
    of its own; else dask's default, spawn (fork() is unsafe on macOS, absent on Windows). Also
    spawn where this process started numba's or PARDISO's threads (a notebook's solve before
    its sweep): a child fork()ed from it solves on one thread (threads.forked_from_threads);
    and where this process (or one it was fork()ed from) made a 3D mesh: a child fork()ed from
    it meshes each 3D case in a fresh Python (mesh._gmsh.in_fresh_process), dearer than the
    imports fork() saves. And where another thread of this process runs code of its own (a
    user's thread, a notebook kernel's; _other_threads): a lock it holds as fork() copies the
    process stays held in the child for good (a thread meshing, between two of functools.
    cached_property's RLock calls, hung the worker at its first case)."""
    from tactileskin.threads import threads_started

    gmsh_state = sys.modules.get("tactileskin.mesh._gmsh")
    meshed_3d = gmsh_state is not None and gmsh_state._meshed_3d_in is not None
    return ("fork" if sys.platform.startswith("linux") and not threads_started() and not meshed_3d
            and not _other_threads() else "spawn")


def _restore_environ(saved: dict) -> None:
    """Put back this process's values (None: unset) of the variables in `saved`."""
    for k, v in saved.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v


def _close_unfinished_clusters(before: set) -> None:
    """Close the clusters (not in `before`) a Ctrl-C interrupted while they started: dask's
    exit hook would close them too, and end in an AssertionError traceback on one still in
    Status.init."""
    from distributed.deploy.spec import SpecCluster

    for cluster in [c for c in SpecCluster._instances if c not in before]:
        try:
            cluster.close(timeout=5)
        except BaseException:  # noqa: BLE001 - interrupted already; nothing left to report
            pass
        cluster.shutdown_on_close = False


def _raise_fd_limit(n: int) -> None:
    """Each case being computed holds an open lock file; make room for n of them."""
    try:
        import resource

        soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        want = n + 256
        if soft != resource.RLIM_INFINITY and soft < want:
            resource.setrlimit(resource.RLIMIT_NOFILE, (want if hard == resource.RLIM_INFINITY else min(want, hard), hard))
    except (ImportError, ValueError, OSError):
        pass


def worker_threads(n: int) -> str:
    """PARDISO threads of each of n local workers for its large (3D) systems
    (TACTILESKIN_THREADS, fe.linsolve.default_threads; the other systems and the workers'
    BLAS stay at one): the user's setting if any (threads.user_setting), else the CPUs
    shared out, so that fewer cases than cores (a lone 3D case, `--workers 1`) still use
    every core and n = cores gives each worker one thread."""
    from tactileskin.threads import available_cpus, user_setting

    user = user_setting(large=True)
    if user is not None:
        return user[1]
    return str(max(1, available_cpus() // max(1, n)))


def run_sweep(
    scenes: Iterable[Scene],
    cache: ResultCache,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    serial: bool = False,
    on_event: Callable[[CaseOutcome], None] | None = None,
) -> list[CaseOutcome]:
    """Solve every scene without a valid cache entry; returns one outcome per scene, in order.

    scheduler: address of a running dask scheduler; None starts a LocalCluster.
    workers: LocalCluster worker processes (default: number of cores).
    serial: run in this process without Dask (debugging, profiling).
    A case is computed while holding its lock; cases locked by another run are waited for
    after our own, then taken from the cache, or computed if that run did not store them.
    """
    scenes = list(scenes)
    if workers is not None and workers < 1 and not serial and not scheduler:
        raise ParameterError("workers", workers, ">= 1 (or use serial)")
    keys = [cache.key(sc) for sc in scenes]  # reads every material file before any work
    ids = case_ids(scenes)
    outcomes: list[CaseOutcome | None] = [None] * len(scenes)
    locks: dict[int, object] = {}

    def emit(oc: CaseOutcome, i: int) -> None:
        outcomes[i] = oc
        on_event and on_event(oc)

    def claim(i: int, blocking: bool) -> bool:
        """True: case i is ours to compute (lock held); False: cached, or locked elsewhere."""
        lock = cache.lock(keys[i], blocking=blocking)
        if lock is None:
            return False
        rec = cache.lookup(scenes[i], keys[i])  # under the lock: a damaged entry is removed
        if rec is None:
            locks[i] = lock
            return True
        lock.release()
        emit(CaseOutcome(scenes[i], "cached", case=ids[i], record=rec, key=keys[i]), i)
        return False

    def finish(i: int, packed) -> None:
        sc = scenes[i]
        status, result, secs, err, diag = packed
        rec = None
        if status == "done":
            try:
                rec = cache.store_record(sc, result, keys[i])
                if rec is None:
                    status, err = "failed", "the stored result did not pass the cache's validation"
            except TactileSkinError as e:
                status, err = "failed", str(e)
        locks.pop(i).release()
        if status == "failed":  # the caller reports it (on_event, the outcome's status): not twice
            log.info("case %s failed: %s", ids[i], err)
        emit(CaseOutcome(sc, status, secs, err, diag, case=ids[i], record=rec, key=keys[i]), i)

    _raise_fd_limit(len(scenes))
    runner = _Runner(scenes, keys, serial=serial, scheduler=scheduler, workers=workers)
    try:
        todo, busy, held = [], [], set()
        for i, sc in enumerate(scenes):
            if keys[i] in held:
                busy.append(i)  # the same entry as an earlier case of this sweep
            elif (rec := cache.lookup(sc, keys[i], repair=False)) is not None:
                emit(CaseOutcome(sc, "cached", case=ids[i], record=rec, key=keys[i]), i)
            elif claim(i, blocking=False):
                todo.append(i)
                held.add(keys[i])
            elif outcomes[i] is None:
                busy.append(i)  # another run holds it
        runner(todo, finish)
        # One lock at a time from here on, so that waiting runs cannot deadlock.
        for i in busy:
            ours = claim(i, blocking=False)
            if not ours and outcomes[i] is None:
                log.warning("case %s is being computed by another run (lock %s); waiting for it",
                            ids[i], cache.root / f"{keys[i]}.lock")
                ours = claim(i, blocking=True)
            if ours:
                runner([i], finish)
    finally:
        runner.close()
        for lock in locks.values():
            lock.release()
    return outcomes


def _api_sweep():
    from tactileskin.api import sweep

    return sweep


class _CallableModule(type(os)):
    # `tactileskin.sweep(grid, ...)` runs a sweep from Python (tactileskin.api.sweep) while
    # `tactileskin.sweep` stays this module (run_sweep, expand_grid, ...). help() and
    # inspect.signature() of it must describe the call a user makes, so both come from the
    # API function (pydoc documents any module as a module: its __doc__ is the API's).

    def __call__(self, grid=None, **kw):
        return _api_sweep()(grid, **kw)

    @property
    def __signature__(self):
        import inspect

        return inspect.signature(_api_sweep())

    @property
    def __doc__(self):
        import inspect

        fn = _api_sweep()
        own = self.__dict__.get("__doc__") or ""
        return (f"tactileskin.sweep{inspect.signature(fn)}\n\n{inspect.cleandoc(fn.__doc__ or '')}\n\n"
                f"(The module tactileskin.sweep behind it, which the CLI uses:)\n\n{own}")


import sys as _sys  # noqa: E402

_sys.modules[__name__].__class__ = _CallableModule
