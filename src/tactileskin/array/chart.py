"""The design chart: classification accuracy over skin thickness x array pitch x noise.

Per material and thickness the stimulus maps come from map sources (today: the bone
surface, the paper's sensor film):

- "paper": the paper's three indenters on the paper's fingertip: flat and curved (their 2D
  plane-strain bone profile extruded along z; exact for an indenter uniform along the finger,
  away from the slab ends) and one Braille dot (the 3D bone map of the single-dot solve).
- "shapes": the paper's three and a sphere (radius ChartConfig.sphere_radius, 3D on the
  fingertip at the `sphere_quality` 3D preset): the issue's stimulus list beyond the
  paper's claim, which stays on the "paper" set.
- "letters": the 26 letters a-z as cells and the digits 0-9 as the number sign and a-j's
  cell (surrogate.char_centres), each the superposition of the single-dot response at its
  dots in the frame of its full cells, each dot weighted by its load beside its neighbours
  (ChartConfig.letters_model; surrogate.interaction_weights: the lone dot's surface
  deflection and load-approach law, the latter from a second lone-dot solve at
  surrogate.SHALLOW x the depth; its error against full solves is stated by
  `validate_surrogate`), on
  `skin` (default the flat pad, where a dot's response translates exactly; on the
  fingertip the translation across the curved finger is approximate).

Solves go through the sweep's result cache (run_sweep), so a rerun only reads files.
Each (material, thickness, set, pitch) gets one draw of offsets; every noise level reads
the same noise-free readings (so the noise axis compares like with like). The noise axis is
fractions of each set's full scale (noise_fs) or a fixed std in MPa (noise_mpa); it enters
no solve, so either reads the same cached solves.
"""

from __future__ import annotations

import json
import logging
import time
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from typing import Callable

import numpy as np

from tactileskin.array import classify, surrogate
from tactileskin.array.maps import mirrored
from tactileskin.array.config import SETS, ChartConfig
from tactileskin.errors import ParameterError, TactileSkinError
from tactileskin.geometry.braille import get_standard
from tactileskin.results import BoneMap, read_bone_map

log = logging.getLogger(__name__)

PAPER_PITCH = 0.75          # the paper's rule: Braille span 1.5 mm at t = 1 mm -> 0.75 mm pitch
GOOD = 0.95                 # accuracy at which a set counts as discriminated


# --- map sources ----------------------------------------------------------------------------

def dot_scene(thickness, material, cfg: ChartConfig, text: str = "", skin: str | None = None):
    from tactileskin.scene import Scene

    size, ratio = cfg.mesh_for(thickness)
    return Scene(dim=3, skin=skin or cfg.skin, indenter="braille", thickness=thickness, material=material,
                 braille_text=text, braille_standard=cfg.standard, mesh_size=size,
                 refinement=ratio, depth=cfg.depth_for(thickness), sensors=depth_sensor(cfg, thickness))


def depth_sensor(cfg: ChartConfig, thickness) -> tuple:
    """The sensors of a 3D chart scene: a chart read inside the skin (raw_map_of at its depth) is
    meshed as a scene with a one-point sensor there, so mesh.sizing keeps the contact spot fine
    for sensors in the skin (its thick-skin coarsening was measured on the bone map only; 0.4 mm
    deep under it a t = 5 dot read +36 %); () for a chart read on the bone."""
    sd = cfg.sensor_depth_at(thickness)
    if sd is None or sd >= float(thickness) - 1e-9:
        return ()
    return ({"name": "chart_depth", "s": [0.0], "depth": float(sd)},)


def accuracy_text(a: float) -> str:
    """An accuracy to 2 decimals, or to as many more as keep it on its side of GOOD: 0.9462, not
    discriminated, read '0.95' beside a legend 'bold at >= 0.95'."""
    for k in range(2, 7):
        text = f"{a:.{k}f}"
        if (float(text) >= GOOD) == (a >= GOOD):
            return text
    return repr(float(a))


def section_scene(thickness, material, indenter, skin="fingertip", depth=None):
    from tactileskin.scene import Scene

    return Scene(dim=2, skin=skin, indenter=indenter, thickness=thickness, material=material, depth=depth)


def sphere_scene(thickness, material, cfg: ChartConfig):
    """The shapes set's sphere: 3D on the paper's fingertip at the chart's depth."""
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    sc = Scene(dim=3, skin="fingertip", indenter="sphere", indenter_radius=cfg.sphere_radius, thickness=thickness,
               material=material, depth=cfg.depth_for(thickness), sensors=depth_sensor(cfg, thickness))
    return with_quality(sc, cfg.sphere_quality)


def plate_touches(dot) -> bool:
    """True if the Braille scene `dot` indents past the dot height (its base plate presses too)."""
    return dot.indentation > get_standard(dot.braille_standard).height + 1e-12


def blank_scene(dot):
    """The blank Braille plate of the scene `dot` alone: a flat plate at the plate's own depth
    (depth - dot height), at the same rate, on the same skin: the 3D pad (the flat plate is wider
    than the pad, so it presses the whole top like the Braille plate), or the fingertip's 2D
    section (extruded along z by `blank_map`). Coarse mesh: its bone map is smooth away from the
    pad's edges."""
    from tactileskin.scene import Scene

    d = dot.indentation - get_standard(dot.braille_standard).height
    if d <= 0:
        raise ParameterError("depth", dot.indentation, "> the dot height for a blank-plate solve")
    if dot.skin == "pad":
        return Scene(dim=3, skin="pad", indenter="flat", thickness=dot.thickness, material=dot.material,
                     depth=d, rate=dot.rate, mesh_size=dot.mesh_size, refinement=1.0)
    return Scene(dim=2, skin=dot.skin, indenter="flat", thickness=dot.thickness, material=dot.material,
                 depth=d, rate=dot.rate)


def blank_map(scene, record, like: BoneMap, depth: float | None = None) -> BoneMap:
    """The blank plate's full bone map (3D) or its 2D profile extruded over like.z (at the
    sensor `depth` below the contact surface where given: map_of, profile_of)."""
    if scene.dim == 3:
        return map_of(record, depth)
    return extruded(*profile_of(record, depth), like.z)


def result_cache(cache):
    """The ResultCache of `cache`: one as given, a folder path (str or os.PathLike), or None for
    api.default_cache_dir(), as ts.sweep takes it (a path failed with "AttributeError: 'str'
    object has no attribute 'key'")."""
    from tactileskin import validate
    from tactileskin.cache import ResultCache, open_cache

    if isinstance(cache, ResultCache):
        return cache
    if cache is None:
        from tactileskin.api import default_cache

        return default_cache()
    return open_cache(validate.path(cache, "cache", "a folder path (str or os.PathLike), a ResultCache or None"), "cache")


