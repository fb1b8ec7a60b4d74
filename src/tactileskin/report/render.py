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
    """Render `vtu` (the solver's result.vtu, already in the deformed configuration) coloured by
    mean pressure."""
    import pyvista as pv

    _quiet_vtk()
    pv.OFF_SCREEN = True
    grid = pv.read(str(vtu))
    field = next((n for n in ("pressure", "pressure_mpa", "P") if n in grid.point_data or n in grid.cell_data), None)
    p = pv.Plotter(off_screen=True, window_size=(900, 700))
    try:
        p.add_mesh(grid, scalars=field, cmap="jet", show_edges=False,
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
