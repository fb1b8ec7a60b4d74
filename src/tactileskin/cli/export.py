"""`tactileskin export`: a scene as an Abaqus or CalculiX input deck (.inp)."""

from __future__ import annotations

import click

from tactileskin.cli._choice import Choice
from tactileskin.cli._common import scene_from_options, scene_options


@click.command("export")
@scene_options
@click.option("--out", "-o", type=click.Path(dir_okay=False), required=True, help="Deck to write (.inp).")
@click.option("--dialect", type=Choice(["abaqus", "calculix"]), default=None,
              help="abaqus (2D default): analytical rigid indenter, *VISCOELASTIC Prony, hard contact; "
                   "calculix (3D: the only one): meshed indenter, instantaneous hyperfoam (ccx has no "
                   "Prony), penalty contact.")
def command(out, dialect, scene_opts):
    """Write the scene (mesh, sets, surfaces, material, supports, indenter, contact, step) as
    an input deck for Abaqus/Standard or CalculiX (units mm, s, N, MPa; 2D per mm of depth;
    3D: CalculiX, C3D10 skin, the quarter or half the symmetry allows)."""
    from rich.markup import escape

    from tactileskin import ownership
    from tactileskin.cli._console import new_console
    from tactileskin.errors import ParameterError
    from tactileskin.mesh.deck import write_deck

    if not out.lower().endswith(".inp"):
        raise ParameterError("--out", out, "a file name ending in .inp")
    scene = scene_from_options(scene_opts, "export")  # --elastic: leave out the Prony series
    if dialect is None:
        dialect = "calculix" if scene.dim == 3 else "abaqus"
    elif scene.dim == 3 and dialect != "calculix":  # before meshing
        raise ParameterError("--dialect", dialect, "calculix for a 3D deck",
                             "a 3D Abaqus deck (R3D3 rigid surfaces) is not written yet")
    ownership.claim_file(out)  # before meshing: a user's file of that name is refused
    with ownership.written_file(out) as tmp:
        deck = write_deck(scene, tmp, dialect=dialect)
    extra = (f", {deck.info['indenter_cells']} C3D6 indenter wedges, contact penalty "
             f"{deck.info['penalty_mpa_per_mm']:.3g} MPa/mm" if scene.dim == 3 else "")
    new_console().print(f"wrote {escape(out)}: {deck.n_skin_cells} {deck.etype} cells, {deck.n_skin_nodes} nodes"
                        f"{extra}, {'viscoelastic' if deck.info['viscoelastic'] else 'elastic'} {dialect} deck")