def solve_cached(scenes, cache, on_event=None, workers: int | None = None) -> dict:
    """{scene: cache record} through the sweep's cache, the uncached cases on a local Dask
    cluster of `workers` processes (None: one per core; 1: in this process). Every solve
    is single-threaded, so two cores solve two cases at once: the chart's nine 3D solves of
    one material took 553 s one at a time. A failed case raises TactileSkinError naming it."""
    from tactileskin.sweep import run_sweep

    cache = result_cache(cache)
    scenes = list(dict.fromkeys(scenes))
    out = {}
    serial = workers == 1 or len(scenes) == 1
    for oc in run_sweep(scenes, cache, serial=serial, workers=workers, on_event=on_event):
        if oc.status == "failed":
            raise TactileSkinError(f"solve of {oc.case or oc.scene.label()} failed: {oc.error}")
        out[oc.scene] = oc.record
    return out


BLANK_DATA = ("data", "blank_plate.json")  # measured errors of the blank plate's maps (blank_measured)
# The order the blank's maps converge at in the max norm, the lowest measured (1.2 -> 0.8 -> 0.6 / 1 at t = 3,
# 1 mm above the bone; benchmarks/results/blank_plate.md): a reference whose last refinement step, by a size
# ratio r, moved its map by s is taken s / (r^order - 1) off (1.41 s for 0.6 / 2 -> 0.42 / 2; order 2: 0.96 s)
BLANK_ORDER = 1.5


def reference_error(row: dict) -> float | None:
    """The reference's own error estimated from a blank_plate.json row's reference_shift (its last step, from
    shift_mesh, at BLANK_ORDER); None without them."""
    if row.get("reference_shift") is None or row.get("shift_mesh") is None:
        return None
    r = (float(row["shift_mesh"][0]) / float(row["shift_mesh"][1])) / (
        float(row["reference_mesh"][0]) / float(row["reference_mesh"][1]))
    return float(row["reference_shift"]) / (r ** BLANK_ORDER - 1.0) if r > 1.0 else None


@lru_cache(maxsize=1)
def _blank_data() -> dict:
    return json.loads(resources.files("tactileskin").joinpath(*BLANK_DATA).read_text(encoding="utf-8"))


def blank_measured(blank, extent: float, sensor_depth: float | None = None) -> dict | None:
    """The measured error of the blank plate `blank`'s map (data/blank_plate.json, written by
    benchmarks/blank_plate.py) as a chart reads it: the bone map (sensor_depth None) or the
    map at that depth below the contact surface, inside |s|, |z| <= `extent`; the row of the
    same scene (material, thickness, depth, mesh, pad, rate) whose error plus its reference's
    own error (reference_error: its last refinement step, reference_shift from shift_mesh, at
    BLANK_ORDER) is within surrogate.TOLERANCE, else None (unmeasured, measured past it, or
    without reference_shift: the reference's error unknown). blank_scene's
    mesh is coarser than the preview preset's, so quality flags it coarse_mesh; this measurement
    is what covers that flag (suspect_solves)."""
    data = _blank_data()
    close = lambda a, b: abs(float(a) - float(b)) <= 1e-9  # noqa: E731
    height = None if sensor_depth is None else float(blank.thickness) - float(sensor_depth)
    for r in data["cases"]:
        if blank.dim == 3 and blank.skin == "pad" and r["material"] == blank.material \
                and all(close(a, b) for a, b in ((r["thickness_mm"], blank.thickness),
                                                 (r["depth_mm"], blank.indentation),
                                                 (r["mesh"][0], blank.mesh_size), (r["mesh"][1], blank.refinement),
                                                 (r["pad_mm"][0], blank.pad_width), (r["pad_mm"][1], blank.pad_length),
                                                 (r["rate"], blank.rate))) \
                and float(r["extent_mm"]) >= extent - 1e-9 \
                and (r["sensor_height_mm"] is None) == (height is None) \
                and (height is None or close(r["sensor_height_mm"], height)) \
                and reference_error(r) is not None \
                and float(r["max_error"]) + reference_error(r) <= surrogate.TOLERANCE:
            return r
    return None


def suspect_solves(recs: dict, measured: dict | None = None) -> list[str]:
    """A note per solve of the chart whose result tactileskin.quality flags (its summary's
    status is not "ok": no contact, the law out of its range, a peak at the skin's edge, ...):
    the maps built on it are as suspect as it is. `measured` {scene: blank_measured row}: those
    solves' coarse_mesh flag is covered by the measured error of their maps and does not count;
    their other flags do."""
    out = []
    for sc, rec in recs.items():
        summary = getattr(rec, "summary", None) or {}
        status = str(summary.get("status", "ok"))
        if status != "ok" and (measured or {}).get(sc) is not None:
            status = _without_coarse_mesh(summary, status)
        if status != "ok":
            out.append(f"the solve {sc.label()} ({sc.indenter_label()}, t = {sc.thickness:g} mm, {sc.material}) "
                       f"is {status}: the chart's maps built on it are suspect")
    return out


def _without_coarse_mesh(summary: dict, status: str) -> str:
    """`status` of a summary less its coarse_mesh flag; `status` as it is where it is not the
    status quality computes from the summary (a flag cannot be told apart then)."""
    from tactileskin import quality

    found = quality.flags(summary)
    if quality.status_of(found) != status:
        return status
    return quality.status_of([f for f in found if f.code != "coarse_mesh"])


def blank_note(blank, row: dict) -> str:
    """What the chart says of a blank plate whose coarse_mesh flag a measurement covers."""
    where = "bone map" if row["sensor_height_mm"] is None else f"map {row['sensor_height_mm']:g} mm above the bone"
    return (f"the blank plate {blank.label()} (t = {blank.thickness:g} mm, {blank.material}) is meshed coarser than "
            f"the preview preset ({blank.mesh_size:g} / {blank.refinement:g}); its {where} is measured "
            f"{row['max_error']:.1%} off (max, L2 {row['l2_error']:.1%}) a {row['reference_mesh'][0]:g} / "
            f"{row['reference_mesh'][1]:g} mesh (its own last refinement step moved it {row['reference_shift']:.1%}, "
            f"its own error taken as {reference_error(row):.1%}) "
            f"within |s|, |z| <= {row['extent_mm']:g} mm "
            f"(data/blank_plate.json; tolerance {surrogate.TOLERANCE:.0%})")


def bone_map_of(record) -> BoneMap:
    return mirrored(read_bone_map(record.path / "bone_map.csv"))


def map_of(record, depth: float | None = None) -> BoneMap:
    """The full map a chart reads from a 3D solve: its bone map, or (depth in mm below the
    contact surface) the pressure on that depth surface (raw_map_of), mirrored as the bone map."""
    return bone_map_of(record) if depth is None else mirrored(raw_map_of(record, depth))


