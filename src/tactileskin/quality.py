"""Whether a solve's result is a normal result: flags computed from the result's own numbers.

`flags(summary)` takes the numbers of `Result.summary()` (or a cached summary.json) and
returns one `Flag` per reason to distrust them; `status(summary)` is "ok" or
"suspect: <reason>; <reason>". A failed case (no result) is "failed: <error>"
(`failed_status`). The ranges are stated once, here; docs/hard_cases.md explains them.
Pure Python, no solver import.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

# Largest |principal Cauchy stress| (MPa) at any quadrature point of a trusted result. Soft
# skin elastomers fail in tension at 1-10 MPa (cast silicones) and a few tens of MPa at most
# (polyurethane elastomers); the paper's cases stay below 1 MPa, the hardest converged one
# (3 mm silicone at 40 % strain) reaches 5 MPa. Above 50 MPa the stress comes from the
# hyperfoam's volumetric term J^(-alpha*beta) (alpha*beta = 379.75 for Table I silicone term
# 2: 4e5 MPa at J = 0.95), i.e. the lock-up of the law, not from the skin's response.
MAX_ABS_STRESS_MPA = 50.0
# ... and relative to the law's own small-strain shear modulus mu0: the lock-up scales with the
# moduli (every mu_i 1000x smaller: the same state at 1/1000 of each stress), so a soft gel's
# lock-up stays far below 50 MPa (Table I silicone with mu/1000 pressed 60 %: 38.5 MPa = 4.3e5
# mu0, J 0.956, read "ok"). 550 mu0 is the 50 MPa of Table I silicone (mu0 = 0.09 MPa: 556 mu0),
# so Table I results keep their status (the hardest "ok" one, 1 mm silicone at 40 %: 360 mu0).
MAX_STRESS_OVER_MU0 = 550.0
# ... in 3D much lower: the 3D presets' meshes do not resolve the bone pressure once the law locks
# up. An R 2.5 sphere 0.6 mm into 1 mm silicone (fingertip; max |stress| 46-50 mu0) read the peak
# 4.09 / 3.79 / 3.57 MPa at preview / default / fine (+15 / +6 % over fine, which still moved 6 %),
# on the pad 4.32 / 3.83 (49-55 mu0), status ok; at 0.4 mm (4.5 mu0) preview and default agree to 1 %
# (0.3033 / 0.3003), and the paper's 3D cases stay below 4 mu0 (t = 5 silicone full cell: 3.8). 2D meshes
# resolve it (3 mm silicone at 40 %, 57 mu0: +0.47 % from h = 1 to 0.5).
MAX_STRESS_OVER_MU0_3D = 15.0

# Volume ratio J (current / reference volume) range the material law may visit. Table I's
# elastomers have nu = 0.47-0.49, i.e. a small-strain bulk modulus of only 2.7-4.5 MPa,
# three orders below a real elastomer's (1-3 GPa); the paper's cases (20 % strain) stay at
# J = 0.96-0.99, 3 mm silicone at 40 % at 0.98. A volume change beyond 10 % is outside anything a solid
# elastomer undergoes, so there the result reflects the law's volumetric term, not the skin.
J_RANGE = (0.9, 1.1)
# ... judged only for a law of a solid elastomer: small-strain Poisson ratio nu0 >= NU_SOLID.
# A compressible foam's law (a hyperfoam with nu = 0: J = lambda in uniaxial compression,
# exact to 1e-6 on a pad at 20 %) changes volume as its normal response.
NU_SOLID = 0.45
# Linear (P1) displacement elements lock for a nearly incompressible law: the t = 1 mm flat
# plate read +181 % (silicone) and +92 % (polyurethane) against P2 mixed, +186 % / +101 % at
# half the size (P2 displacement: +1.1 / +0.7 %, then +0.03 / +0.1 %).
NU_LOCKING = 0.4
# A mesh coarser than the `preview` preset (the coarsest whose peak error is measured, <= 3.6 %
# in 2D) by more than these factors (refined size; global size) is not trusted. On the 2D
# fingertip (peak against 0.25 / 3): refined 0.5 mm (1.5 / 3 x preview) read -2.7 to -20 %
# (t = 1 flat / Braille), 1 mm -13 to -80 %, 2 mm -46 to -86 %.
COARSE_REFINED = 1.5
COARSE_GLOBAL = 2.0
# ... and a refined size above this fraction of the skin's thickness: the presets' sizes are
# absolute, their errors measured on skins of t >= 0.5 mm (2D preview: 0.2 mm = 0.4 t there, -2.8 %
# at t = 0.5); a thinner pad gets fewer elements through it. 0.1 mm pad under an R 2 cylinder,
# refined size / t = 2, 1, 0.6, 0.4, 0.2: peak -12, -4.6, -4.3, -3.3, -0.8 %, reaction -26, -13,
# -5.8, -3.3, -0.9 % against h = 0.05 t (preview, 2 x t, read "ok").
COARSE_OVER_THICKNESS = 0.5
# ... and a contact zone narrower than the mesh resolves: fewer contact points than this (a tiny
# press; the presets' sizes are absolute). 2D flat plate, elastic silicone, peak against a 0.0148 mm
# refined mesh: 1 mm skin at 1e-3 mm, 1 point (preview) -12.8 %, 3 points (fine) -2.0 %; 3 mm skin at
# 1e-3 mm, 1 point -8.2 % (preview) and -8.6 % (default, stated 0.7 %), 2 points (fine) -1.0 %; at
# 4e-3 mm, 2 points (preview) -1.8 % (t = 1) and -2.6 % (t = 3). All read "ok" before.
MIN_CONTACT_POINTS = 2
# ... in 3D (P2 triangles: 3 points per contact facet), fewer than one facet's points. R 2.5 sphere
# on a 1 mm silicone pad at 1e-3 mm, 2 points: reaction 1.08e-5 N (preview) and 2.30e-5 N (default)
# against 2.54e-5 N of the bonded-layer Hertz law (materials.indentation; -3 % at 1e-2 and 3e-2 mm,
# 6-15 points), peak 6.8e-6 and 1.6e-5 MPa, status ok; 6 points at 4e-3 mm (default): -4.3 %, as those.
MIN_CONTACT_POINTS_3D = 3
# ... and, for 3D Braille whose dots touch late (off a curved top's crown), the deepest-pressed dot
# indented less than this fraction of the dot patch's element size (the size meshed there: "dot_patch",
# the refined size where absent). The t = 0.5 mm
# silicone full cell (dots at x = +-1.25 touch after 0.069 of 0.1 mm) at 0.2 / 0.1 / 0.075 mm (preview /
# default / fine; indentation 0.16 / 0.31 / 0.41 of it) read -18 / -9.2 / -6.6 % from the Richardson
# limit, status ok; from 0.5 on the measured cases stay within their presets' errors (t = 0.5 dot at
# preview -4.2 %, t = 1 cell at preview, 0.66: -5.4 %; benchmarks/results/convergence3d.md). A centred
# dot, touching at once, is within them below it too (t = 1 at 0.05 mm, 0.25 of preview's: -2.9 %).
MIN_DOT_INDENTATION_OVER_SIZE = 0.45


SEPARATOR = "; "  # parts the reasons of a status ("suspect: <reason>; <reason>"): no reason holds it


@dataclass(frozen=True)
class Flag:
    code: str      # "no_contact" | "stress_range" | "volume_range" | "locking" | "coarse_mesh" | "edge_peak" | "no_bone_map" | "indenter_cap" | "buckling" | "mirrored_x" | "mirrored_z" | "tensile_bone" | "non_finite"
    reason: str

    def __post_init__(self):
        # status() joins the reasons with SEPARATOR and titles count them by it: a reason holding
        # it (a number formatted into it, a later text) is mended, not raised on at the end of a solve
        if SEPARATOR in self.reason:
            object.__setattr__(self, "reason", self.reason.replace(SEPARATOR, ", "))

    def to_dict(self) -> dict:
        return {"code": self.code, "reason": self.reason}


def _num(summary: dict, key: str):
    v = summary.get(key)
    try:
        return None if v is None else float(v)
    except (TypeError, ValueError):
        return None


def reaction_key(summary: dict) -> str:
    """The summary's reaction key: reaction_n in 3D, reaction_n_per_mm in 2D (results.reaction_key)."""
    return "reaction_n" if "reaction_n" in summary else "reaction_n_per_mm"


