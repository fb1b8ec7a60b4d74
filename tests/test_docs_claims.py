"""Numbers and statements of README.md and docs/ that the code can check, so a doc does not
go stale when the stored measurements or flags change."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _text(name: str) -> str:
    # whitespace-normalised: the docs wrap lines anywhere
    return " ".join((ROOT / name).read_text(encoding="utf-8").split())


def _ridge_ranges():
    from tactileskin.planner import MEASURED_RIDGE_VS_DOTS

    peaks = [1 + m["peak"] for m in MEASURED_RIDGE_VS_DOTS.values()]
    spans = [100 * m["span"] for m in MEASURED_RIDGE_VS_DOTS.values()]
    return (round(min(peaks), 1), round(max(peaks), 1)), (round(min(spans)), round(max(spans)))


def test_hard_cases_ridge_section_states_the_planners_measurements():
    """docs/hard_cases.md said MEASURED_RIDGE_VS_DOTS 'stays empty' and the ridge 'Not measured'
    long after the table was filled (t = 1, 3, 5 mm)."""
    (lo, hi), (slo, shi) = _ridge_ranges()
    doc = _text("docs/hard_cases.md")
    assert "MEASURED_RIDGE_VS_DOTS` stays empty" not in doc
    assert f"peak reads {lo}-{hi}x the dots', spans {slo} to +{shi} %" in doc


def test_architecture_and_readme_ridge_ranges_match_the_planner():
    """docs/architecture.md still gave the first coarse estimates (1.9-2.8x, spans -6..+20 %)
    after the planner's table was re-measured (1.9-3.1x, -7..+2 %); the README quotes the peak
    range twice."""
    (lo, hi), (slo, shi) = _ridge_ranges()
    assert f"peak is {lo}-{hi}x the dots', spans within {slo}..+{shi} %" in _text("docs/architecture.md")
    readme = _text("README.md")
    assert f"reads {lo}-{hi} times their bone pressure" in readme and f"reads {lo}-{hi}x their peak" in readme


def test_hard_cases_status_table_gives_the_status_a_solve_gets_now():
    """docs/hard_cases.md's status table (h = 1 mm, refinement 2) read 'ok' for the 20 % plate
    after such meshes came to be flagged coarse_mesh; its first row solved as the table says."""
    from tactileskin.fe import solve
    from tactileskin.scene import Scene

    words = {"stress_range": "stress", "volume_range": "J", "coarse_mesh": "coarse mesh"}
    r = solve(Scene(thickness=1, material="silicone", indenter="flat", mesh_size=1.0, refinement=2))
    codes = [f["code"] for f in r.summary()["flags"]]
    status = "suspect (" + ", ".join(words[c] for c in codes) + ")" if codes else "ok"
    assert f"| t1 silicone flat, 20 % | {r.peak:.3f} | {r.summary()['min_J']:.3f} |" in _text("docs/hard_cases.md")
    assert f"| t1 silicone flat, 20 % | 0.308 | 0.986 | 0.33 | {status} |" in _text("docs/hard_cases.md")



def _contact_pressures(scene, out):
    """contact.csv's (x, pressure per current area) and the largest facet value of result.vtu's
    contact_pressure_MPa (per reference area), as a user reads them."""
    import csv

    import meshio
    import numpy as np

    from tactileskin.fe import solve

    solve(scene).write(out)
    with open(out / "contact.csv", newline="") as f:
        rows = [(float(r["x_mm"]), float(r["contact_pressure_mpa"])) for r in csv.DictReader(f)]
    reference = meshio.read(out / "result.vtu").cell_data_dict["contact_pressure_MPa"]["line"]
    return np.array(rows), float(reference.max())


def test_readme_contact_pressure_numbers_are_what_the_files_read(tmp_path):
    """The README quoted 'Braille 0.28-0.29 against 0.33' beside the silicone plate without
    naming the material: those are polyurethane's; silicone's ridge reads 0.19 against 0.23."""
    import numpy as np

    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    readme = _text("README.md")
    flat = with_quality(Scene(thickness=1, material="silicone", indenter="flat"), "preview")
    cur, ref = _contact_pressures(flat, tmp_path / "flat")
    centre = cur[np.argmin(np.abs(cur[:, 0])), 1]
    assert f"silicone at `preview`: {centre:.3f} against {ref:.3f} MPa at the centre" in readme
    dot = with_quality(Scene(thickness=1, material="polyurethane", indenter="braille"), "preview")
    cur, ref = _contact_pressures(dot, tmp_path / "dot")
    top = np.sort(cur[:, 1])[-2:]
    assert f"polyurethane Braille ridge {top[0]:.2f}-{top[1]:.2f} against {ref:.2f})" in readme


def test_architecture_does_not_say_the_dome_parts_are_refused():
    """docs/architecture.md said the dome's STLs were not watertight and export_parts refused
    them, long after `build --skin dome` wrote them watertight (tests/test_skin_dome.py)."""
    doc = _text("docs/architecture.md")
    assert "`export_parts` refuses them" not in doc
    assert "`build --skin dome` exports them all as watertight STLs" in doc


def test_speed_vs_error_states_the_2d_presets_of_presets_json():
    """docs/speed_vs_error.md's last section, 'Quality presets (proposal for --quality)', gave
    preview 1.0 / 2 and default 0.25 / 3 as the presets; they are 1 / 5 and 0.5 / 3 (Braille
    0.5 / 6) since the second speed pass."""
    from tactileskin.presets import load

    p = load()["2"]

    def sizes(q, key="mesh"):
        return "{:g} / {:g}".format(*p[q][key])

    doc = _text("docs/speed_vs_error.md")
    assert (f"preview {sizes('preview')}, default {sizes('default')} (Braille {sizes('default', 'braille_mesh')}), "
            f"fine {sizes('fine')} (mesh_size / refinement)") in doc
    assert "## Quality presets (proposal for `--quality`)" not in doc


def test_readme_layout_lists_every_package():
    """The README's Layout left out skins/ and array/ (the pad, dome and file skins; the
    sensor-array chart), so a reader found no home for half of the Commands table."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    layout = text[text.index("## Layout"):text.index("## Documentation")]
    pkgs = sorted(p.name for p in (ROOT / "src" / "tactileskin").iterdir()
                  if (p / "__init__.py").is_file())
    assert len(pkgs) >= 9
    assert [p for p in pkgs if f"\n  {p}/" not in layout] == []


