"""Figures and report section of the sensor-array design chart (array.chart)."""

from __future__ import annotations

import math

from pathlib import Path

import numpy as np

from tactileskin.array.chart import GOOD, PAPER_PITCH, accuracy_text, verdicts
from tactileskin.fileio import atomic_write_text
from tactileskin.report.figures import _fit_width, _plt, _save

SET_TITLES = {"paper": "flat / curved / Braille dot", "letters": "Braille characters {chars}",
              "shapes": "flat / curved / Braille dot / sphere R{r:g}"}


def set_title(set_: str, cfg) -> str:
    from tactileskin.array.config import DIGITS, LETTERS

    have = set(cfg.letters)
    chars = {frozenset(LETTERS + DIGITS): "a-z, 0-9", frozenset(LETTERS): "a-z", frozenset(DIGITS): "0-9"}.get(
        frozenset(have), cfg.letters)
    return SET_TITLES[set_].format(r=cfg.sphere_radius, chars=chars)


def write_figures(chart, out: Path, method: str = "template", indicative: dict | None = None,
                  notes: list | None = None) -> list[Path]:
    """One figure per material and stimulus set: accuracy over thickness (rows) x pitch
    (columns), a panel per noise level; the paper's 0.75 mm pitch dashed, the paper's
    "5 mm cannot" row hatched; PNG and SVG. `indicative` {(material, t): why}: those letters
    rows are marked † (as in the report's tables); `notes` (report.suspect): the title says
    the chart has suspect parts (the figures were titled as a clean chart)."""
    indicative = indicative or {}
    plt = _plt()
    cfg = chart.config
    paths = []
    ts, ps = list(cfg.thicknesses), list(cfg.pitches)
    for material in cfg.materials:
        for set_ in cfg.sets:
            levels = cfg.noise_levels
            fig, axes = plt.subplots(1, len(levels), figsize=(3.6 * len(levels) + 1.0, 0.55 * len(ts) + 2.0),
                                     squeeze=False, constrained_layout=True)
            for ax, noise in zip(axes[0], levels):
                A = np.array([[chart.accuracy(material, t, set_, p, noise, method) for p in ps] for t in ts])
                im = ax.imshow(A, vmin=0, vmax=1, cmap="viridis", aspect="auto", origin="lower")
                for i in range(len(ts)):
                    for j in range(len(ps)):
                        ax.text(j, i, accuracy_text(A[i, j]), ha="center", va="center", fontsize=7,
                                color="white" if A[i, j] < 0.6 else "black")
                ax.set_xticks(range(len(ps)), [f"{p:g}" for p in ps])
                ax.set_yticks(range(len(ts)), [f"{t:g}" + (" †" if set_ == "letters" and (material, t) in indicative
                                                          else "") for t in ts])
                ax.set_xlabel("pitch (mm)")
                ax.set_ylabel("skin thickness t (mm)")
                ax.set_title(f"noise {noise:g} {cfg.noise_unit}", fontsize=9)
                if PAPER_PITCH in ps:
                    ax.axvline(ps.index(PAPER_PITCH), color="tab:red", ls="--", lw=1.2, label="paper: 0.75 mm")
                if 5.0 in ts and set_ == "paper":
                    i = ts.index(5.0)
                    ax.add_patch(plt.Rectangle((-0.5, i - 0.5), len(ps), 1, fill=False, hatch="//",
                                               edgecolor="tab:red", lw=0.0, label="paper: 5 mm cannot"))
            if axes[0][0].get_legend_handles_labels()[0]:  # the paper's marks, where on the grid
                axes[0][0].legend(loc="upper right", fontsize=7, framealpha=0.8)
            fig.colorbar(im, ax=axes[0].tolist(), label=f"accuracy ({method})", shrink=0.9)
            title = f"{material}: {set_title(set_, cfg)} (chance {1 / len(chart.labels[set_]):.2f})"
            if set_ == "letters" and any(k[0] == material for k in indicative):
                title += "\n† indicative: the letters' surrogate not shown within its tolerance (array_chart.md)"
            if notes:
                title += f"\nSUSPECT parts of the chart: {len(notes)} note{'s' if len(notes) > 1 else ''} in array_chart.md"
            fig.suptitle(title, fontsize=10)
            _fit_width(fig)  # a one-thickness, one-noise chart (4.6 in) cut its † and SUSPECT lines
            paths += _save(fig, out, f"array_{material}_{set_}")
    return paths


