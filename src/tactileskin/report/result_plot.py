"""Result.plot(): a matplotlib figure of one solve (the bone profile; in 3D also the map)."""

from __future__ import annotations

import io
from pathlib import Path

from tactileskin import quality
from tactileskin.errors import ParameterError
from tactileskin.fileio import atomic_write_bytes

FORMATS = ("png", "svg", "pdf")
PROFILE_TITLE_WIDTH = {False: 60, True: 48}  # characters of the title's status lines (2D, 3D)


def _label(result) -> str:
    sc = result.scene or {}
    if "thickness" not in sc:
        return "bone pressure"
    from tactileskin.scene import material_labels

    mat = str(sc.get("material", "?"))
    # a file by its name, not its path (the user's folders), as the sweep's tables name it
    mat = material_labels([mat])[mat]
    return f"t = {sc['thickness']:g} mm, {mat}, {sc.get('indenter', '?')} ({sc.get('dim', 2)}D)"


def _s_label(result) -> str:
    """What s is on the result's skin (Skin.s_axis): arc length along the bone on the fingertip,
    x across the board on a pad, x - x_top on a user's file."""
    from tactileskin import skins

    try:
        kind = skins.get((result.scene or {}).get("skin") or "fingertip")
    except ParameterError:  # a skin this version does not know (a result file from another)
        return "s (mm)"
    return f"{kind.s_axis} (mm)"


def plot_result(result, path=None, *, ax=None):
    """(figure, axes) of `result`: P(s) along the bonded surface; a 3D result with a bone map adds the
    maximum over z (dashed) and a second panel, the map P(s, z) (viridis, colour bar in MPa).
    `ax` draws the profile into the caller's axes (2D results only). `path` also writes the
    figure (atomically; .png, .svg or .pdf)."""
    import matplotlib.pyplot as plt

    if path is not None:
        path = Path(path)
        fmt = path.suffix.lower().lstrip(".")
        if fmt not in FORMATS:
            raise ParameterError("plot path suffix", path.suffix, ", ".join("." + f for f in FORMATS))
    bmap = result.bone_map
    if ax is not None:
        if bmap is not None:
            raise ParameterError("ax", "given for a 3D result", "None (a 3D result draws two panels)")
        fig, axes = ax.figure, ax
        pax = ax
    elif bmap is None:
        fig, axes = plt.subplots(figsize=(6.0, 3.8), constrained_layout=True)
        pax = axes
    else:
        fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.0), constrained_layout=True)
        pax = axes[0]
    s, p = result._profile()
    plane = result.stats.get("profile_plane_z")
    pax.plot(s, p, color="#0072B2", lw=1.6,
             label="section plane z = %g mm" % plane if plane is not None else "P(s)")
    pax.set_xlabel(_s_label(result))
    pax.set_ylabel("mean pressure P (MPa)")
    # a suspect result's figure says so (it was titled as an ok one's); narrower in 3D, the
    # profile is the left of two panels
    pax.set_title(quality.suspect_title(_label(result), result.status, width=PROFILE_TITLE_WIDTH[bmap is not None]),
                  loc="left", fontsize="medium")
    pax.grid(alpha=0.3)
    if bmap is not None:
        ms, mp, _ = bmap.max_over_z()
        pax.plot(ms, mp, color="#D55E00", lw=1.4, ls="--", label="maximum over z")
        pax.legend(fontsize="small")
        mx = axes[1]
        shading = "gouraud" if len(bmap.z) > 1 and len(bmap.s) > 1 else "nearest"
        im = mx.pcolormesh(bmap.s, bmap.z, bmap.pressure, cmap="viridis", shading=shading)
        mx.axhline(bmap.section_z, color="white", lw=0.8, ls="--")
        mx.set_aspect("equal")
        mx.set_xlabel("s (mm)")
        mx.set_ylabel("z (mm)")
        mx.set_title("bone pressure P(s, z); dashed: section plane", loc="left", fontsize="medium")
        fig.colorbar(im, ax=mx, label="P (MPa)")
    if path is not None:
        from tactileskin.report.figures import save_reproducibly

        buf = io.BytesIO()
        save_reproducibly(fig, buf, fmt, 150)
        atomic_write_bytes(path, buf.getvalue())
    return fig, axes
