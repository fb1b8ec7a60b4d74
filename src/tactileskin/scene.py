"""Scene: the single, validated, hashable description that every stage reads.

Units: mm, s, N, MPa. A Scene is immutable; `replace()` returns a changed copy. Its
`key()` is a stable hash (SHA-256 of canonical JSON) of the scene's own fields; the result
cache's key (`tactileskin.cache.cache_key`) adds the content of the material and geometry
files the scene names, and the solver version.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path

from tactileskin import loading as _loading
from tactileskin import presets as _presets
from tactileskin import validate
from tactileskin.errors import ParameterError, check_range
from tactileskin.geometry.indenters import registry as _indenters
from tactileskin.skins import registry as _skins

# bump when a field's meaning or the solver's answer for it changes, so cached results are
# not reused (2: bone pressure from the boundary fit, second-order QLV update; 3: contact
# penetration tolerance relative to the facet size, multipliers updated within Newton, and 3D
# Braille meshes refined locally at the dots, mesh.sizing.local_plan; 4: contact points held
# off the first Newton step of an increment, earlier multiplier updates: other increment
# sequences, peaks within 0.06 %; 5: result.vtu carries the contact pressure on the outer
# surface; 6: contact penalty raised per point, other increment sequences on 3D dots past
# travel 0.3 mm, peaks within 0.01 %; 7: the first increment's travel capped at 0.1 x the
# indenter's tip radius, other increment sequences for dots, spheres and cylinders, peaks
# within 0.03 %; 8: the bone map's summary peak (peak_map_mpa) at least one thickness from
# the bonded skin's edges, the edge's corner value apart as peak_map_edge_mpa; and the GMRES
# back-off of fe.linsolve, other Newton paths on 3D models; and the 3D bone pressure from
# the local fit at the bone nodes, as in 2D, instead of the nodal projection: 3D peaks move
# by 1-3 %; 9: the 3D contact penetration tolerance 1e-3 h (was 1e-4 h), 3D peaks within
# 0.07 %, and increments capped at 0.7 x a failed one, peaks within 0.03 %; 10: ascent
# directions recomputed with the held contact points (and 2D short steps retried): other
# increment sequences on the 2D Braille, curved and flat cases, peaks within 0.10 %; 11: the
# 3D Braille bone patches at most 2.3 x the dot patch size (mesh.sizing.BONE_SCALE_MAX):
# other meshes from t = 3.3 mm; 12: summary keys named with their units: auc_mpa_mm, and the
# reaction reaction_n_per_mm (2D) or reaction_n (3D), which 3D results had called per mm;
# 13: 3D spheres and file indenters meshed by the local plan at their contact spots, as
# Braille dots: their peaks move by up to 12 %; the 3D reaction is the whole indenter's force
# (it was the modelled half or quarter's); a file indenter's profile runs through the map's peak;
# 14: in 3D every increment's travel capped at 0.1 x the tip radius and the committed contact
# points sticky from the second Newton iterate: other increment sequences for dots, spheres and
# cylinders, peaks within 0.4 % (the capped viscoelastic update is the closer))
SCHEMA_VERSION = 14


# Element size and refinement defaults per dimension (mm, coarse / refined size ratio).
# 2D: with the boundary fit of the bone pressure (fe.recovery.PointFit) 0.5 / 3 keeps the
# flat and curved peaks within 0.4 % of the mesh-converged value; Braille needs the refined
# size 0.083 mm at the dot (base radius 0.72 mm; 0.5 / 3 reads -1.7 % at t = 1 silicone),
# which 0.5 / 6 gives with 25 % fewer dofs than 0.25 / 3 at t = 5 for the same peak (within
# 0.1 %); see benchmarks/results/preset_accuracy_fit.md. In 3D the same sizes would be ~1e6
# P2 tetrahedra.
# The sizes are the `default` quality preset (tactileskin/data/presets.json, the one source;
# 3D: chosen by the convergence study benchmarks/convergence3d.py).
DEFAULT_MESH = {2: _presets.mesh(2, "default"), 3: _presets.mesh(3, "default")}
DEFAULT_MESH_BRAILLE_2D = _presets.mesh(2, "default", braille=True)
# 3D Braille: (coarse size, coarse / fine ratio) of the local plan (mesh.sizing.local_plan),
# thin skins (thick ones: presets.mesh(..., thickness=))
DEFAULT_MESH_BRAILLE_3D = _presets.mesh(3, "default", braille=True)


def default_mesh(dim: int, indenter, thickness: float | None = None, skin: str = "fingertip") -> tuple[float, float]:
    """(mesh_size, refinement) a scene of this dimension, indenter, skin thickness and skin
    gets by default (the kind says whether its 2D section needs the finer preset; in 3D a kind
    that touches in spots is refined there on a skin with the local plan, at the local
    presets' sizes, with the thick-skin sizes from their thickness on)."""
    return preset_mesh("default", dim, indenter, thickness, skin)


def preset_mesh(quality: str, dim: int, indenter, thickness: float | None = None,
                skin: str = "fingertip") -> tuple[float, float]:
    """(mesh_size, refinement) of a quality preset (data/presets.json) for a dimension,
    indenter kind, skin thickness and skin: the "braille_mesh" sizes for a 2D kind with
    `fine_2d_mesh` and for 3D spot contacts (`local_3d`) on a skin with the local plan."""
    kind = _indenters.get(indenter)
    if dim == 3:
        local = kind.local_3d and _skins.get(skin).local_plan
        return _presets.mesh(3, quality, braille=local, thickness=thickness)
    return _presets.mesh(dim, quality, braille=kind.fine_2d_mesh)


# The registered indenter kinds (geometry/indenters/, one file per kind) as an enum, so
# `scene.indenter.value` and `IndenterKind.FLAT` keep working; the kind objects answer
# everything else (`Scene.indenter_kind`).
IndenterKind = Enum("IndenterKind", [(n.upper(), n) for n in _indenters.names()], type=str)


# Scene fields that belong to one skin (skins.*.scene_params)
SKIN_FIELDS = ("fingertip", "pad_width", "pad_length", "skin_file", "skin_bonded", "skin_outer",
               "dome_length", "dome_tip")


class Formulation(str, Enum):
    MIXED = "mixed"                # locking-free (F-bar / three-field); the default
    DISPLACEMENT = "displacement"  # plain displacement formulation, kept for comparison


def _enum(cls, name, value):
    try:
        return cls(value)
    except (ValueError, TypeError):
        raise ParameterError(name, value, "one of " + ", ".join(m.value for m in cls)) from None


def _fingertip_overrides(value) -> tuple[tuple[str, float], ...]:
    """Fingertip overrides as sorted (name, float) pairs, from a table or pairs; names are
    checked against the Fingertip parameters (geometry/fingertip.toml)."""
    from tactileskin.geometry.fingertip import OVERRIDES

    if isinstance(value, dict):
        items = list(value.items())
    elif isinstance(value, (list, tuple)) and all(isinstance(p, (list, tuple)) and len(p) == 2 for p in value):
        items = [tuple(p) for p in value]
    else:
        raise ParameterError("fingertip", value, "a table of overrides: " + ", ".join(OVERRIDES))
    validate.known_keys(dict(items), OVERRIDES, "fingertip")
    return tuple(sorted((str(k), validate.number(v, f"fingertip.{k}")) for k, v in items))


DEPTH_FRACTION = 0.2  # Scene.depth_fraction's default
# valid ranges of Scene's fields (the one source: validation, the array chart and --help read them)
MAX_DEPTH_FRACTION = 0.6               # depth <= 0.6 t (and depth_fraction <= 0.6)
MESH_SIZE = (0.01, 5.0)                # mesh_size (mm)
REFINEMENT = (1.0, 20.0)               # refinement (coarse / refined size ratio)
RATE = _loading.RATE                   # rate (mm/s) and force_rate (N/s), as a [[loading]] ramp's


@dataclass(frozen=True)
class Scene:
    thickness: float = 3.0                 # skin thickness t (mm)
    material: str = "silicone"             # preset name (see tactileskin.materials)
    indenter: IndenterKind = IndenterKind.FLAT
    braille_text: str = ""                 # empty: a single dot on the symmetry line
    braille_standard: str = "standard_american"
    depth: float | None = None             # indentation (mm); None -> depth_fraction * t
    depth_fraction: float = DEPTH_FRACTION  # the paper's 20 % nominal strain
    rate: float = 1.0                      # indentation rate (mm/s)
    dim: int = 2                           # 2: plane-strain half section; 3: extruded slab
    order: int = 2                         # element order
    mesh_size: float | None = None         # global element size (mm); None: DEFAULT_MESH[dim]
    refinement: float | None = None        # size ratio global / refined (contact, bone); None: default
    formulation: Formulation = Formulation.MIXED
    viscoelastic: bool = True
    fingertip: tuple[tuple[str, float], ...] = field(default_factory=tuple)  # overrides of fingertip.toml
    sensors: tuple = field(default_factory=tuple)  # sensors.SensorLayout, TOML [[sensors]]; () none
    # parameters of some indenter kinds (None: not given; a kind that does not read one refuses it)
    indenter_radius: float | None = None   # sphere, cylinder (mm)
    indenter_axis: str | None = None       # cylinder: "z" (along the finger, default) or "x"
    indenter_file: str | None = None       # file: closed STL/OBJ/PLY/OFF or STEP surface (mm)
    # the skin geometry (tactileskin.skins: "fingertip", the paper's; "pad", a flat pad on a board)
    # and its parameters (None: not given; a skin that does not read one refuses it)
    skin: str = "fingertip"
    pad_width: float | None = None         # pad: x extent of the whole pad (mm)
    pad_length: float | None = None        # pad: z extent (mm)
    skin_file: str | None = None           # file: a .msh (named groups) or STEP skin solid (mm)
    skin_bonded: str | None = None         # file: .msh bonded group name(s); STEP: a face rule
    skin_outer: str | None = None          # file: .msh contact-surface group name(s)
    dome_length: float | None = None       # dome: length of the finger before its dome (mm)
    dome_tip: float | None = None          # dome: semi-axis of the dome along the finger (mm)
    # loading (tactileskin.loading; None / () not given, absent from to_dict so keys are unchanged)
    force: float | None = None             # force control: target force (N on the whole indenter in 3D, N/mm of the half section in 2D)
    force_rate: float | None = None        # N/s (N/mm/s); None: load_time
    load_time: float | None = None         # s to reach `force`; None: DEPTH_FRACTION * t / rate
    loading: tuple = field(default_factory=tuple)  # loading.Segment after the first ramp, TOML [[loading]]

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 (frozen dataclass)
        set_("indenter", _enum(IndenterKind, "indenter", self.indenter))
        set_("formulation", _enum(Formulation, "formulation", self.formulation))
        set_("material", validate.string(self.material, "material", "a material preset name"))
        set_("braille_text", validate.string(self.braille_text, "braille_text"))
        set_("braille_standard", validate.string(self.braille_standard, "braille_standard",
                                                 "a Braille standard name"))
        set_("viscoelastic", validate.boolean(self.viscoelastic, "viscoelastic"))
        set_("dim", validate.integer(self.dim, "dim", "2 or 3"))
        set_("order", validate.integer(self.order, "order", "1 or 2"))
        set_("fingertip", _fingertip_overrides(self.fingertip))
        set_("skin", validate.string(self.skin, "skin", "a skin name"))
        for name in ("skin_file", "skin_bonded", "skin_outer"):
            if getattr(self, name) is not None:
                v = getattr(self, name)
                set_(name, validate.string(str(v) if isinstance(v, Path) else v, name, "a string"))
        skin = self.skin_kind
        for name in SKIN_FIELDS:
            if getattr(self, name) not in (None, ()) and name not in skin.scene_params:
                takers = [k for k in _skins.names() if name in _skins.get(k).scene_params]
                raise ParameterError(name, getattr(self, name), f"only with skin = {' or '.join(takers)}",
                                     f"the {skin.name} skin does not take it")
        for name, value in skin.check_scene(self).items():  # thickness and the skin's own fields
            set_(name, value)
        set_("depth_fraction", check_range("depth_fraction", self.depth_fraction, 0.0, MAX_DEPTH_FRACTION,
                                                   lo_open=True))
        if self.depth is not None:
            set_("depth", check_range("depth", self.depth, 0.0, MAX_DEPTH_FRACTION * self.thickness, lo_open=True,
                                          unit="mm"))
            if self.depth_fraction != DEPTH_FRACTION:  # two depths: the record would show the unused one
                raise ParameterError("depth_fraction", self.depth_fraction, f"not given with depth = {self.depth:g} mm",
                                     "give the depth (mm) or the depth_fraction of t, not both")
        set_("rate", check_range("rate", self.rate, *RATE, unit="mm/s"))
        if self.dim not in (2, 3):
            raise ParameterError("dim", self.dim, "2 or 3")
        if self.order not in (1, 2):
            raise ParameterError("order", self.order, "1 or 2")
        if self.order == 1 and self.formulation is Formulation.MIXED:
            # On linear triangles/tets J is constant per element, so the element-mean dilatation
            # of the mixed formulation equals J: it silently becomes the locking displacement one.
            raise ParameterError("order", 1, "2 with the mixed formulation",
                                 "order 1 locks; use formulation='displacement' to study it")
        size0, ref0 = default_mesh(self.dim, self.indenter, self.thickness, self.skin)
        set_("mesh_size", check_range("mesh_size", size0 if self.mesh_size is None else self.mesh_size,
                                      *MESH_SIZE, unit="mm"))
        set_("refinement", check_range("refinement", ref0 if self.refinement is None else self.refinement,
                                       *REFINEMENT))
        if not self.material:
            raise ParameterError("material", self.material, "a material preset name")
        if not str(self.material).endswith(".toml"):  # a preset name: known now, not at the solve
            from tactileskin.materials import list_materials

            names = list_materials()
            if self.material not in names:
                raise ParameterError("material", self.material, "one of " + ", ".join(names) + ", or a path to "
                                     "a .toml file", validate.did_you_mean(str(self.material).lower(), names))
        kind = self.indenter_kind
        for name in ("indenter_radius", "indenter_axis", "indenter_file"):
            if getattr(self, name) is not None and name not in kind.scene_params:
                takers = [k for k in _indenters.names() if name in _indenters.get(k).scene_params]
                raise ParameterError(name, getattr(self, name), f"only with indenter = {' or '.join(takers)}",
                                     f"the {kind.name} indenter does not take it")
        if self.braille_text and "braille_text" not in kind.scene_params:  # it would only change the key
            raise ParameterError("braille_text", self.braille_text, "only with indenter = braille",
                                 f"the {kind.name} indenter does not take it")
        if self.indenter_axis is not None:
            set_("indenter_axis", validate.string(self.indenter_axis, "indenter_axis", "'z' or 'x'"))
        if self.indenter_file is not None:
            set_("indenter_file", validate.string(str(self.indenter_file) if isinstance(self.indenter_file, Path)
                                                  else self.indenter_file, "indenter_file", "a file path"))
        for name, value in kind.check_scene(self).items():
            set_(name, value)
        if self.sensors:
            from tactileskin import sensors

            set_("sensors", sensors.layouts(self.sensors))
            sensors.sites_for(self)  # raises ParameterError for a sensor outside the skin
        else:
            set_("sensors", ())
        self._check_loading(set_)

    def _check_loading(self, set_) -> None:
        if self.force is not None:
            if self.depth is not None:
                raise ParameterError("depth", self.depth, "not with force (force control finds the travel)",
                                     "give depth or force")
            set_("force", check_range("force", self.force, _loading.MIN_FORCE, _loading.MAX_FORCE,
                                      unit="N (N/mm in 2D)"))
            if self.depth_fraction != DEPTH_FRACTION:  # the travel is the output: the record would show an input
                raise ParameterError("depth_fraction", self.depth_fraction,
                                     "not with force (force control finds the travel)",
                                     "the time to reach the force: force_rate or load_time")
        for name in ("force_rate", "load_time"):
            if getattr(self, name) is not None and self.force is None:
                raise ParameterError(name, getattr(self, name), "only with force")
        if self.force_rate is not None and self.load_time is not None:
            raise ParameterError("force_rate", self.force_rate, "force_rate or load_time, not both")
        if self.force_rate is not None:
            set_("force_rate", check_range("force_rate", self.force_rate, *RATE, unit="N/s (N/mm/s in 2D)"))
        if self.load_time is not None:
            set_("load_time", check_range("load_time", self.load_time, _loading.MIN_RAMP_TIME, _loading.MAX_TIME,
                                          unit="s"))
        self._check_first_ramp()
        set_("loading", _loading.segments_from(self.loading or [], max_depth=self.max_travel,
                                               default_rate=self.rate) if self.loading else ())
        _loading.check_program(self.program())

    def _check_first_ramp(self) -> None:
        """The first ramp (from first touch) takes at least loading.MIN_RAMP_TIME, as a
        [[loading]] ramp does; the error names the field that sets its duration."""
        if self.force is not None and self.force_rate is not None:
            _loading.check_ramp("force_rate", self.force_rate, 0.0, self.force, "N/s (N/mm/s in 2D)")
        elif self.force is None or self.load_time is None:  # load_time's own range holds the rest
            travel = self.depth if self.depth is not None else self.depth_fraction * self.thickness
            if travel / _loading.MIN_RAMP_TIME >= RATE[0]:  # else no rate does: the depth's contact check names it
                _loading.check_ramp("rate", self.rate, 0.0, travel, "mm/s")

    # --- derived -----------------------------------------------------------------------
    @property
    def indentation(self) -> float:
        """Largest prescribed indentation depth (mm): depth or depth_fraction * t and the
        depths of `loading`; under force control DEPTH_FRACTION * t is the expected travel
        that sizes the mesh's contact zone."""
        first = self.depth if self.depth is not None else self.depth_fraction * self.thickness
        return max([first] + [g.target for g in self.loading if g.kind == "depth"])

    @property
    def duration(self) -> float:
        """Time (s) of the first ramp (from first touch to the depth at `rate`, or to the force)."""
        if self.force is not None:
            if self.force_rate is not None:
                return self.force / self.force_rate
            if self.load_time is not None:
                return self.load_time
            return self.depth_fraction * self.thickness / self.rate
        return (self.depth if self.depth is not None else self.depth_fraction * self.thickness) / self.rate

    @property
    def max_travel(self) -> float:
        """Largest travel (mm) a depth may ask or force control may reach: 0.6 t."""
        return MAX_DEPTH_FRACTION * self.thickness

    @property
    def reach(self) -> float:
        """Largest travel (mm) this scene's loading can take the indenter to: the indentation,
        or max_travel if a force controls any part of it (the travel is not known before)."""
        if self.force is not None or any(g.kind == "force" for g in self.loading):
            return self.max_travel
        return self.indentation

    def program(self) -> list:
        """The loading history as a list of loading.Segment: the first ramp (depth at rate, or
        force in `duration`) then `loading`."""
        from tactileskin.loading import Segment

        if self.force is not None:
            first = Segment("force", self.force, time=self.duration)
        else:
            first = Segment("depth", self.depth if self.depth is not None else self.depth_fraction * self.thickness,
                            rate=self.rate)
        return [first, *self.loading]

    def fingertip_model(self):
        from tactileskin.geometry.fingertip import Fingertip

        return Fingertip.from_params(**dict(self.fingertip))

    def section(self):
        """The skin's 2D section (curves, top, arc length s along the bonded surface)."""
        return self.skin_kind.section(self)

    @property
    def skin_kind(self):
        """The skin class (tactileskin.skins: section, mesh, sensor coordinates, parts)."""
        return _skins.get(self.skin)

    @property
    def sample_length(self) -> float:
        """z extent of the 3D model and of the indenter plates (mm)."""
        return self.skin_kind.sample_length(self)

    @property
    def indenter_kind(self):
        """The indenter kind object (geometry.indenters: gap, symmetry, 2D model, extent, label)."""
        return _indenters.get(self.indenter)

    def replace(self, **changes) -> "Scene":
        """A changed copy. Changing `dim`, `indenter` or `thickness` re-derives mesh defaults
        left at default (3D Braille's depend on the thickness); changing `indenter` drops kind
        parameters the new kind does not read; a `depth` or a `force` replaces a depth_fraction."""
        names = [f.name for f in dataclasses.fields(self)]
        unknown = sorted(set(changes) - set(names))
        if unknown:
            raise ParameterError("scene field", unknown[0], "one of " + ", ".join(names))
        if (changes.get("depth") is not None or changes.get("force") is not None) and "depth_fraction" not in changes:
            changes["depth_fraction"] = DEPTH_FRACTION  # a depth or force given now replaces the fraction
        new_dim = changes.get("dim", self.dim)
        if "dim" in changes:  # looked up below (DEFAULT_MESH): a list is refused as __post_init__ does
            new_dim = validate.integer(new_dim, "dim", "2 or 3")
        new_skin = changes.get("skin", self.skin)
        if new_skin != self.skin:
            reads = _skins.get(new_skin).scene_params
            for name in SKIN_FIELDS:
                if name not in changes and name not in reads:
                    changes[name] = () if name == "fingertip" else None
        new_ind = changes.get("indenter", self.indenter)
        if new_ind != self.indenter:
            reads = _indenters.get(new_ind).scene_params
            for name in ("indenter_radius", "indenter_axis", "indenter_file"):
                if name not in changes and name not in reads:
                    changes[name] = None
            if "braille_text" not in changes and "braille_text" not in reads:
                changes["braille_text"] = ""
        new_t = changes.get("thickness", self.thickness)
        new_skin = changes.get("skin", self.skin)
        if (new_dim != self.dim or new_ind != self.indenter or new_t != self.thickness
                or new_skin != self.skin) and new_dim in DEFAULT_MESH:
            size0, ref0 = default_mesh(self.dim, self.indenter, self.thickness, self.skin)
            if "mesh_size" not in changes and self.mesh_size == size0:
                changes["mesh_size"] = None
            if "refinement" not in changes and self.refinement == ref0:
                changes["refinement"] = None
        return dataclasses.replace(self, **changes)

    # --- serialisation -------------------------------------------------------------------
    def to_dict(self) -> dict:
        d = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, Enum):
                v = v.value
            if f.name == "fingertip":
                v = dict(v)
            if f.name == "skin" and v == "fingertip":  # the default: absent, so keys stay as they were
                continue
            if f.name == "sensors":  # none: absent, so that scenes without sensors keep their keys
                v = [lay.to_dict() for lay in v] or None
            if f.name == "depth_fraction" and (self.depth is not None or self.force is not None):  # not in effect: not recorded
                continue
            if f.name == "loading":  # likewise: absent unless the history has more segments
                v = [g.to_dict() for g in v] or None
            if v is None:
                continue
            d[f.name] = v
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "Scene":
        validate.table(d, "scene")
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(str(k) for k in d if k not in names)
        if unknown:
            raise ParameterError("scene field", unknown[0], "one of " + ", ".join(sorted(names)),
                                 validate.did_you_mean(unknown[0], names))
        return cls(**d)

    def key(self) -> str:
        """Stable hash of the scene's fields (names a scene; the result cache uses
        cache.cache_key, which adds material and geometry file content and versions)."""
        payload = json.dumps({"schema": SCHEMA_VERSION, **self.to_dict()}, sort_keys=True,
                             separators=(",", ":"))
        return hashlib.sha256(payload.encode()).hexdigest()[:20]

    def indenter_label(self) -> str:
        """The indenter as case ids, tables and figures name it (braille[text], sphere-R2.5, ...)."""
        return self.indenter_kind.label(self)

    def material_tag(self) -> str:
        """The material as labels and case ids name it: a material file by its name ('gel' for
        /data/gel.toml), as a skin file is named."""
        return Path(self.material).stem if self.material.endswith(".toml") else self.material

    def label(self) -> str:
        # the sweep's case id of the same scene (sweep.case_ids): `solve` named a material
        # file by its path ('t1-gel.toml-curved-2d' for the sweep's 't1-gel-curved-2d')
        return f"{self.skin_kind.label(self)}t{self.thickness:g}-{self.material_tag()}-{self.indenter_label()}-{self.dim}d"

    def to_toml(self, path: str | Path) -> None:
        import tomli_w

        from tactileskin import fileio
        from tactileskin.scenefile import relative_paths

        # file paths relative to the TOML's folder, as from_toml reads them
        fileio.atomic_write_text(path, tomli_w.dumps(relative_paths(self.to_dict(), path)))

    @classmethod
    def from_toml(cls, path: str | Path) -> "Scene":
        from tactileskin.params import read_toml
        from tactileskin.scenefile import resolve_paths

        return cls.from_dict(resolve_paths(read_toml(path, "scene file"), path))


