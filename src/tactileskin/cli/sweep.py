"""`tactileskin sweep`: the paper's thickness sweep (or any grid), cached and parallel."""

from __future__ import annotations

import time
from pathlib import Path

import click

from tactileskin.cli._choice import Choice
from tactileskin.cli._common import _field_changes, check_dim_kept, claimed_output, has_2d_section, scene_options
from tactileskin.errors import ParameterError


EXIT_FAILED, EXIT_SUSPECT = 1, 3
BRAILLE_DIM_CHOICES = {"2": (2,), "3": (3,), "both": (2, 3)}


@click.command("sweep", epilog=(
    "Exit status: 0 every case ok; 1 some case failed (the others are reported); 3 no case "
    "failed but some result is suspect (no contact, the material law outside its range, "
    "locking P1 elements, a mesh coarser than the preview preset's, a peak at the bonded "
    "skin's edge, ...: the 'status' column of results.csv and the top of report.md say why; "
    "docs/hard_cases.md, \"Result status\"); 2 an error "
    "before any case ran (bad parameter, output folder)."))
@scene_options(grid=True)
@click.option("--out", "-o", "out", type=click.Path(file_okay=False), default="out", show_default=True,
              help="Output folder: results.csv/.parquet, profiles.csv/.parquet, figures, report.md (a "
                   "new or empty folder, or one written by `sweep`; other files are never touched).")
@click.option("--braille-dim", "braille_dim", type=Choice(["2", "3", "both"]), default=None,
              help="Braille cases as the paper's 2D ridge section (2), as the 3D slab with real "
                   "dots (3), or both side by side in the report. Default: both at the default "
                   "quality (--quality default, or none and no mesh sizes; the paper sweep then takes "
                   "about 100 s on 2 cores), else the [scene] dim; one dim under force control. Flat and "
                   "curved cases stay 2D (exact for them). 3D solves take 4-60 s each at default.")
@click.option("--scheduler", default=None, help="Address of a running Dask scheduler (tcp://host:8786).")
@click.option("--workers", type=click.IntRange(min=1), default=None,
              help="Local worker processes (default: all cores).")
@click.option("--serial", is_flag=True, help="Run in this process, without Dask.")
@click.option("--cache", "cache_dir", type=click.Path(file_okay=False), default=None,
              help="Result cache folder (default OUT/cache).")
@click.option("--no-render", is_flag=True, help="Skip the Fig. 9 renders (fig9_CASE.png: matplotlib in 2D, pyvista in 3D).")
def command(out, scene_opts, braille_dim, scheduler, workers, serial, cache_dir, no_render):
    """Run a sweep; rerunning reuses every finished case from the cache."""
    from rich.markup import escape
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
    from rich.text import Text

    from tactileskin import quality as result_quality  # `quality` is the mesh preset option
    from tactileskin.cli import raise_if_signalled
    from tactileskin.cli._console import new_console

    from tactileskin import staging
    from tactileskin.report.outputs import SWEEP_ALWAYS_WRITTEN, write_outputs
    from tactileskin.cache import open_cache, out_cache
    from tactileskin.sweep import ResultCache, check_reachable, run_sweep

    console = new_console()
    if scheduler is not None:
        check_reachable(scheduler)  # before the folder is claimed: a refusal leaves nothing
    scenes = scenes_from_options(scene_opts, braille_dim)
    out = Path(out)
    cache = open_cache(cache_dir) if cache_dir else ResultCache(out_cache(out))
    with claimed_output(out, "sweep"):  # before any solving
        # an edited report.md or results.csv would be refused only after every case was solved
        staging.check_replaceable(out, SWEEP_ALWAYS_WRITTEN)
        console.print(f"sweep: {len(scenes)} cases → {escape(str(out))}")

        t0 = time.perf_counter()
        with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                      TimeElapsedColumn(), console=console, transient=False) as bar:
            task = bar.add_task("solving", total=len(scenes))

            def on_event(oc):
                raise_if_signalled()
                style = {"cached": "dim", "done": "green", "failed": "bold red"}[oc.status]
                extra = f" ({oc.seconds:.1f} s)" if oc.status == "done" else (f": {oc.error}" if oc.error else "")
                word, why = oc.status, ""
                if oc.status != "failed":
                    st = _case_status(cache, oc)
                    if st != "ok":
                        word, style, why = "suspect", "bold yellow", f" - {st.split(': ', 1)[-1]}"
                line = Text.assemble((f"{word:>7}", style), f" {oc.case or oc.scene.label()}{extra}{why}")
                bar.console.print(line, highlight=False)
                bar.advance(task)

            outcomes = run_sweep(scenes, cache, scheduler=scheduler, workers=workers, serial=serial,
                                 on_event=on_event)
        wall = time.perf_counter() - t0
        with console.status("writing results, figures and report"):  # transient; nothing off a terminal
            paths = write_outputs(out, outcomes, cache, wall, render=not no_render)
    nfail = len(paths["failures"])
    nsus = sum(1 for r in paths.get("rows", []) if result_quality.kind(r.get("status", "")) == "suspect")
    console.print(f"report: {escape(str(paths['report']))}  ({len(scenes) - nfail - nsus}/{len(scenes)} ok, "
                  f"{nsus} suspect, {nfail} failed, {wall:.1f} s)", highlight=False)
    return EXIT_FAILED if nfail else (EXIT_SUSPECT if nsus else 0)


