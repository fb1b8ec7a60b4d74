"""Fig. 9A-style render of a deformed section coloured by mean pressure.

2D (the paper's section): matplotlib, the deformed mesh (reference points + displacement_mm)
shaded by the nodal mean pressure with viridis (perceptually uniform), axes in mm at equal
aspect, a scale bar, the colour bar with its unit and, given the scene, the indenter's
outline at full depth (its working face, `Indenter.surface_y`). 3D results: pyvista,
off-screen (the optional `render` extra).
"""

from __future__ import annotations

import io
import logging
from pathlib import Path

import numpy as np

from tactileskin.fileio import atomic_write_bytes

log = logging.getLogger(__name__)

CMAP = "viridis"
PRESSURE_FIELDS = ("pressure_MPa", "pressure", "pressure_mpa", "P")
# linear sub-triangles of the quadratic cells (meshio/VTK node order), so that the shading
# follows the mid-side nodes' values
_SPLIT = {
    "triangle": [(0, 1, 2)],
    "triangle6": [(0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5)],
    "quad": [(0, 1, 2), (0, 2, 3)],
    "quad9": [(0, 4, 8), (0, 8, 7), (4, 1, 5), (4, 5, 8), (8, 5, 2), (8, 2, 6), (7, 8, 6), (7, 6, 3)],
}


def _nice(x: float) -> float:
    """The largest of 1, 2, 5 x 10^k not above x."""
    k = np.floor(np.log10(x))
    for m in (5.0, 2.0, 1.0):
        if m * 10 ** k <= x:
            return float(m * 10 ** k)
    return float(10 ** k)


def scale_bar_length(extent: float) -> float:
    """A round scale-bar length (mm) of about a fifth of the drawn extent."""
    return _nice(0.2 * extent)


def _section(vtu: Path):
    """(deformed xy points, linear triangles, pressure, field name) of a 2D result.vtu."""
    from tactileskin.results import read_vtu

    m = read_vtu(vtu)
    X = np.asarray(m.points, float)[:, :2]
    if "displacement_mm" in m.point_data:  # reference mesh + displacement (older files: deformed points)
        X = X + np.asarray(m.point_data["displacement_mm"], float)[:, :2]
    field = next((n for n in PRESSURE_FIELDS if n in m.point_data), None)
    if field is None:
        raise ValueError(f"{vtu} has no pressure field ({', '.join(PRESSURE_FIELDS)})")
    tris = []
    bid = m.cell_data.get("boundary_id")
    for k, block in enumerate(m.cells):
        if block.type not in _SPLIT or (bid is not None and np.any(bid[k] != 0)):
            continue  # the boundary facets, not the body
        c = np.asarray(block.data)
        tris.append(np.concatenate([c[:, list(t)] for t in _SPLIT[block.type]]))
    if not tris:
        raise ValueError(f"{vtu} has no 2D cells")
    return X, np.concatenate(tris), np.asarray(m.point_data[field], float), field


def indenter_outline(scene, x_max: float, cap: float, depth: float | None = None) -> np.ndarray | None:
    """(k, 2) closed outline of the indenter in the 2D section, x in [0, x_max] (the half
    model): its working face y = surface_y(x, d = depth, default the scene's indentation) and
    a band `cap` above it; None when the kind has no 2D section."""
    from tactileskin.geometry.indenters import indenter_for_scene

    ind = indenter_for_scene(scene, warn=False)
    half = min(0.5 * ind.width, x_max)
    x = np.linspace(0.0, half, 200)
    try:
        y = np.asarray(ind.surface_y(x, d=scene.indentation if depth is None else depth), float)
    except Exception as e:  # noqa: BLE001 - a kind without a 2D face: no outline, still a render
        log.debug("no indenter outline: %s", e)
        return None
    top = float(np.max(y)) + cap
    return np.vstack([np.column_stack([x, y]), [[half, top], [0.0, top]], [[x[0], y[0]]]])