def _meshes(cfg) -> str:
    """The single dots' mesh sizes / refinement, per thickness where they differ."""
    by = {}
    for t in cfg.thicknesses:
        by.setdefault(cfg.mesh_for(t), []).append(t)
    if len(by) == 1:
        return "{:g} / {:g}".format(*next(iter(by)))
    return ", ".join(f"{m[0]:g} / {m[1]:g} at t = {', '.join(f'{t:g}' for t in ts)} mm" for m, ts in by.items())


def _skins(cfg) -> str:
    """Which skin each of the chart's sets is on: a letters-only chart read 'letters on the pad,
    the paper and shapes sets on the fingertip' (sets it had not computed)."""
    out = [f"letters on the {cfg.skin}"] if "letters" in cfg.sets else []
    others = [s for s in ("paper", "shapes") if s in cfg.sets]
    if others:
        out.append(f"the {' and '.join(others)} set{'s' if len(others) > 1 else ''} on the fingertip")
    return ", ".join(out)


def _sensor_plane(cfg) -> str:
    """Where the taxels sit (ChartConfig.sensor_depth or sensor_height)."""
    if _on_bone(cfg):
        return "the bonded surface, t below the contact surface (the paper's film on the bone)"
    where = (f"{cfg.sensor_depth:g} mm below the contact surface (`--sensor-depth`; t - {cfg.sensor_depth:g} mm above "
             "the bone" if cfg.sensor_height is None else f"{cfg.sensor_height:g} mm above the bonded surface "
             f"(`--sensor-height`; t - {cfg.sensor_height:g} mm below the contact surface")
    return (where + ", in the undeformed skin), P = -tr(sigma) / 3 read there from each cached solve's result.vtu "
            "along the skin's normal, s the arc length on that surface")


def _on_bone(cfg) -> bool:
    """The taxels on the bonded surface (neither a sensor depth nor a height)."""
    return cfg.sensor_depth is None and cfg.sensor_height is None


def _pad_text(cfg) -> str:
    """Where the letters' Braille plate touches the pad, the maps are the pad's size's: a bonded,
    nearly incompressible layer pressed over its whole top is stiffer the wider it is, and no
    pad converges to a larger skin's (benchmarks/results/blank_pad_length.md)."""
    if "letters" not in cfg.sets or cfg.skin != "pad":
        return ""
    from tactileskin.geometry.braille import get_standard
    from tactileskin.scene import Scene
    from tactileskin.skins.pad import DEFAULT_LENGTH, DEFAULT_WIDTH

    h = get_standard(cfg.standard).height
    depths = {t: cfg.depth_for(t) for t in cfg.thicknesses}  # None: the scene's 20 % of t
    past = [t for t, d in depths.items() if (Scene.depth_fraction * t if d is None else d) > h + 1e-12]
    if not past:
        return ""
    ts = ", ".join(f"{t:g}" for t in past)
    return (f" At t = {ts} mm the Braille plate presses the whole {DEFAULT_WIDTH:g} x {DEFAULT_LENGTH:g} mm pad: "
            "those maps hold for this pad's size only (a bonded skin pressed over its whole top is stiffer the "
            "wider it is: a 40 x 40 mm pad's mean plate pressure is 2.0-2.5x this one's at t = 3 and 5 mm; "
            "benchmarks/results/blank_pad_length.md).")


def _cap_text(cfg) -> str:
    """The depth cap's sentence: it keeps the Braille plate off only below the dot height (a
    cap of 0.55 mm read 'below the dot height, so the plate never touches' while the notes
    said the plate touched)."""
    if not cfg.max_depth:
        return ""
    from tactileskin.geometry.braille import get_standard

    h = get_standard(cfg.standard).height
    if cfg.max_depth <= h:
        return (f", capped at {cfg.max_depth:g} mm (ChartConfig.max_depth: not past the dot height {h:g} mm, so "
                "the Braille plate never touches)")
    return (f", capped at {cfg.max_depth:g} mm (ChartConfig.max_depth: past the dot height {h:g} mm, so the "
            "Braille plate touches where the depth exceeds it)")


