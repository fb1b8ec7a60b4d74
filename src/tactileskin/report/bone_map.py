"""Figure of a 3D result's bone-pressure map P(s, z) (matplotlib, Agg backend)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from tactileskin.fileio import atomic_write_bytes


def write_bone_map_figure(bone_map, path, title: str = "") -> Path:
    """Write `bone_map` (results.BoneMap) as a PNG: P over (s, z) in mm, equal aspect,
    viridis (perceptually uniform), colour bar "P (MPa)", the section plane dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s, z, P = bone_map.s, bone_map.z, bone_map.pressure
    ratio = float(np.ptp(z)) / max(float(np.ptp(s)), 1e-9)
    fig, ax = plt.subplots(figsize=(8.0, float(np.clip(6.0 * ratio + 1.6, 2.4, 8.0))), constrained_layout=True)
    try:
        # gouraud: the colour at each grid point is its value (no cell-centre shift on the
        # non-uniform s grid); one row (a single z) cannot be shaded, so it is drawn as cells
        shading = "gouraud" if len(z) > 1 and len(s) > 1 else "nearest"
        im = ax.pcolormesh(s, z, P, cmap="viridis", shading=shading, vmin=min(0.0, float(P.min())))
        ax.axhline(bone_map.section_z, color="tab:red", lw=1.0, ls="--", label="section plane (profile.csv)")
        ax.set_aspect("equal")
        ax.set_xlabel("s (mm)")
        ax.set_ylabel("z (mm)")
        if title:
            ax.set_title(title, loc="left")
        ax.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize="small", frameon=False)
        fig.colorbar(im, ax=ax, label="P (MPa)", fraction=0.05, pad=0.02)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=150)
    finally:
        plt.close(fig)
    return atomic_write_bytes(path, buf.getvalue())
