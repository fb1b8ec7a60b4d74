"""The paper's figures from sweep records: Fig. 10 (profiles), 11 (peak), 12 (span), 13 (AUC),
and the designer's figure: peak, span and AUC against thickness, one line per indenter and
material (metrics_vs_thickness), the one a thickness is chosen from.

Each figure is written as PNG and SVG (text kept as text), the designer's figure also as PDF. Sizes follow the grid: panels wrap
into rows of at most MAX_COLUMNS, so 11 thicknesses give a block, not a strip. Colours are
the Okabe-Ito palette (safe for the common colour-vision deficiencies), told apart by line
style and marker too. matplotlib runs on the Agg backend (no display).
"""

from __future__ import annotations

import io
from functools import partial
from pathlib import Path

import numpy as np

from tactileskin import quality
from tactileskin.cache import material_of
from tactileskin.fileio import atomic_write_bytes, make_dirs

INDENTER_ORDER = ("flat", "curved", "braille")
# Okabe & Ito (2008), "Color Universal Design": blue, vermillion, bluish green
COLOURS = {"flat": "#0072B2", "curved": "#D55E00", "braille": "#009E73"}
MATERIAL_MARKERS = ("o", "s", "^", "D", "v", "P")
MAX_COLUMNS = 4
FORMATS = ("png", "svg")  # raster for the report, vector (text kept as text)
# the designer's figure also as PDF; for the paper figures a PDF would add about as much as
# their SVG (2 s CPU over the five figures of an 18-case sweep, ~8 % of `./dev run`)
DESIGN_FORMATS = FORMATS + ("pdf",)
DESIGN_STEMS = ("metrics_vs_thickness",)


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.rcParams["svg.fonttype"] = "none"  # SVG text stays text (searchable, editable)
    plt.rcParams["pdf.fonttype"] = 3       # matplotlib default: subset Type 3 fonts (text stays text)
    return plt