def raw_map_of(record, depth: float | None = None) -> BoneMap:
    """The map of a 3D solve's modelled part: bone_map.csv, or at `depth` below the contact
    surface P = -tr(sigma) / 3 read from its result.vtu (fe.probe.result_sampler: the cached
    solve, not solved again) at the bone map's (s, z) carried along the skin's normal to that
    depth (sensors.coordinates_for, as a sensor layout at that depth reads it), s then the arc
    length on the depth surface (the array lies on it)."""
    m = read_bone_map(record.path / "bone_map.csv")
    if depth is None:
        return m
    s, P = _at_depth_kept(record, m.s, m.z, depth)
    return BoneMap(s, m.z, P, m.section_z)


def profile_of(record, depth: float | None = None) -> tuple:
    """(s, P) of a 2D solve: its bone profile, or P on the depth surface (as raw_map_of)."""
    if depth is None:
        return record.s, record.pressure
    return _at_depth_kept(record, np.asarray(record.s, float), None, depth)


MEMO_DIR = "derived_maps"  # in a cache entry: its maps read at a sensor depth (_at_depth_kept)
MEMO_VERSION = 1           # the memo's own layout


def _at_depth_kept(record, s, z, depth: float) -> tuple:
    """_at_depth of a validated cache entry (a cache.CaseRecord), kept in the entry's MEMO_DIR:
    a 3D map at depth locates every grid point in the P2 mesh of result.vtu (2.3 s for the
    t = 1 mm fingertip dot on 1.2 / 4; about 3 s on the default meshes), on every rerun. The memo
    is named and checked by everything that made it: the entry's key and the digests cache.json
    holds of its files (result.vtu, the grids' files), s and z, the depth, and the code
    (cache.code_digest, which the key holds too); one that does not match or does not read back
    whole is recomputed and rewritten (logged), never an error; one that cannot be written is
    skipped (logged). Any other record (not in the cache) is read as it is."""
    key = _memo_key(record, s, z, depth)
    path = None if key is None else record.path / MEMO_DIR / f"{key}.npz"
    if path is not None and path.exists():
        got = _read_memo(path, key, np.asarray(s).size, None if z is None else np.asarray(z).size)
        if got is not None:
            return got
    out = _at_depth(record, s, z, depth)
    if path is not None:
        _write_memo(path, key, *out)
    return out


def _memo_key(record, s, z, depth: float) -> str | None:
    """The memo's name: SHA-256 of what made the map (_at_depth_kept); None for a record that is
    not a cache entry."""
    import hashlib
    import json

    from tactileskin.cache import CaseRecord, code_digest

    if not isinstance(record, CaseRecord):
        return None
    try:
        meta = json.loads((record.path / "cache.json").read_text(encoding="utf-8"))
        payload = {"entry": meta["key"], "files": meta["files"], "depth": float(depth).hex(), "code": code_digest(),
                   "version": MEMO_VERSION,
                   "grid": [hashlib.sha256(np.ascontiguousarray(v, float).tobytes()).hexdigest() if v is not None
                            else None for v in (s, z)]}
        text = json.dumps(payload, sort_keys=True)
    except (OSError, ValueError, KeyError, TypeError) as e:  # read as if there were no memo
        log.info("no map memo for %s: %s", record.path, e)
        return None
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def _memo_digest(s, P) -> str:
    import hashlib

    return hashlib.sha256(np.ascontiguousarray(s, float).tobytes() + np.ascontiguousarray(P, float).tobytes()).hexdigest()


def _read_memo(path, key: str, ns: int, nz: int | None) -> tuple | None:
    """(s, P) of a memo written by _write_memo under `key` with the shapes of an (ns, nz) grid;
    None (logged) where it is anything else."""
    import zipfile

    try:
        with np.load(path, allow_pickle=False) as f:
            s, P, memo = f["s"], f["P"], f["memo"]
        shape = (ns,) if nz is None else (nz, ns)
        if str(memo) != f"{key} {_memo_digest(s, P)}" or s.shape != (ns,) or P.shape != shape \
                or not (np.all(np.isfinite(s)) and np.all(np.isfinite(P))):
            raise ValueError("another map's or altered")
    except (OSError, ValueError, KeyError, EOFError, TypeError, zipfile.BadZipFile) as e:  # TypeError: a bare .npy
        log.warning("map memo %s is damaged (%s); the map is read from result.vtu again", path, e)
        return None
    return s, P


def _write_memo(path, key: str, s, P) -> None:
    import io

    from tactileskin import fileio

    buf = io.BytesIO()
    np.savez(buf, s=np.asarray(s, float), P=np.asarray(P, float), memo=np.array(f"{key} {_memo_digest(s, P)}"))
    try:
        # the memo folder alone, not its parents (atomic_write_bytes makes them): an entry
        # discarded meanwhile by another process would come back as a key folder, no cache.json
        path.parent.mkdir(exist_ok=True)
        fileio.atomic_write_bytes(path, buf.getvalue())
    except (OSError, TactileSkinError) as e:  # a read-only cache: the map is used, not kept
        log.info("map memo %s not written: %s", path, e)


def _at_depth(record, s, z, depth: float) -> tuple:
    """(arc length on the depth surface (ns,), P (nz, ns), or (ns,) in 2D where z is None) of a
    solve at the bone positions s (and z) carried to `depth`; positions past the end of the
    skin at that depth (the fingertip's nail cut: sensors.SectionCoordinates.s_limit) read 0."""
    from tactileskin.fe.probe import result_sampler
    from tactileskin.sensors import coordinates_for

    coords = coordinates_for(record.scene)
    s = np.asarray(s, float)
    limit = coords.s_limit(depth) if hasattr(coords, "s_limit") else np.inf
    inside = np.abs(s) <= limit + 1e-9
    xy = coords.frame(s[inside], np.full(int(inside.sum()), depth))[0]
    if z is None:
        pts = xy
    else:  # z-major, as the bone map's rows
        pts = np.column_stack([np.tile(xy, (len(z), 1)), np.repeat(np.asarray(z, float), len(xy))])
    sig = result_sampler(record.path / "result.vtu")(pts)
    P = np.zeros((1 if z is None else len(z), s.size))
    P[:, inside] = (-np.trace(sig, axis1=1, axis2=2) / 3.0).reshape(P.shape[0], -1)
    if not getattr(coords, "straight", False):  # a curved section: s as arc length at that depth
        fine = np.linspace(0.0, max(float(np.abs(s).max()), 1e-12), 4001)
        jac = np.ones_like(fine)
        ok = fine <= limit
        jac[ok] = coords.frame(fine[ok], np.full(int(ok.sum()), depth))[3]
        arc = np.concatenate([[0.0], np.cumsum(0.5 * (jac[1:] + jac[:-1]) * np.diff(fine))])
        s = np.sign(s) * np.interp(np.abs(s), fine, arc)
    return s, (P[0] if z is None else P)