def material_labels(materials) -> dict[str, str]:
    """{material: label} for the materials of one sweep, as its tables and figures name them:
    a preset by its name, a .toml file by its stem ('gel' for /home/alice/gel.toml; its full
    path was long and showed the user's folders). A file whose stem is a preset's name or
    another material's label is named by the last parts of its path that tell it apart
    ('silicone.toml'; 'a/gel.toml' and 'b/gel.toml'), so no two materials share a label and a
    file is never read as the preset of its name (the paper checks key on the preset names)."""
    from tactileskin.materials import list_materials

    names = sorted({str(m) for m in materials})
    files = [m for m in names if m.endswith(".toml")]
    out = {m: m for m in names if m not in files}
    taken = set(out) | set(list_materials())
    stems = [Path(f).stem for f in files]
    for f, stem in zip(files, stems):
        if stem not in taken and stems.count(stem) == 1:
            out[f] = stem
    rest = [f for f in files if f not in out]
    # the parts below the root ('/x/gel.toml' -> x, gel.toml: no '//x/gel.toml' label)
    parts = {f: [p for p in Path(f).parts if p != Path(f).anchor] for f in rest}
    k = 1
    while rest:
        tails = {f: "/".join(parts[f][-k:]) for f in rest}
        for f, tail in tails.items():
            if list(tails.values()).count(tail) == 1 and tail not in out.values():
                out[f] = tail
            elif k > max(len(parts[g]) for g in rest):  # one tail spelled twice ('gel.toml', './gel.toml')
                out[f] = f
        rest = [f for f in rest if f not in out]
        k += 1
    return out


from tactileskin import scene_doc as _scene_doc  # noqa: E402 (needs the class)

Scene.__doc__ = _scene_doc.docstring(Scene)