def render_figure(vtu: Path, title: str = "", scene=None, depth: float | None = None):
    """The matplotlib figure of a 2D result.vtu (see the module doc); the caller closes it.
    `depth`: the indenter's travel in the result's state when the scene does not prescribe it
    (force control, a history: summary loading.profile_travel_mm); None: the scene's depth."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

    X, tris, P, _ = _section(Path(vtu))
    xmin, ymin = X.min(axis=0)
    xmax, ymax = X.max(axis=0)
    w, h = xmax - xmin, ymax - ymin
    fig, ax = plt.subplots(figsize=(7.0, float(np.clip(7.0 * h / max(w, 1e-9), 2.5, 7.0)) + 0.8),
                           constrained_layout=True)
    im = ax.tripcolor(X[:, 0], X[:, 1], tris, P, shading="gouraud", cmap=CMAP,
                      vmin=min(0.0, float(P.min())), vmax=float(P.max()))
    outline = indenter_outline(scene, xmax, 0.08 * h, depth) if scene is not None and scene.dim == 2 else None
    top = ymax
    if outline is not None:
        ax.add_patch(Polygon(outline, closed=True, facecolor="0.85", edgecolor="black", lw=1.0, alpha=0.9,
                             label=(f"indenter at full depth ({scene.indentation:g} mm)" if depth is None
                                    else f"indenter at the travel reached ({depth:.3g} mm)"), zorder=3))
        top = max(top, float(outline[:, 1].max()))
        ax.legend(loc="upper right", fontsize="small", framealpha=0.9)
    ax.set_xlim(xmin - 0.02 * w, xmax + 0.02 * w)
    ax.set_ylim(ymin - 0.02 * h, top + 0.02 * h)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    bar = scale_bar_length(w)
    ax.add_artist(AnchoredSizeBar(ax.transData, bar, f"{bar:g} mm", loc="lower left", pad=0.6,
                                  sep=4, frameon=True, size_vertical=0.01 * h))
    fig.colorbar(im, ax=ax, label="mean pressure P (MPa)", shrink=0.9)
    ax.set_title(_titled(vtu, title or "deformed section, mean pressure", 64), loc="left", fontsize="medium")
    return fig


def render_case(vtu: Path, png: Path, title: str = "", scene=None, depth: float | None = None) -> Path:
    """Render `vtu` (the solver's result.vtu) deformed, coloured by mean pressure, into `png`
    (atomically). 2D: matplotlib (`render_figure`; `scene` adds the indenter outline); 3D:
    pyvista off-screen (needs the `render` extra; MissingDependency without)."""
    from tactileskin.results import read_vtu

    vtu = Path(vtu)
    cells = {b.type for b in read_vtu(vtu).cells}
    if cells & {"tetra", "tetra10", "hexahedron", "hexahedron27"}:
        return _render_3d(vtu, png, title)
    import matplotlib.pyplot as plt

    fig = render_figure(vtu, title, scene, depth)
    try:
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=150)
    finally:
        plt.close(fig)
    return atomic_write_bytes(png, buf.getvalue())


def _titled(vtu: Path, title: str, width: int) -> str:
    """`title` with the SUSPECT note of the result's status, as result.vtu holds it
    (results.vtu_status; a file written without one: the title alone)."""
    from tactileskin.quality import suspect_title
    from tactileskin.results import vtu_reasons, vtu_status

    status = vtu_status(vtu)
    return suspect_title(title, status, width, reasons=vtu_reasons(vtu, status))


def _quiet_vtk() -> None:
    """VTK warns "bad X server connection" on stderr when it probes for a display, although
    off-screen rendering needs none; keep its errors, drop its warnings (same image)."""
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)


def _render_3d(vtu: Path, png: Path, title: str = "") -> Path:
    from tactileskin.errors import require_pyvista

    pv = require_pyvista("the render of a 3D result")
    _quiet_vtk()
    pv.OFF_SCREEN = True
    grid = pv.read(str(vtu))
    if "boundary_id" in grid.cell_data:  # the body only, not the boundary facets
        grid = grid.extract_cells(np.flatnonzero(grid.cell_data["boundary_id"] == 0))
    if "displacement_mm" in grid.point_data:
        grid = grid.warp_by_vector("displacement_mm", factor=1.0)
    field = next((n for n in PRESSURE_FIELDS if n in grid.point_data or n in grid.cell_data), None)
    p = pv.Plotter(off_screen=True, window_size=(900, 700))
    try:
        p.add_mesh(grid, scalars=field, cmap=CMAP, show_edges=False,
                   scalar_bar_args={"title": "mean pressure P (MPa)"})
        p.show_axes()
        title = _titled(vtu, title, 80)
        if title:
            p.add_text(title, font_size=10)
        buf = io.BytesIO()
        p.screenshot(buf)  # PNG bytes; the file is written atomically below
    finally:
        p.close()
    return atomic_write_bytes(png, buf.getvalue())