def reaction_of(summary: dict):
    """The reaction of a summary, whichever its dimension, or None."""
    return summary.get(reaction_key(summary))


def flags(summary: dict) -> list[Flag]:
    """Reasons not to trust a result, from its summary numbers (empty: a normal result).

    Keys read: peak_mpa, profile_min_mpa, reaction_n_per_mm (2D) or reaction_n (3D), contact_points, min_J, max_abs_stress_mpa,
    material_nu0, material_mu0_mpa, element_order, mesh_sizes_mm, peak_interior_mpa (+ its s and peak_edge_s_mm),
    profile_plane_from_map / profile_plane_unknown with peak_map_edge_* and profile_plane_z,
    indenter_cap, mirrored_x, mirrored_z (a
    key that is missing is not checked; a non-finite value is flagged).
    """
    out = []
    rkey = reaction_key(summary)
    peak, reaction = _num(summary, "peak_mpa"), _num(summary, rkey)
    npts = _num(summary, "contact_points")
    none = []
    if npts is not None and npts <= 0:
        none.append("no contact point")
    if reaction is not None and reaction == 0.0:
        none.append("reaction 0")
    if peak is not None and peak <= 0.0:
        none.append(f"peak {peak:g} MPa")
    if none:
        # a scene is made only if its indenter reaches the skin within the depth (require_contact):
        # no pressed point then means a contact narrower than the mesh's contact points (a 1e-3 mm
        # press of a Braille dot at preview), which "never pressed" misread
        out.append(Flag("no_contact", "no contact (" + ", ".join(none) + "): the indenter pressed no contact "
                        "point of the skin within the indentation depth (a press shallower than the mesh resolves: "
                        "a deeper press or a finer mesh)"))
    low = _num(summary, "profile_min_mpa")
    if not none and peak is not None and low is not None and low < -peak:
        # an auxetic law (nu0 < 0) pulls the mean stress at the bone into tension under the load:
        # the profile's largest value is then noise far from it (nu = -0.99: 4e-10 MPa against
        # -0.0021 at s = 0, contact pressure 0.023 MPa), and peak, span and area describe nothing
        out.append(Flag("tensile_bone", f"the bone's mean pressure is tensile under the load (down to {low:.4g} MPa, "
                        f"more than the peak {peak:.4g} MPa): peak, span and area do not describe the press (the "
                        "material's volumetric response, e.g. an auxetic law with nu0 < 0, pulls the bone, so "
                        "read the contact pressure or the reaction instead)"))
    stress, mu0 = _num(summary, "max_abs_stress_mpa"), _num(summary, "material_mu0_mpa")
    if stress is not None and not (abs(stress) <= MAX_ABS_STRESS_MPA):
        out.append(Flag("stress_range", f"stress {stress:.4g} MPa beyond {MAX_ABS_STRESS_MPA:g} MPa "
                        "(more than a skin elastomer bears: the material law or its parameters are outside their "
                        "range, e.g. a hyperfoam's volumetric lock-up or a modulus far above an elastomer's)"))
    elif stress is not None and mu0 is not None and mu0 > 0 and abs(stress) > MAX_STRESS_OVER_MU0 * mu0:
        out.append(Flag("stress_range", f"stress {stress:.4g} MPa = {abs(stress) / mu0:.3g} mu0 beyond "
                        f"{MAX_STRESS_OVER_MU0:g} mu0 (the law's small-strain shear modulus mu0 = {mu0:.4g} MPa): "
                        "the material law outside its range, e.g. a hyperfoam's volumetric lock-up"))
    elif stress is not None and mu0 is not None and mu0 > 0 and rkey == "reaction_n" \
            and abs(stress) > MAX_STRESS_OVER_MU0_3D * mu0:
        out.append(Flag("stress_range", f"stress {stress:.4g} MPa = {abs(stress) / mu0:.3g} mu0 beyond "
                        f"{MAX_STRESS_OVER_MU0_3D:g} mu0 in 3D (mu0 = {mu0:.4g} MPa): the material locks up under "
                        "this press and the 3D meshes do not resolve it (an R 2.5 sphere 0.6 mm into 1 mm silicone "
                        "read the peak 15 % / 6 % high at preview / default against fine, which still moved 6 %), so "
                        "use a smaller depth or force"))
    J, nu0 = _num(summary, "min_J"), _num(summary, "material_nu0")
    lo, hi = J_RANGE
    if J is not None and not (lo <= J <= hi) and (nu0 is None or nu0 >= NU_SOLID):
        out.append(Flag("volume_range", f"volume ratio J = {J:.4g} outside [{lo:g}, {hi:g}] "
                        "(material law outside its range)"))
    if _num(summary, "element_order") == 1 and (nu0 is None or nu0 >= NU_LOCKING):
        out.append(Flag("locking", "linear (P1) displacement elements with a nearly incompressible law"
                        + (f" (nu0 = {nu0:.3g})" if nu0 is not None else "") + " lock: the t = 1 mm flat plate "
                        "read 2-3x the bone pressure, and refining does not cure it: use order 2"))
    if summary.get("profile_plane_unknown"):
        out.append(Flag("no_bone_map", "no bone map of this skin file's bonded surface (not a graph over x: "
                        f"s = x - x_top folds), so the profile is on z = {_num(summary, 'profile_plane_z') or 0:g} mm, "
                        "not through the file indenter's load"))
    pe = _num(summary, "peak_map_edge_mpa")
    if summary.get("profile_plane_from_map") and pe is not None:
        out.append(Flag("edge_peak", f"the bone map's largest value {pe:.4g} MPa is at s = "
                        f"{_num(summary, 'peak_map_edge_s_mm'):g} mm, z = {_num(summary, 'peak_map_edge_z_mm'):g} mm, "
                        "within one skin thickness of where the bonded skin ends, and the profile was taken on "
                        f"the interior's plane z = {_num(summary, 'profile_plane_z'):g} mm: the load is near the "
                        "skin's end (or that is a corner singularity), so move it inward or lengthen the skin"))
    sizes = summary.get("mesh_sizes_mm")
    why = []
    if isinstance(sizes, dict):
        coarse = [f"{what} size {sizes[k]:g} mm against {sizes['preview_' + k]:g}" for k, what, f in
                  (("refined", "refined", COARSE_REFINED), ("global", "global", COARSE_GLOBAL))
                  if _num(sizes, k) is not None and _num(sizes, "preview_" + k) is not None
                  and sizes[k] > f * sizes["preview_" + k]]
        if coarse:
            why.append("mesh coarser than the preview preset's (" + ", ".join(coarse) + "), the coarsest whose "
                       "error is measured: peaks on such meshes read 3-86 % low (use --quality or a smaller mesh size)")
        t = _num(sizes, "thickness")
        if t is not None and _num(sizes, "refined") is not None and sizes["refined"] > COARSE_OVER_THICKNESS * t:
            why.append(f"refined size {sizes['refined']:g} mm against the skin's thickness {t:g} mm (more than "
                       f"{COARSE_OVER_THICKNESS:g} t: too few elements through the skin, whose preset errors are "
                       "measured from t = 0.5 mm at 0.4 t: 0.6 t read the peak 4 % and the reaction 6 % low, 2 t "
                       "12 % and 26 %, so use a smaller mesh size)")
        di = _num(sizes, "dot_indentation")
        patch = _num(sizes, "dot_patch") or _num(sizes, "refined")  # the size meshed at the dots
        if di is not None and patch is not None and di < MIN_DOT_INDENTATION_OVER_SIZE * patch:
            why.append(f"the Braille dots are pressed {di:.3g} mm past their first touch, less than "
                       f"{MIN_DOT_INDENTATION_OVER_SIZE:g} of the dot patch's {patch:.3g} mm elements: "
                       "the contact under each dot is narrower than the mesh resolves (the t = 0.5 mm full cell "
                       "on the fingertip read 18 % low at preview, 9 % at default), so use a smaller mesh size "
                       "or a deeper press")
    least = MIN_CONTACT_POINTS_3D if rkey == "reaction_n" else MIN_CONTACT_POINTS
    if npts is not None and 0 < npts < least:
        why.append(f"the contact zone holds {npts:g} contact point{'s' if npts > 1 else ''} (fewer than {least}): it "
                   "is narrower than the mesh resolves (1e-3 mm presses read the peak 8-13 % low on one point in 2D, "
                   "up to 58 % on two in 3D), so use a smaller mesh size or a deeper press")
    if why:
        out.append(Flag("coarse_mesh", ", and ".join(why)))  # one flag: "; " parts the status
    pi = _num(summary, "peak_interior_mpa")
    if pi is not None and peak is not None:
        out.append(Flag("edge_peak", f"the peak {peak:.4g} MPa is at s = {_num(summary, 'peak_edge_s_mm'):g} mm, "
                        "within one skin thickness of where the bonded skin ends: a corner singularity that "
                        f"grows with mesh refinement, and the interior peak is {pi:.4g} MPa at s = "
                        f"{_num(summary, 'peak_interior_s_mm'):g} mm"))
    cap = summary.get("indenter_cap")
    if isinstance(cap, dict) and _num(cap, "contact_mm") is not None:
        out.append(Flag("indenter_cap", f"the contact reaches {_num(cap, 'contact_mm'):.3g} mm from the indenter's "
                        f"centre along {cap.get('axis', 'x')}, past its printed working face (half width "
                        f"{_num(cap, 'face_half_mm') or math.nan:.3g} mm): there the printed part has its sides or "
                        "mount, the model more of the face (a cylinder's whole circle), so use a larger radius or a "
                        "smaller depth or force"))
    elif isinstance(cap, dict):
        out.append(Flag("indenter_cap", f"the indenter travelled {_num(cap, 'travel_mm') or math.nan:.3g} mm, past its printed "
                        f"working face ({_num(cap, 'cap_mm') or math.nan:.3g} mm: a sphere's cap is 0.95 R high, its mount "
                        "plate starts there, and a cylinder's face is a strip one chord wide, its edges and mount start "
                        "at the chord's sagitta, met by the undeformed skin's top): the printed part would press "
                        "with those, which the model does not have, so use a larger radius or a smaller depth or force"))
    buck = summary.get("buckling")
    if isinstance(buck, dict):
        out.append(Flag("buckling", f"pressed to {_num(buck, 'strain') or math.nan:.3g} of its thickness, past the "
                        f"{_num(buck, 'euler_strain') or math.nan:.3g} at which this slender pad buckles under the "
                        "plate (Euler, clamped to the board and guided by the plate), and the model cannot buckle "
                        "and reads the unbuckled state: a real pad bends sideways and presses less"))
    if summary.get("mirrored_x"):
        out.append(Flag("mirrored_x", "the indenter is not symmetric about x = 0, but the model is the "
                        "half x >= 0: the result is that of the indenter and its mirror image together "
                        "(a pad skin models the full width)"))
    if summary.get("mirrored_z"):
        out.append(Flag("mirrored_z", "the indenter is not symmetric about z = 0, but the skin file's model "
                        "is the half z >= 0 (its symmetry_z group): the result is that of the indenter and "
                        "its mirror image together"))
    for key in ("peak_mpa", rkey):
        v = _num(summary, key)
        if v is not None and not math.isfinite(v):
            out.append(Flag("non_finite", f"{key} is {v}"))
    return out