def markdown(chart, validation=None, method: str = "template") -> str:
    """The report section: conditions, the skin as a filter, accuracy tables, verdicts, and the
    surrogate's validation."""
    cfg = chart.config
    trust = letters_trust(chart, validation) if "letters" in cfg.sets else {}
    notes = suspect(chart, validation, trust)
    measured = list(getattr(chart, "measured", None) or [])  # flags a measured error covers (chart.blank_note)
    lines = ["## Sensor-array design chart", "", *(["**Suspect:** " + n for n in notes] + [""] if notes else []),
             *(["**Measured:** " + n for n in measured] + [""] if measured else []),
             f"Skin: {_skins(cfg)}. Sensor plane: " + _sensor_plane(cfg) + ", map P(s, z) of 3D single-dot solves "
             f"(mesh {_meshes(cfg)})" + ("; flat and curved: 2D " + ("bone profiles" if _on_bone(cfg) else "profiles at that depth")
                                            + " extruded along z"
                                         if {"paper", "shapes"} & set(cfg.sets) else "")
             + (f"; sphere (R {cfg.sphere_radius:g} mm): 3D at the `{cfg.sphere_quality}` preset" if "shapes" in cfg.sets else "")
             + f". Array: square taxels of {cfg.taxel_fraction:g} x pitch (area averaged) over a "
             f"{cfg.window:g} mm window, {cfg.bits} bits over each set's full scale, Gaussian noise "
             + ("as a fraction of full scale" if cfg.noise_mpa is None else "of a fixed std in MPa (--noise-mpa)")
             + f"; stimuli at random sub-pitch offsets ({cfg.n_test} test and "
             f"{cfg.n_train} training reads per stimulus); rules: " + _rules(cfg, method) + ". "
             f"Computed in {chart.seconds:.0f} s.", "",
             "### The skin as a spatial filter", "",
             "| material | t (mm) | indentation (mm) | skin | single-dot peak (MPa) | measured cut-off (rad/mm) | Nyquist pitch (mm) | half-space Nyquist pitch at depth "
             + ("t" if _on_bone(cfg) else f"{cfg.sensor_depth:g} mm" if cfg.sensor_height is None
                else f"t - {cfg.sensor_height:g} mm") + " (mm) |",
             "|---|---|---|---|---|---|---|---|"]
    for c in chart.cutoffs:
        kc, ny = c["kc_rad_per_mm"], c["nyquist_pitch_mm"]
        # not measurable: a spectrum that never falls to 10 % (inf) or a response without a mean (nan)
        kc_s = f"{kc:.2f}" if math.isfinite(kc) else ("n/a (spectrum stays above 10 %)" if kc == math.inf
                                                      else "n/a (not measurable)")
        ny_s = f"{ny:.2f}" if math.isfinite(ny) else "n/a"
        lines.append(f"| {c['material']} | {c['thickness_mm']:g} | {c.get('depth_mm', float('nan')):.3g} | {c.get('skin', 'fingertip')} | "
                     f"{c['peak_mpa']:.4f} | {kc_s} | {ny_s} | {c['halfspace_nyquist_pitch_mm']:.2f} |")
    lines += ["", "Cut-off where the spectrum of the single dot's map along s (its projection over z: the "
              "map's 2D spectrum along k_s; or of the half-space kernel (1 + kt) e^-kt) falls to 10 %; Nyquist pitch pi / k_c: the coarsest pitch that samples the map without aliasing, not a limit on telling known stimuli apart (the accuracy tables below say that). The paper's rule (half the 1.5 mm span of the Braille pressure at t = 1) gives 0.75 mm at t = 1. "
              "Indentation (each stimulus's travel into the skin from first touch: depth control, not force): 20 % of t"
              + _cap_text(cfg) + "." + _pad_text(cfg), ""]
    for set_ in cfg.sets:
        for material in cfg.materials:
            # the noise also in MPa and the taxels a pitch takes: a header "noise" with fractions
            # of a full scale the report never gave (it differs per thickness: 0.042 MPa at t = 1,
            # 0.032 at t = 2 for the letters) and pitches without their channel count
            lines += [f"### {material}: {set_title(set_, cfg)} (chance {1 / len(chart.labels[set_]):.2f})", "",
                      "| t (mm) | noise (x full scale) | noise (MPa) | "
                      + " | ".join(f"{p:g} mm ({cfg.spec(p).n} x {cfg.spec(p).n})" for p in cfg.pitches) + " |",
                      "|---|---|---|" + "---|" * len(cfg.pitches)]
            for t in cfg.thicknesses:
                mark = " †" if set_ == "letters" and trust[(material, t)]["status"] not in TRUSTED else ""
                for n in cfg.noise_levels:
                    lines.append(f"| {t:g}{mark} | {_noise_cells(chart, material, t, set_, n)} | " + " | ".join(
                        _cell(chart.accuracy(material, t, set_, p, n, method)) for p in cfg.pitches) + " |")
            lines.append("")
    if chart.rows:
        lines += [f"Accuracy ({method}): the fraction of test readings told right; **bold** at >= {GOOD:g}. Columns: the "
                  f"array pitch (taxel centre to centre, mm) and its taxels (n x n: n = floor({cfg.window:g} / pitch) + 1 "
                  f"over the {cfg.window:g} mm window), each taxel a square of {cfg.taxel_fraction:g} x the pitch "
                  "averaging the pressure on the sensor plane over it. Noise: Gaussian, its std "
                  + ("as a fraction of the set's full scale (its largest pressure at that thickness; `full_scale_mpa` in "
                     "accuracies.csv) and in MPa. " if cfg.noise_mpa is None else
                     "fixed in MPa (`--noise-mpa`: the same at every thickness and set) and as the fraction of the set's "
                     "full scale it is (its largest pressure at that thickness; `full_scale_mpa` in accuracies.csv). ")
                  + 
                  # the readings share one draw of offsets: at a coarse pitch the draw moves the
                  # accuracy by 4-5x the binomial std over the readings (docs/commands.md: seeds 0-5 at 2.5 mm)
                  f"Each accuracy is one draw of {cfg.n_test} random offsets, shared by all stimuli and noise levels: "
                  "where the offset matters (a pitch near the dots' 2.5 mm spacing) another draw moves it more than "
                  "a binomial 95 % interval over the readings says, so accuracies.csv's `ci_low` / `ci_high` (and the "
                  "verdicts' \"borderline\") take the wider of that and a t-interval over the offsets' own "
                  f"accuracies; before choosing on a cell near {GOOD:g} rerun it with another `--seed` and more "
                  "`--offsets`.", ""]
    if "letters" in cfg.sets:
        lines += _trust_section(chart, trust)
    lines += ["### The paper's design claims", "", "| material | claim | verdict | evidence |", "|---|---|---|---|"]
    for v in verdicts(chart, method):
        m = trust.get((v["material"], 1.0))
        if v["claim"].startswith("0.75") and v["verdict"] != "not evaluated" and m and m["status"] not in TRUSTED:
            v = {**v, "verdict": v["verdict"] + " (indicative: the letters' surrogate is "
                 + ("not validated" if m["error"] is None else f"off by {m['error']:.1%}") + " at t = 1 mm)"}
        lines.append(f"| {v['material']} | {v['claim']} | {v['verdict']} | {v['evidence']} |")
    lines += ["", f"(a set counts as discriminated at accuracy >= {GOOD:g}, at the lowest noise level)", ""]
    if validation:
        lines += validation_table(validation, "### Surrogate validation (superposition of single-dot responses against full 3D solves)")
    return "\n".join(lines)


