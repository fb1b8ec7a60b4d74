"""One TOML layout for a scene and a sweep (read by `solve`, `mesh`, `sweep` and the Python API).

A file holds Scene fields, either at the top level (as `Scene.to_toml` writes them) or in a
`[scene]` table, an optional `quality` preset (preview / default / fine) beside them, and an
optional `[sweep]` table of lists (thicknesses, materials, indenters, depths, braille_texts,
braille_dims) that turns it into a grid:

    thickness = 2.0            # or, as a sweep: [sweep] thicknesses = [1, 2, 3]
    material = "silicone"
    quality = "preview"        # mesh sizes; mesh_size / refinement, if given, override it

So a scene file is a sweep of one case, and a sweep file whose lists each hold one value is
a scene. A field given both ways (`thickness` and `sweep.thicknesses`) is refused.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from tactileskin import validate
from tactileskin.errors import ParameterError

# Scene field -> the sweep list that varies it
AXES = {"thickness": "thicknesses", "material": "materials", "indenter": "indenters",
        "depth": "depths", "braille_text": "braille_texts", "force": "forces"}
MESH_FIELDS = ("mesh_size", "refinement")


@dataclass
class SceneFile:
    """The parsed file: `fields` (Scene fields as written), `quality` (or None) and `axes`
    ({sweep list name: values}, as sweep.load_spec returns them)."""

    fields: dict = field(default_factory=dict)
    quality: str | None = None
    axes: dict = field(default_factory=dict)
    path: str = ""


# Scene fields that name a file (material: when it is a path ending in .toml)
PATH_FIELDS = ("indenter_file", "skin_file")


def _resolve(value, base: Path):
    if isinstance(value, str) and value and not Path(value).expanduser().is_absolute():
        return os.path.normpath(base / value)
    return value


def resolve_paths(fields: dict, source) -> dict:
    """`fields` with the relative file paths it names (indenter_file, skin_file, a .toml
    material, a sweep's .toml materials) resolved against the folder of the file `source`
    they were read from, not the working folder: a scene file then means the same files
    wherever it is run from (as film calibration CSVs name their images). A skin_file without
    a skin implies skin = "file", as --skin-file does."""
    base = Path(source).expanduser().absolute().parent
    out = dict(fields)
    if out.get("skin_file") and "skin" not in out:
        out["skin"] = "file"
    for k in PATH_FIELDS:
        if k in out:
            out[k] = _resolve(out[k], base)
    if isinstance(out.get("material"), str) and out["material"].endswith(".toml"):
        out["material"] = _resolve(out["material"], base)
    if isinstance(out.get("materials"), (list, tuple)):
        out["materials"] = type(out["materials"])(_resolve(m, base) if isinstance(m, str) and m.endswith(".toml")
                                                  else m for m in out["materials"])
    return out


def relative_paths(fields: dict, target) -> dict:
    """`fields` with their file paths written relative to the folder of the file `target` they
    are saved in (the inverse of resolve_paths; a path on another drive stays absolute)."""
    base = Path(target).expanduser().absolute().parent
    out = dict(fields)
    keys = [k for k in PATH_FIELDS if isinstance(out.get(k), str) and out[k]]
    if isinstance(out.get("material"), str) and out["material"].endswith(".toml"):
        keys.append("material")
    for k in keys:
        p = Path(out[k]).expanduser().absolute()
        try:
            out[k] = Path(os.path.relpath(p, base)).as_posix()
        except ValueError:
            out[k] = str(p)
    return out


def read(path: str | Path | None) -> SceneFile:
    """Parse a scene or sweep file (None: an empty one). ParameterError names the bad key."""
    if path is None:
        return SceneFile()
    from tactileskin.params import read_toml

    data = read_toml(path, "scene file")
    top = {k: v for k, v in data.items() if k not in ("scene", "sweep")}
    scene_tab = validate.table(data.get("scene", {}), "[scene]")
    both = sorted(set(top) & set(scene_tab))
    if both:
        raise ParameterError(both[0], top[both[0]], "given once in the scene file (top level or [scene], not both)",
                             f"{path} gives it twice")
    fields = resolve_paths({**top, **scene_tab}, path)
    quality = fields.pop("quality", None)
    if quality is not None:
        from tactileskin.presets import check_quality

        check_quality(quality)
    axes = resolve_paths(sweep_lists(data["sweep"]), path) if "sweep" in data else {}
    for f, ax in AXES.items():
        if f in fields and ax in axes:
            raise ParameterError(f, fields[f], f"either {f} or sweep.{ax}, not both", f"{path} gives both")
    if not fields and quality is None and not axes:  # surely a mistake: it would run the default scene
        raise ParameterError("scene file", str(path), "a TOML file with at least one setting",
                             "it sets nothing; leave out --scene for the default scene")
    if fields:
        from tactileskin.scene import Scene

        # unknown or invalid fields fail here, naming the field; with a listed indenter kind
        # (its own fields: indenter_radius with sweep.indenters = ["sphere"])
        Scene.from_dict(with_base_indenter(fields, axes.get("indenters")))
    return SceneFile(fields, quality, axes, str(path))


INDENTER_FIELDS = ("indenter_radius", "indenter_axis", "indenter_file")


def with_base_indenter(fields: dict, kinds) -> dict:
    """`fields` of a sweep's base scene with the indenter of `kinds` (its indenters list) that
    takes the kind's own fields among them (base_indenter), unless they name one or no list is
    given."""
    if not kinds or "indenter" in fields:
        return fields
    return {**fields, "indenter": base_indenter(kinds, fields)}


def base_indenter(kinds, fields: dict) -> str:
    """The kind of `kinds` (a sweep's indenters) its base scene is built with: the first that
    takes each of the kind's own fields set in `fields` (indenter_radius with indenters =
    ["flat", "sphere"]: the sphere; each case of another kind drops them), else the first
    (its refusal names the field and the kinds that take it)."""
    from tactileskin.geometry.indenters import registry

    own = [f for f in INDENTER_FIELDS if fields.get(f) is not None]
    for kind in kinds:
        if kind not in registry.names():  # Scene.from_dict names the unknown kind
            break
        if all(f in registry.get(kind).scene_params for f in own):
            return kind
    return tuple(kinds)[0]


def sweep_lists(table) -> dict:
    """The [sweep] lists of a file, each checked (numbers, names or Braille dimensions)."""
    from tactileskin.sweep import MAX_AXIS_VALUES, _SPEC_LISTS, check_braille_dims

    sw = validate.table(table, "[sweep]")
    validate.known_keys(sw, _SPEC_LISTS, "sweep")
    spec = {}
    for k, v in sw.items():
        name = f"sweep.{k}"
        if _SPEC_LISTS[k] == "numbers":
            spec[k] = validate.number_list(v, name, MAX_AXIS_VALUES, min_len=1)
        elif _SPEC_LISTS[k] == "dims":
            spec[k] = check_braille_dims(v, name)
        else:
            spec[k] = validate.string_list(v, name, MAX_AXIS_VALUES, min_len=1)
    return spec


def single_scene_fields(sf: SceneFile, command: str = "solve") -> dict:
    """The file's Scene fields for one scene: each sweep list must hold one value (its
    field is then that value); more is a ParameterError that points to `sweep`."""
    out = dict(sf.fields)
    inverse = {v: k for k, v in AXES.items()}
    for ax, values in sf.axes.items():
        values = list(values)
        if len(values) != 1:
            raise ParameterError(f"sweep.{ax}", values, f"one value for `{command}` (one scene)",
                                 f"this file is a sweep of {len(values)} values: run "
                                 f"`tactileskin sweep --scene {sf.path}`, or the Python tactileskin.sweep()")
        if ax == "braille_dims":
            out["dim"] = values[0]
        else:
            out[inverse[ax]] = values[0]
    return out


def apply_quality(scene, quality: str | None, overrides: dict):
    """`scene` at the quality preset of its dimension (if any), then the explicit mesh
    fields in `overrides` (mesh_size, refinement) over it."""
    if quality is not None:
        from tactileskin.planner import with_quality

        scene = with_quality(scene, quality)
    mesh = {k: v for k, v in overrides.items() if k in MESH_FIELDS and v is not None}
    return scene.replace(**mesh) if mesh else scene