def surface_deflection(record, top: float):
    """w(dx, dz): the downward deflection of the free surface y = `top` of a single-dot solve
    (its result.vtu; a half or quarter model is mirrored by |dx|, |dz|), linear between the
    surface nodes, 0 beyond the modelled surface."""
    from scipy.interpolate import LinearNDInterpolator

    from tactileskin.results import read_vtu

    try:
        m = read_vtu(record.path / "result.vtu")
    except (OSError, ValueError) as e:
        raise TactileSkinError(f"cannot read the single-dot result {record.path}: {e}") from None
    X, u = m.points, m.point_data["displacement_mm"]
    on = np.abs(X[:, 1] - top) <= 1e-6 * max(top, 1.0)
    f = LinearNDInterpolator(np.abs(X[on][:, [0, 2]]), -u[on, 1], fill_value=0.0)
    return lambda dx, dz: f(np.abs(np.asarray(dx, float)), np.abs(np.asarray(dz, float)))


def extruded(s, p, z) -> BoneMap:
    """A plane-strain profile P(s) (s >= 0) as a map uniform along z, mirrored to s < 0."""
    s, p = np.asarray(s, float), np.asarray(p, float)
    s, idx = np.unique(np.round(s, 9), return_index=True)
    return mirrored(BoneMap(s, np.asarray(z, float), np.tile(p[idx], (len(z), 1))))


def stimulus_maps(kernel: BoneMap, section, profiles: dict, cfg: ChartConfig, paper_kernel: BoneMap = None,
                  base: BoneMap | None = None, letters: dict | None = None, sphere: BoneMap | None = None,
                  weights: dict | None = None) -> dict:
    """{set: {name: BoneMap}} for one material and thickness: the letters from `kernel` (the
    single dot on cfg.skin, `section` its section; plus `base`, the blank plate, for the
    plate-aware kernel; `weights` {character: its dots' loads}, see `letter_weights`; default
    1 each) unless given as `letters` (full solves), the paper set's dot `paper_kernel` (the
    fingertip's; default `kernel`), the shapes set's `sphere`."""
    out = {}
    pk = kernel if paper_kernel is None else paper_kernel
    paper = {name: extruded(*profiles[name], pk.z) for name in ("flat", "curved")} if profiles else {}
    if "paper" in cfg.sets:
        out["paper"] = {**paper, "braille": pk}
    if "shapes" in cfg.sets:
        if sphere is None:
            raise ParameterError("sphere map", None, "the sphere's bone map for the shapes set")
        out["shapes"] = {**paper, "braille": pk, "sphere": sphere}
    if "letters" in cfg.sets and letters is not None:
        out["letters"] = letters
    elif "letters" in cfg.sets:
        out["letters"] = {c: surrogate.superpose(kernel, surrogate.char_centres(c, cfg.standard), section,
                                                 weights=None if weights is None else weights[c], base=base)
                          for c in cfg.letters}
    return out


def letter_weights(cfg: ChartConfig, deflection, exponent: float = 1.0) -> dict:
    """{character: the loads of its dots} from the lone dot's surface deflection w(dx, dz)
    and load-approach exponent (surrogate.interaction_weights). Raises ParameterError naming
    the character where a dot would carry no load (its neighbours pushing the surface below
    its reach)."""
    out = {}
    for c in cfg.letters:
        w = surrogate.interaction_weights(surrogate.char_centres(c, cfg.standard), deflection, exponent)
        if not np.all(np.isfinite(w) & (w > 0)):
            raise ParameterError(f"interaction weights of {c!r}", np.round(w, 3).tolist(),
                                 "finite and > 0 (a surface deflection that gives a dot no load)")
        out[c] = w
    return out


# --- the chart ------------------------------------------------------------------------------

@dataclass
class Chart:
    config: ChartConfig
    rows: list = field(default_factory=list)        # one dict per (material, t, set, pitch, noise, method)
    confusions: dict = field(default_factory=dict)  # (material, t, set, pitch, noise) -> {method: matrix}
    labels: dict = field(default_factory=dict)      # set -> class names
    cutoffs: list = field(default_factory=list)     # per (material, t): the single dot's measured cut-off
    notes: list = field(default_factory=list)       # what makes a part of the chart suspect
    measured: list = field(default_factory=list)    # flags covered by a measured error (blank_note)
    letters_models: dict = field(default_factory=dict)  # (material, t) -> the letters' model used
    fallbacks: dict = field(default_factory=dict)  # (material, t) -> the surrogate's measured error that
    #                                                sent its letters to full solves (validity.measured)
    suspect: dict = field(default_factory=dict)    # (material, t) -> why its solves are suspect
    seconds: float = 0.0

    def accuracy(self, material, t, set_, pitch, noise, method="template") -> float:
        """The accuracy of one cell of the chart; a value the chart was not made for (a noise
        level mistyped, a pitch not charted) is a ParameterError naming it and the charted
        values (it read NaN). NaN only for a charted cell that has no row (its solves failed)."""
        cfg = self.config
        methods = sorted({r["method"] for r in self.rows}) or ["template"]
        for name, value, charted in (("material", material, cfg.materials), ("t", t, cfg.thicknesses),
                                     ("set_", set_, cfg.sets), ("pitch", pitch, cfg.pitches),
                                     ("noise", noise, cfg.noise_levels), ("method", method, methods)):
            if value not in charted:
                raise ParameterError(name, value, "one the chart was made for: "
                                     + ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in charted),
                                     "noise in MPa" if name == "noise" and cfg.noise_key == "noise_mpa" else "")
        for r in self.rows:
            if (r["material"], r["thickness_mm"], r["set"], r["pitch_mm"], r[cfg.noise_key], r["method"]) == \
                    (material, t, set_, pitch, noise, method):
                return r["accuracy"]
        return float("nan")

    def to_csv(self, indicative: dict | None = None) -> str:
        """The accuracy rows (columns in docs/commands.md, `tactileskin array`; `n_test`: test readings per
        stimulus, so an accuracy counts n_test / chance readings); `indicative` {(material,
        thickness): reason} marks the letters rows whose surrogate is not shown within the
        tolerance (status "indicative: reason"), as the report's daggers do."""
        cols = ["material", "thickness_mm", "set", "pitch_mm", "taxel_mm", "sensor_depth_mm", "sensor_height_mm",
                "noise_fs", "noise_mpa",
                "full_scale_mpa", "bits", "method", "accuracy", "chance", "n_test", "ci_low", "ci_high"]
        lines = [",".join(cols + ["status"])]
        for r in self.rows:
            why = (indicative or {}).get((r["material"], r["thickness_mm"])) if r["set"] == "letters" else None
            bad = self.suspect.get((r["material"], r["thickness_mm"]))
            status = ('"suspect: ' + bad.replace('"', "'") + '"' if bad else f'"indicative: {why}"' if why else "ok")
            # older rows: no interval, taxels on the bonded surface (t below the contact surface)
            depth = r.get("sensor_depth_mm", r["thickness_mm"])
            vals = [r.get(c, "") if c in ("ci_low", "ci_high") else depth if c == "sensor_depth_mm"
                    else r.get(c, r["thickness_mm"] - depth) if c == "sensor_height_mm" else r[c] for c in cols]
            lines.append(",".join([*(f"{v:.6g}" if isinstance(v, float) else str(v) for v in vals), status]))
        return "\n".join(lines) + "\n"


