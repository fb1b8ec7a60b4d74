"""Figure of a 3D result's bone-pressure map P(s, z) (matplotlib, Agg backend)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from tactileskin.fileio import atomic_write_bytes

LOADED_FRACTION = 0.01  # the zoomed panel shows where P >= 1 % of the map's peak


def loaded_box(bone_map, fraction: float = LOADED_FRACTION) -> tuple[float, float, float, float] | None:
    """(s0, s1, z0, z1) around the grid points with P >= fraction * peak, padded by a quarter
    of its size (at least 0.5 mm) and clipped to the map; None if the peak is not positive."""
    P = bone_map.pressure
    top = float(P.max())
    if top <= 0:
        return None
    j, i = np.nonzero(P >= fraction * top)
    s0, s1 = bone_map.s[i.min()], bone_map.s[i.max()]
    z0, z1 = bone_map.z[j.min()], bone_map.z[j.max()]
    ps, pz = max(0.25 * (s1 - s0), 0.5), max(0.25 * (z1 - z0), 0.5)
    s, z = bone_map.s, bone_map.z
    return (max(s0 - ps, s[0]), min(s1 + ps, s[-1]), max(z0 - pz, z[0]), min(z1 + pz, z[-1]))


def write_bone_map_figure(bone_map, path, title: str = "") -> Path:
    """Write `bone_map` (results.BoneMap) as a PNG: P over (s, z) in mm, equal aspect,
    viridis (perceptually uniform), colour bar "P (MPa)", the section plane dashed. When the
    load covers less than half of the surface in s or z (a Braille dot), a second panel
    zooms on it (`loaded_box`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s, z, P = bone_map.s, bone_map.z, bone_map.pressure
    box = loaded_box(bone_map)
    zoom = box is not None and ((box[1] - box[0]) < 0.5 * np.ptp(s) or (box[3] - box[2]) < 0.5 * np.ptp(z))
    ratio = float(np.ptp(z)) / max(float(np.ptp(s)), 1e-9)
    height = float(np.clip((4.0 if zoom else 6.0) * ratio + 1.6, 2.4, 6.0))
    fig, axes = plt.subplots(1, 2 if zoom else 1, figsize=(11.0 if zoom else 8.0, height),
                             constrained_layout=True, squeeze=False)
    try:
        # gouraud: the colour at each grid point is its value (no cell-centre shift on the
        # non-uniform s grid); a single row or column cannot be shaded, so it is drawn as cells
        shading = "gouraud" if len(z) > 1 and len(s) > 1 else "nearest"
        norm = matplotlib.colors.Normalize(vmin=min(0.0, float(P.min())), vmax=float(P.max()))
        for k, ax in enumerate(axes[0]):
            im = ax.pcolormesh(s, z, P, cmap="viridis", shading=shading, norm=norm)
            # over the spines (zorder 2.5) and unclipped: a centred dot's plane is z = 0, the
            # map's edge, where the spine covered the line the title names
            ax.axhline(bone_map.section_z, color="tab:red", lw=1.5, ls="--", zorder=3, clip_on=False)
            ax.set_aspect("equal")
            ax.set_xlabel("s (mm)")
            ax.set_ylabel("z (mm)")
            if k == 1:
                ax.set_xlim(box[0], box[1])
                ax.set_ylim(box[2], box[3])
                ax.set_title(f"where P >= {LOADED_FRACTION:.0%} of the peak", loc="left", fontsize="medium")
            else:
                ax.set_title("whole bone surface; dashed: section plane (profile.csv)", loc="left",
                             fontsize="medium")
        fig.suptitle(title or "bone pressure P(s, z)")
        fig.colorbar(im, ax=axes[0].tolist(), label="P (MPa)", fraction=0.05, pad=0.02)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=150)
    finally:
        plt.close(fig)
    return atomic_write_bytes(path, buf.getvalue())