TRUSTED = ("within", "full")  # letters statuses that need no mark: the surrogate within tolerance, or none


def letters_trust(chart, validation=None) -> dict:
    """{(material, t): array.validity.measured(...)} for the letters set's dot scenes."""
    from tactileskin.array.chart import surrogate_trust

    cfg, out = chart.config, {}
    fallbacks = getattr(chart, "fallbacks", {})
    for material in cfg.materials:
        for t in cfg.thicknesses:
            model = getattr(chart, "letters_models", {}).get((material, t), cfg.letters_model)
            if model == "full":
                why = fallbacks.get((material, t))
                src = "full 3D solves of every letter (no surrogate)" if why is None else (
                    f"full 3D solves of every letter: the surrogate measured {why['error']:.1%} off "
                    f"({why['source'] or 'this run'})")
                out[(material, t)] = {"error": None, "texts": list(cfg.letters), "status": "full",
                                      "source": src, "model": "full"}
                continue
            out[(material, t)] = {**surrogate_trust(cfg, material, t, model, validation), "model": model}
    return out


def suspect(chart, validation=None, trust: dict | None = None) -> list[str]:
    """What makes a part of the chart suspect: the chart's notes (plate contact) and every
    material whose letters rest on a surrogate not shown within the tolerance."""
    if trust is None:
        trust = letters_trust(chart, validation) if "letters" in chart.config.sets else {}
    flagged = list(dict.fromkeys(
        f"the validation of '{r['text']}' at t = {r['thickness_mm']:g} mm ({r['material']}) is not counted: "
        f"{r['solve_status']}" for r in validation or () if r.get("solve_status", "ok") != "ok"))
    return list(getattr(chart, "notes", None) or []) + flagged + _trust_notes(trust)


