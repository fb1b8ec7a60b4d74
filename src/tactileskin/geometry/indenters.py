"""Rigid indenters as exact analytic surfaces: signed gap and normal, 2D section and 3D.

Pure numpy. The dimensions come from data/geometry/indenters.toml and data/geometry/braille.toml,
the same numbers the CAD solids are built from.

Conventions (mm): x lateral, y towards the pulp, z along the finger. The indenter sits above
the skin; its lowest point starts at y0 (the skin top on x = 0) and moves by -d (d >= 0 the
travel). `gap(points, d)` returns the signed distance g from each point to the indenter
surface (g > 0 separated, g < 0 inside the indenter) and the unit normal n of the indenter
surface at the closest point, pointing out of the indenter towards the skin. Points may be
(..., 2) (the plane section z = section_z) or (..., 3).

Kinds:
- flat: the half-space y >= y0 - d.
- curved: the solid cylinder of radius R (axis along z) with lowest point (0, y0 - d).
- braille: base plane y_b = y0 + h - d plus spherical-cap dots protruding h below it; each
  dot is a sphere of radius R centred `centre_offset` = R - h above the base plane (so the
  part of the sphere below the plane is exactly the cap). The solid is the union of the
  half-space above the base plane and the spheres. Outside a union the distance is exactly the
  minimum of the parts' distances; inside we also return the minimum of the parts' signed
  distances, i.e. minus the deepest penetration into any single part (a lower bound on the
  depth to the union's boundary; exact when only one part is penetrated). The 2D section is
  the cut through one dot row (plane z = section_z): the dots of that row become circles of
  radius R; the default row is the one nearest z = 0 (for empty text: one dot at x = 0).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np

from tactileskin import params
from tactileskin.errors import ParameterError, check_range
from tactileskin.geometry import braille as _braille

log = logging.getLogger(__name__)

KINDS = ("flat", "curved", "braille")
_ROW_TOL = 1e-9  # mm; dot rows are computed with identical arithmetic, so this only absorbs round-off


def _as_points(points) -> tuple[np.ndarray, tuple[int, ...]]:
    p = np.asarray(points, dtype=float)
    if p.ndim < 1 or p.shape[-1] not in (2, 3):
        raise ParameterError("points", f"array of shape {p.shape}", "shape (..., 2) or (..., 3)")
    if not np.isfinite(p).all():
        raise ParameterError("points", "non-finite coordinates", "finite coordinates (mm)")
    return p.reshape(-1, p.shape[-1]), p.shape[:-1]


def _check_d(d) -> float:
    return check_range("d", d, 0.0, None, unit="mm")


@dataclass(frozen=True, eq=False)
class Indenter:
    """Common data of the analytic indenters. Use `make_indenter` / `indenter_for_scene`."""

    kind: str
    y0: float                # lowest point at d = 0 (mm)
    dim: int                 # model dimension the indenter was made for (2 or 3)
    width: float             # x extent of the working face (mm)
    length: float            # z extent of the working face / base plate (mm)
    stem_diameter: float
    stem_length: float

    # -- interface -------------------------------------------------------------------------
    def gap(self, points, d: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance g (...,) and unit outward normal n (..., D) of points (..., D), D = 2 or 3."""
        p, shape = _as_points(points)
        g, n = self._gap(p, _check_d(d))
        return g.reshape(shape), n.reshape(shape + (p.shape[-1],))

    def surface_y(self, x, z=None, d: float = 0.0) -> np.ndarray:
        """y of the working face at (x[, z]) (the lowest point of the solid on that vertical line).

        Without z: the 2D section. Valid on the face, |x| <= width/2 (and |z| <= length/2);
        points outside raise ParameterError.
        """
        x = np.asarray(x, dtype=float)
        if np.any(np.abs(x) > 0.5 * self.width + 1e-9):
            raise ParameterError("x", f"max |x| = {np.abs(x).max():g}", f"|x| <= {0.5 * self.width:g} mm (face half-width)")
        if z is not None:
            z = np.asarray(z, dtype=float)
            if np.any(np.abs(z) > 0.5 * self.length + 1e-9):
                raise ParameterError("z", f"max |z| = {np.abs(z).max():g}", f"|z| <= {0.5 * self.length:g} mm (face half-length)")
            x, z = np.broadcast_arrays(x, z)
        return self._surface_y(x, z, _check_d(d))

    @property
    def lowest_point(self) -> float:
        return self.y0

    def face_box(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, zmin, zmax) of the working face, centred on x = 0, z = 0."""
        return (-0.5 * self.width, 0.5 * self.width, -0.5 * self.length, 0.5 * self.length)

    # implemented by the kinds
    def _gap(self, p: np.ndarray, d: float):  # pragma: no cover - abstract
        raise NotImplementedError

    def _surface_y(self, x, z, d):  # pragma: no cover - abstract
        raise NotImplementedError


@dataclass(frozen=True, eq=False)
class FlatIndenter(Indenter):
    thickness: float = 5.0

    def _gap(self, p, d):
        g = (self.y0 - d) - p[:, 1]  # the plate occupies y >= y0 - d; points below are separated
        n = np.zeros_like(p)
        n[:, 1] = -1.0
        return g, n

    def _surface_y(self, x, z, d):
        return np.full(np.shape(x), self.y0 - d)


@dataclass(frozen=True, eq=False)
class CurvedIndenter(Indenter):
    radius: float = 12.0
    back_thickness: float = 4.0

    @property
    def sagitta(self) -> float:
        """Rise of the arc from its lowest point to the face edge |x| = width/2."""
        R, c = self.radius, 0.5 * self.width
        return R - math.sqrt(R * R - c * c)

    def _gap(self, p, d):
        R = self.radius
        v = np.zeros_like(p)  # from the axis to the point, in the x-y plane (z ignored)
        v[:, 0] = p[:, 0]
        v[:, 1] = p[:, 1] - (self.y0 - d + R)
        dist = np.hypot(v[:, 0], v[:, 1])
        n = np.zeros_like(p)
        on_axis = dist == 0.0
        safe = np.where(on_axis, 1.0, dist)
        n[:, 0] = v[:, 0] / safe
        n[:, 1] = np.where(on_axis, -1.0, v[:, 1] / safe)  # on the axis: any direction; take -y
        return dist - R, n

    def _surface_y(self, x, z, d):
        R = self.radius
        return self.y0 - d + R - np.sqrt(R * R - x * x)


@dataclass(frozen=True, eq=False)
class BrailleIndenter(Indenter):
    standard: _braille.BrailleStandard | None = None
    text: str = ""
    dots: np.ndarray = field(default_factory=lambda: np.zeros((1, 2)))  # (n, 2) dot centres (x, z)
    row: int = 0                      # index into `rows` of the 2D section
    plate_thickness: float = 3.0
    margin: float = 3.0

    @property
    def rows(self) -> np.ndarray:
        """Sorted distinct z of the dot rows."""
        z = np.sort(self.dots[:, 1])
        keep = np.concatenate([[True], np.diff(z) > _ROW_TOL])
        return z[keep]

    @property
    def section_z(self) -> float:
        return float(self.rows[self.row])

    @property
    def section_x(self) -> np.ndarray:
        """x of the dot centres cut by the 2D section plane z = section_z (sorted)."""
        on = np.abs(self.dots[:, 1] - self.section_z) <= _ROW_TOL
        return np.sort(self.dots[on, 0])

    @property
    def section_symmetric(self) -> bool:
        """True if the section's dots are mirror-symmetric about x = 0 (a half-section model is exact)."""
        x = self.section_x
        return bool(np.allclose(x, -x[::-1], atol=1e-9))

    def base_plane(self, d: float = 0.0) -> float:
        """y of the base plane the dots protrude from."""
        return self.y0 + self.standard.height - d

    def _gap(self, p, d):
        std = self.standard
        R, yb = std.sphere_radius, self.base_plane(d)
        yc = yb + std.centre_offset
        # base half-space y >= yb: distance yb - y, normal -y
        g = yb - p[:, 1]
        n = np.zeros_like(p)
        n[:, 1] = -1.0
        if p.shape[1] == 2:
            centres = [(x, None) for x in self.section_x]
        else:
            centres = [(x, z) for x, z in self.dots]
        # loop over dots (few), vectorised over points; running minimum keeps memory O(points)
        for cx, cz in centres:
            v = p.copy()
            v[:, 0] -= cx
            v[:, 1] -= yc
            if cz is not None:
                v[:, 2] -= cz
            dist = np.sqrt(np.einsum("ij,ij->i", v, v))
            gs = dist - R
            closer = gs < g
            if np.any(closer):
                dc = dist[closer]
                ns = v[closer] / np.where(dc == 0.0, 1.0, dc)[:, None]
                ns[dc == 0.0, 1] = -1.0  # at the centre any direction is a normal; take -y
                n[closer] = ns
                g = np.where(closer, gs, g)
        return g, n

    def _surface_y(self, x, z, d):
        std = self.standard
        R, yb = std.sphere_radius, self.base_plane(d)
        yc = yb + std.centre_offset
        y = np.full(np.shape(x), yb)
        if z is None:
            centres = [(cx, None) for cx in self.section_x]
        else:
            centres = [(cx, cz) for cx, cz in self.dots]
        for cx, cz in centres:
            rho2 = (x - cx) ** 2 + (0.0 if cz is None else (z - cz) ** 2)
            inside = rho2 < R * R
            ys = yc - np.sqrt(np.where(inside, R * R - rho2, 0.0))
            y = np.where(inside, np.minimum(y, ys), y)
        return y