def scenes_from_options(scene_opts: dict, braille_dim: str | None = None):
    """The sweep's scenes: the file's [sweep] lists and Scene fields (a field is a one-value
    list), the options over them (lists), the quality preset of each case's dimension and
    the explicit mesh sizes over it. Axes given nowhere are the paper's (1,3,5 mm x silicone,
    polyurethane x flat, curved, Braille)."""
    from tactileskin import scenefile
    from tactileskin.scene import Scene
    from tactileskin.sweep import expand_grid, parse_values

    o = scene_opts
    sf = scenefile.read(o.get("scene_file"))
    fields = dict(sf.fields)
    axes = dict(sf.axes)
    for f, ax in scenefile.AXES.items():
        if f in fields:  # kept in the base too: its own fields (indenter_radius) need it there
            axes[ax] = (fields[f],)
    mesh = {k: fields.pop(k) for k in scenefile.MESH_FIELDS if k in fields}
    mesh.update({k: o[k] for k in scenefile.MESH_FIELDS if o.get(k) is not None})
    single = {k: v for k, v in o.items() if k not in ("thickness", "material", "indenter", "depth", "braille_text")}
    changes = _field_changes(single)
    if o.get("indenter") is not None:  # the base takes the kind's own options (--indenter-radius) with it
        axes["indenters"] = _names(o["indenter"], "indenter")
        changes["indenter"] = scenefile.base_indenter(axes["indenters"], {**fields, **changes})
    else:
        # the file's `indenters` list, as the option: its kind's own fields ([scene]
        # indenter_radius with indenters = ["sphere"]) were refused against the default flat plate
        fields = scenefile.with_base_indenter(fields, axes.get("indenters"))
    base = Scene.from_dict(fields).replace(**changes)
    check_dim_kept(changes.get("dim", fields.get("dim")), base)
    if base.skin_kind.fixes_thickness and "thicknesses" not in axes:
        axes["thicknesses"] = (base.thickness,)  # a skin file fixes it: not the paper's 1, 3, 5
    if o.get("thickness") is not None:
        axes["thicknesses"] = parse_values(o["thickness"], "thickness")
    if o.get("material") is not None:
        axes["materials"] = _names(o["material"], "material")
    if o.get("depth") is not None:
        axes["depths"] = parse_values(o["depth"], "depth")
    if o.get("braille_text"):
        axes["braille_texts"] = tuple(o["braille_text"])
    if braille_dim:
        if 2 in BRAILLE_DIM_CHOICES[braille_dim] and not has_2d_section(base):
            raise ParameterError("--braille-dim", braille_dim, "3 with skin = " + base.skin,
                                 f"the {base.skin} skin has no 2D section")
        axes["braille_dims"] = BRAILLE_DIM_CHOICES[braille_dim]
    elif "braille_dims" not in axes and (o.get("dim") is not None or "dim" in fields):
        axes["braille_dims"] = (base.dim,)  # a dim asked for: the Braille cases' too
    # the preset per scene (it depends on the indenter and dim), explicit mesh sizes over it
    try:
        return expand_grid(base=base, quality=o.get("quality") or sf.quality, overrides=mesh or None, **axes)
    except ParameterError as e:
        # the grid's refusal of its dims names the API's braille_dims: name what the user gave
        if e.name != "braille_dims" or not (braille_dim or "braille_dims" in sf.axes):
            raise
        name, value = ("--braille-dim", braille_dim) if braille_dim else ("sweep.braille_dims", e.value)
        raise ParameterError(name, value, e.valid, e.hint) from None


def _case_status(cache, oc) -> str:
    """Status of a finished case from its numbers (tactileskin.quality): the record run_sweep
    already validated, read from the cache only if the outcome carries none."""
    from tactileskin import quality

    try:
        rec = oc.record if oc.record is not None else cache.load(oc.scene)
        return quality.status(rec.summary)
    except Exception as e:  # noqa: BLE001 - the report step reports an unreadable entry
        return f"suspect: cached entry unreadable ({e})"


def _names(text: str, name: str) -> tuple[str, ...]:
    items = tuple(x.strip() for x in text.split(","))
    if not all(items):  # "" or "a,,b": a name left out by mistake
        raise ParameterError(name, text, "a comma-separated list of names, none of them empty")
    return items