def _chart_scenes(cfg: ChartConfig, material: str, t: float) -> tuple:
    """(dot, paper dot, blank plate, {flat, curved} sections, sphere) of one material and
    thickness: the letters on cfg.skin; the paper and shapes sets (flat, curved, dot; sphere)
    on the paper's fingertip, where the 2D sections are exact (a plate wider than the pad has
    no converged solve there)."""
    shapes = "shapes" in cfg.sets
    dot = dot_scene(t, material, cfg) if "letters" in cfg.sets else None
    pdot = dot_scene(t, material, cfg, skin="fingertip") if "paper" in cfg.sets or shapes else None
    sec2 = {k: section_scene(t, material, k, depth=cfg.depth_for(t)) for k in ("flat", "curved")} if pdot else {}
    blank = blank_scene(dot) if dot is not None and plate_touches(dot) else None
    sphere = sphere_scene(t, material, cfg) if shapes else None
    return dot, pdot, blank, sec2, sphere


def letters_model(cfg: ChartConfig, dot, base) -> str:
    """The letters' model used for the dot scene `dot` (`base`: its blank plate, or None): "full",
    or where the plate touches "plate + sum" (the blank plate plus the plate-aware kernels);
    else cfg.letters_model, except that the interaction weights need the flat pad's free
    surface: elsewhere the plain sum."""
    if cfg.letters_model == "full":
        return "full"
    if base is not None:
        return "plate + sum"
    if cfg.letters_model == "interaction" and (dot is None or dot.skin != "pad"):
        return "sum"
    return cfg.letters_model


def surrogate_trust(cfg: ChartConfig, material: str, t: float, model: str, validation=None) -> dict:
    """array.validity.measured of the letters' `model` at (material, t) as this chart reads
    them (its dot scene's depth and mesh, its read square), from `validation` rows, else the
    project's measurements."""
    from tactileskin.array.validity import measured

    dot = dot_scene(t, material, cfg)
    return measured(material, cfg.skin, cfg.mesh_for(t), t, float(dot.indentation), validation,
                    model=model, extent=cfg.read_extent, taxel=cfg.min_taxel, standard=cfg.standard,
                    sensor_depth=cfg.sensor_depth_at(t))


def letters_judgment(cfg: ChartConfig, material: str, t: float, dot, blank, validation=None) -> dict | None:
    """surrogate_trust of the letters' model at (material, t) where a fallback to full solves
    could apply (cfg.fallback on, a dot scene, the letters set, a surrogate); else None."""
    if not cfg.fallback or dot is None or "letters" not in cfg.sets or cfg.letters_model == "full":
        return None
    return surrogate_trust(cfg, material, t, letters_model(cfg, dot, blank), validation)


def fallback_reason(cfg: ChartConfig, material: str, t: float, dot, blank, validation=None) -> dict | None:
    """The measured error (letters_judgment) that sends the letters of (material, t) to full
    solves: its status is "exceeds" against full solves on the chart's own mesh; else None.
    Measured past the tolerance only against a finer mesh, the letters stay on the surrogate
    (marked): full solves on the chart's mesh carry its discretisation error too (a 1.2 / 8
    chart at t = 1 mm silicone: the full cell on 1.2 / 8 reads 6.8 % off 0.8 / 8, the
    surrogate's worst letter 5.5 %)."""
    from tactileskin.array.validity import finer_reference

    m = letters_judgment(cfg, material, t, dot, blank, validation)
    if m is None or m["status"] != "exceeds" or finer_reference(m, cfg.mesh_for(t)):
        return None
    return m


def shallow_scene(dot):
    """The lone dot at surrogate.SHALLOW x its depth: with `dot`, its load-approach law
    (surrogate.load_exponent)."""
    return dot.replace(depth=surrogate.SHALLOW * float(dot.indentation))


def dot_exponent(rec, rec_shallow) -> float:
    """surrogate.load_exponent of the lone dot's two solves (their reactions)."""
    from tactileskin.quality import reaction_of

    return surrogate.load_exponent(float(reaction_of(rec.summary)), float(reaction_of(rec_shallow.summary)))


def letter_scenes(cfg: ChartConfig, material: str, t: float, full: bool = False) -> dict:
    """{letter: its full 3D scene} when cfg.letters_model is "full" or `full`, else {}."""
    if "letters" not in cfg.sets or not (full or cfg.letters_model == "full"):
        return {}
    return {c: dot_scene(t, material, cfg, c) for c in cfg.letters}


