"""Helpers shared by CLI command modules."""

from __future__ import annotations

import functools

import click

from tactileskin.cli._choice import Choice
from tactileskin.scene import Formulation, IndenterKind, Scene


QUALITIES = ("preview", "default", "fine")
# Scene options every scene command takes (geometry and mesh), then the loading and material
# ones of the commands that solve. `grid=True` (sweep): the axis options take lists.
SCENE_KEYS = ("scene_file", "thickness", "material", "indenter", "braille_text", "braille_standard",
              "indenter_radius", "indenter_axis", "indenter_file", "skin", "pad_width", "pad_length",
              "skin_file", "skin_bonded", "skin_outer", "depth", "dim", "quality", "mesh_size", "refinement",
              "order")
PHYSICS_KEYS = ("rate", "force", "force_rate", "formulation", "elastic")


class _RangeHelpOption(click.Option):
    """An option whose help is a callable, evaluated when --help is shown: the valid ranges
    and defaults it quotes are read from the constants the validation uses (one source),
    and the fingertip's range (a parameter file) is not computed on every command."""

    def __init__(self, *args, help=None, **kw):  # noqa: A002 (click's keyword)
        self._help = help
        super().__init__(*args, help=None if callable(help) else help, **kw)

    def get_help_record(self, ctx):
        if callable(self._help):
            self.help = self._help()
        return super().get_help_record(ctx)


class _HelpText:
    """Range and default texts of the scene options, from the validation's constants."""

    @staticmethod
    def thickness() -> str:
        from tactileskin.errors import range_text
        from tactileskin.geometry.fingertip import Fingertip
        from tactileskin.skins import pad

        return (f"fingertip {range_text(*Fingertip.from_params().thickness_bounds)}, "
                f"pad {range_text(*pad.THICKNESS)}")

    @staticmethod
    def default(field: str, grid: bool = False) -> str:
        import dataclasses

        from tactileskin import sweep
        from tactileskin.errors import fmt_bound

        if grid and field in ("thickness", "material", "indenter"):  # the sweep's paper grid
            values = {"thickness": sweep.PAPER_THICKNESSES, "material": sweep.PAPER_MATERIALS,
                      "indenter": sweep.PAPER_INDENTERS}[field]
        else:
            values = [{f.name: f.default for f in dataclasses.fields(Scene)}[field]]
        return ",".join(fmt_bound(v) if isinstance(v, float) else getattr(v, "value", str(v)) for v in values)

    @staticmethod
    def scene_range(name: str, unit: str = "") -> str:
        from tactileskin import scene
        from tactileskin.errors import range_text

        return "in " + range_text(*getattr(scene, name), unit=unit)

    @staticmethod
    def depth() -> str:
        from tactileskin.errors import fmt_bound
        from tactileskin.scene import MAX_DEPTH_FRACTION

        return f"in (0, {fmt_bound(MAX_DEPTH_FRACTION)} t]"

    @staticmethod
    def depth_default() -> str:
        from tactileskin.scene import DEPTH_FRACTION

        return f"{DEPTH_FRACTION:.0%} of t".replace("%", " %")

    @staticmethod
    def radius() -> str:
        from tactileskin.errors import range_text
        from tactileskin.geometry.indenters.base import radius_ranges

        return ", ".join(f"{k} {range_text(*r, lo_open=True)}" for k, r in radius_ranges().items())

    @staticmethod
    def pad_size() -> str:
        from tactileskin.errors import range_text
        from tactileskin.skins import pad

        return f"in {range_text(*pad.SIZE)} (up to {pad.PLATE_SIZE:g} mm under the flat plate)"

    @staticmethod
    def pad(which: str) -> str:
        from tactileskin.errors import fmt_bound
        from tactileskin.skins import pad

        return fmt_bound(getattr(pad, f"DEFAULT_{which}"))

    @staticmethod
    def force() -> str:
        from tactileskin.errors import range_text
        from tactileskin.loading import MAX_FORCE, MIN_FORCE

        return "in " + range_text(MIN_FORCE, MAX_FORCE, unit="N")

    @staticmethod
    def formulation() -> str:
        from tactileskin.scene import Formulation

        default = _HelpText.default("formulation")
        what = {"mixed": "locking-free", "displacement": "locks; for comparison"}
        parts = []
        for k in Formulation:
            notes = [n for n in (what.get(k.value), "default" if k.value == default else None) if n]
            parts.append(k.value + (f" ({'; '.join(notes)})" if notes else ""))
        return " or ".join(parts)


