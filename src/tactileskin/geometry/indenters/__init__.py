"""Rigid indenters: each kind an object that answers for itself (pure numpy).

The contract is `base.Indenter` (gap function, symmetry, 2D model, contact extent, label,
printable solid); the kinds live one per module here and register themselves in
`registry` (flat, curved, braille: the paper's; cylinder, sphere, file). The dimensions of
the paper's kinds come from data/geometry/indenters.toml and braille.toml, the same numbers
the CAD solids are built from. See docs/architecture.md, "geometry.indenters".
"""

from __future__ import annotations

import logging
import math

import numpy as np

from tactileskin import params
from tactileskin.errors import ParameterError, check_range
from tactileskin.geometry.indenters import registry
from tactileskin.geometry.indenters.base import KIND_FIELDS, Indenter, hertz_halfwidth  # noqa: F401
from tactileskin.geometry.indenters.registry import get as get_kind  # noqa: F401

KINDS = registry.names()  # imports every kind module
from tactileskin.geometry.indenters.braille import BrailleIndenter  # noqa: E402,F401
from tactileskin.geometry.indenters.cylinder import CurvedIndenter, CylinderIndenter  # noqa: E402,F401
from tactileskin.geometry.indenters.file import FileIndenter  # noqa: E402,F401
from tactileskin.geometry.indenters.flat import FlatIndenter  # noqa: E402,F401
from tactileskin.geometry.indenters.sphere import SphereIndenter  # noqa: E402,F401

log = logging.getLogger(__name__)

PAPER_KINDS = tuple(k for k in KINDS if get_kind(k).paper)


def _sample_length() -> float:
    return float(params.load("fingertip")["sample"]["length"])


def scene_kind_params(scene) -> dict:
    """The Scene fields the scene's indenter kind reads, by name."""
    return {f: getattr(scene, f) for f in get_kind(scene.indenter).scene_params}


def make_indenter(kind, *, y0: float | None = None, dim: int = 2, row: int | None = None,
                  sample_length: float | None = None, warn: bool = True, **kind_params) -> Indenter:
    """Build the indenter of `kind` (a registered name) with lowest point y0.

    `kind` may also be a Scene, in which case everything comes from the scene (see
    `indenter_for_scene`). `kind_params` are the kind's Scene fields (braille_text,
    braille_standard, indenter_radius, indenter_axis, indenter_file). `row` picks the dot row
    of the 2D Braille section (default the row nearest z = 0). `sample_length` (default
    fingertip.toml [sample] length) is the z extent of the face plates. warn=False keeps a
    kind's warnings (an asymmetric Braille section) for the solve that uses it.
    """
    if hasattr(kind, "indenter") and hasattr(kind, "section"):
        return indenter_for_scene(kind, row=row, warn=warn)
    cls = get_kind(kind)
    if y0 is None:
        raise ParameterError("y0", None, "a finite number (mm): the skin top on x = 0")
    y0 = check_range("y0", y0, -1e6, 1e6, unit="mm")
    if dim not in (2, 3):
        raise ParameterError("dim", dim, "2 or 3")
    length = _sample_length() if sample_length is None else check_range(
        "sample_length", sample_length, 0.0, None, lo_open=True, unit="mm")
    return cls.from_params(y0=y0, dim=dim, length=length, row=row, warn=warn, **kind_params)


def indenter_for_scene(scene, *, row: int | None = None, warn: bool = True, lift: float = 0.0) -> Indenter:
    """The scene's indenter; its lowest point initially touches the skin top on x = 0 (raised
    by `lift` mm: fe.model_for_scene's start at first touch on a skin higher off the axis)."""
    # (no half-section warning for a skin that models its full width for such an indenter)
    warn = warn and not scene.skin_kind.full_width_if_asymmetric
    return make_indenter(scene.indenter, y0=scene.section().top + lift, dim=scene.dim, row=row,
                         sample_length=scene.sample_length, warn=warn,
                         **scene_kind_params(scene))


# an initial overlap of the indenter and the skin below this fraction of the travel is left
# (below the contact tolerance's own cap, fe.model.TOL_TRAVEL)
START_OVERLAP = 1e-3


def at_first_touch(scene, ind: Indenter, points) -> Indenter:
    """`ind` (the scene's indenter_for_scene), or, where the skin's contact `points` (n, dim)
    overlap it by more than START_OVERLAP of the travel, the same raised to first touch, with a
    warning: a user's skin may stand higher off the indenters' axis than on it (skins.file.AXIS_GAP
    allows 2 % of t), where a flat plate started inside it by that much. The solver
    (fe.model_for_scene) and the decks (mesh.deck) start it alike. Built-in skins never overlap
    (their top is the highest point under every indenter)."""
    g0, _ = ind.gap(np.asarray(points, float).reshape(-1, scene.dim))
    overlap = -float(np.min(g0)) if g0.size else 0.0
    if not overlap > START_OVERLAP * scene.indentation:
        return ind
    log.warning("the skin's contact surface stands %.3g mm above its top point on the indenters' axis "
                "where the indenter (%s) meets it: it starts there, at first touch", overlap, scene.indenter_label())
    return indenter_for_scene(scene, lift=overlap, warn=False)  # warned already, if at all


def indenter_symmetry(scene) -> tuple[bool, bool]:
    """(about x = 0, about z = 0): mirror symmetry of the scene's indenter where it can touch
    the skin within the travel its loading can reach (`Scene.reach`; the kind's answer). The
    one symmetry test of the 3D mesher and the planner."""
    return indenter_for_scene(scene, warn=False).symmetry(scene.reach)


