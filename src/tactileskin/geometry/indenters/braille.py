"""braille: base plane y_b = y0 + h - d plus spherical-cap dots protruding h below it.

Each dot is a sphere of radius R centred `centre_offset` = R - h above the base plane (so the
part of the sphere below the plane is exactly the cap); text and standard from
data/geometry/braille.toml (geometry/braille.py). The solid is the union of the half-space
above the base plane and the spheres. Outside a union the distance is exactly the minimum
of the parts' distances; inside we also return the minimum of the parts' signed distances,
i.e. minus the deepest penetration into any single part (a lower bound on the depth to the
union's boundary; exact when only one part is penetrated). The 2D section is the cut through
one dot row (plane z = section_z): the dots of that row become circles of radius R (the
paper's ridge model); the default row is the one nearest z = 0 (for empty text: one dot at
x = 0).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from tactileskin import params
from tactileskin.errors import ParameterError
from tactileskin.geometry import braille as _braille
from tactileskin.geometry.indenters.base import Indenter, hertz_halfwidth, stem_params
from tactileskin.geometry.indenters.registry import register

log = logging.getLogger(__name__)

_ROW_TOL = 1e-9  # mm; dot rows are computed with identical arithmetic, so this only absorbs round-off


@register
@dataclass(frozen=True, eq=False)
class BrailleIndenter(Indenter):
    standard: _braille.BrailleStandard | None = None
    text: str = ""
    dots: np.ndarray = field(default_factory=lambda: np.zeros((1, 2)))  # (n, 2) dot centres (x, z)
    row: int = 0                      # index into `rows` of the 2D section
    plate_thickness: float = 3.0
    margin: float = 3.0

    name = "braille"
    order = 2
    scene_params = ("braille_text", "braille_standard")
    section_2d = "ridge"
    fine_2d_mesh = True   # the dot's base radius (0.72 mm) needs the finer 2D preset
    paper = True
    local_3d = True

    @classmethod
    def check_scene(cls, scene) -> dict:
        std = _braille.get_standard(scene.braille_standard)  # raises ParameterError if unknown
        if scene.braille_text:
            _braille.check_text(scene.braille_text)   # raises on unknown characters, > MAX_CELLS
            # and on a text with no raised dot (only spaces): refused with the scene, as any bad
            # field, not by the solve (a sweep reported it as a failed case in a written folder)
            _braille.dot_centres(scene.braille_text, std)
            cls._check_on_top(scene, std)
        return {}

    @classmethod
    def _check_on_top(cls, scene, std) -> None:
        """Every dot's base on the skin's top: a dot past its edge presses nothing, and the
        result would be that of a shorter text, unflagged (abcd on a 10 mm pad solved 'ok')."""
        extent = scene.skin_kind.top_extent(scene)
        if extent is not None:  # the dome states none: its curved top is checked below
            xh, zh = extent
            xmin, xmax, zmin, zmax = _braille.footprint(scene.braille_text, std)
            x_out = max(-xmin, xmax) > xh + 1e-9
            z_out = scene.dim == 3 and max(-zmin, zmax) > zh + 1e-9
            if x_out or z_out:
                fixes = [f"{name} >= {2 * need:.3g} mm" for name, need, out in
                         (("pad_width", max(-xmin, xmax), x_out), ("pad_length", max(-zmin, zmax), z_out))
                         if out and scene.skin == "pad"]
                hint = (f"its dot bases span x {xmin:.3g} to {xmax:.3g} mm, z {zmin:.3g} to {zmax:.3g} mm; "
                        + (f"give {' and '.join(fixes)} or " if fixes else "") + "use fewer cells")
                raise ParameterError("braille_text", scene.braille_text,
                                     f"a text whose dots lie on the {scene.skin} skin's top (|x| <= {xh:g} mm"
                                     + (f", |z| <= {zh:g} mm" if scene.dim == 3 else "") + ")", hint)
        if scene.skin_kind.top_curved:
            # inside the half width a curved top falls away: 'a b' (dots at x = +-6.2 mm, where
            # the fingertip lies 2.6 mm below its top) passed, and only its base plate pressed
            x, touch = cls.dot_touch(scene, std)
            far = touch >= scene.max_travel - 1e-9
            if far.any():
                raise ParameterError("braille_text", scene.braille_text,
                                     f"a text whose dots all reach the {scene.skin} skin within the deepest "
                                     f"travel 0.6 t = {scene.max_travel:g} mm",
                                     f"its dots at |x| = {x[far].min():.3g} mm first touch it after "
                                     f"{touch[far].min():.3g} mm, where its top has fallen away; use fewer cells")

    @classmethod
    def dot_touch(cls, scene, std) -> tuple[np.ndarray, np.ndarray]:
        """(|x|, travel) of each distinct |x| of the text's dots: the travel (mm, from the start
        at the skin's top) after which a dot there first touches the skin's section contour, the
        same in every z plane of a `top_curved` skin, or later (the dome's tip; undeformed: the
        skin pulled down around a pressed dot only delays it). A dot's sphere (radius R, centre
        R above its tip) beyond its cap lies inside the base plate, so the sphere's distance is
        the dot's."""
        sec = scene.section()
        pts = sec.outer_points(4000)
        R = float(std.sphere_radius)
        x = np.unique(np.round(np.abs(_braille.dot_centres(scene.braille_text, std)[:, 0]), 9))
        gap = np.hypot(pts[None, :, 0] - x[:, None], pts[None, :, 1] - (sec.top + R)) - R
        return x, np.maximum(gap.min(axis=1), 0.0)

    @classmethod
    def label(cls, scene) -> str:
        return cls.name + (f"[{scene.braille_text}]" if scene.braille_text else "")

    @classmethod
    def from_params(cls, *, y0, dim, length, row=None, warn=True, braille_text="",
                    braille_standard="standard_american", **_):
        q = params.load("indenters")["braille"]
        std = _braille.get_standard(braille_standard)
        dots = _braille.dot_centres(braille_text, std)
        margin = float(q["margin"])
        xmin, xmax, zmin, zmax = _braille.footprint(braille_text, std)
        # The plate covers the dots with the margin, at least min_width in x and the sample length in z.
        width = max(float(q["min_width"]), 2.0 * (max(-xmin, xmax) + margin))
        length = max(length, 2.0 * (max(-zmin, zmax) + margin))
        ind = cls(kind=cls.name, y0=y0, dim=dim, width=width, length=length, standard=std,
                  text=braille_text, dots=dots, row=0,
                  plate_thickness=float(q["plate_thickness"]), margin=margin, **stem_params())
        rows = ind.rows
        if row is None:
            # nearest z = 0; of two rows equally near, the text's upper one (the larger z:
            # braille.dot_centres), which is also the z >= 0 one a 3D quarter model holds
            ties = np.flatnonzero(np.abs(rows) <= np.min(np.abs(rows)) + _ROW_TOL)
            row = int(ties[-1])
        elif not (isinstance(row, (int, np.integer)) and 0 <= row < len(rows)):
            raise ParameterError("row", row, f"an integer in [0, {len(rows) - 1}] (dot rows of the text)")
        object.__setattr__(ind, "row", int(row))
        if warn and dim == 2 and not ind.section_symmetric:
            log.warning("Braille section z=%g has dots at x=%s, not symmetric about x = 0; a half-section "
                        "model with a symmetry line sees only the mirrored x >= 0 half", ind.section_z,
                        np.round(ind.section_x, 4).tolist())
        return ind

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
    def tip_radius(self) -> float:
        return float(self.standard.sphere_radius)

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

    def symmetry(self, depth=None) -> tuple[bool, bool]:
        """By the dot pattern (to 1e-9 mm)."""
        key = lambda a: {tuple(np.round(r, 9)) for r in a}  # noqa: E731
        xz = self.dots
        return tuple(key(xz * np.where(np.arange(2) == ax, -1.0, 1.0)) == key(xz) for ax in (0, 1))

    def contact_halfwidth(self, depth, r_top):
        """The dot row's extent plus a dot radius, and the flat estimate for the base plate if
        the depth exceeds the dot height."""
        std, xz = self.standard, self.dots
        row = xz[np.argmin(np.abs(xz[:, 1])), 1]
        xs = xz[np.abs(xz[:, 1] - row) < 1e-9, 0]
        w = float(np.max(np.abs(xs))) + 2.0 * std.base_radius
        return max(w, hertz_halfwidth(r_top, depth - std.height))

    def contact_zrange(self, depth):
        _, _, zmin, zmax = _braille.footprint(self.text, self.standard)
        m = self.standard.base_radius
        return zmin - m, zmax + m

    def contact_patches(self, depth):
        """Every dot, its base radius: the contact radius is at most that."""
        a = float(self.standard.base_radius)
        return tuple((float(x), float(z), a) for x, z in self.dots)

    def plate_depth(self, depth):
        return max(0.0, float(depth) - float(self.standard.height))

    def contact_planes(self) -> np.ndarray:
        return self.rows  # a dot's gap is smallest in its own row's plane

    def solid(self):
        from tactileskin.geometry import solids

        return solids.braille_indenter(self)

    def describe(self) -> str:
        std = self.standard
        return (f"Braille indenter {self.text!r} ({std.name}, {len(self.dots)} dots)" if self.text
                else f"Braille indenter, single dot ({std.name})")

    def part_parameters(self) -> dict:
        std = self.standard
        return dict(text=self.text, standard=std.name, dots=int(len(self.dots)), base_diameter=std.base_diameter,
                    height=std.height, dot_pitch=std.dot_pitch, cell_pitch=std.cell_pitch,
                    line_pitch=std.line_pitch)

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
