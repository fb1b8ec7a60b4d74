"""`tactileskin solve`: indent one scene and write its pressure profile and fields."""

from __future__ import annotations

import click

from tactileskin.cli._common import scene_from_options, scene_options


@click.command("solve")
@scene_options
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Output folder (profile.csv, contact.csv, summary.json, result.vtu).")
@click.option("--elastic", is_flag=True, default=False, help="Ignore viscoelasticity (Prony series).")
def command(out, elastic, **kw):
    """Solve the finite-strain contact problem of one scene and write the results."""
    from rich.console import Console
    from rich.table import Table

    from tactileskin.fe import solve

    scene = scene_from_options(**kw)
    if elastic:
        scene = scene.replace(viscoelastic=False)
    res = solve(scene)
    path = res.write(out)
    s = res.summary()
    t = Table(title=f"{scene.label()} -> {path}", show_header=False)
    t.add_row("peak bone pressure", f"{s['peak_mpa']:.4g} MPa")
    t.add_row("span (P >= 10 % of peak)", f"{s['span_mm']:.3g} mm")
    t.add_row("area under P(s)", f"{s['auc']:.4g} MPa mm")
    if scene.dim == 3:
        t.add_row("bone profile on plane", f"z = {res.stats.get('profile_plane_z', 0.0):g} mm")
        t.add_row("reaction (modelled part of the slab)", f"{s['reaction_n_per_mm']:.4g} N")
    else:
        t.add_row("reaction (half section)", f"{s['reaction_n_per_mm']:.4g} N/mm")
    t.add_row("dofs / increments / Newton", f"{s['dofs']} / {s['increments']} / {s['newton_iterations']}")
    t.add_row("wall time", f"{s['wall_s']:.2f} s")
    Console().print(t)
    return 0
