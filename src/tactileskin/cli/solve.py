"""`tactileskin solve`: indent one scene and write its pressure profile and fields."""

from __future__ import annotations

import contextlib
from pathlib import Path

import click

from tactileskin import quality, results
from tactileskin.cli._common import claimed_output, has_2d_section, scene_from_options, scene_options

# every file of a solve folder (results.SOLVE_FILES, shared with Result.write), all listed as
# the result's files after a solve (--compare-2d's compare_2d.json and section_2d/ too)
OWN_FILES = RESULT_FILES = results.SOLVE_FILES
ALWAYS_WRITTEN = ("profile.csv", "contact.csv", "summary.json", "result.vtu")  # by every solve


EXIT_SUSPECT = 3  # a result was written but tactileskin.quality flags it (see the help text)


@click.command("solve", epilog=(
    "Exit status: 0 the result is ok; 3 the result was written but is suspect (no contact, "
    "the material law outside its range, locking P1 elements, a mesh coarser than the preview "
    "preset's, a peak at the bonded skin's edge, ...: see 'status' and 'flags' in summary.json "
    "and docs/hard_cases.md, \"Result status\"; with --compare-2d, also the 2D section's, "
    "compare_2d.json 'status'); 2 an "
    "error (bad parameter, refused mesh, no convergence, output folder), nothing written."))
@scene_options
@click.option("--out", "-o", "out", type=click.Path(file_okay=False), required=True,
              help="Output folder (profile.csv, contact.csv, summary.json, result.vtu; 3D also "
                   "bone_map.csv, bone_map.png, profile_max_z.csv): a new or empty folder, or one "
                   "written by `solve`; only these files are replaced.")
@click.option("--history", is_flag=True, default=False,
              help="Also write result.pvd: the displacement of every increment as a ParaView time "
                   "series (result_steps/).")
@click.option("--compare-2d", is_flag=True, default=False,
              help="3D scenes: also solve the paper's 2D section (a Braille row as a ridge) at "
                   "the 2D mesh of the same --quality (default for other sizes), write it to "
                   "OUT/section_2d and report the differences.")
@click.option("--sensors", "sensors_file", type=click.Path(dir_okay=False), default=None,
              help="TOML file of [[sensors]] layouts (replaces the scene file's): writes "
                   "sensors.csv and sensors.png.")