def compute(cfg: ChartConfig, cache=None, progress: Callable[[str], None] | None = None,
            workers: int | None = None, validation=None) -> Chart:
    """The chart of `cfg`; solves (single dots in 3D, flat and curved in 2D) through `cache`
    (a folder path, a ResultCache, or None: api.default_cache_dir(); result_cache),
    all of them first, in one batch on `workers` processes (solve_cached). `validation`: this
    run's validate_surrogate rows, which judge the letters' surrogate together with the
    project's measurements (fallback_reason, array.validity.measured)."""
    from tactileskin import quality
    from tactileskin.array import halfspace
    from tactileskin.array.validity import finer_mesh_reason

    say = progress or (lambda msg: None)
    cache = result_cache(cache)  # a wrong one refused before the scenes are planned
    t0 = time.perf_counter()
    chart = Chart(cfg)
    cases = {(m, t): _chart_scenes(cfg, m, t) for m in cfg.materials for t in cfg.thicknesses}
    for (m, t), c in cases.items():
        why = fallback_reason(cfg, m, t, c[0], c[2], validation)
        if why is not None:
            chart.fallbacks[(m, t)] = why
            msg = (f"t = {t:g} mm ({m}): the letters' surrogate is measured {why['error']:.1%} off full solves "
                   f"(over {', '.join(why['texts'])}; tolerance {surrogate.TOLERANCE:.0%}), so its "
                   f"{len(cfg.letters)} letters are solved in full ({len(cfg.letters)} 3D solves"
                   + ("; a depth cap below the dot height keeps the plate off" if c[2] is not None else "")
                   + "; fallback off keeps the surrogate, marked indicative)")
        else:
            j = letters_judgment(cfg, m, t, c[0], c[2], validation)
            if j is None or j["status"] != "exceeds":
                continue
            # exceeds against a finer mesh only (fallback_reason)
            msg = (f"t = {t:g} mm ({m}): the letters' surrogate is measured {j['error']:.1%} off "
                   + finer_mesh_reason(j, cfg.mesh_for(t)))
        log.info(msg)
        say(msg)
    full = {(m, t): letter_scenes(cfg, m, t, full=(m, t) in chart.fallbacks) for m, t in cases}
    shallow = {k: shallow_scene(c[0]) for k, c in cases.items()
               if not full[k] and letters_model(cfg, c[0], c[2]) == "interaction"}
    wanted = [x for dot, pdot, blank, sec2, sphere in cases.values()
              for x in (dot, pdot, blank, *sec2.values(), sphere) if x is not None]
    wanted += [x for f in full.values() for x in f.values()] + list(shallow.values())
    say(f"solving {len(set(wanted))} cases (cached cases are read)")
    recs = solve_cached(wanted, cache, on_event=lambda oc: say(f"  {oc.status} {oc.case} ({oc.seconds:.0f} s)"),
                        workers=workers)
    for (m, t), c in cases.items():
        mine = [x for x in (c[0], c[1], c[2], *c[3].values(), c[4], *full[(m, t)].values(), shallow.get((m, t)))
                if x is not None]
        row = None if c[2] is None else blank_measured(c[2], cfg.read_extent, cfg.sensor_depth_at(t))
        notes = suspect_solves({x: recs[x] for x in mine}, {c[2]: row})
        if row is not None and any(f.code == "coarse_mesh" for f in quality.flags(recs[c[2]].summary or {})):
            chart.measured.append(blank_note(c[2], row))  # named in the report, not a suspect note
        for note in notes:
            log.warning(note)
            chart.notes.append(note)
        if notes:
            chart.suspect[(m, t)] = "; ".join(notes)
    for material in cfg.materials:
        for t in cfg.thicknesses:
            dot, pdot, blank, sec2, sphere = cases[(material, t)]
            sd = cfg.sensor_depth_at(t)  # None: the bone maps
            kernels = {x: map_of(recs[x], sd) for x in (dot, pdot) if x is not None}
            height = get_standard(cfg.standard).height
            base = None
            if blank is not None:
                base = blank_map(blank, recs[blank], kernels[dot], sd)
                if not full[(material, t)]:
                    note = (f"t = {t:g} mm: the depth {dot.indentation:.3g} mm passes the dot height {height:g} mm, "
                            "so the Braille plate presses the skin too: the letters are the blank plate plus the "
                            "plate-aware kernels (surrogate.plate_kernel)")
                    log.info(note)
                    chart.notes.append(note)
            profiles = {k: profile_of(recs[sc], sd) for k, sc in sec2.items()}
            letter_kernel = kernels.get(dot) if base is None else surrogate.plate_kernel(kernels[dot], base)
            for sc, kernel in kernels.items():
                if sc == dot:  # the filter of a dot is what it adds to the plate
                    kernel = letter_kernel
                kc = map_cutoff(kernel)
                chart.cutoffs.append({"material": material, "thickness_mm": t, "skin": sc.skin,
                                      "depth_mm": float(sc.indentation),
                                      "peak_mpa": float(kernel.pressure.max()), "kc_rad_per_mm": kc,
                                      "nyquist_pitch_mm": float(np.pi / kc) if 0 < kc < np.inf else float("nan"),
                                      "halfspace_nyquist_pitch_mm": halfspace.nyquist_pitch(t if sd is None else sd)})
            letters = {c: surrogate.placed(raw_map_of(recs[sc], sd), c, dot.section(),
                                           cfg.standard) for c, sc in full[(material, t)].items()} or None
            model = "full" if letters else letters_model(cfg, dot, base)
            weights = None
            if model == "interaction":
                try:
                    weights = letter_weights(cfg, surface_deflection(recs[dot], dot.section().top),
                                             dot_exponent(recs[dot], recs[shallow[(material, t)]]))
                except ParameterError as e:
                    note = f"t = {t:g} mm ({material}): the letters fall back to the plain sum: {e}"
                    log.warning(note)
                    chart.notes.append(note)
                    model = "sum"
            if dot is not None:
                chart.letters_models[(material, t)] = model
            sets = stimulus_maps(letter_kernel, dot and dot.section(), profiles, cfg, kernels.get(pdot), base=base,
                                 letters=letters, sphere=None if sphere is None else map_of(recs[sphere], sd),
                                 weights=weights)
            for set_, maps_ in sets.items():
                chart.labels[set_] = list(maps_)
                fs = max(float(m.pressure.max()) for m in maps_.values())
                # which thickness and what the numbers are: the pitch lines came once per thickness
                # and material ("letters pitch 1 mm: 1.00, 0.98"), naming neither, nor the noise
                say(f"  {material}, t = {t:g} mm, {set_}: accuracy at noise "
                    + ", ".join(f"{n:g}" for n in cfg.noise_levels) + f" {cfg.noise_unit}")
                for pitch in cfg.pitches:
                    spec = cfg.spec(pitch)
                    rng = np.random.default_rng([cfg.seed, int(t * 1000), int(pitch * 1000), SETS.index(set_)])
                    clean = classify.clean_readings(maps_, spec, rng, n_train=cfg.n_train, n_test=cfg.n_test,
                                                    template_grid=cfg.template_grid)
                    for noise in cfg.noise_levels:
                        ro = cfg.readout(fs, noise)
                        ev = classify.evaluate(maps_, spec, ro, rng, clean=clean)
                        chart.confusions[(material, t, set_, pitch, noise)] = ev.confusion
                        for m, acc in ev.accuracy.items():
                            lo, hi = accuracy_interval(acc, int(round(ev.n_test / ev.chance)),
                                                       ev.offset_accuracy.get(m))
                            chart.rows.append(dict(material=material, thickness_mm=float(t), set=set_,
                                                   pitch_mm=float(pitch), taxel_mm=float(spec.taxel),
                                                   sensor_depth_mm=float(t if sd is None else sd),
                                                   sensor_height_mm=float(cfg.sensor_height_at(t)),
                                                   noise_fs=float(noise if cfg.noise_mpa is None else ro.sigma / fs),
                                                   noise_mpa=float(ro.sigma),
                                                   full_scale_mpa=fs, bits=cfg.bits, method=m, accuracy=acc,
                                                   chance=ev.chance, n_test=ev.n_test, ci_low=lo, ci_high=hi))
                    say(f"    pitch {pitch:g} mm: " + ", ".join(
                        accuracy_text(chart.accuracy(material, t, set_, pitch, n)) for n in cfg.noise_levels))
    chart.seconds = time.perf_counter() - t0
    return chart