def test_architecture_newton_range_holds_a_default_solve():
    """docs/architecture.md gave 29-284 Newton iterations per default 2D solve (the
    2026-11-22 solver); the 18 paper cases take 22-87 now (t1 polyurethane curved 25)."""
    import re

    from tactileskin.fe import solve
    from tactileskin.scene import Scene

    lo, hi = map(int, re.search(r"Speed: a default-quality 2D solve takes [^;]*?(\d+)-(\d+) Newton iterations",
                                _text("docs/architecture.md")).groups())
    r = solve(Scene(thickness=1, material="polyurethane", indenter="curved"))
    assert lo <= r.stats["newton_iterations"] <= hi


def test_hard_cases_p1_note_says_the_scene_is_refused():
    """Solver note 1 said Scene accepts order=1 silently and gave a scene to reproduce the
    locking; that scene is refused now (ParameterError naming order), so the note says so."""
    import pytest

    from tactileskin.errors import ParameterError
    from tactileskin.scene import Scene

    with pytest.raises(ParameterError, match="order"):
        Scene(thickness=1, material="silicone", indenter="flat", order=1, mesh_size=0.354, refinement=3)
    Scene(thickness=1, material="silicone", indenter="flat", order=1, mesh_size=0.354, refinement=3,
          formulation="displacement")
    doc = _text("docs/hard_cases.md")
    assert "*Resolved:* `Scene` refuses `order=1` with the mixed formulation" in doc