def command(out, history, compare_2d, scene_opts, sensors_file=None):
    """Solve the finite-strain contact problem of one scene and write the results."""
    from rich.markup import escape
    from rich.table import Table
    from rich.text import Text

    from tactileskin import fileio, staging
    from tactileskin.cli._console import new_console
    from tactileskin.errors import TactileSkinError
    from tactileskin.fe import solve

    scene = scene_from_options(scene_opts, "solve")
    if sensors_file:
        from tactileskin import validate
        from tactileskin.errors import ParameterError
        from tactileskin.params import read_toml

        doc = read_toml(sensors_file, "sensors file")
        validate.known_keys(doc, ["sensors"], "sensors file")
        if not doc.get("sensors"):
            raise ParameterError("sensors file", sensors_file, "[[sensors]] tables (one per layout)")
        scene = scene.replace(sensors=doc["sensors"])
    if compare_2d and scene.dim != 3:
        raise click.UsageError("--compare-2d needs a 3D scene (--dim 3)")
    if compare_2d and not has_2d_section(scene):
        raise click.UsageError(f"--compare-2d needs a skin with a 2D section (fingertip, pad), not {scene.skin}")
    with claimed_output(out, "solve"):  # a folder of other files is refused before solving
        # ... and one where this result's files could not replace the earlier ones (edited)
        staging.check_replaceable(out, _will_write(scene, history, compare_2d))
        with solve_progress(scene.label()) as show:
            res = solve(scene, progress=show, history=history)
        r2, r2_error = None, None
        if compare_2d:
            try:
                r2 = _solve_2d(scene)
            except TactileSkinError as e:  # the 3D result (minutes of solving) is kept
                r2_error = e
        # one result in the folder: staged, then moved in together (summary.json last); files
        # of an earlier result this one has not (a map, a 2D section) are removed
        with staging.staged_files(out, OWN_FILES, last="summary.json") as tmp:
            res.write_owned(tmp)
            _write_map_figure(res, tmp, scene.label())
            _write_sensors_figure(res, tmp, scene.label())
            if r2 is not None:
                r2.write_owned(tmp / "section_2d")
                fileio.atomic_write_json(tmp / "compare_2d.json", _compare_doc(scene, res.summary(), r2))
        path = Path(out)
    s = res.summary()
    t = Table(title=escape(f"{scene.label()} -> {path}"), show_header=False)
    t.add_row("peak bone pressure", f"{s['peak_mpa']:.4g} MPa")
    t.add_row("span (P >= 10 % of peak)", f"{s['span_mm']:.3g} mm")
    t.add_row("area under P(s)", f"{s['auc_mpa_mm']:.4g} MPa mm")
    if scene.dim == 3:
        t.add_row("bone profile on plane", f"z = {res.stats.get('profile_plane_z', 0.0):g} mm")
        if "peak_map_mpa" in s:
            t.add_row("peak of the bone map P(s, z)", f"{s['peak_map_mpa']:.4g} MPa at s = "
                      f"{_mm(s['peak_map_s_mm'])} mm, z = {_mm(s['peak_map_z_mm'])} mm (>= t from the skin's edges)")
        if "peak_map_edge_mpa" in s:
            t.add_row("at the skin's bonded edge", f"{s['peak_map_edge_mpa']:.4g} MPa at s = {_mm(s['peak_map_edge_s_mm'])} mm, "
                      f"z = {_mm(s['peak_map_edge_z_mm'])} mm (a corner singularity: grows with mesh refinement)")
        t.add_row("force on the indenter (whole)", f"{quality.reaction_of(s):.4g} N")
    else:
        t.add_row("reaction (half section)", f"{quality.reaction_of(s):.4g} N/mm")
    if "loading" in s:
        from tactileskin.loading import force_unit

        lo, unit = s["loading"], force_unit(scene.dim)
        if lo.get("target_force") is not None:
            t.add_row("force control", f"{lo['reached_force']:.5g} {unit} (target {lo['target_force']:.5g}) "
                      f"at travel {lo['reached_travel_mm']:.4g} mm")
        t.add_row("profile state", f"peak load, t = {lo['profile_t_s']:.4g} s; final: t = {lo['final']['t_s']:.4g} s, "
                  f"travel {lo['final']['travel_mm']:.4g} mm, reaction {lo['final']['reaction']:.4g} {unit}")
    if "peak_sensor_pressure_mpa" in s:
        t.add_row("sensors / peak sensor P", f"{s['sensors']} / {s['peak_sensor_pressure_mpa']:.4g} MPa "
                  f"({s['peak_sensor_id']})")
    if scene.dim == 2 and scene.indenter_kind.section_2d == "ridge":
        t.add_row("model", _ridge_note(scene))
    t.add_row("dofs / increments / Newton", f"{s['dofs']} / {s['increments']} / {s['newton_iterations']}")
    t.add_row("wall time", f"{s['wall_s']:.2f} s")
    t.add_row("files", ", ".join(sorted({n.split("/")[0] for n in RESULT_FILES if any(path.glob(n))})))
    if "min_J" in s:
        t.add_row("min volume ratio J / max |stress|",
                  f"{s['min_J']:.4g} / {s['max_abs_stress_mpa']:.4g} MPa")
    t.add_row("status", Text("ok", style="green") if s["status"] == "ok"
              else Text(s["status"], style="bold yellow"))
    console = new_console()
    console.print(t)
    rc = 0
    if s["status"] != "ok":
        console.print(Text("warning: suspect result (exit status 3): ", style="bold yellow")
                      + Text(s["status"].split(": ", 1)[-1]), highlight=False)
        rc = EXIT_SUSPECT
    if r2 is not None:
        doc = _compare_doc(scene, s, r2)
        _print_compare_2d(doc, r2.summary())
        if doc["status"] != "ok":  # a suspect 2D section makes compare_2d.json suspect: not exit 0
            rc = EXIT_SUSPECT
    if r2_error is not None:
        console.print(Text("warning: --compare-2d: the 2D section could not be solved, so there is no "
                           "compare_2d.json: ", style="bold yellow") + Text(str(r2_error).splitlines()[0]),
                      highlight=False)
    return rc