def _trust_section(chart, trust: dict) -> list[str]:
    from tactileskin.array.validity import finer_mesh_reason, finer_reference, tolerance

    cfg_full = all(m.get("model") == "full" for m in trust.values())

    out = ["### How far the letters can be trusted", "",
           ("The letters are full 3D solves of every letter (" + (
               "`letters_model = full`" if chart.config.letters_model == "full" else
               "the surrogate is measured past the tolerance at every thickness of the chart: fallback") + ")."
            if cfg_full else
            "The letters are superposed single-dot responses (a surrogate: `interaction` weighs each dot "
            "by the load the lone dot's surface deflection and load-approach law leave it beside its "
            "neighbours; `sum` adds lone "
            "dots). Its error against full 3D "
            "solves of the same characters, as the chart's smallest taxels read them (worst over the "
            "validated characters; `tactileskin array --validate` measures it for a run; "
            "`--letters-model full` solves every letter instead; where the error is measured past the "
            "tolerance the chart solves that thickness's letters in full, model `full`):"), "",
           "| material | t (mm) | model | surrogate error / peak | validated on | status | source |",
           "|---|---|---|---|---|---|---|"]
    for (material, t), m in trust.items():
        mesh = chart.config.mesh_for(t)
        err = "-" if m["error"] is None else f"{m['error']:.1%}"
        status = {"full": "no surrogate", "within": f"within {tolerance():.0%}", "exceeds": f"exceeds {tolerance():.0%}: indicative only",
                  "not validated": "not validated: indicative only"}[m["status"]]
        if m["status"] == "exceeds" and finer_reference(m, mesh):
            status += f" (against {finer_mesh_reason(m, mesh)})"
        out.append(f"| {material} | {t:g} | {m.get('model', '-')} | {err} | {', '.join(m['texts']) or '-'} | {status} "
                   f"| {m['source'] or '-'} |")
    out += ["", "† in the letters tables: a thickness whose surrogate is not within the tolerance or not validated.", ""]
    return out


def _trust_notes(trust: dict) -> list[str]:
    from tactileskin.array.validity import tolerance

    bad = {}
    for (material, t), m in trust.items():
        if m["status"] not in TRUSTED:
            what = "not validated" if m["error"] is None else f"{m['error']:.1%}"
            bad.setdefault(material, []).append(f"t = {t:g} mm ({what})")
    return [f"{material}: the letters' surrogate is not shown within {tolerance():.0%} of full solves at "
            + ", ".join(ts) + "; those letters accuracies are indicative only" for material, ts in bad.items()]