def map_cutoff(m: BoneMap) -> float:
    """Measured cut-off (rad/mm) of a map along s: the 1D spectrum of its projection onto s
    (the integral over z), which is the map's 2D spectrum along k_s (projection-slice
    theorem), the one an array sampling along s aliases. The spectrum of the section row (a
    slice) is not: for a point load on a half-space it reads 4.46 / d against the 2D 3.89 / d
    (halfspace.cutoff), a 13 % smaller Nyquist pitch."""
    return _cutoff(m.s, np.trapezoid(m.pressure, m.z, axis=0))


def _cutoff(s, row) -> float:
    """Measured cut-off of a response along s, resampled on an even grid."""
    from tactileskin.array import halfspace

    grid = np.arange(s[0], s[-1], 0.02)
    try:
        kc, _, _ = halfspace.measured_cutoff(grid, np.interp(grid, s, row))
    except ParameterError:
        return float("nan")
    return kc


# --- the paper's claims ---------------------------------------------------------------------

def _off_paper_depth(cfg: ChartConfig, t: float) -> str:
    """'' where the chart indents a thickness at the paper's 20 % of t; else the qualifier
    of a verdict on it (the depth cap's depth is not the paper's condition)."""
    from tactileskin.scene import Scene

    d = cfg.depth_for(t)
    out = "" if d is None else f" (at the capped depth {d:g} mm, not the paper's {Scene.depth_fraction * t:g} mm)"
    if cfg.sensor_depth is not None:  # the paper's claims are about its film on the bone
        out += f" (sensors {cfg.sensor_depth:g} mm below the surface, not the paper's film on the bone)"
    elif cfg.sensor_height is not None:
        out += f" (sensors {cfg.sensor_height:g} mm above the bone, not the paper's film on it)"
    return out


def _row(chart: Chart, material, t, set_, pitch, noise, method) -> dict | None:
    for r in chart.rows:
        if (r["material"], r["thickness_mm"], r["set"], r["pitch_mm"], r[chart.config.noise_key], r["method"]) == \
                (material, t, set_, pitch, noise, method):
            return r
    return None


def wilson(acc: float, n: int) -> tuple[float, float]:
    """95 % Wilson score interval of an accuracy measured on n readings (scipy's binomtest)."""
    from scipy.stats import binomtest

    ci = binomtest(int(round(acc * n)), int(n)).proportion_ci(0.95, method="wilson")
    return float(ci.low), float(ci.high)


def accuracy_interval(acc: float, n: int, by_offset=None) -> tuple[float, float]:
    """95 % interval of an accuracy on n readings: the wider of the Wilson interval over the
    readings and a t-interval over the test offsets' accuracies (`by_offset`), which every
    stimulus shares, so readings at one offset are not independent: at t = 1, 2.5 mm, 1 % noise
    seeds 0-5 read 0.79-0.93 against a Wilson interval of 0.91-0.95 (4x the binomial spread)."""
    from scipy.stats import t as student

    lo, hi = wilson(acc, n)
    a = np.asarray(by_offset if by_offset is not None else [], float)
    if a.size >= 2:
        half = float(student.ppf(0.975, a.size - 1) * a.std(ddof=1) / np.sqrt(a.size))
        lo, hi = min(lo, max(0.0, float(a.mean()) - half)), max(hi, min(1.0, float(a.mean()) + half))
    return lo, hi


def _borderline(acc: float, row: dict | None) -> str:
    """'' unless the accuracy's 95 % interval (accuracy_interval) spans GOOD: then the verdict
    could go either way with another draw of offsets and noise (said in the verdict's evidence)."""
    if row is None or not np.isfinite(acc) or not (row.get("n_test") and row.get("chance")):
        return ""
    n = int(round(row["n_test"] / row["chance"]))
    lo, hi = (row["ci_low"], row["ci_high"]) if "ci_low" in row else wilson(acc, n)
    if lo < GOOD <= hi:
        return (f" (borderline: {accuracy_text(acc)} on {n} readings at {row['n_test']} offsets, 95 % interval "
                f"{accuracy_text(lo)}-{accuracy_text(hi)} spans {GOOD:g})")
    return ""


def verdicts(chart: Chart, method: str = "template") -> list[dict]:
    """The paper's two design claims checked on the chart, per material, at the lowest noise.
    A claim checked at a thickness the depth cap indents less than the paper's 20 % of t says
    so in its verdict and evidence (the paper's claim is about 20 %)."""
    cfg = chart.config
    noise = min(cfg.noise_levels)
    out = []
    for material in cfg.materials:
        if "letters" in cfg.sets and 1.0 in cfg.thicknesses and PAPER_PITCH in cfg.pitches:
            a = chart.accuracy(material, 1.0, "letters", PAPER_PITCH, noise, method)
            coarser = [p for p in cfg.pitches if p > PAPER_PITCH]
            worst = {p: chart.accuracy(material, 1.0, "letters", p, noise, method) for p in coarser}
            ok = a >= GOOD
            off = _off_paper_depth(cfg, 1.0)
            line = _borderline(a, _row(chart, material, 1.0, "letters", PAPER_PITCH, noise, method))
            out.append({"material": material, "claim": "0.75 mm pitch reads Braille at t = 1 mm",
                        "verdict": ("supported" if ok else "not supported") + off,
                        "evidence": f"letters at 0.75 mm: {accuracy_text(a)}{line}; "
                                    + ", ".join(f"{p:g} mm: {accuracy_text(v)}" for p, v in worst.items())})
        else:
            out.append({"material": material, "claim": "0.75 mm pitch reads Braille at t = 1 mm",
                        "verdict": "not evaluated", "evidence": "needs t = 1, pitch 0.75 and the letters set"})
        if "paper" in cfg.sets and 5.0 in cfg.thicknesses:
            acc5 = [chart.accuracy(material, 5.0, "paper", p, noise, method) for p in cfg.pitches]
            best = max(acc5)
            off = _off_paper_depth(cfg, 5.0)
            pb = cfg.pitches[int(np.argmax(acc5))]
            line = _borderline(best, _row(chart, material, 5.0, "paper", pb, noise, method))
            out.append({"material": material, "claim": "5 mm cannot discriminate flat/curved/Braille",
                        "verdict": ("supported" if best < GOOD else "not supported") + off,
                        "evidence": f"best accuracy at t = 5 mm over pitches: {accuracy_text(best)}" + line + off})
        elif 5.0 in cfg.thicknesses:  # the claim is the paper set's: a chart with t = 5 but without it
            out.append({"material": material, "claim": "5 mm cannot discriminate flat/curved/Braille",
                        "verdict": "not evaluated (no paper set)",
                        "evidence": "needs the paper set (flat/curved/Braille dot, --set paper) at t = 5 mm"})
        else:
            thick = [t for t in cfg.thicknesses if "paper" in cfg.sets]
            ev = ", ".join(f"t = {t:g}: {accuracy_text(max(chart.accuracy(material, t, 'paper', p, noise, method) for p in cfg.pitches))}"
                           for t in thick)
            out.append({"material": material, "claim": "5 mm cannot discriminate flat/curved/Braille",
                        "verdict": "not evaluated (no t = 5 mm)", "evidence": f"best accuracy {ev}" if ev else ""})
    return out