def _will_write(scene, history: bool, compare_2d: bool) -> list[str]:
    """The result files this solve will write (a map only in 3D, and only where the skin has
    one: a name it may not write is left out, as an edited file it does not replace stays)."""
    names = list(ALWAYS_WRITTEN)
    if scene.dim == 3 and scene.skin != "file":
        names += ["bone_map.csv", "profile_max_z.csv", "bone_map.png"]
    if scene.sensors:
        names += ["sensors.csv", "sensors.png"]
    if scene.loading:  # [[loading]] segments; a --force ramp alone writes no history.csv
        names.append("history.csv")
    if history:
        names.append("result.pvd")
    if compare_2d:
        names += ["compare_2d.json", *(f"section_2d/{n}" for n in ALWAYS_WRITTEN)]
    return names


def _ridge_note(scene) -> str:
    """What a 2D Braille result is: the paper's ridge, not the dots (their measured ratio)."""
    from tactileskin.planner import measured_ridge_vs_dots

    meas = measured_ridge_vs_dots(scene)
    ratio = (f"{1.0 + meas['peak']:.2g}x the peak of the 3D dots measured at this thickness and material"
             if meas else "1.9-3.1x the peak of real dots where measured (t = 1, 3, 5 mm)")
    return f"the paper's 2D ridge (a dot row as a ridge along the finger): it reads {ratio}; --dim 3 solves the dots"


@contextlib.contextmanager
def solve_progress(label: str):
    """A transient progress line on stderr for one solve; yields the callback for
    fe.solve(progress=) (increment, time, travel and Newton iterations)."""
    from rich.markup import escape
    from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    from tactileskin.cli import raise_if_signalled
    from tactileskin.cli._console import new_console

    console = new_console(stderr=True)
    if not console.is_terminal:
        # off a terminal (a log, a pipe) the transient line shows nothing but leaves an empty
        # line on stderr, before an error's one line too
        yield lambda i: raise_if_signalled()
        return
    with Progress(SpinnerColumn(), TextColumn("{task.description}"), BarColumn(bar_width=16),
                  TextColumn("{task.fields[info]}"), TimeElapsedColumn(),
                  console=console, transient=True) as bar:
        task = bar.add_task(escape(label), total=1.0, info="meshing, setting up")

        def show(i):  # short: it must fit an 80-column terminal beside the label
            raise_if_signalled()
            bar.update(task, completed=i.t, total=i.T,
                       info=f"increment {i.increment}, t {i.t:.3g}/{i.T:.3g} s, d {i.travel:.3g} mm, "
                            f"Newton {i.newton} ({i.newton_total})")

        yield show


def _write_figure(data, png, draw: str, title: str) -> None:
    """png drawn by `draw` ("module:function", imported only when there is something to draw:
    matplotlib stays out of a plain 2D solve) when the result has `data`."""
    import importlib

    if data is None:
        return
    module, func = draw.split(":")
    getattr(importlib.import_module(module), func)(data, png, title=title)


