"""The paper's figures from sweep records: Fig. 10 (profiles), 11 (peak), 12 (span), 13 (AUC).

Each figure is written as PNG and SVG. matplotlib runs on the Agg backend (no display).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from tactileskin.fileio import atomic_write_bytes, make_dirs

INDENTER_ORDER = ("flat", "curved", "braille")
COLOURS = {"flat": "#1f77b4", "curved": "#d62728", "braille": "#2ca02c"}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, out: Path, stem: str) -> list[Path]:
    paths = []
    for ext in ("png", "svg"):
        p = out / f"{stem}.{ext}"
        buf = io.BytesIO()
        fig.savefig(buf, format=ext, dpi=150, bbox_inches="tight")
        atomic_write_bytes(p, buf.getvalue())
        paths.append(p)
    _plt().close(fig)
    return paths


def _axes_keys(records):
    mats = sorted({r.scene.material for r in records})
    thick = sorted({r.scene.thickness for r in records})
    return mats, thick


def _series(indenter: str, text: str, variant: str) -> str:
    """The name of a case within a (material, thickness) panel: indenter, Braille text and
    the case id's variant suffix (sweep.case_variants), so two depths are two series."""
    return indenter + (f" '{text}'" if text else "") + (f" {variant}" if variant else "")


def _ind_name(r) -> str:
    label, text = r.scene.indenter_label(), r.scene.braille_text
    if text and label.endswith(f"[{text}]"):
        label = label[: -len(text) - 2]  # the text is named separately
    return _series(label, text, getattr(r, "variant", ""))


def _order(indenter: str) -> int:
    return INDENTER_ORDER.index(indenter) if indenter in INDENTER_ORDER else len(INDENTER_ORDER)


_DASHES = ("-", "--", ":", "-.")
_HATCHES = ("", "//", "..", "xx", "\\\\", "++")


def profiles_figure(records, out: Path) -> list[Path]:
    """Fig. 10 style: P(s) along the bone; rows materials, columns thicknesses."""
    plt = _plt()
    mats, thick = _axes_keys(records)
    fig, axes = plt.subplots(len(mats), len(thick), figsize=(3.6 * len(thick), 2.8 * len(mats)),
                             squeeze=False, sharex=True)
    for i, m in enumerate(mats):
        for j, t in enumerate(thick):
            ax = axes[i][j]
            variants = sorted({getattr(r, "variant", "") for r in records})
            dims = sorted({r.scene.dim for r in records})  # 2D ridge and 3D dots: told apart
            for r in sorted((r for r in records if r.scene.material == m and r.scene.thickness == t),
                            key=lambda r: (_order(r.scene.indenter.value), r.scene.braille_text,
                                           getattr(r, "variant", ""), r.scene.dim)):
                k = variants.index(getattr(r, "variant", "")) + len(variants) * dims.index(r.scene.dim)
                ax.plot(r.s, r.pressure, _DASHES[k % len(_DASHES)], color=COLOURS.get(r.scene.indenter.value),
                        label=_ind_name(r) + (f" {r.scene.dim}d" if len(dims) > 1 else ""))
            ax.set_title(f"{m}, t = {t:g} mm", fontsize=9)
            ax.axhline(0, color="0.7", lw=0.5)
            ax.set_xlim(0, 8)
            if j == 0:
                ax.set_ylabel("mean pressure P (MPa)")
            if i == len(mats) - 1:
                ax.set_xlabel("distance along bone s (mm)")
    axes[0][0].legend(fontsize=8)
    fig.suptitle("Subsurface mean pressure along the bone (cf. paper Fig. 10)", fontsize=10)
    return _save(fig, out, "fig10_profiles")


def metric_figure(rows: list[dict], metric: str, ylabel: str, stem: str, title: str, out: Path) -> list[Path]:
    """Fig. 11-13 style grouped bars: x thickness, one bar per case (indenter, Braille text,
    variant) at each thickness, one panel per material."""
    plt = _plt()
    mats = sorted({r["material"] for r in rows})
    thick = sorted({r["thickness_mm"] for r in rows})
    key = lambda r: (_order(r["indenter"]), r.get("braille_text") or "", r.get("variant") or "",  # noqa: E731
                     r.get("dim", 2))
    series = sorted({key(r) + (r["indenter"],) for r in rows})
    variants = sorted({r.get("variant") or "" for r in rows})
    dims = {r.get("dim", 2) for r in rows}
    fig, axes = plt.subplots(1, len(mats), figsize=(4.2 * len(mats), 3.2), squeeze=False)
    w = 0.8 / max(len(series), 1)
    for k, m in enumerate(mats):
        ax = axes[0][k]
        for q, (*sk, ind) in enumerate(series):
            vals = []
            for t in thick:
                v = [r[metric] for r in rows if r["material"] == m and r["thickness_mm"] == t
                     and list(key(r)) == sk and r.get("status", "ok") == "ok"]
                vals.append(v[0] if v else np.nan)
            ax.bar(np.arange(len(thick)) + (q - (len(series) - 1) / 2) * w, vals, w,
                   label=_series(ind, sk[1], sk[2]) + (f" {sk[3]}d" if len(dims) > 1 else ""),
                   color=COLOURS.get(ind),
                   hatch=_HATCHES[variants.index(sk[2]) % len(_HATCHES)])
        ax.set_xticks(np.arange(len(thick)), [f"{t:g} mm" for t in thick])
        ax.set_title(m, fontsize=9)
        ax.set_ylabel(ylabel)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    return _save(fig, out, stem)


def all_figures(records, rows, out: Path) -> list[Path]:
    make_dirs(out)
    paths = profiles_figure(records, out)
    paths += metric_figure(rows, "peak_mpa", "peak P (MPa)", "fig11_peak", "Peak pressure (cf. Fig. 11)", out)
    paths += metric_figure(rows, "span_mm", "span (mm)", "fig12_span", "Span of the pressure profile (cf. Fig. 12)", out)
    paths += metric_figure(rows, "auc", "area under P(s) (MPa mm)", "fig13_auc", "Area under the curve (cf. Fig. 13)", out)
    return paths
