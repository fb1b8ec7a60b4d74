"""`tactileskin array`: the sensor-array design chart (accuracy over thickness x pitch x noise)."""

from __future__ import annotations

from pathlib import Path

import click

from tactileskin import validate as validate_mod  # `validate` is also an option's name
from tactileskin.cli._choice import Choice
from tactileskin.cli._common import claimed_output
from tactileskin.errors import ParameterError

EXIT_SUSPECT = 3  # the chart was written but a part of it is suspect (as `solve` and `sweep`)
KEYS = {"thicknesses", "materials", "pitches", "noise_fs", "noise_mpa", "taxel_fraction", "bits", "window", "sets",
        "letters", "n_train", "n_test", "template_grid", "seed", "mesh_size", "refinement", "standard",
        "validate", "skin", "max_depth", "letters_model", "fallback", "sphere_radius", "sphere_quality",
        "sensor_depth", "sensor_height"}
MAX_TEXTS = 100  # Braille texts to validate: each is a full 3D solve per thickness


# list-valued keys: a single value is a one-element list, and a string of names is split at
# commas as the matching CLI option (--set paper,letters) is; a string of numbers is refused
# by ChartConfig (TOML has numbers: "1,3" there is a mistake)
NAME_LISTS = {"materials", "sets", "validate"}
NUMBER_LISTS = {"thicknesses", "pitches", "noise_fs", "noise_mpa"}


def load_config(path) -> dict:
    """The [array] table of a TOML file; an unreadable, non-UTF-8 or malformed file and unknown
    keys raise ParameterError naming them."""
    from tactileskin.params import read_toml
    from tactileskin.scenefile import resolve_paths

    data = read_toml(path, "config")
    outside = sorted(set(data) - {"array"})
    if outside:  # read as nothing, they would start the whole default chart (hours)
        raise ParameterError("config", f"{path}: key {outside[0]!r} outside the [array] table",
                             "every setting under [array]", "e.g. [array] then thicknesses = [1, 3]")
    table = data.get("array", {})
    if not isinstance(table, dict):
        raise ParameterError("config [array]", table, "a table of settings, e.g. [array] then thicknesses = [1, 3]")
    validate_mod.known_keys(table, KEYS, "config [array]")
    if not table:  # surely a mistake: it would start the whole default chart (36 full 3D solves, hours)
        raise ParameterError("config", str(path), "a TOML file with at least one setting in its [array] table",
                             "it sets nothing; leave out --config for the default chart")
    out = {}
    for k, v in table.items():
        if k in NAME_LISTS and isinstance(v, str):
            v = [x.strip() for x in v.split(",") if x.strip()]
        elif k in NUMBER_LISTS and validate_mod.is_number(v):
            v = [v]
        out[k] = tuple(v) if isinstance(v, list) else v
    if "validate" in out:
        out["validate"] = validate_mod.string_list(out["validate"], "validate", MAX_TEXTS, min_len=1)
    return resolve_paths(out, path)


@click.command("array")
@click.option("--out", "-o", "out", type=click.Path(file_okay=False), default="out_array", show_default=True,
              help="Output folder: accuracies.csv, array_chart.md, figures (new, empty or written by `array`).")
@click.option("--config", type=click.Path(dir_okay=False), default=None, help="TOML with an [array] table; flags override it.")
@click.option("--thickness", "-t", default=None, help="Thicknesses (mm), e.g. '1,3'. Default 1,3.")
@click.option("--material", "-m", default=None, help="Materials, comma-separated. Default silicone.")
@click.option("--pitch", default=None, help="Array pitches (mm): taxel centre to centre, a square lattice on the "
              "bonded surface (or at --sensor-depth / --sensor-height) over an 8 mm window. Default 0.5,0.75,1,1.5,2,4.")
@click.option("--noise", default=None, help="Noise std as fractions of full scale: each set's largest pressure at that "
              "thickness, so one fraction is a different noise in MPa at each thickness (array_chart.md gives it). "
              "In [0, 1] (0.05 is 5 %). Default 0.01,0.05,0.1.")
