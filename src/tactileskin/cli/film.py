"""`tactileskin film ...`: pressure-film calibration, scan analysis, comparison."""

from __future__ import annotations

import click

from tactileskin.cli._choice import Choice
from tactileskin.cli._common import claimed_output
from tactileskin.film import models

EXIT_SUSPECT = 3  # written, but suspect (as `solve`, `sweep`, `array`, `material fit`)


@click.group("film")
def command() -> None:
    """Pressure-film calibration and scan analysis (paper Sec. IV, Eqs. 7-8)."""


@command.command()
@click.argument("cal_csv", type=click.Path(dir_okay=False))
@click.option("--out", "-o", type=click.Path(dir_okay=False), required=True,
              help="Calibration JSON to write (.json).")
@click.option("--model", type=Choice(["auto", *models.MODELS]), default="auto",
              show_default=True, help="Fitting function; auto selects by AICc.")
@click.option("--activation-range", nargs=2, type=float, default=None,
              help="Clip range LO HI (MPa) of the pressure readings, 0 <= LO < HI (default 0 .. the "
                   "reading at the darkest press); a reading below LO is unactivated film: 0.")
@click.option("--plot", type=click.Path(dir_okay=False), default=None,
              help="Also write a PNG (.png) of the fit, its 90 % band and residuals.")
def calibrate(cal_csv, out, model, activation_range, plot):
    """Fit grayscale -> pressure (P = F/A, MPa) from calibration presses in CAL_CSV.

    Columns: force_n, area_mm2, and gray (mean grayscale 0-255) or image (path relative
    to the CSV; optional x0,y0,x1,y1 crop in px).
    """
    from pathlib import Path

    from tactileskin import ownership
    from tactileskin.errors import ParameterError
    from tactileskin.film import calibrate_csv

    # the writers' formats are fixed: a name of another format got JSON / PNG bytes under it
    if not out.lower().endswith(".json"):  # as mesh and export check theirs: '.json' is a name
        raise ParameterError("--out", out, "a path ending in .json")
    if plot and not plot.lower().endswith(".png"):
        raise ParameterError("--plot", plot, "a path ending in .png")
    if plot and Path(plot).absolute() == Path(out).absolute():
        raise ParameterError("--plot", plot, "a file other than --out")
    for path, what in ((out, "--out"), (plot, "--plot")):
        if path:  # before the fit: a user's file (the input CSV too) is refused, not overwritten
            ownership.claim_file(path, what)
    cal = calibrate_csv(cal_csv, model=model, activation_range=activation_range)
    if plot:
        from tactileskin.film import plots

        with ownership.written_file(plot) as tmp:
            plots.calibration_plot(cal, tmp)
    with ownership.written_file(out) as tmp:
        cal.save(tmp)
    r = cal.report
    lin = r["linear"]
    (a_lo, a_hi), (b_lo, b_hi) = lin["param_ci90"]
    click.echo(f"{r['n_points']} presses; linear P = a*GS + b: a = {lin['params'][0]:.5g} "
               f"[{a_lo:.5g}, {a_hi:.5g}], b = {lin['params'][1]:.5g} [{b_lo:.5g}, {b_hi:.5g}] "
               f"(90 %), R^2 = {lin['r2']:.4f}")
    for alt in r["alternatives"]:
        aicc = f"{alt['aicc']:.2f}" if alt["aicc"] is not None else "n/a"
        note = alt["reason"] or ("" if alt["monotonic"] else "non-monotonic")
        click.echo(f"  {alt['model']:<12} AICc {aicc:>9}  {note}")
    click.echo(f"selected: {cal.model} ({r['selected_because']}); activation range "
               f"{cal.p_range[0]:g}-{cal.p_range[1]:.4g} {cal.unit}; wrote {out}")


@command.command()
@click.argument("scan", type=click.Path(dir_okay=False))
@click.option("--calibration", "-c", default="paper_eq8", show_default=True,
              help="Calibration JSON, or paper_eq8 (the paper's Eq. 8).")
@click.option("--px-per-mm", type=float, default=8.0, show_default=True, help="Scan scale.")
@click.option("--box-px", nargs=4, type=int, default=None,
              help="Region X0 Y0 X1 Y1 (pixels). Default: the activated strip, found on the "
                   "scan (refused if ambiguous); the region used is printed and saved.")
@click.option("--box-mm", nargs=4, type=float, default=None, help="Region X0 Y0 X1 Y1 (mm).")
@click.option("--axis", type=Choice(["x", "y"]), default="x", show_default=True,
              help="Direction of the strip in the image.")
@click.option("--centre", default="peak", show_default=True,
              help="Origin of s: peak, midspan, or a position in mm from the image edge.")
@click.option("--rows", type=Choice(["all", "centre"]), default="all", show_default=True,
              help="Across the strip: all (the profile is the mean of the region's rows) or centre (the "
                   "row through the peak: a round press's centre line, one row's noise).")