def test_commands_doc_dome_sensor_numbers_are_the_dome_coordinates():
    """The README's dome sentence said layouts were not taken; it now gives the sensors' s = x
    against the profile's bone arc length, and the skin's thickness along the surface's normal
    line (a height 0 sensor's depth; it was along a vertical line, 2.015 and 2.159 mm at x = 1
    and 3), which the dome's own coordinates must reproduce: on the axis t, everywhere between
    the least bone-to-surface distance (skins.dome.min_thickness) and t. (The sentence moved
    with the Commands table's long cells to docs/commands.md.)"""
    import numpy as np

    from tactileskin.scene import Scene
    from tactileskin.sensors import sites_for
    from tactileskin.skins.dome import min_thickness

    sec = Scene(skin="dome", thickness=2.0).section()
    s3 = sec.s_of_point([[3.0, (sec.b - 2.0) * np.sqrt(1 - (3.0 / (sec.a - 2.0)) ** 2)]])[0]
    S, Z = np.meshgrid(np.linspace(0.0, 7.9, 30), np.linspace(-10.0, 7.9, 30))
    on = (S / sec.a) ** 2 + (np.maximum(Z, 0.0) / sec.c) ** 2 < 0.999  # over the skin
    lays = [{"name": "x", "s": [0.0, 1.0, 3.0], "z": [0.0], "height": 0.0},
            {"name": "all", "s": S[on].tolist(), "z": Z[on].tolist(), "height": 0.0}]
    st = sites_for(Scene(skin="dome", thickness=2.0, sensors=lays))  # refused where no bone is met
    thick = st.depth[:3]
    least = min_thickness(sec.a, sec.b, sec.c, 2.0)
    readme = _text("docs/commands.md")
    assert f"x = 3 mm is s = {s3:.2f} mm at t = 2" in readme and thick[0] == 2.0
    assert f"({thick[1]:.5f} mm at x = 1, {thick[2]:.5f} at x = 3, t = 2)" in readme
    assert least - 1e-9 <= st.depth.min() and st.depth.max() <= 2.0 + 1e-9
    assert f"the skin is {least:.3f}-2.0 mm thick everywhere at t = 2" in readme


def test_readme_choosing_an_array_runs_and_names_what_the_chart_writes():
    """The README's how-to for choosing an array: its command's options are `tactileskin
    array`'s, and what it tells the reader to look for is what array_chart.md and
    accuracies.csv hold."""
    import re
    import shlex

    from tactileskin.array.chart import Chart, ChartConfig
    from tactileskin.cli.array import command
    from tactileskin.report.array_chart import markdown

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "### Choosing an array" in text
    howto = text.split("### Choosing an array", 1)[1].split("\n### ", 1)[0]
    assert 5 <= len([ln for ln in howto.splitlines() if ln.strip()]) <= 12
    cmd = re.search(r"`(tactileskin array [^`]+)`", howto).group(1)
    args = shlex.split(cmd)[2:]
    ctx = command.make_context("array", list(args))  # an unknown option or a bad value raises
    ChartConfig(thicknesses=(float(ctx.params["thickness"]),), pitches=tuple(
        float(p) for p in ctx.params["pitch"].split(",")), noise_mpa=(float(ctx.params["noise_mpa"]),),
        sets=(ctx.params["sets"],))
    for opt in re.findall(r"`(--[a-z-]+)", howto):
        assert any(opt in p.opts or opt in p.secondary_opts for p in command.params), opt
    ch = Chart(ChartConfig(thicknesses=(2.0,), pitches=(1.0,), noise_mpa=(0.002,), sets=("paper",)))
    ch.labels["paper"] = ["flat", "curved", "braille"]
    ch.rows.append(dict(material="silicone", thickness_mm=2.0, set="paper", pitch_mm=1.0, taxel_mm=0.8,
                        noise_fs=0.02, noise_mpa=0.002, full_scale_mpa=0.1, bits=12, method="template",
                        accuracy=0.97, chance=1 / 3, n_test=16, ci_low=0.9, ci_high=0.99))
    md = markdown(ch)
    # the table (its header gives the taxels), the bold rule, the rule's name, the filter table
    assert "| t (mm) | noise (x full scale) | noise (MPa) | 1 mm (9 x 9) |" in md
    assert "| 2 | 0.02 | 0.002 | **0.97** |" in md and "**bold** at >= 0.95" in md
    assert "template: the nearest of every stimulus's noise-free readings" in md
    assert "### The skin as a spatial filter" in md and "Nyquist pitch (mm)" in md
    assert {"ci_low", "ci_high", "method"} <= set(ch.to_csv().splitlines()[0].split(","))


def _anchors(path: Path):
    """GitHub's heading ids: lower case, punctuation but '-' and '_' dropped, spaces to '-',
    repeats numbered; headings inside code fences are not headings."""
    import re

    seen: dict[str, int] = {}
    fence = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            fence = not fence
        m = None if fence else re.match(r"#{1,6} (.*)", line)
        if m:
            slug = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower()).replace(" ", "-")
            n = seen.get(slug, 0)
            seen[slug] = n + 1
            yield slug if n == 0 else f"{slug}-{n}"