def mirrored_x(scene) -> bool:
    """True if the scene's indenter is not mirror-symmetric about x = 0 where it can touch (2D:
    its section; Braille: the row's dots), so that a half model (x >= 0) solves it together
    with its mirror image, not as it is."""
    ind = indenter_for_scene(scene, warn=False)
    if scene.dim == 2:
        return not getattr(ind, "section_symmetric", True)
    return not ind.symmetry(scene.reach)[0]


def first_contact_travel(scene, samples: int = 4000) -> float:
    """Travel (mm) after which the scene's indenter first touches the skin, as the model
    sees it: the smallest gap at the start over the outer contour x >= 0 (the half model; both
    halves where the skin models its full width, a pad under an x-asymmetric indenter),
    sampled every ~0.01 mm, in 3D on the kind's contact planes (`contact_planes`: the
    Braille dot rows; the slab is uniform along z, so a dot's gap is smallest in its own
    row's plane). 0 for plates, cylinders and spheres (they touch at x = 0 at the start); a
    Braille text without a dot near the centre touches later, or only with its base plate."""
    ind = indenter_for_scene(scene, warn=False)
    sec = scene.section()
    pts = sec.outer_points(samples)
    if scene.skin_kind.full_width_if_asymmetric and not indenter_symmetry(scene)[0]:
        pts = np.concatenate([pts, pts * np.array([-1.0, 1.0])])  # the x < 0 half is modelled too
    if scene.dim == 3:
        # a plane beyond the slab's end (a file indenter placed past it) is read at the end
        half = 0.5 * scene.sample_length
        planes = np.clip(np.asarray(ind.contact_planes(), float), -half, half)
        pts = np.concatenate([np.column_stack([pts, np.full(len(pts), z)]) for z in planes])
    g, _ = ind.gap(pts, 0.0)
    return max(0.0, float(np.min(g)))


def _require_every_dot(scene) -> None:
    """ParameterError naming the depth if a Braille text's dots on a curved top (the fingertip,
    the dome) do not all touch it within the travel: the base plate touches at the dot height
    (0.48 mm) wherever the dots are, and a text whose outer dots press nothing read as a shorter
    text's ('a b' at t = 5, depth 1: its dots touch after 1.81 mm, the plate pressed alone)."""
    if not (scene.indenter_kind.name == "braille" and scene.braille_text and scene.skin_kind.top_curved):
        return
    from tactileskin.geometry import braille as _braille

    x, touch = BrailleIndenter.dot_touch(scene, _braille.get_standard(scene.braille_standard))
    far = touch >= scene.reach - 1e-9
    if far.any():
        need = float(touch.max())
        raise ParameterError("depth", scene.indentation,
                             f"> {need:.3g} mm for the text {scene.braille_text!r}, at most {scene.max_travel:g} mm",
                             f"its dots at |x| = {x[far].min():.3g} mm first touch the skin after "
                             f"{touch[far].min():.3g} mm and would press nothing; use a larger depth or fewer cells")


def _up3(x: float) -> float:
    """x rounded up at 3 significant digits: a bound shown that no refused value exceeds."""
    e = math.floor(math.log10(x)) - 2
    return math.ceil(x / 10.0 ** e) * 10.0 ** e


def require_contact(scene) -> None:
    """Raise ParameterError if the scene's indenter cannot touch the skin within its depth
    (a solve would return zero pressure everywhere: no contact)."""
    travel = first_contact_travel(scene)
    depth = scene.indentation
    if depth > travel + 1e-9:
        _require_every_dot(scene)
        return
    label = get_kind(scene.indenter).label(scene)
    why = f"the {label} indenter first touches the skin after {travel:.3g} mm of travel"
    ind = indenter_for_scene(scene, warn=False)
    if isinstance(ind, BrailleIndenter):
        x = ind.section_x if scene.dim == 2 else ind.dots[:, 0]
        seen = x[x >= -1e-9]  # the half model (x >= 0)
        why += f": the pattern of {scene.braille_text!r} is centred on x = 0"
        if seen.size:
            why += (f"; its nearest modelled dot is at x = {seen.min():.3g} mm, where the fingertip has "
                    f"curved away{'' if scene.dim == 3 else ' (a 3D model has the same contour)'}")
        symmetric = ind.section_symmetric if scene.dim == 2 else ind.symmetry()[0]
        if not symmetric and not scene.skin_kind.full_width_if_asymmetric:
            why += "; the half model (x >= 0) does not see the dots at x < 0"
    elif scene.dim == 3 and scene.skin_kind.halves_x and mirrored_x(scene):
        why += "; the half model (x >= 0) sees the indenter's part at x >= 0 only, mirrored"
    dmax = 0.6 * scene.thickness
    if travel < dmax:
        hint = " or a text with a dot on the centre line" if isinstance(ind, BrailleIndenter) else ""
        raise ParameterError("depth", depth, f"> {_up3(travel + 1e-9):.3g} mm for this indenter, at most {dmax:g} mm",
                             f"no contact: {why}; use a larger depth{hint}")
    # the kind's own parameters place it: name the first (the text, the file), else the kind
    field_ = next(iter(get_kind(scene.indenter).scene_params), "indenter")
    value = getattr(scene, field_) if field_ != "indenter" else scene.indenter.value
    raise ParameterError(field_, value, "an indenter that reaches the skin within the depth",
                         f"no contact: {why}; use a text with a dot on the centre line"
                         if isinstance(ind, BrailleIndenter) else f"no contact: {why}")