@click.option("--noise-mpa", default=None, help="Noise std in MPa instead of --noise, the same at every thickness "
              "and set (a real sensor's noise floor), e.g. '0.001,0.005'.")
@click.option("--taxel", type=float, default=None, help="Taxel side as a fraction of the pitch (0 = point). Default 0.8.")
@click.option("--bits", type=int, default=None, help="ADC bits over full scale. Default 12.")
@click.option("--set", "sets", default=None, help="Stimulus sets: paper (flat/curved/dot), letters (a-z, 0-9), shapes (the paper's three and a "
                   "sphere). Default all three.")
@click.option("--letters", default=None, help="Characters of the letters set: a-z and 0-9 (a digit reads as the number sign and "
                   "its a-j cell). Default all 36.")
@click.option("--offsets", type=int, default=None, help="Random offsets per stimulus (train and test each). Default 16.")
@click.option("--mesh-size", type=float, default=None, help="3D single-dot mesh size (mm), at every thickness. Default: the 3D Braille default preset below t = 3 mm (0.8), 1.2 from it.")
@click.option("--refinement", type=float, default=None, help="3D single-dot refinement ratio. Default 8.")
@click.option("--max-depth", type=float, default=None,
              help="Depth cap (mm) for thick skins: a t whose 20 % depth exceeds it is indented by this "
                   "instead (below the dot height 0.48 mm the Braille plate never touches). Default none.")
@click.option("--sphere-radius", type=float, default=None, help="Radius (mm) of the shapes set's sphere. Default 2.5.")
@click.option("--sphere-quality", type=Choice(["preview", "default", "fine"]), default=None,
              help="3D mesh preset of the sphere solves. Default preview.")
@click.option("--sensor-depth", type=float, default=None,
              help="Taxels at this depth (mm) below the contact surface, inside every skin of the chart "
                   "(0 < depth < the thinnest t), read from the cached solves (no solve again). Default: the "
                   "bonded surface (the paper's film on the bone).")
@click.option("--sensor-height", type=float, default=None,
              help="Taxels at this height (mm) above the bonded surface, the same in every skin of the chart "
                   "(a sensor sheet on a stand-off, the skin cast over it; 0 < height < the thinnest t; read at "
                   "the depth t - height), not with --sensor-depth. Default: the bonded surface.")
@click.option("--seed", type=int, default=None, help="Random seed. Default 0.")
@click.option("--skin", type=Choice(["pad", "fingertip"]), default=None,
              help="Skin of the 3D dot solves: pad (flat, a dot's response translates exactly; default) or "
                   "fingertip (the paper's; validation refuses x-asymmetric texts, solved mirrored there).")
@click.option("--validate", default=None,
              help="Braille texts to solve in full and compare with the superposition, e.g. '⠿,l,c'.")
@click.option("--letters-model", type=Choice(["interaction", "sum", "full"]), default=None,
              help="Letters from superposed single-dot solves, each dot's load from the lone dot's surface "
                   "deflection and load-approach law (interaction, default; a second lone-dot solve at 0.9 x "
                   "the depth; on the pad below the dot height; past it the blank plate plus plate-aware dots; "
                   "on the fingertip sum) or as lone "
                   "dots (sum): their measured errors are in the report; or a full 3D solve of every letter "
                   "(full: one solve per letter and thickness).")
@click.option("--fallback/--no-fallback", default=None,
              help="Where the letters' surrogate is measured past 5 % of full solves (this run's --validate "
                   "rows together with the project's measurements, the worse), solve that thickness's letters in full (default), or "
                   "keep the surrogate and mark those letters indicative.")
@click.option("--workers", type=click.IntRange(min=1), default=None,
              help="Processes solving uncached cases at once (each single-threaded). Default: one per core.")
@click.option("--cache", "cache_dir", type=click.Path(file_okay=False), default=None,
              help="Result cache folder (default OUT/cache; share the sweep's to reuse its solves).")