def _links(path: Path):
    """Relative markdown links [text](target) outside code fences and inline code."""
    import re

    fence = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            fence = not fence
            continue
        if not fence:
            for target in re.findall(r"\]\(([^)\s]+)\)", re.sub(r"`[^`]*`", "", line)):
                if not re.match(r"[a-z]+:", target):
                    yield target


def test_every_relative_link_in_readme_and_docs_resolves():
    """The README's Commands table links to sections of docs/commands.md: a renamed heading or
    file would leave a dead link."""
    docs = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    dead, n = [], 0
    for doc in docs:
        for target in _links(doc):
            n += 1
            file, _, anchor = target.partition("#")
            dest = (doc.parent / file).resolve() if file else doc
            if not dest.is_file() or (anchor and anchor not in set(_anchors(dest))):
                dead.append(f"{doc.relative_to(ROOT)}: {target}")
    assert n >= 20 and dead == []


def test_readme_commands_table_is_short_and_links_each_row_to_its_section():
    """The README's Commands table had cells of 1,500-5,600 characters (array, export, the
    file skin...); each row is now one sentence and a link to its section of docs/commands.md,
    where the full text lives."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    table = text[text.index("| command | what it does |"):].split("\n\n")[0]
    rows = [ln for ln in table.splitlines() if ln.startswith("| `tactileskin")]
    assert len(rows) >= 15
    for row in rows:
        what = row.rsplit(" | ", 1)[1]
        assert len(what) <= 300 and "](docs/commands.md#" in what, row
    assert "docs/commands.md" in text[text.index("## Documentation"):text.index("## Development")]


def test_docs_say_a_step_skins_sensors_are_checked_on_its_cad_faces():
    """commands.md and architecture.md said the scene checks a STEP skin's sensors on the
    straight chords of its analysis mesh; since 7834a83 it reads them on the CAD faces (the
    chords only find the faces), and since 1c84faf the solve holds what the scene held."""
    from tactileskin.skins.file import FileCoordinates, _coordinates

    assert "cad" in FileCoordinates.__init__.__code__.co_varnames
    assert "cad=" in __import__("inspect").getsource(_coordinates)
    for name in ("docs/commands.md", "docs/architecture.md"):
        doc = _text(name)
        assert "(a STEP's: the straight chords of a size/8 mesh, within their sag" not in doc, name
        assert "(a STEP's: chords of its size / 8 mesh, 0.006-0.039 mm under an R 6 cap)" not in doc, name
        assert "on its CAD faces" in doc, name


def _commands_section(start: str, end: str) -> str:
    text = _text("docs/commands.md")
    return text[text.index(start):text.index(end)]


def test_commands_doc_names_every_file_a_solve_writes():
    """The solve section listed profile.csv, summary.json and result.vtu, not the contact.csv
    every solve writes, nor the section_2d/ folder of --compare-2d."""
    from tactileskin.cli.solve import _will_write
    from tactileskin.scene import Scene

    doc = _commands_section("## solve", "### Sensors inside the skin")
    names = {*_will_write(Scene(thickness=3, indenter="curved"), True, False),
             *_will_write(Scene(thickness=1, indenter="braille", braille_text="a", dim=3), False, True)}
    assert {"contact.csv", "section_2d/profile.csv", "bone_map.png", "result.pvd"} <= names
    for name in names:
        assert f"`{name.split('/')[0]}" in doc or f"/{name.split('/')[0]}/`" in doc, name


def _toml_blocks(section: str) -> list[str]:
    """The ```toml blocks of a docs/commands.md section (fences may be indented in a list)."""
    import re
    import textwrap

    text = (ROOT / "docs/commands.md").read_text(encoding="utf-8")
    part = text[text.index(section):]
    part = part[:part.index("\n### ", 1)]
    return [textwrap.dedent(b) for b in re.findall(r"```toml\n(.*?)\n *```", part, flags=re.S)]


def test_commands_doc_sensor_and_loading_examples_are_valid_files(tmp_path):
    """The sensors and the loading-history sections named the TOML keys but showed no file, and
    the natural guess at a history, a first [[loading]] segment pressing to the depth, is
    refused (the first ramp is the scene's depth): each section now shows a file that loads."""
    import tomllib

    from tactileskin import scenefile
    from tactileskin.scene import Scene

    (sensors,) = _toml_blocks("### Sensors inside the skin")
    scene = Scene(thickness=3, indenter="curved", sensors=tomllib.loads(sensors)["sensors"])
    assert [lay.name for lay in scene.sensors] == ["bone", "mid"]
    (history,) = _toml_blocks("### Force control and loading histories")
    (tmp_path / "hold.toml").write_text(history)
    sc = Scene.from_dict(scenefile.single_scene_fields(scenefile.read(tmp_path / "hold.toml")))
    assert [g.to_dict() for g in sc.program()] == [{"depth": 0.4, "rate": 1.0}, {"hold": 10.0},
                                                   {"depth": 0.0, "rate": 1.0}]  # indent, hold, release


def test_commands_doc_film_and_fit_inputs_are_what_the_commands_read(tmp_path):
    """The film section's command line was 'tactileskin film calibrate / analyze / compare'
    (no input, option or output named) and the uniaxial fit did not name its CSV columns: the
    doc's lines parse as the commands', and the columns and files it names are theirs."""
    import re
    import shlex

    from tactileskin.cli import film
    from tactileskin.materials.fit import read_uniaxial_csv

    text = (ROOT / "docs/commands.md").read_text(encoding="utf-8")
    sec = text[text.index("\n## film"):text.index("\n## material")]
    lines = re.search(r"```bash\n(.*?)\n```", sec, flags=re.S).group(1).splitlines()
    assert [shlex.split(ln)[:3] for ln in lines] == [["tactileskin", "film", c] for c in ("calibrate", "analyze", "compare")]
    for ln in lines:
        args = shlex.split(ln)
        film.command.commands[args[2]].make_context(args[2], args[3:])  # an unknown option raises
    doc = " ".join(sec.split())
    helps = " ".join(" ".join(p.help.split()) for c in film.command.commands.values() for p in c.params
                     if getattr(p, "help", None))
    for name in ("profile.csv", "summary.json", "pressure_map.png", "comparison.json", "overlay.png"):
        assert f"`{name}`" in doc and name in helps, name
    calib = " ".join(film.calibrate.help.split())
    for col in ("force_n", "area_mm2", "gray", "image"):
        assert f"`{col}`" in doc and col in calib, col
    fit = _commands_section("### Fitting a law to a uniaxial test", "### Fitting the shear modulus")
    for stretch in ("stretch", "strain"):
        assert f"`{stretch}`" in fit and "`nominal_stress_mpa`" in fit
        (tmp_path / "t.csv").write_text(f"{stretch},nominal_stress_mpa\n1.2,0.05\n0.9,-0.03\n")
        lam, p = read_uniaxial_csv(tmp_path / "t.csv")
        assert list(p) == [0.05, -0.03] and lam[1] == (0.9 if stretch == "stretch" else 1.9)


def test_commands_doc_3d_braille_case_times_cover_the_paper_sweeps():
    """commands.md gave 4-50 s per 3D Braille case of a sweep while `sweep --help` said 4-60 s
    and the paper sweep's measured 3D cases took 12-60 s (t5 silicone 60.1 s)."""
    import re

    from tactileskin.cli.sweep import command

    bench = (ROOT / "benchmarks/results/paper_sweep_3d.md").read_text(encoding="utf-8")
    times = [float(t) for t in re.findall(r"done t[\d.]+-\w+-braille-3d \(([\d.]+) s\)", bench)]
    assert len(times) == 6
    help_ = " ".join(next(p for p in command.params if p.name == "braille_dim").help.split())
    lo, hi = map(int, re.search(r"3D solves take (\d+)-(\d+) s each", help_).groups())
    assert f"as 3D dots ({lo}-{hi} s per case)" in _text("docs/commands.md")
    assert lo <= min(times) and max(times) < hi + 0.5, times  # whole seconds: 60.1 s is "60"


def test_readme_contact_force_sum_under_the_ridge_is_what_result_vtu_integrates(tmp_path):
    """The README said the sum of contact_pressure_MPa over the facets is '7 % above the
    vertical reaction' under a Braille dot without naming the model: the 3D dot (t = 1 mm
    silicone, preview) reads 7.1 %, the 2D ridge of the same case 4.1 %."""
    import json

    import meshio
    import numpy as np

    from tactileskin.fe import solve
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    solve(with_quality(Scene(thickness=1, material="silicone", indenter="braille"), "preview")).write(tmp_path)
    m = meshio.read(tmp_path / "result.vtu")
    lines = m.cells_dict["line"]
    length = np.linalg.norm(m.points[lines[:, 1]] - m.points[lines[:, 0]], axis=1)
    summed = float((m.cell_data_dict["contact_pressure_MPa"]["line"] * length).sum())  # Integrate Variables
    reaction = json.loads((tmp_path / "summary.json").read_text())["reaction_n_per_mm"]
    pct = 100 * (summed / reaction - 1)
    assert pct > 1  # tilted normals: the facets' sum exceeds the vertical reaction
    assert f"7 % on the 3D dot, {pct:.0f} % on the 2D ridge, t = 1 mm silicone at `preview`" in _text("README.md")


def test_readme_defines_the_metrics_before_using_them():
    """The README used peak, span and AUC from its Quick start on (the report, r.span, the
    figures) and defined them only in docs/metrics.md; it now says what they are, with the
    span's threshold that results.span uses."""
    import inspect

    from tactileskin.results import span

    frac = inspect.signature(span).parameters["fraction"].default
    readme = _text("README.md")
    define = readme.index("**span** (the extent of s where P >= ")
    assert f"**span** (the extent of s where P >= {100 * frac:.0f} % of the peak)" in readme
    assert define < readme.index("r.peak, r.span, r.auc") and define < readme.index("## Commands")
    assert "**peak** (its maximum)" in readme and "**AUC** (the area under P(s), MPa·mm)" in readme


def test_readme_says_where_the_tactileskin_command_is_before_using_it():
    """The Quick start sets up .venv through ./dev, and the Commands table then types a bare
    `tactileskin`, which a fresh shell does not find ('command not found'): the section says
    to activate the environment ./dev builds, where ./dev's own run finds the command."""
    dev = (ROOT / "dev").read_text(encoding="utf-8")
    assert "VENV=.venv" in dev and 'exec "$VENV/bin/tactileskin"' in dev
    readme = _text("README.md")
    commands = readme[readme.index("## Commands"):readme.index("| command | what it does |")]
    assert "`source .venv/bin/activate`" in commands and "`./dev run solve ...`" in commands


def test_output_folders_doc_names_every_hidden_file_a_run_leaves(tmp_path):
    """A solve folder holds four hidden files; the Output folders section named three, not
    the .tactileskin-run.lock every run leaves, which a user listing the folder finds."""
    from tactileskin.cli import main

    out = tmp_path / "o"
    assert main(["solve", "-t", "1", "--quality", "preview", "--elastic", "--out", str(out)]) == 0
    hidden = sorted(p.name for p in out.iterdir() if p.name.startswith("."))
    assert len(hidden) == 4, hidden
    section = _commands_section("## Output folders", "## Exit status")
    for name in hidden:
        assert f"`{name}`" in section, name


def test_pardiso_ordering_summary_states_its_table():
    """benchmarks/results/pardiso_ordering.md summed its per-matrix table up as 'analysis
    40-50 % less' where the rows give 37-47 % (t1 flat default 3.00 / 4.78 ms: 37 %)."""
    text = (ROOT / "benchmarks/results/pardiso_ordering.md").read_text(encoding="utf-8")
    rows = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip("|").split("|")]
        if len(cells) == 10 and cells[4] in ("amd", "metis"):
            rows[(cells[0], cells[1], cells[4])] = (float(cells[5]), float(cells[6]), float(cells[7]))
    cases = {(c, q) for c, q, _ in rows}
    assert len(cases) == 5

    def less(i):
        d = [100 * (1 - rows[(c, q, "amd")][i] / rows[(c, q, "metis")][i]) for c, q in cases]
        return f"{round(min(d))}-{round(max(d))} %"

    summary = " ".join(text[text.index("AMD: "):].split())
    assert summary.startswith(f"AMD: {less(2)} fewer factor nonzeros, factorisation + solve {less(1)} less CPU, "
                              f"analysis {less(0)} less"), summary[:140]
