"""Helpers shared by CLI command modules."""

from __future__ import annotations

import contextlib
from pathlib import Path

import click

from tactileskin.scene import Formulation, IndenterKind


def scene_options(f):
    """Click options that map one-to-one onto Scene fields."""
    opts = [
        click.option("--scene", "scene_file", type=click.Path(dir_okay=False), default=None,
                     help="Scene TOML file; flags below override its fields."),
        click.option("--thickness", "-t", type=float, default=None, help="Skin thickness (mm)."),
        click.option("--material", "-m", type=str, default=None, help="Material preset name."),
        click.option("--indenter", "-i", type=click.Choice([k.value for k in IndenterKind]), default=None),
        click.option("--braille-text", type=str, default=None, help="Text for a Braille indenter."),
        click.option("--braille-standard", type=str, default=None, help="Braille standard name."),
        click.option("--indenter-radius", type=float, default=None, help="Sphere or cylinder radius (mm)."),
        click.option("--indenter-axis", type=click.Choice(["z", "x"]), default=None,
                     help="Cylinder axis: z along the finger (2D-exact), x across it (3D)."),
        click.option("--indenter-file", type=str, default=None,
                     help="Closed STL/OBJ/PLY/OFF or STEP surface (mm) of a 'file' indenter."),
        click.option("--depth", type=float, default=None, help="Indentation depth (mm); default 20% of t."),
        click.option("--rate", type=float, default=None, help="Indentation rate (mm/s)."),
        # loading (tactileskin.loading): force control; holds and releases via [[loading]] in --scene
        click.option("--force", type=float, default=None,
                     help="Force control: target reaction (N in 3D, N/mm in 2D) instead of --depth."),
        click.option("--force-rate", type=float, default=None, help="Force rate (N/s, N/mm/s in 2D) for --force."),
        click.option("--dim", type=click.Choice(["2", "3"]), default=None, help="2D section or 3D slab."),
        click.option("--mesh-size", type=float, default=None, help="Global element size (mm)."),
        click.option("--refinement", type=float, default=None, help="Global/refined size ratio."),
        click.option("--formulation", type=click.Choice([k.value for k in Formulation]), default=None),
    ]
    for o in reversed(opts):
        f = o(f)
    return f


def scene_from_options(scene_file=None, **kw):
    from tactileskin.scene import Scene

    base = Scene.from_toml(scene_file) if scene_file else Scene()
    changes = {k: v for k, v in kw.items() if v is not None}
    if "dim" in changes:
        changes["dim"] = int(changes["dim"])
    return base.replace(**changes) if changes else base


@contextlib.contextmanager
def claimed_output(out, kind: str, own_names=(), what: str = "--out"):
    """Claim the output folder `out` (fileio.claim_dir) for the body; if the body fails and the
    folder was created here and holds nothing but our marker, remove it again (no empty
    leftovers from a refused or failed run)."""
    from tactileskin import fileio

    out = Path(out)
    existed = out.exists()
    fileio.claim_dir(out, kind, own_names=own_names, what=what)
    try:
        yield out
    except BaseException:
        if not existed:
            with contextlib.suppress(OSError):
                if [p.name for p in out.iterdir()] == [fileio.MARKER]:
                    (out / fileio.MARKER).unlink()
                    out.rmdir()
        raise