def status(summary: dict) -> str:
    """'ok', or 'suspect: <reason>; <reason>' (see `flags`)."""
    return status_of(flags(summary))


def status_of(found: list[Flag]) -> str:
    return "ok" if not found else "suspect: " + SEPARATOR.join(f.reason for f in found)


def failed_status(error) -> str:
    """Status of a case without a result: 'failed: <first line of the error>'."""
    text = str(error or "").strip().splitlines()
    return "failed: " + (text[0] if text else "unknown error")


def kind(status_text: str) -> str:
    """'ok', 'suspect' or 'failed' of a status string."""
    k = str(status_text).split(":", 1)[0].strip()
    return k if k in ("ok", "suspect", "failed") else "failed"


def suspect_title(text: str, status: str | None, width: int = 72, max_lines: int = 3,
                  reasons: list[str] | None = None) -> str:
    """A figure's title `text`, with "SUSPECT: <reasons>" (the status text, summary.json's)
    below it when `status` is not "ok": wrapped to `width` characters so that it stays inside
    the figure (one 100-character line ran past both sides of an 8-inch one), at most
    `max_lines` lines. Reasons that do not fit are left out whole and counted, "(+2 more)"
    (the whole text is in summary.json); a first reason too long alone is cut with "...".
    None (a file written without its status): `text` alone. `reasons`: the status's reasons
    where known apart (summary.json's flags; an older status held '; ' inside a reason), else
    the status split on SEPARATOR."""
    import textwrap

    if status is None or kind(status) == "ok":
        return text
    word = kind(status).upper()
    body = str(status).split(":", 1)[-1].strip()
    if not reasons or SEPARATOR.join(reasons) != body:
        reasons = body.split(SEPARATOR)

    def wrap(s: str) -> list[str]:
        return textwrap.wrap(s, width, break_on_hyphens=False)

    n = len(reasons)
    for k in range(n, 0, -1):  # as many whole reasons as fit, the rest counted
        lines = wrap(f"{word}: " + SEPARATOR.join(reasons[:k]) + (f" (+{n - k} more)" if k < n else ""))
        if len(lines) <= max_lines:
            return "\n".join([text, *lines])
    more = f" (+{n - 1} more)" if n > 1 else ""
    lines = wrap(f"{word}: " + reasons[0])[:max_lines]
    lines[-1] = lines[-1][:width - 3 - len(more)] + "..." + more
    return "\n".join([text, *lines])
