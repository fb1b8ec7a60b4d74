"""Film figures (matplotlib, Agg, imported lazily): pressure colour map with colour bar,
calibration fit with its 90 % band, and the film-vs-simulation overlay.

Colour maps: ``viridis`` (perceptually uniform) by default; ``jet`` reproduces the paper's
MATLAB figures (Sec. IV-D), which is why it is offered.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tactileskin.errors import ParameterError

DEFAULT_CMAP = "viridis"


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _check_cmap(cmap: str) -> str:
    import matplotlib

    if cmap not in matplotlib.colormaps:
        raise ParameterError("cmap", cmap, "a matplotlib colormap name, e.g. viridis, jet")
    return cmap


def _save(fig, path) -> Path:
    """Render to a temporary sibling and rename (fileio.atomic_path): no partial PNG."""
    from tactileskin import fileio

    path = Path(path)
    try:
        with fileio.atomic_path(path, suffix=".png") as tmp, fileio.os_errors(path):
            fig.savefig(tmp, dpi=120, format="png")
    finally:
        _plt().close(fig)
    return path


def pressure_map(fp, path, *, cmap: str = DEFAULT_CMAP) -> Path:
    """Colour map of a FilmProfile's pressure image (mm axes, s from the origin) + colour bar."""
    cmap = _check_cmap(cmap)
    plt = _plt()
    nw, nx = fp.pressure_map.shape
    ds = 1.0 / fp.px_per_mm
    extent = (fp.s_mm[0] - ds / 2, fp.s_mm[-1] + ds / 2, nw * ds, 0.0)
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7, 5), sharex=True,
                                  gridspec_kw={"height_ratios": [1, 1.2]})
    im = ax.imshow(fp.pressure_map, cmap=cmap, extent=extent, aspect="auto",
                   vmin=fp.calibration.p_range[0], vmax=fp.calibration.p_range[1],
                   interpolation="nearest")
    ax.set_ylabel("across strip (mm)")
    ax.set_title(f"film pressure ({fp.calibration.name})" + _suspect_note(fp.warnings, "summary.json"))
    fig.colorbar(im, ax=[ax, ax2], label=f"pressure ({fp.unit})", shrink=0.9)
    # rows="centre" (--rows centre) reads the one row through the peak, not the rows' mean
    ax2.plot(fp.s_mm, fp.pressure, "k-", lw=1.2,
             label="row through the peak" if "rows" in (fp.region or {}) else "mean across width")
    if fp.band_lo is not None:
        ax2.fill_between(fp.s_mm, fp.band_lo, fp.band_hi, color="0.7", alpha=0.6,
                         label="calibration 90 % band")
    ax2.set_xlabel("s (mm)")
    ax2.set_ylabel(f"P ({fp.unit})")
    ax2.legend(fontsize=8)
    return _save(fig, path)


def _suspect_note(warnings, where: str) -> str:
    """A second title line for a suspect result (its figure was titled as any other)."""
    n = len(warnings or [])
    return f"\nSUSPECT: {n} warning{'s' if n > 1 else ''} in {where}" if n else ""


def calibration_plot(cal, path) -> Path:
    """Presses, the selected fit and its 90 % confidence band, and residuals."""
    plt = _plt()
    pts = cal.report.get("points", {})
    g = np.linspace(*cal.gs_range, 200)
    # constrained layout: the residuals' wider tick labels pushed their y-label off the left edge
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(6, 6), sharex=True, layout="constrained",
                                  gridspec_kw={"height_ratios": [2, 1]})
    if pts:
        ax.plot(pts["gray"], pts["pressure"], "o", label="presses (F/A)")
    ax.plot(g, cal.pressure(g), "-", label=f"{cal.model} fit")
    band = cal.band(g)
    if band is not None:
        ax.fill_between(g, band[0], band[1], alpha=0.3, label="90 % confidence band")
    ax.set_ylabel(f"P ({cal.unit})")
    # a name from a CSV called calibration.csv read "calibration calibration"
    name = cal.name if "calibration" in cal.name.lower() else f"calibration {cal.name}"
    ax.set_title(f"{name} ({cal.model} fit)")
    ax.legend(fontsize=8)
    res = cal.report.get("selected_fit", {}).get("residuals")
    if pts and res:
        ax2.axhline(0, color="0.5", lw=0.8)
        ax2.plot(pts["gray"], res, "o")
    ax2.set_xlabel("mean grayscale GS")
    ax2.set_ylabel(f"residual P - fit ({cal.unit})")
    fig.align_ylabels((ax, ax2))
    return _save(fig, path)


def overlay(comp, path) -> Path:
    """Film profile (two-sided and folded) against the simulated half profile, mirrored."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(comp.film_s, comp.film_p, color="0.6", lw=1, label="film (two-sided)")
    ax.plot(comp.film_fold_s, comp.film_fold_p, "b-", lw=1.6, label="film folded (s >= 0)")
    ax.plot(comp.sim_s, comp.sim_p, "r--", lw=1.6, label="simulation")
    ax.plot(-comp.sim_s, comp.sim_p, "r--", lw=0.8, alpha=0.5)
    d = comp.percent_diff
    ax.set_title(f"peak {d['peak']:+.1f} %, span {d['span_mm']:+.1f} %, area {d['auc']:+.1f} % "
                 "(sim vs film)" + _suspect_note(comp.warnings, "comparison.json"), fontsize=10)
    ax.set_xlabel("s (mm)")
    ax.set_ylabel(f"P (film {comp.film_unit}; simulation MPa)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, path)
