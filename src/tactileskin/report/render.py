"""Fig. 9A-style render of a deformed section coloured by mean pressure (pyvista, off-screen)."""

from __future__ import annotations

import io
import logging
from pathlib import Path

from tactileskin.fileio import atomic_write_bytes

log = logging.getLogger(__name__)


def _quiet_vtk() -> None:
    """VTK warns "bad X server connection" on stderr when it probes for a display, although
    off-screen rendering needs none; keep its errors, drop its warnings (same image)."""
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)


def render_case(vtu: Path, png: Path, title: str = "") -> Path:
    """Render `vtu` (the solver's result.vtu) deformed, coloured by mean pressure (viridis,
    perceptually uniform). A result.vtu on the reference mesh (displacement_mm) is warped by
    its displacement; one of an earlier version (points already deformed) is shown as is."""
    import pyvista as pv

    _quiet_vtk()
    pv.OFF_SCREEN = True
    grid = pv.read(str(vtu))
    if "boundary_id" in grid.cell_data:  # the body only, not the boundary facets
        import numpy as np

        grid = grid.extract_cells(np.flatnonzero(grid.cell_data["boundary_id"] == 0))
    if "displacement_mm" in grid.point_data:
        grid = grid.warp_by_vector("displacement_mm", factor=1.0)
    field = next((n for n in ("pressure_MPa", "pressure", "pressure_mpa", "P")
                  if n in grid.point_data or n in grid.cell_data), None)
    p = pv.Plotter(off_screen=True, window_size=(900, 700))
    try:
        p.add_mesh(grid, scalars=field, cmap="viridis", show_edges=False,
                   scalar_bar_args={"title": "mean pressure P (MPa)"})
        if title:
            p.add_text(title, font_size=10)
        p.view_xy()
        buf = io.BytesIO()
        p.screenshot(buf)  # PNG bytes; the file is written atomically below
    finally:
        p.close()
    atomic_write_bytes(png, buf.getvalue())
    return png