def _sample_length() -> float:
    return float(params.load("fingertip")["sample"]["length"])


def make_indenter(kind, *, y0: float | None = None, braille_text: str = "",
                  braille_standard: str = "standard_american", dim: int = 2,
                  row: int | None = None, sample_length: float | None = None) -> Indenter:
    """Build the analytic indenter of `kind` (flat, curved, braille) with lowest point y0.

    `kind` may also be a Scene, in which case everything comes from the scene (see
    `indenter_for_scene`). `row` picks the dot row of the 2D Braille section (index into
    `BrailleIndenter.rows`; default the row nearest z = 0). `sample_length` (default
    fingertip.toml [sample] length) is the z extent of the face plates.
    """
    if hasattr(kind, "indenter") and hasattr(kind, "section"):
        return indenter_for_scene(kind, row=row)
    kind = getattr(kind, "value", kind)
    if kind not in KINDS:
        raise ParameterError("indenter", kind, "one of " + ", ".join(KINDS))
    if y0 is None:
        raise ParameterError("y0", None, "a finite number (mm): the skin top on x = 0")
    y0 = check_range("y0", y0, -1e6, 1e6, unit="mm")
    if dim not in (2, 3):
        raise ParameterError("dim", dim, "2 or 3")
    length = _sample_length() if sample_length is None else check_range(
        "sample_length", sample_length, 0.0, None, lo_open=True, unit="mm")
    p = params.load("indenters")
    stem = dict(stem_diameter=float(p["stem"]["diameter"]), stem_length=float(p["stem"]["length"]))
    if kind == "flat":
        q = p["flat"]
        return FlatIndenter(kind=kind, y0=y0, dim=dim, width=float(q["width"]), length=length,
                            thickness=float(q["thickness"]), **stem)
    if kind == "curved":
        q = p["curved"]
        R, w = float(q["radius"]), float(q["chord_width"])
        if not 0.0 < w < 2.0 * R:
            raise ParameterError("curved.chord_width", w, f"(0, {2 * R:g}) mm (less than the diameter)")
        return CurvedIndenter(kind=kind, y0=y0, dim=dim, width=w, length=length, radius=R,
                              back_thickness=float(q["back_thickness"]), **stem)
    q = p["braille"]
    std = _braille.get_standard(braille_standard)
    dots = _braille.dot_centres(braille_text, std)
    margin = float(q["margin"])
    xmin, xmax, zmin, zmax = _braille.footprint(braille_text, std)
    # The plate covers the dots with the margin, at least min_width in x and the sample length in z.
    width = max(float(q["min_width"]), 2.0 * (max(-xmin, xmax) + margin))
    length = max(length, 2.0 * (max(-zmin, zmax) + margin))
    ind = BrailleIndenter(kind=kind, y0=y0, dim=dim, width=width, length=length, standard=std,
                          text=braille_text, dots=dots, row=0,
                          plate_thickness=float(q["plate_thickness"]), margin=margin, **stem)
    rows = ind.rows
    if row is None:
        # nearest z = 0; ties -> the smallest z, except for a dot pattern mirror-symmetric in z:
        # its rows +-z cut the same section, and the 3D quarter model holds only z >= 0
        ties = np.flatnonzero(np.abs(rows) <= np.min(np.abs(rows)) + _ROW_TOL)
        zkey = {tuple(np.round(r, 9)) for r in dots}
        zsym = {tuple(np.round(r * (1.0, -1.0), 9)) for r in dots} == zkey
        row = int(ties[-1] if zsym else ties[0])
    elif not (isinstance(row, (int, np.integer)) and 0 <= row < len(rows)):
        raise ParameterError("row", row, f"an integer in [0, {len(rows) - 1}] (dot rows of the text)")
    object.__setattr__(ind, "row", int(row))
    if dim == 2 and not ind.section_symmetric:
        log.warning("Braille section z=%g has dots at x=%s, not symmetric about x = 0; a half-section "
                    "model with a symmetry line sees only the mirrored x >= 0 half", ind.section_z,
                    np.round(ind.section_x, 4).tolist())
    return ind


