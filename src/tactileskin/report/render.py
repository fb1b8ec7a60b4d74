"""Fig. 9A-style render of a deformed section coloured by mean pressure (pyvista, off-screen)."""

from __future__ import annotations

import logging
from pathlib import Path

log = logging.getLogger(__name__)


def render_case(vtu: Path, png: Path, title: str = "") -> Path:
    """Render `vtu` (the solver's result.vtu) warped by its displacement, coloured by pressure."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    grid = pv.read(str(vtu))
    field = next((n for n in ("pressure", "pressure_mpa", "P") if n in grid.point_data or n in grid.cell_data), None)
    disp = next((n for n in ("displacement", "u") if n in grid.point_data), None)
    if disp is not None:
        vec = grid.point_data[disp]
        if vec.shape[1] == 2:  # pad 2D vectors
            import numpy as np

            vec = np.column_stack([vec, np.zeros(len(vec))])
            grid.point_data["_disp3"] = vec
            disp = "_disp3"
        grid = grid.warp_by_vector(disp, factor=1.0)
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