def scene_options(f=None, *, grid: bool = False, physics: bool = True):
    """Click options that map onto Scene fields, the same on `solve`, `mesh` and `sweep` (one
    definition, so they cannot drift). The command receives them as one dict `scene_opts`.
    grid: thickness, material, indenter, depth and Braille text take lists (sweep axes).
    physics: also --rate, --formulation, --elastic (not on `mesh`: they do not change it)."""
    if f is None:
        return lambda g: scene_options(g, grid=grid, physics=physics)
    many = " (comma-separated list, or start:stop:step)" if grid else ""
    names = " (comma-separated list)" if grid else ""
    h = _HelpText  # ranges and defaults come from the validation's constants when help is shown
    opt = functools.partial(click.option, cls=_RangeHelpOption)
    opts = [
        click.option("--scene", "--config", "scene_file", type=click.Path(dir_okay=False), default=None,
                     help="Scene or sweep TOML (Scene fields, optional quality, optional [sweep] lists); "
                          "the options below override it."),
        opt("--thickness", "-t", type=str if grid else float, default=None,
            help=lambda: f"Skin thickness (mm){many}: {h.thickness()}. Default {h.default('thickness', grid)}."),
        opt("--material", "-m", type=str, default=None,
            help=lambda: f"Material preset name or .toml file{names}. Default {h.default('material', grid)}."),
        opt("--indenter", "-i", default=None,
            type=str if grid else Choice([k.value for k in IndenterKind]),
            help=lambda: (f"Indenters: {', '.join(k.value for k in IndenterKind)}{names}. "
                          f"Default {h.default('indenter', grid)}.") if grid
            else f"Indenter kind. Default {h.default('indenter')}."),
        click.option("--braille-text", type=str, default=None, multiple=grid,
                     help="Text for a Braille indenter" + (" (repeatable)." if grid else ".")),
        click.option("--braille-standard", type=str, default=None, help="Braille standard name."),
        opt("--indenter-radius", type=float, default=None,
            help=lambda: f"Indenter radius (mm): {h.radius()}; required by those kinds."),
        click.option("--indenter-axis", type=Choice(["z", "x"]), default=None,
                     help="Cylinder axis: z along the finger (2D-exact), x across it (3D)."),
        click.option("--indenter-file", type=str, default=None,
                     help="Closed STL/OBJ/PLY/OFF or STEP surface (mm) of a 'file' indenter."),
        opt("--depth", type=str if grid else float, default=None,
            help=lambda: f"Indentation depth (mm){many}, {h.depth()}; default {h.depth_default()}."),
        click.option("--dim", type=Choice(["2", "3"]), default=None,
                     help="2D plane-strain section or 3D slab. Default 2 (a dome or a 3D skin file: 3)."),
        click.option("--quality", type=Choice(QUALITIES), default=None,
                     help="Mesh preset of the scene's dimension (data/presets.json; "
                          "docs/speed_vs_error.md). Default: the `default` sizes."),
        opt("--mesh-size", type=float, default=None,
            help=lambda: f"Global element size (mm), {h.scene_range('MESH_SIZE')}; overrides --quality."),
        opt("--refinement", type=float, default=None,
            help=lambda: f"Global / refined element size ratio, {h.scene_range('REFINEMENT')}; overrides --quality."),
        click.option("--order", type=Choice(["1", "2"]), default=None, help="Element order (default 2)."),
        click.option("--skin", type=str, default=None,
                     help="Skin geometry: fingertip (default), pad, dome (rounded 3D tip) or file."),
        click.option("--skin-file", type=str, default=None,
                     help="File skin: a gmsh .msh with named groups (solved on its own mesh: --quality and "
                          "the mesh sizes do not apply) or a STEP solid (mm; its bonded faces: --skin-bonded, "
                          "default 'normal:-y'); implies --skin file."),
        opt("--skin-bonded", type=str, default=None,
            help=lambda: "File skin's bonded surface: a .msh's physical group name(s), comma-separated (default "
                         "bone_interface/bonded/board/...), or a STEP's face rule, " + _rule_forms() +
                         " (default 'normal:-y': outward normals within 10 degrees of -y)."),
        click.option("--skin-outer", type=str, default=None,
                     help="File skin (.msh): the contact surface's physical group name(s), comma-separated "
                          "(default outer_surface/..., or the rest of the boundary)."),
        opt("--pad-width", type=float, default=None,
            help=lambda: f"Pad: x extent of the whole pad (mm), {h.pad_size()}. Default {h.pad('WIDTH')}."),
        opt("--pad-length", type=float, default=None,
            help=lambda: f"Pad: z extent (mm), {h.pad_size()}. Default {h.pad('LENGTH')}."),
    ]
    if physics:
        opts += [
            opt("--rate", type=float, default=None,
                help=lambda: f"Indentation rate (mm/s), {h.scene_range('RATE')}. "
                             f"Default {h.default('rate')}."),
            # loading (tactileskin.loading): force control; holds and releases via [[loading]] in --scene
            opt("--force", type=float, default=None,
                help=lambda: f"Force control instead of --depth: target force, {h.force()} (the whole indenter "
                             "in 3D; N/mm of the half section in 2D)."),
            opt("--force-rate", type=float, default=None,
                help=lambda: f"Force rate (N/s, N/mm/s in 2D) for --force, {h.scene_range('RATE')}. "
                             f"Default: the depth ramp's time ({h.depth_default()} / rate)."),
            opt("--formulation", type=Choice([k.value for k in Formulation]), default=None,
                help=lambda: f"{h.formulation()}."),
            click.option("--elastic", is_flag=True, default=None,
                         help="Ignore viscoelasticity (the Prony series)."),
        ]
    keys = SCENE_KEYS + (PHYSICS_KEYS if physics else ())

    @functools.wraps(f)
    def wrapper(*args, **kw):
        kw["scene_opts"] = {k: kw.pop(k, None) for k in keys}
        return f(*args, **kw)

    for o in reversed(opts):
        wrapper = o(wrapper)
    return wrapper


