"""dome: a 3D fingertip with a rounded tip (not an extrusion). The paper's elliptical section
(semi-axes a = half_width, b = height of data/geometry/fingertip.toml) runs along the finger
for z in [-dome_length, 0] and is closed for z > 0 by a half ellipsoid of semi-axis `dome_tip`
along z; the rigid bone inside is the same shape with every semi-axis reduced by t
(geometry/dome_parts.py). 3D only; the half x >= 0 is meshed (gmsh from the build123d/OCC
solid, P2 tetrahedra curved onto the CAD) with `bone_interface` (the bone for z <= 0, fixed;
the bone map's surface), `bone_tip` (the bone under the dome, fixed), `outer_surface`,
`symmetry` (x = 0) and `end_back` (z = -dome_length, free).

Indenters start on the pulp line (x = 0, y = b), centred on z = 0 where the dome begins: a
sphere or a Braille dot there presses half on the finger and half on the dome. s is the arc
length along the bone's ellipse (a - t, b - t) from its top, by the angle of (x, y) (so it
also parametrises the bone under the dome); the 3D profile's section plane is z = 0.

Sensors (`DomeCoordinates`): a user's file skin's normal lines (skins.file_coordinates.FileCoordinates):
s = x and z (in [-dome_length, dome_tip]) of the outer surface's point, depth along its inward
normal there (the outer body's exact gradient), height along that line from where it meets the
bone, the sensor plane along the outer surface there (normal the surface's, out of the plane z =
const on the tip; t1 in the x-y plane). The bone is the outer body shrunk by t per semi-axis,
not its offset (no common normal from the surface to the bone): along the surface's normal the
skin is 1.994-2.0 mm thick at t = 2 (c = a), and the line meets the bone everywhere (the
vertical line missed it over the flanks and the last t of the tip). The scene checks the
layouts on the exact surfaces, the solve places them on the mesh it solves (mesh_coordinates).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError, check_range
from tactileskin.skins.base import Skin
from tactileskin.skins.file import boundary_facets
from tactileskin.skins.file_coordinates import FileCoordinates, FileGeometry
from tactileskin.skins.registry import register

DEFAULT_LENGTH = 10.0
LENGTH = (1.0, 200.0)
TIP = (2.0, 50.0)


# the bone is the outer shape with every semi-axis less t, not its inward offset: the skin is t
# thick at the pulp, the sides and the tip, thinner between (0.3 % at the default tip 8 / t 2,
# 17 % at tip 20 / t 3.5); a scene thinner than this fraction of t anywhere is refused
MIN_THICKNESS_FRACTION = 0.9


@functools.lru_cache(maxsize=64)
def min_thickness(a: float, b: float, c: float, t: float, n: int = 120) -> float:
    """Smallest skin thickness (mm) of the dome: the least distance from the bone's surface
    (semi-axes a - t, b - t, c - t; a quarter of it, n x n points, the cap's z = 0 row being the
    straight part's section; cell midpoints) to the outer ellipsoid (a, b, c). Each point's
    distance is exact:
    the closest point a_i^2 p_i / (a_i^2 + lam) with lam the root of
    sum (a_i p_i / (a_i^2 + lam))^2 = 1 in (-min a_i^2, 0) (the point is inside), by bisection."""
    # cell midpoints: no point on an axis plane, where the root may leave the bracket (the tip of
    # a long dome lies beyond its centre of curvature: its nearest outer points are off the axis)
    w = (np.arange(n) + 0.5) * 0.5 * np.pi / n
    u, v = np.meshgrid(w, w)
    p = np.column_stack([((a - t) * np.cos(u) * np.cos(v)).ravel(), ((b - t) * np.sin(u) * np.cos(v)).ravel(),
                         ((c - t) * np.sin(v)).ravel()])
    ax2 = np.array([a, b, c]) ** 2
    lo = np.full(len(p), -ax2.min() * (1.0 - 1e-12))
    hi = np.zeros(len(p))
    for _ in range(80):
        lam = 0.5 * (lo + hi)
        g = np.sum((np.sqrt(ax2) * p / (ax2 + lam[:, None])) ** 2, axis=1) - 1.0
        inside = g < 0.0  # lam above the root
        hi = np.where(inside, lam, hi)
        lo = np.where(inside, lo, lam)
    lam = 0.5 * (lo + hi)
    foot = ax2 * p / (ax2 + lam[:, None])
    return float(np.linalg.norm(foot - p, axis=1).min())


def _axes():
    from tactileskin import params

    sec = params.load("fingertip")["section"]
    return float(sec["half_width"]), float(sec["height"])


@dataclass(frozen=True)
class DomeSection:
    """The mid-plane (z = 0) section: the `Section` duck type (skins.base)."""

    a: float
    b: float
    c: float
    length: float
    thickness: float

    @property
    def top(self) -> float:
        return self.b

    @property
    def half_width(self) -> float:
        return self.a

    @property
    def min_radius_of_curvature(self) -> float:
        return min(self.b ** 2 / self.a, self.a ** 2 / self.b, self.c ** 2 / self.b)

    def contact_radius(self, indenter) -> float:
        r = getattr(indenter, "radius", None)
        return float(r) if r else self.a ** 2 / self.b

    def outer_length_to_x(self, x: float) -> float:
        return float(x)

    def _table(self):
        ai, bi = self.a - self.thickness, self.b - self.thickness
        u = np.linspace(0.0, math.pi, 4001)
        ds = np.hypot(ai * np.cos(u), bi * np.sin(u))
        s = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(u))])
        return u, s, ai, bi

    @property
    def interface_length(self) -> float:
        return float(self._table()[1][-1])

    def s_of_point(self, points) -> np.ndarray:
        pts = np.atleast_2d(np.asarray(points, float))
        u, s, ai, bi = self._table()
        ang = np.arctan2(np.abs(pts[:, 0]) / ai, pts[:, 1] / bi)
        return np.where(pts[:, 0] < -1e-9 * ai, -1.0, 1.0) * np.interp(ang, u, s)  # x = 0 (to rounding): s >= 0

    def point_at_s(self, s) -> np.ndarray:
        u, st, ai, bi = self._table()
        s = np.asarray(s, float)
        if np.any((np.abs(s) > st[-1] + 1e-9)):
            raise ParameterError("s", f"{np.min(s):g}..{np.max(s):g}", f"[-{st[-1]:.4g}, {st[-1]:.4g}] mm")
        ang = np.interp(np.abs(s), st, u)
        return np.stack([np.sign(s) * ai * np.sin(ang), bi * np.cos(ang)], axis=-1)

    def outer_points(self, n: int = 200) -> np.ndarray:
        u = np.linspace(0.0, math.pi, n)
        return np.column_stack([self.a * np.sin(u), self.b * np.cos(u)])

    def area(self) -> float:
        return 0.5 * math.pi * (self.a * self.b - (self.a - self.thickness) * (self.b - self.thickness))


@register
class DomeSkin(Skin):
    name = "dome"
    map_z_end_free = False  # the bone runs on into the tip (bone_tip) past z = 0
    halves_x = True
    order = 2
    scene_params = ("dome_length", "dome_tip")
    fixed_boundaries = ("bone_interface", "bone_tip")
    # its section is the fingertip's ellipse: a dot off x = 0 touches as late as there (later
    # still on the tip, z > 0), so the fingertip's per-dot check holds ('a b' was taken)
    top_curved = True
    s_path = "the bone"
    s_axis = "distance along bone s"  # arc length on the bone's ellipse, section z = 0
    boundaries_2d = ("bone_interface", "outer_surface", "symmetry", "bone_tip")

    @classmethod
    def check_scene(cls, scene) -> dict:
        a, b = _axes()
        length = DEFAULT_LENGTH if scene.dome_length is None else scene.dome_length
        c = a if scene.dome_tip is None else scene.dome_tip
        c = check_range("dome_tip", c, *TIP, unit="mm")
        tmax = 0.5 * min(a, b, c)
        t = check_range("thickness", scene.thickness, 0.3, tmax, unit="mm")
        thinnest = min_thickness(a, b, c, t)
        if thinnest < MIN_THICKNESS_FRACTION * t:
            ok = [x for x in np.arange(TIP[0], TIP[1] + 1e-9, 0.5) if 2.0 * t <= x
                  and min_thickness(a, b, float(x), t, n=40) >= MIN_THICKNESS_FRACTION * t]
            where = f"about {min(ok):g}-{max(ok):g} mm at this t" if ok else "none at this t"
            raise ParameterError("dome_tip", c, f"a tip with the skin at least {MIN_THICKNESS_FRACTION:.0%} of "
                                 f"t = {t:g} mm thick everywhere: {where} (here it would be {thinnest:.3g} mm "
                                 "at its thinnest)",
                                 f"the bone is the dome shrunk by t per semi-axis, so a tip far from the "
                                 f"section's {a:g} / {b:g} mm thins the skin between pulp and tip")
        return {"thickness": t,
                "dome_length": check_range("dome_length", length, *LENGTH, unit="mm"),
                "dome_tip": c, "dim": _dim3(scene)}

    @classmethod
    def section(cls, scene) -> DomeSection:
        a, b = _axes()
        return DomeSection(a, b, float(scene.dome_tip), float(scene.dome_length), float(scene.thickness))

    @classmethod
    def sample_length(cls, scene) -> float:
        return 2.0 * max(float(scene.dome_length), float(scene.dome_tip)) + 2.0

    @classmethod
    def coordinates(cls, scene) -> "DomeCoordinates":
        return DomeCoordinates(cls.section(scene))

    @classmethod
    def mesh_coordinates(cls, scene, skinmesh):
        """The file skin's coordinates on the mesh solved: its P2 faces lie up to ~5e-4 mm off
        the exact surfaces (h = 2), so a bone sensor placed on the exact bone could lie inside
        the meshed bone and fail to be read. Which sensors are in the skin is the scene's answer
        on the exact surfaces (`reference`, as a STEP skin's): a depth 1e-4 mm short of the
        exact thickness was refused after meshing where the mesh's column is 9e-4 mm thinner."""
        sec = cls.section(scene)
        facets, kind = boundary_facets(skinmesh)
        X = skinmesh.mesh.doflocs
        geo = FileGeometry(dim=3, top_point=(0.0, sec.b, 0.0), thickness=sec.thickness,
                           lo=tuple(X.min(axis=1).tolist()), hi=tuple(X.max(axis=1).tolist()),
                           outer_xy=np.zeros((0, 2)), symmetric=True, facets=facets, facet_kind=kind)
        return FileCoordinates(geo, reference=cls.coordinates(scene))

    @classmethod
    def build_mesh(cls, scene, *, cell: str = "tri", mesh_size=None, refinement=None, order=None, **_):
        from tactileskin.mesh.dome import build_dome_mesh

        if cell != "tri":
            raise ParameterError("cell", cell, "'tri' (tetrahedra) for the dome")
        return build_dome_mesh(scene, mesh_size=mesh_size, refinement=refinement, order=order)

    @classmethod
    def build_parts(cls, thickness, *, molds=True, dome_length=DEFAULT_LENGTH, dome_tip=None, **_):
        from tactileskin.geometry.dome_parts import build_dome_parts
        from tactileskin.scene import Scene

        sc = Scene(skin="dome", thickness=thickness, dome_length=dome_length, dome_tip=dome_tip)
        sec = sc.section()
        return build_dome_parts(sc.thickness, sec.a, sec.b, sec.c, sec.length, molds=molds)

    @classmethod
    def label(cls, scene) -> str:
        return f"dome{scene.dome_length:g}c{scene.dome_tip:g}-"


def _dim3(scene) -> int:
    return 3  # a rounded tip is 3D (Scene's default dim 2 becomes 3)


class DomeCoordinates(FileCoordinates):
    """The dome's sensor coordinates for the scene's check (FileCoordinates' normal lines,
    checked on the vertical columns of the exact surfaces instead of a mesh's faces, the normal
    the exact gradient): the vertical line through (x, z) meets the
    outer body's upper surface (the contact surface) at y = b sqrt(k - (x/a)^2), k = 1 -
    (max(z, 0)/c)^2, then the bone's (bonded) where it passes over the bone, else the skin's
    underside (the outer surface's lower half)."""

    def __init__(self, sec: DomeSection):
        self.sec, self.dim = sec, 3
        self.thickness = float(sec.thickness)
        self.x_top = 0.0
        self._size = max(sec.a, sec.b, sec.c, sec.length)  # FileCoordinates' (surface_normal's step)
        self.tol = 1e-7 * self._size  # FileCoordinates.tol
        self.s_range = (-sec.a, sec.a)
        self.s_max = float(sec.a)
        self.z_range = (-sec.length, sec.c)

    def column(self, s, z=None) -> dict:
        sec, t = self.sec, self.sec.thickness
        x = np.abs(np.atleast_1d(np.asarray(s, float)))  # the half model answers for x < 0
        z = np.broadcast_to(np.asarray(0.0 if z is None else z, float), x.shape)
        zt = np.maximum(z, 0.0)
        out = 1.0 - (zt / sec.c) ** 2 - (x / sec.a) ** 2
        bone = 1.0 - (zt / (sec.c - t)) ** 2 - (x / (sec.a - t)) ** 2
        top = sec.b * np.sqrt(np.maximum(out, 0.0))
        on = (z >= -sec.length - self.tol) & (z <= sec.c + self.tol) & (top > self.tol)
        bonded = on & (bone >= 0.0)
        floor = np.where(bonded, (sec.b - t) * np.sqrt(np.maximum(bone, 0.0)), -top)
        top, floor = np.where(on, top, np.nan), np.where(on, floor, np.nan)
        return {"top": top, "outer": top, "floor": floor, "bonded": bonded}

    def surface_normal(self, s, z=None) -> np.ndarray:
        """(n, 3) the outer surface's outward unit normal over each (s, z): the outer body's
        gradient (x / a^2, y / b^2, max(z, 0) / c^2), exact (FileCoordinates' central difference
        straddled z = 0, where the tip's curvature begins: a 3e-5 z part, 6e-5 mm of a sensor's
        position 2 mm along it); +y off the skin, as there."""
        sec = self.sec
        x = np.atleast_1d(np.asarray(s, float))
        z = np.broadcast_to(np.asarray(0.0 if z is None else z, float), x.shape)
        y = self.column(x, z)["top"]
        n = np.column_stack([x / sec.a ** 2, y / sec.b ** 2, np.maximum(z, 0.0) / sec.c ** 2])
        ok = np.isfinite(y)
        n[~ok] = (0.0, 1.0, 0.0)
        return n / np.linalg.norm(n, axis=1, keepdims=True)