def validation_table(rows, title: str, mesh: bool = False) -> list[str]:
    """Markdown lines of surrogate-validation rows (array.chart.validate_surrogate), with the
    errors of the pointwise maps and, where present, of the maps as the chart's finest taxels
    read them; `mesh`: a column for r['mesh']."""
    taxel = any("max_abs_over_peak_taxel" in r for r in rows)
    head = ("| " + ("mesh | " if mesh else "") + "material | t (mm) | indentation (mm) | text | model | rel. L2 | max error / peak | peak error"
            + (" | taxel: max error / peak | taxel: peak error" if taxel else "") + " | within 5 % |")
    out = [title, "", head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        ok = r.get("within_tolerance_taxel", r["within_tolerance"]) if taxel else r["within_tolerance"]
        flagged = r.get("solve_status", "ok") != "ok"  # judged against flagged solves: not counted
        out.append("| " + (f"{r['mesh']} | " if mesh else "") + f"{r['material']} | {r['thickness_mm']:g} | "
                   f"{r.get('depth_mm', float('nan')):.3g} | {r['text']} | {r.get('model', 'sum')} | {r['rel_l2']:.1%} | "
                   f"{r['max_abs_over_peak']:.1%} | {r['peak_rel']:+.1%}"
                   + (f" | {r['max_abs_over_peak_taxel']:.1%} | {r['peak_rel_taxel']:+.1%}" if taxel else "")
                   + f" | {'not counted (suspect solves)' if flagged else 'yes' if ok else 'no'} |")
    out += ["", "Models: sum = lone-dot responses added; interaction = their loads from the lone dot's "
            "surface deflection under depth control and its load-approach law, load ~ approach^p with p from "
            "a second lone-dot solve at 0.9 x the depth (surrogate.interaction_weights, load_exponent); "
            "interaction, linear = the same with p = 1; sum x a = one "
            "factor per thickness fitted on these same solves (in-sample); plate + sum = the blank plate's "
            "map plus the plate-aware kernels (lone dot with plate minus blank plate, surrogate.plate_kernel), "
            "where the depth passes the dot height. Errors over the full solve's peak, pointwise on its "
            "bone-map grid and (taxel) after both maps are box-averaged over the chart's smallest taxel "
            "(maps.taxel_averaged), inside the square the chart's arrays read (|s|, |z| <= the window's "
            "half side + the coarsest pitch's offset and half taxel, around the cell's centre; "
            "ChartConfig.read_extent) where the row gives it; within 5 % judges the taxel errors where given.", ""]
    return out


def _rules(cfg, method: str) -> str:
    """What each classifier knows: 'nearest template over 4x4 offsets; `lda` in the CSV' did
    not say that the template rule is given every stimulus's noise-free response, which a
    decoder trained on readings is not (t = 1 mm letters, 2.5 mm pitch, noise 0.01: template
    0.93, lda 0.38)."""
    g = cfg.template_grid
    rules = {"template": f"template: the nearest of every stimulus's noise-free readings at {g}x{g} offsets, a reader "
                         "that knows each stimulus's response but not its position",
             "lda": f"lda: a linear discriminant trained on {cfg.n_train} noisy readings per stimulus, as a decoder "
                    "trained on readings would be"}
    return "; ".join(rules.values()) + f" (the tables: {method}; the CSV: both); where the two differ the " \
        "accuracy hangs on what the reader knows"


def _noise_cells(chart, material, t, set_, noise) -> str:
    """The table's two noise cells of (material, t, set_) at the noise level `noise`: its std
    as a fraction of the set's full scale and in MPa (the one the axis does not fix differs
    per thickness)."""
    key = chart.config.noise_key
    for r in chart.rows:
        if (r["material"], r["thickness_mm"], r["set"], r[key]) == (material, t, set_, noise):
            # the axis's own value as given, the other one derived (3 digits)
            return " | ".join(f"{noise:g}" if k == key else f"{r[k]:.3g}" for k in ("noise_fs", "noise_mpa"))
    return f"{noise:g} | -" if key == "noise_fs" else f"- | {noise:g}"


def _cell(a: float) -> str:
    return f"**{accuracy_text(a)}**" if a >= GOOD else accuracy_text(a)


# the files `array` writes into its folder (fnmatch patterns)
ARRAY_FILES = ("accuracies.csv", "array_chart.md", "array_*.png", "array_*.svg")


def write_outputs(chart, out: Path, validation=None, method: str = "template") -> dict:
    """accuracies.csv, array_chart.md and the figures into `out` (claimed by the caller),
    staged and moved in together (the report last): a failed write leaves the earlier chart,
    and figures of an earlier chart this one has not are removed."""
    from tactileskin.staging import staged_files

    trust = letters_trust(chart, validation) if "letters" in chart.config.sets else {}
    indicative = {k: ("the letters' surrogate is " + ("not validated" if m["error"] is None
                                                      else f"off by {m['error']:.1%}"))
                  for k, m in trust.items() if m["status"] not in TRUSTED}
    with staged_files(out, ARRAY_FILES, last="array_chart.md") as tmp:
        atomic_write_text(tmp / "accuracies.csv", chart.to_csv(indicative))
        atomic_write_text(tmp / "array_chart.md", markdown(chart, validation, method) + "\n")
        figures = write_figures(chart, tmp, method, indicative, suspect(chart, validation, trust))
    return {"csv": out / "accuracies.csv", "report": out / "array_chart.md",
            "figures": [out / p.name for p in figures]}