def indenter_for_scene(scene, *, row: int | None = None) -> Indenter:
    """The scene's indenter; its lowest point initially touches the skin top on x = 0."""
    return make_indenter(scene.indenter, y0=scene.section().top, braille_text=scene.braille_text,
                         braille_standard=scene.braille_standard, dim=scene.dim, row=row,
                         sample_length=scene.fingertip_model().sample_length)


def indenter_symmetry(scene) -> tuple[bool, bool]:
    """(about x = 0, about z = 0): mirror symmetry of the scene's indenter. Flat plates and
    cylinders are symmetric in both; Braille by its dot pattern (to 1e-9 mm)."""
    if scene.indenter.value != "braille":
        return True, True
    xz = _braille.dot_centres(scene.braille_text, _braille.get_standard(scene.braille_standard))
    key = lambda a: {tuple(np.round(r, 9)) for r in a}  # noqa: E731
    return tuple(key(xz * np.where(np.arange(2) == ax, -1.0, 1.0)) == key(xz) for ax in (0, 1))


def first_contact_travel(scene, samples: int = 4000) -> float:
    """Travel (mm) after which the scene's indenter first touches the skin, as the model
    sees it: the smallest analytic gap at the start over the outer contour x >= 0 (the half
    model), sampled every ~0.01 mm, in 3D on the planes of the Braille dot rows (the slab is
    uniform along z, so a dot's gap is smallest in its own row's plane). 0 for plates and
    cylinders (they touch at x = 0 at the start); a Braille text without a dot near the
    centre touches later, or only with its base plate (dot height)."""
    ind = indenter_for_scene(scene)
    sec = scene.section()
    pts = sec.fingertip.outer(np.linspace(0.0, sec.u_outer_end, samples))
    if scene.dim == 3:
        rows = ind.rows if isinstance(ind, BrailleIndenter) else np.zeros(1)
        pts = np.concatenate([np.column_stack([pts, np.full(len(pts), z)]) for z in rows])
    g, _ = ind.gap(pts, 0.0)
    return max(0.0, float(np.min(g)))