@click.option("--cmap", default="viridis", show_default=True,
              help="Colour map (viridis: perceptually uniform; jet: as in the paper).")
@click.option("--out", "-o", type=click.Path(file_okay=False), required=True,
              help="Output directory: profile.csv, summary.json, pressure_map.png.")
def analyze(scan, calibration, px_per_mm, box_px, box_mm, axis, centre, rows, cmap, out):
    """Convert a scanned film to pressure and its profile along the strip.

    Exit status 3 when the profile was written but is suspect (saturated film, pixels
    beyond the calibrated range, a strip along the other axis): summary.json `warnings`.
    """
    from tactileskin.film import analyze_scan, load_calibration
    from tactileskin.film.plots import _check_cmap
    from tactileskin.film.scan import area_unit

    _check_cmap(cmap)  # before any work, so a typo writes nothing
    if centre not in ("peak", "midspan"):
        try:
            centre = float(centre)
        except ValueError:
            raise click.BadParameter("peak, midspan or a number (mm)", param_hint="--centre")
    cal = load_calibration(calibration)
    fp = analyze_scan(scan, cal, px_per_mm=px_per_mm, box_px=box_px or None,
                      box_mm=box_mm or None, axis=axis, centre=centre, rows=rows)
    with claimed_output(out, "film-analyze"):  # a failed write leaves no folder of a marker alone
        fp.write_owned(out, cmap=cmap)  # the lock is held: fp.write would take it again
    x0, y0, x1, y1 = fp.box_px
    how = ("found automatically (the activated strip; --box-px/--box-mm to override)"
           if fp.region.get("method") == "auto" else f"given ({fp.region.get('method')})")
    if "rows" in fp.region:
        how += f"; {fp.region['rows']}"
    click.echo(f"region x {x0}-{x1}, y {y0}-{y1} px {how}")
    m, f = fp.metrics, fp.folded["metrics"]
    click.echo(f"origin {fp.origin_mm:.3f} mm; two-sided: peak {m['peak']:.4g} {fp.unit}, "
               f"span {m['span_mm']:.3f} mm, area {m['auc']:.4g} {area_unit(fp.unit)}; folded: peak "
               f"{f['peak']:.4g} {fp.unit}, span {f['span_mm']:.3f} mm, area {f['auc']:.4g} {area_unit(fp.unit)}; "
               f"asymmetry {fp.folded['asymmetry']:.3f}; saturated "
               f"{100 * fp.saturated_fraction:.1f} % of pixels")
    click.echo(f"wrote {out}")
    if fp.warnings:  # each reason is logged as it is found (stderr); one line says what it means
        click.echo(f"warning: suspect profile (exit status 3): {len(fp.warnings)} reason(s) above, also in "
                   f"{out}/summary.json `warnings`", err=True)
    return EXIT_SUSPECT if fp.warnings else 0


@command.command()
@click.argument("film_dir", type=click.Path(file_okay=False))
@click.argument("sim_dir", type=click.Path(file_okay=False))
@click.option("--out", "-o", type=click.Path(file_okay=False), default=None,
              help="Where to write comparison.json and overlay.png (default FILM_DIR).")
def compare(film_dir, sim_dir, out):
    """Compare a `film analyze` result with a simulated profile (percent differences).

    A comparison resting on a suspect film profile or simulated result says so on stderr and
    in comparison.json (`status`, `warnings`), and exits 3.
    """
    from tactileskin.film import compare as do_compare
    from tactileskin.film.scan import area_unit

    comp = do_compare(film_dir, sim_dir)
    comp.write(out or film_dir)
    click.echo(f"{'metric':<8} {'film':>10} {'sim':>10} {'diff %':>8}   (film {comp.film_unit}, "
               "sim MPa; diff = 100 (sim - film)/film)")
    units = {"peak": f"{comp.film_unit} / MPa", "span_mm": "mm", "auc": f"{area_unit(comp.film_unit)} / MPa mm"}
    for k in ("peak", "span_mm", "auc"):
        click.echo(f"{k:<8} {comp.film_metrics[k]:>10.4g} {comp.sim_metrics[k]:>10.4g} "
                   f"{comp.percent_diff[k]:>+8.1f}   {units[k]}")
    status = str(comp.sim_meta.get("status", "ok"))
    if status != "ok":  # comparison.json carries it too (sim_meta, status, warnings)
        click.echo(f"warning: the simulated result is {status}", err=True)
    for w in comp.warnings:  # the comparison's own about the simulation (an asymmetric fold)
        if (w.startswith("simulation: ") and w != f"simulation: {status}") or w.startswith("units: "):
            click.echo(f"warning: {w}", err=True)
    for w in comp.film_warnings:  # the film's own (summary.json): the comparison inherits them
        click.echo(f"warning: the film profile is suspect: {w}", err=True)
    click.echo(f"wrote {out or film_dir}")
    return EXIT_SUSPECT if comp.status != "ok" else 0