def _figure_title(res, text: str) -> str:
    """A figure's title, with the result's suspect status when it has one (a no-contact map
    was titled as any other)."""
    if res.bone_map is None and res.sensors is None:
        return text
    return quality.suspect_title(text, str(res.summary().get("status", "ok")))


def _write_map_figure(res, path, label: str) -> None:
    """bone_map.png of a 3D result."""
    _write_figure(res.bone_map, path / "bone_map.png", "tactileskin.report.bone_map:write_bone_map_figure",
                  _figure_title(res, f"bone pressure, {label}"))


def _write_sensors_figure(res, path, label: str) -> None:
    """sensors.png of a result with sensors."""
    _write_figure(res.sensors, path / "sensors.png", "tactileskin.report.sensors:write_sensors_figure",
                  _figure_title(res, f"sensor readings, {label}"))


def _solve_2d(scene):
    """The 2D section of a 3D scene, solved at the 2D mesh of the 3D mesh's quality preset
    (the default 2D mesh for sizes of no preset); the 3D sizes mean nothing in 2D (a 3D
    preview's 1.6 / 6 read the ridge 4 % low)."""
    from tactileskin.fe import solve
    from tactileskin.planner import with_quality
    from tactileskin.scene import preset_mesh

    sc2 = scene.replace(dim=2, mesh_size=None, refinement=None)
    sizes = (scene.mesh_size, scene.refinement)
    for q in ("default", "fine", "preview"):  # default first: thick Braille's 3D default is its preview
        if preset_mesh(q, 3, scene.indenter, scene.thickness, scene.skin) == sizes:
            sc2 = with_quality(sc2, q)
            break
    with solve_progress(sc2.label()) as show:
        return solve(sc2, progress=show)


def _compare_doc(scene, s3: dict, r2) -> dict:
    """compare_2d.json: the 2D section's peak and span against the 3D result's."""
    s2 = r2.summary()
    # no relative difference when the 3D value is 0 (no contact reached the bone): None, not NaN
    rows = {k: (s2[k], s3[k], (s2[k] - s3[k]) / s3[k] if s3[k] > 0 else None)
            for k in ("peak_mpa", "span_mm")}
    # a difference from a suspect side is suspect too (the file gave it plainly, with no status)
    bad = [f"{d}: {st.split(': ', 1)[-1]}" for d, st in (("3D", s3.get("status", "ok")),
                                                          ("2D", s2.get("status", "ok"))) if quality.kind(st) != "ok"]
    return {"scene_3d": scene.label(), "scene_2d": scene.replace(dim=2).label(),
            "status": "suspect: " + "; ".join(bad) if bad else "ok",
            **{k: {"2d": a, "3d": b, "relative_difference": d} for k, (a, b, d) in rows.items()}}


def _mm(x: float) -> str:
    """A position on the bone map (mm), 3 digits; within 1e-9 mm of 0 it is 0 (a map grid's
    rounding printed the axis as 3.67e-16)."""
    return "0" if abs(x) < 1e-9 else f"{x:.3g}"


def _print_compare_2d(doc: dict, s2: dict) -> None:
    from rich.markup import escape
    from rich.table import Table
    from rich.text import Text

    from tactileskin.cli._console import new_console

    t = Table(title=escape(f"2D section ({doc['scene_2d']}) against 3D; difference = (2D - 3D) / 3D"))
    for c in ("", "2D", "3D", "difference"):
        t.add_column(c)
    for k in ("peak_mpa", "span_mm"):
        a, b, d = doc[k]["2d"], doc[k]["3d"], doc[k]["relative_difference"]
        t.add_row(k, f"{a:.4g}", f"{b:.4g}", "n/a (3D is 0)" if d is None else f"{100 * d:+.1f} %")
    new_console().print(t)
    if s2.get("status", "ok") != "ok":
        why = s2["status"].split(": ", 1)[-1]
        new_console().print(Text(f"warning: the 2D section is suspect (exit status 3): {why}", style="bold yellow"),
                            highlight=False)
