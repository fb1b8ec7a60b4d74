"""Figure of a result's sensor readings (sensors.SensorReadings): per layout, lines (points,
lines, and 2D) as P, -sigma_nn, tau_1, tau_2 against s; grids (3D) as a map of P over (s, z)
beside a map of -sigma_nn (matplotlib, Agg backend)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from tactileskin.fileio import atomic_write_bytes


def _is_grid(r) -> bool:
    s, z = np.unique(np.round(r.s, 9)), np.unique(np.round(r.xyz[:, 2], 9))
    return len(s) > 1 and len(z) > 1 and len(s) * len(z) == len(r)


def write_sensors_figure(readings, path, title: str = "") -> Path:
    """Write one row of panels per layout of `readings` as a PNG (compression positive)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(dict.fromkeys(readings.layout))
    fig, axes = plt.subplots(len(names), 2, figsize=(10.0, 3.4 * len(names)), constrained_layout=True,
                             squeeze=False)
    try:
        for row, name in zip(axes, names):
            r = readings.select(name)
            depth = float(r.depth[0])
            label = f"layout {name!r}, depth {depth:.3g} mm"
            if _is_grid(r):
                s, z = np.unique(np.round(r.s, 9)), np.unique(np.round(r.xyz[:, 2], 9))
                for ax, q, what in ((row[0], r.pressure, "P (MPa)"), (row[1], -r.sigma_nn, "-sigma_nn (MPa)")):
                    im = ax.pcolormesh(s, z, q.reshape(len(z), len(s)), cmap="viridis", shading="nearest")
                    ax.set_aspect("equal")
                    ax.set_xlabel("s (mm)")
                    ax.set_ylabel("z (mm)")
                    ax.set_title(f"{label}: {what}", loc="left", fontsize="medium")
                    fig.colorbar(im, ax=ax, label=what, fraction=0.05, pad=0.02)
                continue
            order = np.argsort(r.s, kind="stable")
            s = r.s[order]
            row[0].plot(s, r.pressure[order], "o-", ms=3, label="P = -tr(sigma)/3")
            row[0].plot(s, -r.sigma_nn[order], "s-", ms=3, label="-sigma_nn")
            row[1].plot(s, r.tau_1[order], "o-", ms=3, label="tau_1 (along s)")
            row[1].plot(s, r.tau_2[order], "s-", ms=3, label="tau_2 (along z)")
            for ax, what in ((row[0], "normal (MPa)"), (row[1], "shear (MPa)")):
                ax.axhline(0.0, color="0.6", lw=0.8)
                ax.set_xlabel("s (mm)")
                ax.set_ylabel(what)
                ax.set_title(label, loc="left", fontsize="medium")
                ax.legend(fontsize="small")
        fig.suptitle(title or "sensor readings")
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=130)
    finally:
        plt.close(fig)
    return atomic_write_bytes(path, buf.getvalue())