def command(out, config, thickness, material, pitch, noise, noise_mpa, taxel, bits, sets, letters, offsets, mesh_size,
            refinement, max_depth, sphere_radius, sphere_quality, sensor_depth, sensor_height, seed, skin, validate, letters_model, fallback,
            workers, cache_dir):
    """Accuracy of an array under the skin at telling stimuli apart; cached, rerun is fast.

    Exit status 0, or 3 when the chart was written but a part of it is suspect (the letters'
    surrogate not shown within 5 % of full solves at some thickness, or the plate touching):
    the report lists them."""
    from rich.markup import escape

    from tactileskin.array.chart import ChartConfig, compute, validate_surrogate
    from tactileskin.cache import ResultCache, open_cache, out_cache
    from tactileskin.cli._console import new_console
    from tactileskin.report.array_chart import suspect, write_outputs
    from tactileskin.sweep import parse_values

    console = new_console(stderr=True)
    kw = load_config(config) if config else {}
    texts = kw.pop("validate", None)
    names = lambda v, n: tuple(x.strip() for x in v.split(",") if x.strip())  # noqa: E731
    if noise is not None and noise_mpa is not None:
        raise ParameterError("noise_mpa (--noise-mpa)", noise_mpa, "not with --noise: the noise is either in MPa "
                             "or x full scale")
    if noise is not None or noise_mpa is not None:  # a flag's noise axis replaces the config's
        kw.pop("noise_fs", None)
        kw.pop("noise_mpa", None)
    if sensor_depth is not None or sensor_height is not None:  # likewise a flag's sensor plane
        kw.pop("sensor_depth", None)
        kw.pop("sensor_height", None)
    flags = dict(thicknesses=thickness and tuple(parse_values(thickness, "thickness")),
                 materials=material and names(material, "material"),
                 pitches=pitch and tuple(parse_values(pitch, "pitch")),
                 noise_fs=noise and tuple(parse_values(noise, "noise")),
                 noise_mpa=noise_mpa and tuple(parse_values(noise_mpa, "noise_mpa (--noise-mpa)")),
                 taxel_fraction=taxel, bits=bits, sets=sets and names(sets, "set"), letters=letters,
                 n_train=offsets, n_test=offsets, mesh_size=mesh_size, refinement=refinement, seed=seed, skin=skin,
                 max_depth=max_depth, letters_model=letters_model, fallback=fallback, sphere_radius=sphere_radius,
                 sphere_quality=sphere_quality, sensor_depth=sensor_depth, sensor_height=sensor_height)
    kw.update({k: v for k, v in flags.items() if v is not None})
    if validate is not None:  # the config key's rule (at most MAX_TEXTS full solves per thickness)
        texts = validate_mod.string_list(names(validate, "validate"), "validate (--validate)", MAX_TEXTS,
                                         min_len=1)
    if texts:  # a repeated text wrote its rows twice: refused, as a chart axis's repeats are
        repeated = next((x for i, x in enumerate(texts) if x in texts[:i]), None)
        if repeated is not None:
            raise ParameterError("validate (--validate)", ",".join(texts), "distinct texts",
                                 f"{repeated!r} is listed twice")
    try:
        cfg = ChartConfig(**kw)
    except TypeError as e:
        raise ParameterError("config", str(e), "keys " + ", ".join(sorted(KEYS))) from None
    from tactileskin.sweep import check_materials

    check_materials(cfg.materials)
    out = Path(out)
    cache = open_cache(cache_dir) if cache_dir else ResultCache(out_cache(out))
    say = lambda msg: console.print(escape(msg), highlight=False)  # noqa: E731
    with claimed_output(out, "array"):
        rows = None
        if texts:  # first: this run's measurements decide where the letters fall back to full solves
            rows = [r for m in cfg.materials
                    for r in validate_surrogate(cfg.thicknesses, m, list(texts), cfg, cache, progress=say,
                                                    workers=workers)]
        chart = compute(cfg, cache, progress=say, workers=workers, validation=rows)
        paths = write_outputs(chart, out, rows)
    console.print(f"report: {escape(str(paths['report']))} ({chart.seconds:.0f} s)", highlight=False)
    notes = suspect(chart, rows)
    for n in notes:
        console.print(f"suspect: {escape(n)}", highlight=False)
    return EXIT_SUSPECT if notes else 0
