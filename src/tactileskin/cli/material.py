"""`tactileskin material ...`: material laws, presets, fitting to test data."""

from __future__ import annotations

from pathlib import Path

import click

from tactileskin.cli._choice import Choice

MARK = "# written by tactileskin material fit"
EXIT_SUSPECT = 3  # the material file was written, but the fit is suspect (as `solve`)


@click.group("material")
def command() -> None:
    """Material laws and presets; fit a law to your own uniaxial test."""


@command.command("list")
def list_() -> None:
    """The registered laws and the preset materials with their sources."""
    from tactileskin.materials import get_material, list_laws, list_materials

    click.echo("laws: " + ", ".join(list_laws()))
    for name in list_materials():
        m = get_material(name)
        click.echo(f"{name}: {m.law_name}, mu0 = {m.law.mu0:.4g} MPa, K0 = {m.law.K0:.4g} MPa; {m.source}")


@command.command()
@click.argument("data", type=click.Path(dir_okay=False))
@click.option("--law", "-l", required=True, help="Law to fit (tactileskin material list).")
@click.option("--out", "-o", type=click.Path(dir_okay=False), required=True, help="Material TOML to write.")
@click.option("--nu", type=float, default=None,
              help="Poisson ratio of the test, in (-1, 0.4999] (default: incompressible; hyperfoam needs it).")
@click.option("--terms", type=int, default=None, help="Terms of yeoh (1-3), ogden or hyperfoam (1-3).")
@click.option("--name", default=None, help="Material name (default: the CSV's name).")
@click.option("--test", "test", type=Choice(["uniaxial", "indentation"]), default="uniaxial", show_default=True,
              help="uniaxial: stretch-stress; indentation: depth_mm, force_n of a sphere on a bonded layer.")
@click.option("--radius", type=float, default=None, help="Indentation: sphere radius R (mm).")
@click.option("--thickness", type=float, default=None, help="Indentation: layer thickness t (mm), bonded to a rigid base.")
def fit(data, law, out, nu, terms, name, test="uniaxial", radius=None, thickness=None):
    """Fit LAW to the uniaxial test in DATA (CSV: stretch or strain, nominal_stress_mpa), or
    with --test indentation to a sphere indentation of a bonded layer (CSV: depth_mm, force_n;
    Hertz with the bonded-layer correction of Dimitriadis et al. 2002, neo_hookean only).

    Prints the parameters and the fit quality (R^2, RMSE, max relative error) and writes a
    material file usable as --material OUT or Scene(material="OUT")."""
    from tactileskin import fileio, ownership
    from tactileskin.errors import ParameterError
    from tactileskin.materials.fit import fit as fit_law, read_uniaxial_csv

    outp = Path(out)
    if outp.suffix != ".toml":
        raise ParameterError("--out", out, "a path ending in .toml")
    # before the fit: only a file this command wrote and nobody changed since is replaced (the
    # folder's record). A file with the MARK line but no record is refused too: an earlier
    # version's output and a hand-edited copy of ours look the same, and only one may go
    ownership.claim_file(outp)
    if test == "indentation":
        from tactileskin.materials.indentation import fit_indentation, read_indentation_csv

        if radius is None or thickness is None:
            raise ParameterError("--radius/--thickness", None, "both given (mm) with --test indentation")
        if nu is not None or terms is not None:
            raise ParameterError("--nu/--terms", nu if nu is not None else terms, "not given with --test indentation",
                                 "the bonded-layer correction is for an incompressible layer")
        d, F = read_indentation_csv(data)
        f = fit_indentation(law, d, F, radius=radius, thickness=thickness)
        q = f.quality
        source = (f"fit of {law} to {Path(data).name} (sphere indentation, R = {radius:g} mm, bonded layer t = "
                  f"{thickness:g} mm, Hertz with the Dimitriadis 2002 bonded correction, {q['n_points']} points, "
                  f"chi <= {q['chi_max']:.3g}): E = {f.E:.5g} MPa, R^2 = {q['r2']:.5f}, RMSE = {q['rmse_n']:.3g} N, "
                  f"max relative error {100 * q['max_rel_err']:.2f} %" + "".join(f"; SUSPECT: {w}" for w in f.warnings))
        with ownership.written_file(outp) as tmp:
            fileio.atomic_write_text(tmp, MARK + "\n" + f.material(name or Path(data).stem, source).to_toml())
        click.echo(f.describe())
        click.echo(f"wrote {out}" + (" (a suspect fit: exit status 3)" if f.warnings else ""))
        return EXIT_SUSPECT if f.warnings else 0
    if radius is not None or thickness is not None:
        raise ParameterError("--radius/--thickness", radius if radius is not None else thickness,
                             "only with --test indentation")
    lam, P = read_uniaxial_csv(data)
    f = fit_law(law, lam, P, nu=nu, terms=terms)
    q = f.quality
    kin = "incompressible" if nu is None else f"nu = {nu:g}"
    source = (f"fit of {law} to {Path(data).name} (uniaxial nominal stress, {kin}, {q['n_points']} points): "
              f"R^2 = {q['r2']:.5f}, RMSE = {q['rmse_mpa']:.3g} MPa, max relative error "
              f"{100 * q['max_rel_err']:.2f} %" + "".join(f"; SUSPECT: {w}" for w in f.warnings))
    mat = f.material(name or Path(data).stem, source)
    with ownership.written_file(outp) as tmp:
        fileio.atomic_write_text(tmp, MARK + "\n" + mat.to_toml())
    click.echo(f.describe())
    click.echo(f"wrote {out}" + (" (a suspect fit: exit status 3)" if f.warnings else ""))
    return EXIT_SUSPECT if f.warnings else 0
