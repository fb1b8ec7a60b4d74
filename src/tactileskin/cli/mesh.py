"""`tactileskin mesh`: mesh the skin of a scene, report counts and quality, export."""

from __future__ import annotations

import click

from tactileskin.cli._choice import Choice
from tactileskin.cli._common import scene_from_options, scene_options


@click.command("mesh")
@scene_options(physics=False)
@click.option("--out", "-o", type=click.Path(dir_okay=False), default=None,
              help="Mesh file to write: .msh (gmsh 2.2), .vtu (ParaView) or .inp (Abaqus/CalculiX).")
@click.option("--cell", type=Choice(["tri", "quad"]), default="tri", show_default=True,
              help="2D cell shape (quad: all-quadrilateral, 9-node when order 2; for export: "
                   "the solver meshes with triangles).")
def command(out, cell, scene_opts):
    """Mesh the skin (gmsh) with named boundaries and print counts and quality."""
    from pathlib import Path

    import numpy as np
    from rich.markup import escape
    from rich.table import Table

    from tactileskin import ownership
    from tactileskin.cli._console import new_console
    from tactileskin.mesh import FORMATS, build_mesh
    from tactileskin.errors import ParameterError

    if out is not None and not any(out.lower().endswith(s) for s in FORMATS):
        raise ParameterError("--out", out, "a file name ending in " + ", ".join(FORMATS))
    if out is not None:
        ownership.claim_file(out)  # before meshing: a user's file of that name is refused
    scene = scene_from_options(scene_opts, "mesh")
    sm = build_mesh(scene, cell=cell)
    q, sec = sm.quality, sm.section

    sizes = (f"as meshed in {scene.skin_file}" if scene.skin_kind.fixes_thickness
             else f"mesh_size {scene.mesh_size:g} mm, refinement {scene.refinement:g}")
    table = Table(title=escape(f"skin mesh {scene.label()} ({sizes})"))
    table.add_column("quantity")
    table.add_column("value", justify="right")
    shape = {"tri": {2: "triangles", 3: "tetrahedra"}[sm.dim], "quad": "quadrilaterals"}[sm.cell]
    kind = f"{'Q' if sm.cell == 'quad' else 'P'}{sm.order} {shape}"
    table.add_row("cells", f"{q['elements']} {kind}")
    table.add_row("nodes (vertices)", f"{q['nodes']} ({q['vertices']})")
    if "fine" in sm.sizes:  # a user's skin file comes meshed: no size plan
        table.add_row("refined size (mm)", f"{sm.sizes['fine']:.4g}")
    if "min_sicn" in q:  # gmsh's shape measure: not computed for a user's mesh file
        table.add_row("min / mean SICN (shape)", f"{q['min_sicn']:.3f} / {q['mean_sicn']:.3f}")
    table.add_row("min scaled Jacobian (curved)", f"{q['min_scaled_jacobian']:.3f}")
    if scene.skin_kind.fixes_thickness:  # a user's file: no CAD section to compare with
        # the measures below are the model's: a symmetric STEP is cut to its half or quarter
        table.add_row("model", {(True, True): "quarter (x >= 0, z >= 0)", (True, False): "half (x >= 0)",
                                (False, True): "half (z >= 0)", (False, False): "whole"}[
                                    (sm.halved, bool(sm.z_symmetric))])
        table.add_row("bonded boundary measure (mm^%d)" % (sm.dim - 1), f"{sm.boundary_measure('bone_interface'):.6g}")
    else:
        # 3D: over the bonded surface's own z extent (a dome's bone_interface ends where its
        # tip begins: z in [-L, 0], not the whole skin's L + dome_tip)
        bonded = np.unique(sm.mesh.facets[:, sm.boundaries["bone_interface"]])
        lz = 1.0 if sm.dim == 2 else float(np.ptp(sm.mesh.p[2, bonded]))
        L = sm.boundary_measure("bone_interface") / lz
        cad = sec.interface_length * (1.0 if sm.halved else 2.0)  # from x = 0; a full-width model has both sides
        table.add_row("bone interface length (mm)", f"{L:.6f} (CAD {cad:.6f}, rel. err {abs(L / cad - 1):.1e})")
    for name, f in sm.boundaries.items():  # as the written file names them
        table.add_row(f"facets: {sm.file_name(name)}", str(len(f)))
    if sm.dim == 3 and not scene.skin_kind.fixes_thickness:
        table.add_row("z symmetry", f"yes ({sm.file_name('end_back')} is z = 0)" if sm.z_symmetric else "no")
    table.add_row("wall time (s)", f"{q['wall_s']:.2f}")
    console = new_console()
    console.print(table)
    if out is not None:
        path = Path(out)
        with ownership.written_file(path) as tmp:
            sm.write(tmp)
        console.print(f"wrote {escape(str(path))}")