def validate_surrogate(thicknesses, material, texts, cfg: ChartConfig, cache, progress=None,
                       workers: int | None = None, reference_mesh: tuple | None = None) -> list[dict]:
    """Surrogate against full nonlinear 3D solves of `texts` at each thickness: one row per
    text and model: "sum" (lone-dot kernels added), "interaction" (the dots' loads from the
    lone dot's surface deflection and load-approach law, surrogate.interaction_weights; the
    chart's model), "interaction, linear" (the same with loads linear in the approach), "sum x a" (one scale a per
    thickness fitted by least squares on these same maps: an in-sample fit). Where the plate
    touches (depth past the dot height): "plate + sum" (the blank plate plus the plate-aware
    kernels, surrogate.plate_kernel), "plate + sum x a", and "sum" (the lone dot's map with
    its plate added per dot: what the plate-blind model would do).
    On the fingertip (a half model) an x-asymmetric text is refused: it would be solved
    mirrored. reference_mesh (mesh_size, refinement): solve the texts in full on that mesh
    (finer than the chart's, whose single dots the surrogates keep): the error of the chart's
    letters against a better reference; each row says its "reference_mesh"."""
    from tactileskin.geometry.braille import check_text, dot_centres

    say = progress or (lambda msg: None)
    for x in texts:  # surrogate.chart_shift's rule, refused after the solves before (minutes to hours)
        cells = check_text(x)
        if len(cells) != 1 or not cells[0]:
            raise ParameterError("validate text", x, "one line of Braille cells, e.g. 'l' (not empty: that is the lone dot)")
    if cfg.skin == "fingertip":
        for x in texts:
            xs = np.sort(np.round(dot_centres(x, cfg.standard)[:, 0], 9))
            if not np.allclose(xs, -xs[::-1]):
                raise ParameterError("validate text", x, "a text mirror-symmetric about x = 0 on the fingertip "
                                     "(its half model would solve the mirrored text; use skin pad)")
    rows = []
    cases = {}
    for t in thicknesses:
        dot = dot_scene(t, material, cfg)
        blank = blank_scene(dot) if plate_touches(dot) else None
        shallow = shallow_scene(dot) if blank is None and cfg.skin == "pad" else None
        fulls = [dot_scene(t, material, cfg, x) for x in texts]
        if reference_mesh is not None:
            fulls = [f.replace(mesh_size=float(reference_mesh[0]), refinement=float(reference_mesh[1])) for f in fulls]
        cases[t] = dot, fulls, blank, shallow
        for x, sc in zip(texts, fulls):  # before any solve: a text too large to mesh failed after the others
            try:
                sc.skin_kind.size_plan(sc)
            except ParameterError as e:
                raise ParameterError("validate text", x, f"a text whose full 3D solve at t = {t:g} mm fits "
                                     "the mesh limit (fewer Braille cells)", hint=str(e)) from None
    say(f"validation {material}: {len(texts) * len(cases)} full solves (cached cases are read)")
    recs = solve_cached([x for c in cases.values() for x in (c[0], c[2], c[3], *c[1]) if x is not None],
                        cache, on_event=lambda oc: say(f"  {oc.status} {oc.case} ({oc.seconds:.0f} s)"),
                        workers=workers)
    for t, (dot, fulls, blank, shallow) in cases.items():
        # a row judged against flagged solves does not show the surrogate (array.validity skips it)
        shared = suspect_solves({sc: recs[sc] for sc in (dot, blank, shallow) if sc is not None},
                                {blank: blank and blank_measured(blank, cfg.read_extent, cfg.sensor_depth_at(t))})
        solve_status = {}
        for x, sc in zip(texts, fulls):
            notes = shared + suspect_solves({sc: recs[sc]})
            solve_status[x] = "suspect: " + "; ".join(notes) if notes else "ok"
        sd = cfg.sensor_depth_at(t)
        kernel = map_of(recs[dot], sd)
        sec = dot.section()
        refs = {x: raw_map_of(recs[sc], sd) for x, sc in zip(texts, fulls)}
        depth = float(dot.indentation)
        if blank is not None:
            base = blank_map(blank, recs[blank], kernel, sd)
            pk = surrogate.plate_kernel(kernel, base)
            scale = surrogate.fit_scale(pk, refs, sec, cfg.standard, base=base)
            models = {"sum": (kernel, {}), "plate + sum": (pk, {"base": base}),
                      f"plate + sum x {scale:.3f}": (pk, {"base": base, "scale": scale})}
        else:
            defl = surface_deflection(recs[dot], sec.top) if cfg.skin == "pad" else None
            scale = surrogate.fit_scale(kernel, refs, sec, cfg.standard)
            models = {"sum": (kernel, {}), f"sum x {scale:.3f}": (kernel, {"scale": scale})}
            if defl is not None:
                models["interaction, linear"] = (kernel, {"deflection": defl})
                models["interaction"] = (kernel, {"deflection": defl,
                                                  "exponent": dot_exponent(recs[dot], recs[shallow])})
        for x in texts:
            for name, (k, kw) in models.items():
                err = surrogate.validate(k, refs[x], x, sec, cfg.standard, taxel=cfg.min_taxel,
                                         extent=cfg.read_extent, **kw)
                rows.append({"material": material, "thickness_mm": t, "depth_mm": depth, "text": x, "model": name,
                             "taxel_mm": float(cfg.min_taxel),
                             "reference_mesh": [float(v) for v in (reference_mesh or cfg.mesh_for(t))],
                             "solve_status": solve_status[x],
                             **({} if sd is None else {"sensor_depth_mm": float(sd),
                                                       "sensor_height_mm": float(cfg.sensor_height_at(t))}),
                             **err})
    return rows
