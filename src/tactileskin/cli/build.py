"""`tactileskin build`: printable STL/STEP of the fingertip (or a pad, a dome, a user's STEP skin),
its casting mold and the indenters."""

from __future__ import annotations

import time
from pathlib import Path

import click

from tactileskin.cli._choice import Choice
from tactileskin.cli._common import _HelpText, _RangeHelpOption, _rule_forms


GEOMETRY_OPTIONS = ("thickness", "indenter", "indenter_radius", "indenter_axis", "braille_text", "braille_standard",
                    "skin", "pad_width", "pad_length", "dome_length", "dome_tip", "skin_file",
                    "skin_bonded")


def _scene_options(path: str) -> dict:
    """build's geometry options from a scene (or one-case sweep) TOML: the skin that `solve
    --scene` solves, its fingertip overrides included (`build` had no option for them and printed
    the default 20 mm, 8 mm fingertip for a scene that solves a 30 mm, 9 mm one); a STEP skin
    file with its `skin_bonded` rule."""
    from tactileskin import scenefile
    from tactileskin.errors import ParameterError
    from tactileskin.scene import Scene

    sc = Scene.from_dict(scenefile.single_scene_fields(scenefile.read(path), "build"))
    if sc.skin == "file":
        from tactileskin.mesh.skinfile import require_step

        require_step(sc.skin_file)  # a .msh has no CAD to make a mold of
    kind = sc.indenter.value
    if kind == "file":
        raise ParameterError("indenter_file", str(sc.indenter_file), "a built-in indenter for `build`",
                             "a file indenter is your own CAD: print it from there")
    opts = dict(thickness=sc.thickness, indenter=kind, skin=sc.skin, braille_text="",
                braille_standard="standard_american", indenter_radius=None, indenter_axis=None,
                pad_width=None, pad_length=None, dome_length=None, dome_tip=None, fingertip=dict(sc.fingertip),
                skin_file=None, skin_bonded=None)
    if kind == "braille":
        opts.update(braille_text=sc.braille_text, braille_standard=sc.braille_standard)
    if kind in ("sphere", "cylinder"):
        opts.update(indenter_radius=sc.indenter_radius, indenter_axis=sc.indenter_axis if kind == "cylinder" else None)
    if sc.skin == "pad":
        opts.update(pad_width=sc.pad_width, pad_length=sc.pad_length)
    if sc.skin == "dome":
        opts.update(dome_length=sc.dome_length, dome_tip=sc.dome_tip)
    if sc.skin == "file":
        opts.update(skin_file=sc.skin_file, skin_bonded=sc.skin_bonded)
    return opts


@click.command("build")
@click.option("--scene", "scene_file", type=click.Path(exists=True, dir_okay=False), default=None,
              help="Scene TOML (as for solve --scene): print its skin (thickness, fingertip overrides, pad or dome "
                   "sizes) and its indenter; the other geometry options are then not given.")
@click.option("--thickness", "-t", type=float, default=None,
              help="Skin thickness (mm); default from data/geometry/fingertip.toml.")
@click.option("--out", "-o", "out_dir", type=click.Path(file_okay=False), default="out", show_default=True,
              help="Output folder: new, empty or a previous build's (only the files that build wrote "
                   "are replaced; others stay).")
@click.option("--indenter", "-i", type=Choice(["flat", "curved", "braille", "sphere", "cylinder", "all", "none"]),
              default="all", show_default=True,
              help="Which indenter(s) to make ('all': the paper's flat, curved and braille).")
@click.option("--indenter-radius", type=float, default=None, cls=_RangeHelpOption,
              help=lambda: f"Sphere or cylinder indenter radius (mm): {_HelpText.radius()}.")
@click.option("--indenter-axis", type=Choice(["z", "x"]), default=None,
              help="Cylinder indenter axis: z along the finger (default) or x across it.")
@click.option("--braille-text", type=str, default="", help="Text for the Braille indenter (default: one dot).")
@click.option("--braille-standard", type=str, default="standard_american", show_default=True,
              help="Braille standard name (data/geometry/braille.toml).")
