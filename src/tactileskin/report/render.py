"""Fig. 9A-style render of a deformed section coloured by mean pressure (pyvista, off-screen)."""

from __future__ import annotations

import logging
from pathlib import Path

log = logging.getLogger(__name__)


def render_case(vtu: Path, png: Path, title: str = "") -> Path:
    """Render `vtu` (the solver's result.vtu, already in the deformed configuration) coloured by
    mean pressure."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    grid = pv.read(str(vtu))
    field = next((n for n in ("pressure", "pressure_mpa", "P") if n in grid.point_data or n in grid.cell_data), None)
    p = pv.Plotter(off_screen=True, window_size=(900, 700))
    p.add_mesh(grid, scalars=field, cmap="jet", show_edges=False,
               scalar_bar_args={"title": "mean pressure P (MPa)"})
    if title:
        p.add_text(title, font_size=10)
    p.view_xy()
    png.parent.mkdir(parents=True, exist_ok=True)
    p.screenshot(str(png))
    p.close()
    return png