def _rule_forms() -> str:
    from tactileskin.mesh.skinfile import RULE_FORMS

    return RULE_FORMS


def _field_changes(opts: dict) -> dict:
    """Scene-field changes of the single-valued options (None: not given)."""
    ch = {k: opts.get(k) for k in ("thickness", "material", "indenter", "braille_text", "braille_standard",
                                    "indenter_radius", "indenter_axis", "indenter_file",
                                    "skin", "pad_width", "pad_length", "skin_file", "skin_bonded", "skin_outer",
                                    "depth", "rate",
                                    "force", "force_rate", "formulation")}
    if ch.get("skin_file") is not None and ch.get("skin") is None:
        ch["skin"] = "file"
    if opts.get("dim") is not None:
        ch["dim"] = int(opts["dim"])
    if opts.get("order") is not None:
        ch["order"] = int(opts["order"])
    if opts.get("elastic"):
        ch["viscoelastic"] = False
    return {k: v for k, v in ch.items() if v is not None and v != ()}


def check_dim_kept(requested, scene) -> None:
    """ParameterError if a dimension the user asked for (an option or a scene file's `dim`) is
    not the scene's: a skin that fixes it (a dome is 3D) would otherwise change it silently."""
    from tactileskin.errors import ParameterError

    if requested is not None and int(requested) != scene.dim:
        # a 3D file skin's 2D section needs a file of its own: say which
        hint = ("; for 2D give a 2D .msh of its section (triangles in a plane z = const, with named "
                "physical groups)" if scene.skin == "file" else "")
        raise ParameterError("dim", int(requested), f"{scene.dim} with skin = {scene.skin}",
                             f"the {scene.skin} skin is {scene.dim}D{hint}")


def has_2d_section(scene) -> bool:
    """Whether the scene's skin has a 2D section (fingertip, pad; not a dome or a 3D file)."""
    return scene.replace(dim=2).dim == 2


def scene_from_options(scene_opts: dict, command: str = "solve"):
    """The Scene of `solve`/`mesh`: the file (scene or one-case sweep), the options over it,
    then the quality preset (option, else file) and explicit mesh sizes over that."""
    from tactileskin import scenefile
    from tactileskin.scene import Scene

    sf = scenefile.read(scene_opts.get("scene_file"))
    fields = scenefile.single_scene_fields(sf, command)
    mesh = {k: fields.pop(k) for k in scenefile.MESH_FIELDS if k in fields}
    changes = _field_changes(scene_opts)
    if command == "mesh" and changes.get("order") == 1:
        changes["formulation"] = "displacement"  # the mesh does not depend on it; P1 needs it
    base = Scene.from_dict(fields).replace(**changes)
    check_dim_kept(changes.get("dim", fields.get("dim")), base)
    mesh.update({k: scene_opts[k] for k in scenefile.MESH_FIELDS if scene_opts.get(k) is not None})
    quality = scene_opts.get("quality") or sf.quality
    if quality is None and mesh:  # sizes without a preset: over the defaults, as Scene does
        return base.replace(**mesh)
    return scenefile.apply_quality(base, quality, mesh)


def claimed_output(out, kind: str, what: str = "--out"):
    """Claim the output folder `out` for the body (outdir.claimed: a folder created here and
    left holding only our marker by a failed body is removed again)."""
    from tactileskin import outdir

    return outdir.claimed(out, kind, what=what)