def require_contact(scene) -> None:
    """Raise ParameterError if the scene's indenter cannot touch the skin within its depth
    (a solve would return zero pressure everywhere: no contact)."""
    travel = first_contact_travel(scene)
    depth = scene.indentation
    if depth > travel + 1e-9:
        return
    why = f"the {scene.indenter.value} indenter first touches the skin after {travel:.3g} mm of travel"
    if isinstance(ind := indenter_for_scene(scene), BrailleIndenter):
        x = ind.section_x if scene.dim == 2 else ind.dots[:, 0]
        seen = x[x >= -1e-9]  # the half model (x >= 0)
        why += f": the pattern of {scene.braille_text!r} is centred on x = 0"
        if seen.size:
            why += (f"; its nearest modelled dot is at x = {seen.min():.3g} mm, where the fingertip has "
                    f"curved away{'' if scene.dim == 3 else ' (a 3D model has the same contour)'}")
        symmetric = ind.section_symmetric if scene.dim == 2 else indenter_symmetry(scene)[0]
        if not symmetric:
            why += "; the half model (x >= 0) does not see the dots at x < 0"
    dmax = 0.6 * scene.thickness
    if travel < dmax:
        raise ParameterError("depth", depth, f"> {travel:.3g} mm for this indenter, at most {dmax:g} mm",
                             f"no contact: {why}; use a larger --depth or a text with a dot on the centre line")
    raise ParameterError("braille_text" if scene.indenter.value == "braille" else "indenter",
                         scene.braille_text if scene.indenter.value == "braille" else scene.indenter.value,
                         "an indenter that reaches the skin within the depth",
                         f"no contact: {why}; use a text with a dot on the centre line")
