"""Fingertip half cross-section: analytic contour, bone interface and its arc length.

Pure numpy/scipy: the CAD solids (build123d), the gmsh model and the solver all derive
from these functions, so they share one set of numbers (data/geometry/fingertip.toml).

Coordinates (mm): x lateral (x = 0 is the symmetry line), y towards the pulp (the
indenter moves in -y), z along the finger. The outer contour is the ellipse
P(u) = (a sin u, b cos u); the bone interface is its inward offset Q(u) = P(u) - t N(u).
For an offset curve |Q'(u)| = |P'(u)| (1 - t kappa(u)), so arc length along the
interface integrates a closed-form speed.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from tactileskin import params
from tactileskin.errors import ParameterError, check_range
from tactileskin.validate import did_you_mean

_N_DENSE = 20001  # samples for arc-length tables; spacing ~1e-3 mm, error ~1e-9 mm


# the Scene.fingertip overrides: the Fingertip fields (fingertip.toml values by default)
OVERRIDES = ("half_width", "height", "max_fraction_of_min_radius", "nail_angle_deg", "sample_length",
             "thickness_min")


@dataclass(frozen=True)
class Fingertip:
    """The fixed outer contour and nail of the fingertip (independent of skin thickness)."""

    half_width: float = 8.0
    height: float = 7.0
    nail_angle_deg: float = 117.5
    sample_length: float = 20.0
    thickness_min: float = 0.5
    max_fraction_of_min_radius: float = 0.9

    @classmethod
    def from_params(cls, **overrides) -> "Fingertip":
        """Defaults from data/geometry/fingertip.toml, with keyword overrides."""
        p = params.load("fingertip")
        kw = dict(
            half_width=p["section"]["half_width"],
            height=p["section"]["height"],
            nail_angle_deg=p["section"]["nail_angle_deg"],
            sample_length=p["sample"]["length"],
            thickness_min=p["thickness"]["min"],
            max_fraction_of_min_radius=p["thickness"]["max_fraction_of_min_radius"],
        )
        unknown = sorted(str(k) for k in overrides if k not in OVERRIDES)
        if unknown:
            raise ParameterError("fingertip key", unknown[0], "one of " + ", ".join(OVERRIDES),
                                 did_you_mean(unknown[0], OVERRIDES))
        kw.update(overrides)
        ft = cls(**kw)
        ft.validate()
        return ft

    def validate(self) -> None:
        check_range("half_width", self.half_width, 2.0, 50.0, unit="mm")
        check_range("height", self.height, 2.0, 50.0, unit="mm")
        check_range("nail_angle_deg", self.nail_angle_deg, 45.0, 175.0, unit="deg")
        check_range("sample_length", self.sample_length, 1.0, 500.0, unit="mm")
        check_range("thickness_min", self.thickness_min, 0.0, 50.0, lo_open=True, unit="mm")
        # at 1 the interface (the inward offset) reaches the contour's centre of curvature: a cusp
        check_range("max_fraction_of_min_radius", self.max_fraction_of_min_radius, 0.0, 1.0,
                    lo_open=True, hi_open=True)
        if self.thickness_min > self.thickness_max:
            raise ParameterError("thickness_min", self.thickness_min,
                                 f"<= {self.thickness_max:.4g} mm (the largest thickness this contour allows)")

    @property
    def nail_angle(self) -> float:
        return math.radians(self.nail_angle_deg)

    @property
    def min_radius_of_curvature(self) -> float:
        a, b = self.half_width, self.height
        return min(a * a / b, b * b / a)

    @property
    def thickness_max(self) -> float:
        """Largest skin thickness whose interface stays smooth (a margin below min radius)."""
        return self.max_fraction_of_min_radius * self.min_radius_of_curvature

    @property
    def thickness_bounds(self) -> tuple[float, float]:
        """Valid skin thickness range as stated to users (max rounded down to 1 um)."""
        return self.thickness_min, math.floor(self.thickness_max * 1000) / 1000

    def check_thickness(self, t: float) -> float:
        return check_range("thickness", t, *self.thickness_bounds, unit="mm")

    def section(self, thickness: float) -> "Section":
        return _section(self, self.check_thickness(thickness))

    # --- outer contour -------------------------------------------------------------
    def outer(self, u) -> np.ndarray:
        u = np.asarray(u, float)
        return np.stack([self.half_width * np.sin(u), self.height * np.cos(u)], axis=-1)

    def outer_speed(self, u) -> np.ndarray:
        u = np.asarray(u, float)
        return np.hypot(self.half_width * np.cos(u), self.height * np.sin(u))

    def outer_normal(self, u) -> np.ndarray:
        """Unit outward normal of the contour."""
        u = np.asarray(u, float)
        n = np.stack([self.height * np.sin(u), self.half_width * np.cos(u)], axis=-1)
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    def curvature(self, u) -> np.ndarray:
        return self.half_width * self.height / self.outer_speed(u) ** 3


@functools.lru_cache(maxsize=16)
def _section(fingertip: Fingertip, thickness: float) -> "Section":
    """One Section per (fingertip, thickness) in a process: its arc-length table and lookup tree
    (20,001 points, built lazily) are then built once, not once per solve of that thickness."""
    return Section(fingertip, thickness)


def _polar(p: np.ndarray) -> np.ndarray:
    """Polar angle measured from +y towards +x."""
    return np.arctan2(p[..., 0], p[..., 1])


@dataclass(frozen=True)
class Section:
    """The skin half-section for one thickness t: outer contour, interface, nail edge."""

    fingertip: Fingertip
    thickness: float

    # --- curves ----------------------------------------------------------------------
    def interface(self, u) -> np.ndarray:
        ft = self.fingertip
        return ft.outer(u) - self.thickness * ft.outer_normal(u)

    def interface_speed(self, u) -> np.ndarray:
        ft = self.fingertip
        return ft.outer_speed(u) * (1.0 - self.thickness * ft.curvature(u))

    @functools.cached_property
    def u_outer_end(self) -> float:
        """Contour parameter where the outer contour meets the nail edge."""
        from scipy.optimize import brentq  # here: importing scipy.optimize is ~0.3 s a sweep's main process never needs

        ft = self.fingertip
        return brentq(lambda u: _polar(ft.outer(u)) - ft.nail_angle, 0.0, math.pi)

    @functools.cached_property
    def u_interface_end(self) -> float:
        """Contour parameter where the bone interface meets the nail edge."""
        from scipy.optimize import brentq

        th = self.fingertip.nail_angle
        return brentq(lambda u: _polar(self.interface(u)) - th, 0.0, math.pi)

    @functools.cached_property
    def _table(self) -> tuple[np.ndarray, np.ndarray]:
        u = np.linspace(0.0, self.u_interface_end, _N_DENSE)
        v = self.interface_speed(u)
        s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(u))])
        # Richardson-free trapezoid on a smooth integrand at 2e4 samples: rel. error < 1e-8.
        return u, s

    @property
    def interface_length(self) -> float:
        """Curvilinear length of the bone interface from the symmetry line to the nail."""
        return float(self._table[1][-1])

    @functools.cached_property
    def outer_length(self) -> float:
        u = np.linspace(0.0, self.u_outer_end, _N_DENSE)
        v = self.fingertip.outer_speed(u)
        return float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(u)))

    # --- curvilinear coordinate s along the bone interface ------------------------------
    def u_of_s(self, s) -> np.ndarray:
        s = np.asarray(s, float)
        L = self.interface_length
        if np.any((s < -1e-9) | (s > L + 1e-9)):
            raise ParameterError("s", f"{s.min():g}..{s.max():g}", f"[0, {L:.4f}] mm along the bone interface")
        u, st = self._table
        return np.interp(s, st, u)

    def point_at_s(self, s) -> np.ndarray:
        """Point(s) on the bone interface at curvilinear distance s from the symmetry line."""
        return self.interface(self.u_of_s(s))

    def s_of_point(self, points) -> np.ndarray:
        """Curvilinear coordinate of the closest interface point to each given point."""
        pts = np.atleast_2d(np.asarray(points, float))[:, :2]
        u, st = self._table
        q = self._tree.data
        _, k = self._tree.query(pts)
        # refine on the neighbouring segment by orthogonal projection
        k0 = np.clip(k - 1, 0, len(u) - 2)
        best = np.empty(len(pts))
        bestd = np.full(len(pts), np.inf)
        for off in (0, 1):
            i = np.clip(k0 + off, 0, len(u) - 2)
            a, b = q[i], q[i + 1]
            ab = b - a
            w = np.clip(np.einsum("ij,ij->i", pts - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
            proj = a + w[:, None] * ab
            d = np.linalg.norm(pts - proj, axis=1)
            sv = st[i] + w * (st[i + 1] - st[i])
            better = d < bestd
            best[better], bestd[better] = sv[better], d[better]
        return best

    @functools.cached_property
    def _tree(self):
        from scipy.spatial import cKDTree

        return cKDTree(self.interface(self._table[0]))

    # --- polylines for CAD and meshing -------------------------------------------------
    def outer_points(self, n: int = 200) -> np.ndarray:
        return self.fingertip.outer(np.linspace(0.0, self.u_outer_end, n))

    def interface_points(self, n: int = 200) -> np.ndarray:
        return self.interface(np.linspace(0.0, self.u_interface_end, n))

    @property
    def outer_end(self) -> np.ndarray:
        return self.fingertip.outer(self.u_outer_end)

    @property
    def interface_end(self) -> np.ndarray:
        return self.interface(self.u_interface_end)

    @property
    def top(self) -> float:
        """y of the outer contour on the symmetry line (first touch of a centred indenter)."""
        return self.fingertip.height

    # --- answers for mesh sizing (the skins.base section contract) ----------------------
    @property
    def half_width(self) -> float:
        """x extent of the outer contour (the widest the contact zone can be)."""
        return self.fingertip.half_width

    @property
    def min_radius_of_curvature(self) -> float:
        return self.fingertip.min_radius_of_curvature

    def contact_radius(self, indenter) -> float:
        """Radius of the contour's top, a^2/b, for the indenter's contact-size estimate."""
        return self.fingertip.half_width ** 2 / self.fingertip.height

    def outer_length_to_x(self, x_end: float) -> float:
        """Arc length of the outer contour from the top (x = 0) to x = x_end."""
        ft = self.fingertip
        u = np.linspace(0.0, np.arcsin(min(x_end / ft.half_width, 1.0)), 400)
        p = ft.outer(u)
        return float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))

    def area(self) -> float:
        """Area of the skin half-section (mm^2), by the shoelace formula on dense polylines."""
        poly = self.polygon(4000)
        x, y = poly[:, 0], poly[:, 1]
        return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))

    def polygon(self, n: int = 400) -> np.ndarray:
        """Closed skin outline, counter-clockwise-agnostic: outer, nail edge, interface reversed."""
        return np.vstack([self.outer_points(n), self.interface_points(n)[::-1]])