@click.option("--no-molds", is_flag=True, help="Skip the casting mold.")
@click.option("--skin", type=Choice(["fingertip", "pad", "dome"]), default="fingertip", show_default=True,
              help="Skin geometry: the paper's fingertip, a flat pad (--pad-width, --pad-length) or a "
                   "finger with a rounded tip (--dome-length, --dome-tip).")
@click.option("--skin-file", type=str, default=None,
              help="Your own skin: a STEP solid (mm) bonded on one flat face y = const facing -y (the faces "
                   "--skin-bonded picks; default 'normal:-y'); builds it and a two-part mold "
                   "cast face down, as the pad's; implies --skin file (a .msh has no CAD: refused).")
@click.option("--skin-bonded", type=str, default=None, cls=_RangeHelpOption,
              help=lambda: "With --skin-file: the rule picking its bonded faces, " + _rule_forms()
              + "; default 'normal:-y' (within 10 degrees).")
@click.option("--pad-width", type=float, default=None, help="Pad: x extent (mm); default 20.")
@click.option("--pad-length", type=float, default=None, help="Pad: z extent (mm); default 20.")
@click.option("--dome-length", type=float, default=None, help="Dome: finger length before the dome (mm); default 10.")
@click.option("--dome-tip", type=float, default=None,
              help="Dome: semi-axis of the dome along the finger (mm); default the section's half width.")