def _grid(n: int, max_cols: int = MAX_COLUMNS) -> tuple[int, int]:
    """(rows, columns) of n panels wrapped at max_cols columns."""
    cols = max(1, min(n, max_cols))
    return -(-n // cols), cols


def _fit_width(fig) -> None:
    """Widen the figure to its suptitle and legends: constrained layout keeps the axes' labels
    inside, but a title or a legend below wider than the figure was cut at both sides (a one-panel
    sweep, 3.2 in wide: 'face mean pressure along the bone', 'bra' for 'braille 3d')."""
    r = fig.canvas.get_renderer()
    need = max([a.get_window_extent(r).width / fig.dpi for a in (fig._suptitle, *fig.legends) if a is not None],
               default=0.0)
    if need + 0.3 > fig.get_figwidth():
        fig.set_figwidth(need + 0.3)


def save_reproducibly(fig, buf, fmt: str, dpi: int) -> None:
    """fig.savefig into `buf`, the same bytes for the same figure: matplotlib stamps SVG and PDF
    with the date and salts SVG ids with a random hash, so a rerun's figures differed from the
    cached run's while its CSVs were byte-identical."""
    import matplotlib

    meta = {"svg": {"Date": None}, "pdf": {"CreationDate": None}}.get(fmt)
    with matplotlib.rc_context({"svg.hashsalt": "tactileskin"}):
        fig.savefig(buf, format=fmt, dpi=dpi, **({"metadata": meta} if meta else {}))


def _save(fig, out: Path, stem: str) -> list[Path]:
    paths = []
    try:
        for ext in DESIGN_FORMATS if stem in DESIGN_STEMS else FORMATS:
            p = out / f"{stem}.{ext}"
            buf = io.BytesIO()
            # every figure has constrained layout, which already keeps its labels inside; a
            # "tight" bounding box would draw each figure once more per format (~45 % of savefig)
            save_reproducibly(fig, buf, ext, 150)
            atomic_write_bytes(p, buf.getvalue())
            paths.append(p)
            # the layout the first format computed serves the others (positions move < 0.3 pt):
            # constrained layout per savefig was ~30 % of the figures' time
            fig.set_layout_engine("none")
    finally:  # a failed write (full disk) too: a notebook's pyplot keeps no figure of ours
        _plt().close(fig)
    return paths


def _axes_keys(records):
    mats = sorted({material_of(r) for r in records})
    thick = sorted({r.scene.thickness for r in records})
    return mats, thick


def _series(indenter: str, text: str, variant: str) -> str:
    """The name of a case within a (material, thickness) panel: indenter, Braille text and
    the variant's legend text (sweep.case_variant_labels, with units), so two depths are two series."""
    return indenter + (f" '{text}'" if text else "") + (f" {variant}" if variant else "")


def _variant_label(r) -> str:
    """A record's or row's variant as legends name it (its id suffix when it has no label)."""
    get = r.get if isinstance(r, dict) else (lambda k, d=None: getattr(r, k, d))
    return get("variant_label") or get("variant") or ""


def _row_labels(rows) -> dict:
    """(variant, dim) -> legend text of the rows' variants (one id suffix is "F0.03" in 2D and 3D:
    N/mm and N)."""
    return {(r.get("variant") or "", r.get("dim", 2)): _variant_label(r) for r in rows}


def _ind_name(r) -> str:
    label, text = r.scene.indenter_label(), r.scene.braille_text
    if text and label.endswith(f"[{text}]"):
        label = label[: -len(text) - 2]  # the text is named separately
    return _series(label, text, _variant_label(r))


def _order(indenter: str) -> int:
    return INDENTER_ORDER.index(indenter) if indenter in INDENTER_ORDER else len(INDENTER_ORDER)


_DASHES = ("-", "--", ":", "-.")
PROFILE_VIEW = (0.0, 8.0)   # Fig. 10's s axis (mm), the paper's; widened to show the loaded part of every profile
VIEW_FRACTION = 0.02        # ... where P >= this fraction of the profile's peak


def _profile_xlim(records) -> tuple[float, float]:
    """PROFILE_VIEW widened to every s where a profile reaches VIEW_FRACTION of its peak: a
    two-sided profile (a whole model: s < 0) or a wide pad's (s > 8) was cut at the view's ends."""
    lo, hi = PROFILE_VIEW
    for r in records:
        s, p = np.asarray(r.s, float), np.asarray(r.pressure, float)
        if p.size and p.max() > 0:
            loaded = s[p >= VIEW_FRACTION * p.max()]
            lo, hi = min(lo, float(loaded.min())), max(hi, float(loaded.max()))
    return lo, hi

_HATCHES = ("", "//", "..", "xx", "\\\\", "++")


def profiles_figure(records, out: Path) -> list[Path]:
    """Fig. 10 style: P(s) along the bone (the bonded surface of the figure's skins); one panel
    per (material, thickness), thicknesses in rows of at most MAX_COLUMNS per material; one y
    axis for all (they are compared)."""
    plt = _plt()
    mats, thick = _axes_keys(records)
    rows_per_mat, cols = _grid(len(thick))
    nrows = rows_per_mat * len(mats)
    fig, axes = plt.subplots(nrows, cols, figsize=(3.2 * cols, 2.5 * nrows + 0.6),
                             squeeze=False, sharex=True, sharey=True, constrained_layout=True)
    variants = sorted({getattr(r, "variant", "") for r in records})
    dims = sorted({r.scene.dim for r in records})  # 2D ridge and 3D dots: told apart
    used = set()
    legend = {}  # every panel's series, not the first panel's: a case may be missing from it
    xlim = _profile_xlim(records)
    # s and its path as the figure's skins define them (a pad has no bone: s = x on the board)
    kinds = sorted({r.scene.skin_kind for r in records}, key=lambda k: k.order)
    xlabel = "; ".join(dict.fromkeys(k.s_axis for k in kinds)) + " (mm)"
    paths = {k.s_path for k in kinds}
    path = paths.pop() if len(paths) == 1 else "the bonded surface"
    for i, m in enumerate(mats):
        for j, t in enumerate(thick):
            ax = axes[i * rows_per_mat + j // cols][j % cols]
            used.add(id(ax))
            order = lambda r: (_order(r.scene.indenter.value), r.scene.braille_text,  # noqa: E731
                               getattr(r, "variant", ""), r.scene.dim)
            for r in sorted((r for r in records if material_of(r) == m and r.scene.thickness == t), key=order):
                k = variants.index(getattr(r, "variant", "")) + len(variants) * dims.index(r.scene.dim)
                name = _ind_name(r) + (f" {r.scene.dim}d" if len(dims) > 1 else "")
                line, = ax.plot(r.s, r.pressure, _DASHES[k % len(_DASHES)], color=COLOURS.get(r.scene.indenter.value),
                                label=name)
                legend.setdefault(name, (order(r), line))
            ax.set_title(f"{m}, t = {t:g} mm", fontsize=9)
            ax.axhline(0, color="0.7", lw=0.5)
            ax.set_xlim(*xlim)
            if j % cols == 0:
                ax.set_ylabel("mean pressure P (MPa)")
            ax.set_xlabel(xlabel)
            ax.label_outer()
    for row in axes:
        for ax in row:
            if id(ax) not in used:
                ax.set_visible(False)
    labels = sorted(legend, key=lambda n: legend[n][0])
    if labels:
        fig.legend([legend[n][1] for n in labels], labels, loc="outside lower center", ncols=min(len(labels), 4),
                   fontsize=8)
    fig.suptitle(f"Subsurface mean pressure along {path} (cf. paper Fig. 10)", fontsize=10)
    _fit_width(fig)
    return _save(fig, out, "fig10_profiles")


def metric_figure(rows: list[dict], metric: str, ylabel: str, stem: str, title: str, out: Path) -> list[Path]:
    """Fig. 11-13 style grouped bars: x thickness, one bar per case (indenter, Braille text,
    variant) at each thickness, one panel per material."""
    plt = _plt()
    mats = sorted({r["material"] for r in rows})
    thick = sorted({r["thickness_mm"] for r in rows})
    key = lambda r: (_order(r["indenter"]), r.get("braille_text") or "", r.get("variant") or "",  # noqa: E731
                     r.get("dim", 2))
    # the series with an ok case: one that only failed or is suspect has no bar to name
    series = sorted({key(r) + (r["indenter"],) for r in rows if r.get("status", "ok") == "ok"})
    variants = sorted({r.get("variant") or "" for r in rows})
    dims = {r.get("dim", 2) for r in rows}
    dim_list = sorted(dims)  # the 2D ridge and the 3D dots: one colour, told apart by hatch
    nrows, cols = _grid(len(mats), 2)
    width = float(np.clip(1.2 + 0.22 * len(thick) * max(len(series), 1), 3.6, 7.5))  # per panel
    fig, axes = plt.subplots(nrows, cols, figsize=(width * cols, 3.2 * nrows + 0.5), squeeze=False,
                             sharey=True, constrained_layout=True)
    for ax in axes.flat[len(mats):]:  # the panels past the last material (per row, none was: 3 on 2 x 2)
        ax.set_visible(False)
    w = 0.8 / max(len(series), 1)
    vlabel = _row_labels(rows)
    for k, m in enumerate(mats):
        ax = axes[k // cols][k % cols]
        for q, (*sk, ind) in enumerate(series):
            vals = []
            for t in thick:
                v = [r[metric] for r in rows if r["material"] == m and r["thickness_mm"] == t
                     and list(key(r)) == sk and r.get("status", "ok") == "ok"]
                vals.append(v[0] if v else np.nan)
            ax.bar(np.arange(len(thick)) + (q - (len(series) - 1) / 2) * w, vals, w,
                   label=_series(ind, sk[1], vlabel[(sk[2], sk[3])]) + (f" {sk[3]}d" if len(dims) > 1 else ""),
                   color=COLOURS.get(ind),
                   hatch=_HATCHES[(variants.index(sk[2]) + len(variants) * dim_list.index(sk[3])) % len(_HATCHES)])
        ax.set_xticks(np.arange(len(thick)), [f"{t:g}" for t in thick],
                      rotation=45 if len(thick) > 8 else 0)
        ax.set_xlabel("skin thickness t (mm)")
        ax.set_title(m, fontsize=9)
        if k % cols == 0:
            ax.set_ylabel(ylabel)
    handles, labels = axes[0][0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncols=min(len(labels), 4), fontsize=8)
    fig.suptitle(title, fontsize=10)
    _fit_width(fig)
    return _save(fig, out, stem)


METRICS = (("peak_mpa", "peak P (MPa)"), ("span_mm", "span (mm)"), ("auc_mpa_mm", "area under P(s) (MPa mm)"))


def thickness_figure(rows: list[dict], out: Path) -> list[Path]:
    """Peak, span and AUC against skin thickness: one panel per metric, one line per
    indenter (colour) and material, Braille text and case variant (marker, line style); ok cases only.
    The figure a thickness is chosen from (docs/metrics.md)."""
    plt = _plt()
    ok = [r for r in rows if r.get("status", "ok") == "ok" and r.get("peak_mpa") is not None]
    mats = sorted({r["material"] for r in ok})
    dims = {r.get("dim", 2) for r in ok}
    key = lambda r: (_order(r["indenter"]), r["indenter"], r.get("braille_text") or "",  # noqa: E731
                     r.get("variant") or "", r.get("dim", 2), r["material"])
    series = sorted({key(r) for r in ok})
    vlabel = _row_labels(ok)
    # one style per (material, text, variant, dim), the colour naming the indenter: by material
    # alone, two forces of one indenter were identical markers (at one thickness, no line)
    looks = sorted({(sk[5], sk[2], sk[3], sk[4]) for sk in series}, key=lambda x: (mats.index(x[0]), x[1:]))
    fig, axes = plt.subplots(1, len(METRICS), figsize=(4.0 * len(METRICS), 3.4), squeeze=False,
                             constrained_layout=True)
    for ax, (metric, label) in zip(axes[0], METRICS):
        for sk in series:
            pts = sorted((r["thickness_mm"], r[metric]) for r in ok if key(r) == sk)
            if not pts:
                continue
            _, ind, text, variant, dim, mat = sk
            j = looks.index((mat, text, variant, dim))  # = the material's index without variants
            t, v = zip(*pts)
            ax.plot(t, v, _DASHES[j % len(_DASHES)], marker=MATERIAL_MARKERS[j % len(MATERIAL_MARKERS)],
                    fillstyle="full" if (j // len(MATERIAL_MARKERS)) % 2 == 0 else "none",
                    color=COLOURS.get(ind), ms=4,
                    label=f"{_series(ind, text, vlabel[(variant, dim)])}{f' {dim}d' if len(dims) > 1 else ''}, {mat}")
        ax.set_xlabel("skin thickness t (mm)")
        ax.set_ylabel(label)
        ax.set_ylim(bottom=0)
        ax.grid(True, lw=0.3, color="0.85")
    handles, labels = axes[0][0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncols=min(len(labels), 3), fontsize=8)
    fig.suptitle("Bone-pressure metrics against skin thickness", fontsize=10)
    _fit_width(fig)
    return _save(fig, out, "metrics_vs_thickness")


FIGURES_SCHEMA = 2  # the layout of figures_key's payload

# row and summary fields no figure draws that change between two runs of the same case (the
# solve's wall time, whether this run solved it or read it from the cache): in the key, a case
# solved again with the same numbers, or cached on a rerun, redrew every figure
UNDRAWN_FIELDS = frozenset({"wall_s", "source"})


def _drawn_fields(d: dict) -> dict:
    return {k: v for k, v in d.items() if k not in UNDRAWN_FIELDS}


def drawing_digest() -> str:
    """SHA-256 of what, besides its data, a matplotlib figure of this package is drawn by: the
    package code (cache.code_digest: the figure and render modules' bytes among the rest),
    matplotlib's and Pillow's versions, matplotlib's settings (as _plt sets them) and the bytes
    of the font files it draws with (not their sizes: a font replaced by another of the same size
    kept the old figures; ~2 ms a call)."""
    import hashlib
    import json
    from importlib import metadata

    import matplotlib
    from matplotlib import font_manager

    from tactileskin.cache import code_digest
    from tactileskin.fileio import file_sha256

    # as _plt sets them for the drawing, whether or not this process drew a figure before; not
    # the backend (Agg draws every figure here), whose value read imports pyplot (~0.5 s of a
    # cached rerun, which draws nothing)
    rc = {k: repr(matplotlib.rcParams[k]) for k in matplotlib.rcParams if not k.startswith("backend")}
    rc.update({"svg.fonttype": repr("none"), "pdf.fonttype": repr(3)})
    fonts = sorted({font_manager.findfont(font_manager.FontProperties(family=[f]))
                    for f in [*matplotlib.rcParams["font.family"], "DejaVu Sans"]})
    payload = [FIGURES_SCHEMA, code_digest(), matplotlib.__version__, metadata.version("pillow"), rc,
               [(f, file_sha256(f)) for f in fonts]]
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


def figures_key(records, rows) -> str:
    """A name for the figures all_figures draws of (records, rows): the SHA-256 of everything
    they are drawn from (every row's fields; each record's case, variant, scene, profile and
    summary, but for UNDRAWN_FIELDS) and by (drawing_digest). Equal keys give byte-identical
    files (save_reproducibly), so a cached rerun copies the files from the cache
    (report.outputs) instead of drawing them again (~3 s of a preview sweep)."""
    import hashlib
    import json

    h = hashlib.sha256(drawing_digest().encode() + b"\0")

    def add(x) -> None:
        h.update(json.dumps(x, sort_keys=True, default=repr).encode() + b"\0")

    add([_drawn_fields(r) for r in rows])
    for r in records:
        add([r.case, getattr(r, "variant", ""), r.scene.to_dict(), _drawn_fields(r.summary)])
        h.update(np.ascontiguousarray(r.s, dtype=float).tobytes() + b"\0"
                 + np.ascontiguousarray(r.pressure, dtype=float).tobytes() + b"\0")
    return h.hexdigest()[:24]


def figure_jobs(records, rows) -> list:
    """Every sweep figure as a function of the folder it is written to (returning its files),
    in all_figures' order. Like the bar and thickness figures (rows of status ok), Fig. 10
    draws the ok results only: a suspect profile is not a result to compare with (it is in
    the tables, marked)."""
    if not any(r.get("status", "ok") == "ok" for r in rows):
        return []  # no ok case: every figure would be empty axes under a legend
    jobs = [partial(thickness_figure, rows)]
    ok = [r for r in records if quality.status(r.summary) == "ok"]
    if ok:
        jobs.append(partial(profiles_figure, ok))
    jobs += [partial(metric_figure, rows, "peak_mpa", "peak P (MPa)", "fig11_peak", "Peak pressure (cf. Fig. 11)"),
             partial(metric_figure, rows, "span_mm", "span (mm)", "fig12_span", "Span of the pressure profile (cf. Fig. 12)"),
             partial(metric_figure, rows, "auc_mpa_mm", "area under P(s) (MPa mm)", "fig13_auc",
                     "Area under the curve (cf. Fig. 13)")]
    return jobs


def all_figures(records, rows, out: Path) -> list[Path]:
    """Every sweep figure (figure_jobs) written into `out`."""
    make_dirs(out)
    return [p for job in figure_jobs(records, rows) for p in job(out)]
