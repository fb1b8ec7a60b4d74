"""The printable part set: skin, rigid base, casting mold halves and indenters.

`build_parts` turns the user's choices (thickness, indenters, Braille text and standard)
into named build123d solids; `export.export_parts` writes and checks them.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

from tactileskin import params
from tactileskin.errors import ParameterError
from tactileskin.geometry import braille as _braille
from tactileskin.geometry.fingertip import Fingertip
from tactileskin.geometry.indenters import KINDS, PAPER_KINDS, get_kind, make_indenter
from tactileskin.geometry.occ import bd

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Part:
    name: str                      # file stem in the output folder
    description: str
    shape: bd.Solid
    parameters: dict = field(default_factory=dict)  # what the part was made from (manifest)


def default_thickness() -> float:
    return float(params.load("fingertip")["thickness"]["default"])


def resolve_indenters(indenters) -> tuple[str, ...]:
    """'all' -> every kind; a kind or an iterable of kinds -> validated tuple; None/'none' -> ()."""
    if indenters is None or indenters == "none":
        return ()
    if indenters == "all":
        return PAPER_KINDS
    kinds = (indenters,) if isinstance(indenters, str) else tuple(indenters)
    for k in kinds:
        if k not in KINDS:
            raise ParameterError("indenter", k, "one of " + ", ".join(KINDS + ("all", "none")))
    return kinds


def _covering(ind, min_width: float):
    """The indenter with a plate face (flat, Braille's base plate) at least `min_width` wide in
    x: the solver presses the skin's whole width with it (a plane), so the printed part must."""
    import dataclasses

    if min_width > 0 and ind.kind in ("flat", "braille") and getattr(ind, "width", 0.0) < min_width:
        return dataclasses.replace(ind, width=float(min_width))
    return ind


def build_parts(thickness: float | None = None, *, indenters="all", braille_text: str = "",
                braille_standard: str = "standard_american", fingertip: bool = True, molds: bool = True,
                fingertip_overrides: dict | None = None, indenter_params: dict | None = None,
                skin_scene=None) -> list[Part]:
    """Build the requested parts (full width) for skin thickness `thickness` (mm).

    "all" indenters are the paper's (flat, curved, braille); other kinds are named and take
    their parameters from `indenter_params` (e.g. {"indenter_radius": 2.5}). `skin_scene`: the
    indenters are for that skin (a pad, a dome: a Scene) as its solver sees them, not for the
    fingertip: lowest point on its top, as long as its sample, plate faces at least as wide.

    Parameters are validated before any CAD work, so a bad value costs no kernel time.
    Raises ParameterError for invalid inputs and CadError if the kernel fails.
    """
    from tactileskin.geometry import molds as _molds
    from tactileskin.geometry import solids

    ft = Fingertip.from_params(**(fingertip_overrides or {}))
    t = default_thickness() if thickness is None else thickness
    sec = ft.section(t)  # validates t
    kinds = resolve_indenters(indenters)
    if "braille" in kinds:
        _braille.get_standard(braille_standard)
        if braille_text:
            _braille.check_text(braille_text)
    opts = {"braille_text": braille_text, "braille_standard": braille_standard, **(indenter_params or {})}
    y0, length, min_width = sec.top, ft.sample_length, 0.0
    if skin_scene is not None:
        skin_sec = skin_scene.section()
        y0, length, min_width = skin_sec.top, skin_scene.sample_length, 2.0 * float(skin_sec.half_width)
    inds = [(kind, _covering(make_indenter(kind, y0=y0, dim=3, sample_length=length,
                                           **{k: v for k, v in opts.items() if k in get_kind(kind).scene_params}),
                             min_width))
            for kind in kinds]  # validates every kind's parameters before any CAD work
    mold_params = _molds.MoldParams.from_params() if molds else None
    if mold_params is not None:
        mold_params.check(sec)

    parts: list[Part] = []
    fp = dict(thickness=sec.thickness, sample_length=ft.sample_length, half_width=ft.half_width,
              height=ft.height, nail_angle_deg=ft.nail_angle_deg)
    t0 = time.perf_counter()
    if fingertip or molds:
        base = solids.base_solid(sec)
    if fingertip:
        parts.append(Part("skin", f"skin, t = {sec.thickness:g} mm (cast in the mold)", solids.skin_solid(sec), fp))
        parts.append(Part("rigid_base", "rigid bone/nail base (mold core)", base, fp))
    if molds:
        lower, upper = _molds.skin_mold(sec, mold_params)
        mp = dict(fp, **{k: getattr(mold_params, k) for k in ("wall", "pin_diameter", "pour_diameter", "vent_diameter",
                                                          "core_clearance")})
        parts.append(Part("mold_lower", "casting mold, lower half (holds the base, pins)", lower, mp))
        parts.append(Part("mold_upper", "casting mold, upper half (sprue near one end, vent near the other)", upper, mp))
    log.info("fingertip parts in %.2f s", time.perf_counter() - t0)
    for kind, ind in inds:
        t1 = time.perf_counter()
        ip = dict(kind=kind, y0=ind.y0, width=ind.width, length=ind.length,
                  stem_diameter=ind.stem_diameter, stem_length=ind.stem_length, **ind.part_parameters())
        desc = ind.describe()
        parts.append(Part(f"indenter_{kind}", desc, solids.indenter_solid(ind), ip))
        log.info("%s indenter in %.2f s", kind, time.perf_counter() - t1)
    return parts