def command(thickness, out_dir, indenter, braille_text, braille_standard, no_molds, skin="fingertip",
            pad_width=None, pad_length=None, dome_length=None, dome_tip=None, indenter_radius=None,
            indenter_axis=None, scene_file=None, skin_file=None, skin_bonded=None):
    """Build the fingertip skin, rigid base, casting mold and indenters into OUT.

    Writes binary STL + STEP per part and OUT/manifest.json (file, volume, bounding box,
    watertight flag). Every STL is checked to be a closed, consistently wound volume.
    """
    from rich.markup import escape
    from rich.table import Table

    from tactileskin.cli._console import new_console
    from tactileskin.errors import ParameterError
    from tactileskin.geometry.fingertip import Fingertip
    from tactileskin.geometry.parts import default_thickness, resolve_indenters

    console = new_console()
    overrides = {}
    if scene_file is not None:
        ctx = click.get_current_context()
        given = [n for n in GEOMETRY_OPTIONS if ctx.get_parameter_source(n) == click.core.ParameterSource.COMMANDLINE]
        if given:
            raise click.UsageError("--scene gives the skin and the indenter: leave out "
                                   + ", ".join("--" + n.replace("_", "-") for n in given))
        opts = _scene_options(scene_file)
        overrides = opts.pop("fingertip") if opts["skin"] == "fingertip" else {}
        thickness, indenter, skin = opts["thickness"], opts["indenter"], opts["skin"]
        braille_text, braille_standard = opts["braille_text"], opts["braille_standard"]
        indenter_radius, indenter_axis = opts["indenter_radius"], opts["indenter_axis"]
        pad_width, pad_length, dome_length, dome_tip = (opts[k] for k in ("pad_width", "pad_length", "dome_length",
                                                                           "dome_tip"))
        skin_file, skin_bonded = opts["skin_file"], opts["skin_bonded"]
    else:
        if skin_bonded is not None and skin_file is None:
            raise click.UsageError("--skin-bonded needs --skin-file")
        if skin_file is not None:
            if click.get_current_context().get_parameter_source("skin") == click.core.ParameterSource.COMMANDLINE:
                raise click.UsageError("--skin-file is the skin: leave out --skin")
            skin = "file"
    t = default_thickness() if thickness is None else thickness
    pad = {}
    if skin != "pad" and (pad_width is not None or pad_length is not None):
        raise click.UsageError("--pad-width and --pad-length need --skin pad")
    if skin != "dome" and (dome_length is not None or dome_tip is not None):
        raise click.UsageError("--dome-length and --dome-tip need --skin dome")
    if skin == "pad":
        from tactileskin.scene import Scene

        sc = Scene(skin="pad", thickness=t, pad_width=pad_width, pad_length=pad_length)  # validates
        pad = dict(pad_width=sc.pad_width, pad_length=sc.pad_length)
    elif skin == "file":
        from tactileskin.mesh.skinfile import DEFAULT_RULE, require_step
        from tactileskin.scene import Scene

        require_step(skin_file)  # a .msh: no CAD, before gmsh reads it
        if Path(skin_file).resolve().parent == Path(out_dir).resolve():
            # the build writes skin.step (and its record) there: a rebuild over its own output would
            # replace its input, and the manifest name bytes that are gone
            raise ParameterError("--skin-file", str(skin_file), "a STEP outside --out",
                                 f"the build writes into {out_dir}: copy the file out of it first")
        given = {} if thickness is None else {"thickness": thickness}  # the file fixes t: another is refused
        sc = Scene(skin="file", skin_file=skin_file, skin_bonded=skin_bonded, **given)  # validates, measures t
        t = sc.thickness
        pad = dict(skin_file=str(sc.skin_file), skin_bonded=sc.skin_bonded or DEFAULT_RULE)
    elif skin == "dome":
        from tactileskin.scene import Scene

        sc = Scene(skin="dome", thickness=t, dome_length=dome_length, dome_tip=dome_tip)  # validates
        pad = dict(dome_length=sc.dome_length, dome_tip=sc.dome_tip)
    else:
        Fingertip.from_params(**overrides).check_thickness(t)  # fail fast, before the CAD imports
    resolve_indenters(indenter)
    if indenter_radius is not None and indenter not in ("sphere", "cylinder"):
        raise click.UsageError("--indenter-radius needs --indenter sphere or cylinder")
    if indenter_axis is not None and indenter != "cylinder":
        raise click.UsageError("--indenter-axis needs --indenter cylinder")
    if indenter not in ("braille", "all") and (braille_text or braille_standard != "standard_american"):
        # else ignored, and recorded in manifest.json as if a Braille indenter had been built
        raise click.UsageError("--braille-text and --braille-standard need --indenter braille (or all)")
    ind_params = {k: v for k, v in (("indenter_radius", indenter_radius), ("indenter_axis", indenter_axis))
                  if v is not None}

    t0 = time.perf_counter()
    with console.status("building solids (build123d)..."):
        from tactileskin import outdir
        from tactileskin.geometry.export import check_target, export_parts
        from tactileskin.geometry.parts import build_parts

        check_target(Path(out_dir).absolute())  # refuse a folder of other files before the work
        outdir.check_free(out_dir, "--out")       # ... and one another run is writing into
        if pad:
            from tactileskin.skins import get

            parts = get(skin).build_parts(t, molds=not no_molds, **pad)
            parts += build_parts(default_thickness(), indenters=indenter, braille_text=braille_text,
                                 braille_standard=braille_standard, fingertip=False, molds=False,
                                 indenter_params=ind_params, skin_scene=sc.replace(dim=3))
        else:
            parts = build_parts(t, indenters=indenter, braille_text=braille_text,
                                braille_standard=braille_standard, molds=not no_molds, indenter_params=ind_params,
                                fingertip_overrides=overrides)
    t1 = time.perf_counter()
    with console.status(f"writing {len(parts)} parts to {escape(str(out_dir))}..."):
        manifest = export_parts(parts, out_dir, meta=dict(thickness=t, indenter=indenter, braille_text=braille_text,
                                                          braille_standard=braille_standard, molds=not no_molds, **ind_params,
                                                          **({"skin": skin, **pad} if pad else {}),
                                                          **({"fingertip": overrides} if overrides else {})))
    t2 = time.perf_counter()

    table = Table(title=escape(f"t = {t:g} mm -> {out_dir}/<part>.stl, .step"))
    table.add_column("part", no_wrap=True)
    table.add_column("volume mm³", justify="right", no_wrap=True)
    table.add_column("x × y × z mm", justify="right", no_wrap=True)
    table.add_column("closed", justify="center")
    table.add_column("what")
    for e in manifest["parts"]:
        size = "×".join(f"{hi - lo:.1f}" for lo, hi in zip(e["bbox_min"], e["bbox_max"]))
        table.add_row(escape(e["name"]), f"{e['volume_mm3']:.1f}", size,
                      "yes" if e["is_volume"] else "[red]no[/]", escape(e["description"]))
    console.print(table)
    console.print(f"solids {t1 - t0:.1f} s, export {t2 - t1:.1f} s; manifest: {escape(str(out_dir))}/manifest.json")
