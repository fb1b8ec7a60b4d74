"""Sensor layouts inside the skin and their readings: the stress at each sensor.

A layout is part of a Scene (`Scene.sensors`, a tuple of `SensorLayout`; TOML `[[sensors]]`
tables). Positions are in the skin's own coordinates (`SectionCoordinates` for the fingertip):
- s (mm): arc length along the bone interface from the symmetry line x = 0 (the paper's path);
  negative s is the mirror half (x < 0), which the symmetric model answers by reflection;
- depth (mm) below the outer surface, measured along the common normal of the outer contour
  and the bone interface (the interface is the contour's inward offset by t, so the normal
  at s is one line from the surface to the bone); or height above the bone, = t - depth.
  depth 0 is the outer surface, depth t (height 0) the bonded (bone) surface;
- z (mm, 3D only): along the finger; the slab spans [-L/2, L/2] (L = fingertip sample_length).
A pad's s is x and its depth along -y (`FlatCoordinates`); a user's file skin's s is x - x_top
and z that of its contact surface's point over (x, z), its depth along that surface's inward
normal n there and its height along the same line from where it leaves the skin through the
bonded face, its plane along the surface there (skins.file_coordinates.FileCoordinates, the dome's too; its
n has a z part where the surface slopes along z). So on every skin a sensor at depth d lies d
from the surface along its plane's normal (Sites.normal_depth = depth, sensors.csv's
normal_depth_mm; a file skin's and the dome's depth was vertical, d cos theta along n under a
slope theta).

Kinds: `points` (s, and in 3D z, one per sensor), `line` (s = [s0, s1] at `pitch`; in 3D at
one z), `grid` (3D: s = [s0, s1], z = [z0, z1], pitch one value or [ps, pz]). A taxel of side
`taxel` (mm; 0 = a point sensor) is area-averaged: Gauss-Legendre `taxel_points` per direction
(default one per 0.25 mm of the side, 3 to 16; taxel_points in 2D, taxel_points**2 in 3D) over the square of that
side on the sensor's depth surface: the side is arc length on that surface (the chip's own size),
not the bone's arc length s, which at depth d of a convex section is shorter by the area element
(1 - d k) / (1 - t k) (1.6-3.2 at mid-depth of the t = 5 mm fingertip); z is straight (exact mean
of a field linear in arc length). Positions s and a line's pitch stay in the bone's s.

For a depth-ramp the stresses are the final state's; under force control or a loading history
the peak-load state's, the same state as the bone profile (fe._run_history).

Readings, per sensor, from the Cauchy stress sigma of the final state (sampled by interpolation
inside the elements, fe.probe): P = -tr(sigma)/3 (the paper's mean pressure, compression
positive), sigma_nn = n.sigma.n (tension positive) and the shears tau_1 = t1.sigma.n,
tau_2 = t2.sigma.n, with n the sensor plane's normal in the undeformed skin (the local normal of
the depth surface, pointing out of the skin; exact on the bonded surface, which does not move; a
file skin's: the contact surface's at the point the sensor hangs from), t1 along increasing s in the x-y plane (n x
e_z normalised) and t2 = t1 x n (+z where n has no z part). A taxel averages the tensor
over its area, then projects it on its centre's frame (a flat, rigid chip). In 2D plane strain
sigma_xz = sigma_yz = 0, so tau_2 = 0 exactly.

Pure numpy (no solver import): `read(sites, sampler)` takes any sampler points -> Cauchy
stresses; the solver's is `fe.probe.stress_sampler`.
"""

from __future__ import annotations

import functools
import io
import logging
from dataclasses import dataclass, field

import numpy as np

from tactileskin import validate
from tactileskin.errors import ParameterError

log = logging.getLogger(__name__)

KINDS = ("points", "line", "grid")
MAX_SENSORS = 20000          # all layouts of a scene together
MIN_PITCH = 0.01             # mm: a line's or grid's pitch, the finest mesh size (scene.MESH_SIZE)
MAX_TAXEL_POINTS = 16        # Gauss points per direction
# default Gauss points per direction: one per TAXEL_SPACING of the taxel's side, at least
# MIN_TAXEL_POINTS. Three for every size read a 2 mm taxel on the bone of a 1 mm ridge 10.6 %
# high and a 10 mm one under the curved indenter 73 % high (the field varies on the skin's
# thickness, not on the taxel); one point per 0.25 mm put both within 1 %.
TAXEL_SPACING = 0.25
MIN_TAXEL_POINTS = 3
# a file skin's taxel keeps its side along x (and z) while its plane follows the surface: on a
# slope theta it averages side / cos theta of the surface (+1.5 % at 10 degrees, +6.4 % at 20,
# +41 % at 45); past 5 % (18.2 degrees) a warning says so
TAXEL_SLOPE_COS = 1.0 / 1.05


def default_taxel_points(taxel: float) -> int:
    """Gauss points per direction of a taxel of side `taxel` (mm) when none are given."""
    import math

    # capped before ceil: a taxel past the skin (refused later, naming the skin's range) would
    # overflow it (1e308 / 0.25 is inf)
    per_side = min(float(MAX_TAXEL_POINTS), float(taxel) / TAXEL_SPACING)
    return int(max(MIN_TAXEL_POINTS, math.ceil(per_side - 1e-9)))
_KEYS = ("name", "kind", "s", "z", "depth", "height", "pitch", "taxel", "taxel_points")
_TOL = 1e-9                  # mm: positions on a range's end are inside


@dataclass(frozen=True)
class SensorLayout:
    """One layout of sensors (see the module docstring for the coordinates)."""

    name: str
    kind: str = "points"
    s: tuple[float, ...] = (0.0,)
    z: tuple[float, ...] = ()
    depth: float | None = None
    height: float | None = None
    pitch: tuple[float, ...] = ()
    taxel: float = 0.0
    taxel_points: int | None = None  # None: default_taxel_points(taxel)

    def __post_init__(self):
        if self.taxel_points is None:
            object.__setattr__(self, "taxel_points", default_taxel_points(self.taxel or 0.0))

    @classmethod
    def from_dict(cls, d, index: int = 0) -> "SensorLayout":
        if isinstance(d, SensorLayout):
            return d
        where = f"sensors[{index}]"
        validate.table(d, where)
        validate.known_keys(d, _KEYS, where)
        name = validate.string(d.get("name", f"L{index}"), f"{where}.name", "a layout name")
        if not name or any(c in name for c in ",\n\r\"") or len(name) > 64:
            raise ParameterError(f"{where}.name", name, "1-64 characters without commas or quotes")
        where = f"sensor layout {name!r}"
        kind = validate.string(d.get("kind", "points"), f"{where} kind")
        if kind not in KINDS:
            raise ParameterError(f"{where} kind", kind, "one of " + ", ".join(KINDS),
                                 validate.did_you_mean(kind, KINDS))
        s = _numbers(d.get("s", [0.0]), f"{where} s")
        z = _numbers(d.get("z", []), f"{where} z")
        pitch = _numbers(d.get("pitch", []), f"{where} pitch")
        depth = d.get("depth")
        height = d.get("height")
        if (depth is None) == (height is None):
            raise ParameterError(f"{where} depth/height", f"depth={depth}, height={height}",
                                 "exactly one: depth below the outer surface or height above the bone (mm)")
        depth = None if depth is None else validate.number(depth, f"{where} depth")
        height = None if height is None else validate.number(height, f"{where} height")
        taxel = validate.number(d.get("taxel", 0.0), f"{where} taxel")
        if taxel < 0:
            raise ParameterError(f"{where} taxel", taxel, ">= 0 mm (0: a point sensor)")
        tp = validate.integer(d.get("taxel_points", default_taxel_points(taxel)), f"{where} taxel_points",
                              f"1..{MAX_TAXEL_POINTS}")
        if not 1 <= tp <= MAX_TAXEL_POINTS:
            raise ParameterError(f"{where} taxel_points", tp, f"1..{MAX_TAXEL_POINTS}")
        if kind == "points":
            if not s:
                raise ParameterError(f"{where} s", list(s), "one s (mm) per sensor")
            if z and len(z) not in (1, len(s)):
                raise ParameterError(f"{where} z", list(z), f"one z for all or one per sensor ({len(s)})")
            if pitch:
                raise ParameterError(f"{where} pitch", list(pitch), "none for kind 'points'")
        else:
            if len(s) != 2 or s[1] < s[0]:
                raise ParameterError(f"{where} s", list(s), "[s0, s1] with s0 <= s1 (mm)")
            npitch = 1 if kind == "line" else (1, 2)
            if len(pitch) not in np.atleast_1d(npitch) or min(pitch) < MIN_PITCH:
                # below the finest mesh size no sensor reads anything new: a file in metres
                # (pitch 0.0005 for 0.5 mm) was solved and shown as ok
                raise ParameterError(f"{where} pitch", list(pitch),
                                     (f"one pitch >= {MIN_PITCH:g} mm" if kind == "line"
                                      else f"[p] or [ps, pz], >= {MIN_PITCH:g} mm"),
                                     hint="positions are in mm, not metres" if 0 < min(pitch, default=0) < MIN_PITCH else "")
            if kind == "line" and len(z) > 1:
                raise ParameterError(f"{where} z", list(z), "one z (mm) for a line")
            if kind == "grid" and (len(z) != 2 or z[1] < z[0]):
                raise ParameterError(f"{where} z", list(z), "[z0, z1] with z0 <= z1 (mm)")
        lay = cls(name, kind, s, z, depth, height, pitch, taxel, tp)
        if lay.count() > MAX_SENSORS:
            raise ParameterError(f"{where} sensors", lay.count(), f"<= {MAX_SENSORS} (a larger pitch)")
        if kind != "points" and taxel > min(pitch) + 1e-9:  # allowed (a smoothing study), but no array
            log.warning("%s: taxels of %g mm at a %g mm pitch overlap (no array can be built so)",
                        where, taxel, min(pitch))
        if kind == "points":
            ps, zs = lay.positions()
            if len(set(zip(np.round(ps, 9), np.round(zs, 9)))) < len(ps):
                log.warning("%s: two sensors at the same place (s, z); they read the same", where)
        return lay

    def to_dict(self) -> dict:
        d = {"name": self.name, "kind": self.kind, "s": list(self.s)}
        if self.z:
            d["z"] = list(self.z)
        if self.depth is not None:
            d["depth"] = self.depth
        if self.height is not None:
            d["height"] = self.height
        if self.pitch:
            d["pitch"] = list(self.pitch)
        if self.taxel:
            d["taxel"] = self.taxel
            d["taxel_points"] = self.taxel_points
        return d

    def _axis(self, lo, hi, p):
        n = int(np.floor((hi - lo) / p * (1 + 1e-12) + 1e-9)) + 1
        last = lo + p * (n - 1)
        if last < hi - _TOL:
            _short_end(self.name, float(lo), float(hi), float(p), float(last))
        return lo + p * np.arange(n)

    def positions(self) -> tuple[np.ndarray, np.ndarray]:
        """(s, z) of the layout's sensor centres (z = 0 where not given)."""
        if self.kind == "points":
            s = np.asarray(self.s, float)
            z = np.broadcast_to(np.asarray(self.z or (0.0,), float), s.shape).copy()
            return s, z
        if self.kind == "line":
            s = self._axis(self.s[0], self.s[1], self.pitch[0])
            return s, np.full(s.shape, self.z[0] if self.z else 0.0)
        ps, pz = (self.pitch[0], self.pitch[-1])
        S, Z = np.meshgrid(self._axis(self.s[0], self.s[1], ps), self._axis(self.z[0], self.z[1], pz))
        return S.ravel(), Z.ravel()  # z-major: row j is one z

    def count(self) -> int:
        if self.kind == "points":
            return len(self.s)
        n = len(self._axis(self.s[0], self.s[1], self.pitch[0]))
        if self.kind == "grid":
            n *= len(self._axis(self.z[0], self.z[1], self.pitch[-1]))
        return n

    def depth_in(self, thickness: float) -> float:
        return float(self.depth) if self.depth is not None else float(thickness - self.height)


@functools.lru_cache(maxsize=256)
def _short_end(name: str, lo: float, hi: float, p: float, last: float) -> None:
    """Say once per layout that its pitch does not reach the range's end."""
    log.warning("sensor layout %r: the pitch %g mm does not divide [%g, %g]: its last sensor is at %g mm, "
                "%g mm short of the end", name, p, lo, hi, last, hi - last)


@functools.lru_cache(maxsize=256)
def _sloped_taxel(name: str, sensor: str, degrees: int, dim: int) -> None:
    """Say once (the scene's check and the solve, on another mesh, both resolve the layout)
    that a taxel under a slope averages more of the surface than its side."""
    log.warning("sensor layout %r: sensor %s lies under a %d degree slope; its taxel's side is along x%s, "
                "so it averages %.0f %% more of the surface than its side", name, sensor, degrees,
                " and z" if dim == 3 else "", 100.0 * (1.0 / np.cos(np.radians(degrees)) - 1.0))


def _numbers(v, name) -> tuple[float, ...]:
    if validate.is_number(v):
        v = [v]
    return validate.number_list(v, name, MAX_SENSORS)


def layouts(value) -> tuple[SensorLayout, ...]:
    """Scene.sensors from a list of tables (TOML [[sensors]]) or SensorLayout objects."""
    if value is None:
        return ()
    if isinstance(value, (SensorLayout, dict)):
        value = [value]
    if not isinstance(value, (list, tuple)):
        raise ParameterError("sensors", value, "a list of sensor layout tables ([[sensors]] in TOML)")
    out = tuple(SensorLayout.from_dict(d, i) for i, d in enumerate(value))
    names = [lay.name for lay in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ParameterError("sensors name", dup[0], "unique layout names")
    total = sum(lay.count() for lay in out)
    if total > MAX_SENSORS:
        raise ParameterError("sensors", f"{total} sensors", f"<= {MAX_SENSORS} in all layouts")
    return out


# --- skin coordinates ---------------------------------------------------------------------------

class SectionCoordinates:
    """(s, depth) -> point, normal, tangent of the fingertip section (Section of
    geometry.fingertip): the point at depth d on the outer contour's normal through the bone
    point at arc length |s|, mirrored to x < 0 for s < 0."""

    def __init__(self, section):
        self.section = section
        self.thickness = float(section.thickness)
        self.s_max = float(section.interface_length)

    def frame(self, s, depth):
        """(xy (n, 2), outward unit normal (n, 2), unit tangent along +s (n, 2), |d point / ds|
        (n,), the area element of the depth surface per unit bone arc length)."""
        s = np.asarray(s, float)
        depth = np.broadcast_to(np.asarray(depth, float), s.shape)
        sec = self.section
        ft = sec.fingertip
        u = sec.u_of_s(np.minimum(np.abs(s), self.s_max))
        n = ft.outer_normal(u)
        p = ft.outer(u) - depth[:, None] * n
        sign = np.where(s < 0, -1.0, 1.0)
        p[:, 0] *= sign
        n[:, 0] *= sign
        tang = np.stack([n[:, 1], -n[:, 0]], axis=-1)  # d point / ds: +x-ward in both halves
        kap = ft.curvature(u)
        jac = (1.0 - depth * kap) / (1.0 - self.thickness * kap)
        return p, n, tang, jac

    def s_limit(self, depth: float) -> float:
        """The largest |s| whose point at `depth` lies in the skin: the skin ends at the nail
        in a cut that is not along the outer normal, so below the surface it ends before
        s_max (t = 3: at depth 1, s <= about 9.3 of 9.45 mm)."""
        poly = self.section.polygon(800)

        def inside(s_):
            p = self.frame(np.array([s_]), np.array([depth]))[0][0]  # s_ >= 0: the half x >= 0
            return _inside(poly, p)

        if inside(self.s_max):
            return self.s_max
        lo, hi = 0.0, self.s_max
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if inside(mid) else (lo, mid)
        return lo


# Own point-in-polygon (a few lines of numpy): matplotlib's Path.contains_points would pull
# matplotlib into every Scene that has sensors (sensors are validated when the scene is made).
def _inside(poly: np.ndarray, p: np.ndarray, tol: float = 1e-4) -> bool:
    """Whether point p lies in the closed polygon (ray casting; a point within tol (mm) of an
    edge counts as inside: the surface and the bone are in the skin, and the sampled outline's
    chords cut under the curve by ~1e-5 mm)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0.0, 1.0)
    if np.min(np.linalg.norm(a + t[:, None] * ab - p, axis=1)) <= tol:
        return True
    cross = (a[:, 1] > p[1]) != (b[:, 1] > p[1])
    x_at = a[:, 0] + (p[1] - a[:, 1]) * ab[:, 0] / np.where(ab[:, 1] == 0, 1e-300, ab[:, 1])
    return bool(np.sum(cross & (p[0] < x_at)) % 2)


class FlatCoordinates:
    """A flat layer: s = x in [-half_width, half_width], depth below y = top. For blocks
    and pads (the tests' homogeneous block)."""

    straight = True  # taxel_s: s is arc length on every depth surface

    def __init__(self, top: float, thickness: float, half_width: float):
        self.top, self.thickness, self.s_max = float(top), float(thickness), float(half_width)

    def frame(self, s, depth):
        s = np.asarray(s, float)
        depth = np.broadcast_to(np.asarray(depth, float), s.shape)
        p = np.stack([s, self.top - depth], axis=-1)
        n = np.tile([0.0, 1.0], (len(s), 1))
        t = np.tile([1.0, 0.0], (len(s), 1))
        return p, n, t, np.ones(len(s))


def coordinates_for(scene):
    """The skin coordinates of a scene (the skin's answer: skins.*.coordinates)."""
    return scene.skin_kind.coordinates(scene)


# --- sites: the resolved points ---------------------------------------------------------------

@dataclass
class Sites:
    """Resolved sensors: centres, frames and taxel sample points with their weights.

    xyz (n, 3) centres; normal, t1, t2 (n, 3); samples (n, k, 3) taxel points and weights
    (n, k) summing to 1 per sensor; ids, layout names, s, z, depth per sensor."""

    ids: list
    layout: list
    s: np.ndarray
    z: np.ndarray
    depth: np.ndarray
    xyz: np.ndarray
    normal: np.ndarray
    t1: np.ndarray
    t2: np.ndarray
    samples: np.ndarray
    weights: np.ndarray
    dim: int = 2
    # the distance along the normal from the contact surface: depth on every skin (a file
    # skin's and the dome's was vertical, depth * n_y along it); None: unknown (NaN in the
    # readings)
    normal_depth: np.ndarray | None = None

    @classmethod
    def at(cls, points, normals, ids=None, dim: int | None = None) -> "Sites":
        """Point sensors at given points with given plane normals (any orientation; t1 =
        n x e_z normalised, t2 = t1 x n: in 2D t1 lies in the plane and t2 = e_z)."""
        pts = np.atleast_2d(np.asarray(points, float))
        dim = dim or pts.shape[1]
        xyz = _to3(pts)
        n = _to3(np.atleast_2d(np.asarray(normals, float)))
        n = n / np.linalg.norm(n, axis=1, keepdims=True)
        t1 = np.cross(n, [0.0, 0.0, 1.0])
        norm = np.linalg.norm(t1, axis=1, keepdims=True)
        if np.any(norm < 1e-12):
            raise ParameterError("sensor normal", "along z", "a normal with an x or y component")
        t1 /= norm
        t2 = np.cross(t1, n)
        k = len(xyz)
        ids = list(ids) if ids is not None else [f"p{i}" for i in range(k)]
        return cls(ids, ["points"] * k, np.full(k, np.nan), xyz[:, 2].copy(), np.full(k, np.nan), xyz, n,
                   t1, t2, xyz[:, None, :].copy(), np.ones((k, 1)), dim)


def _to3(p):
    return p if p.shape[1] == 3 else np.column_stack([p, np.zeros(len(p))])


def _check_range(where, what, v, lo, hi, unit="mm", note=""):
    v = np.atleast_1d(v)
    bad = (v < lo - _TOL) | (v > hi + _TOL)
    if np.any(bad):
        raise ParameterError(f"{where} {what}", float(v[bad][0]), f"[{lo:.6g}, {hi:.6g}] {unit}{note}")


def _surface_arc(coords, depth: float, lim: float) -> tuple[np.ndarray, np.ndarray]:
    """(S, A): the arc length A on the surface at `depth` from s = -lim to each S in [-lim, lim]
    (trapezoids of coords.frame's area element on 801 points; within 1e-4 mm of the polyline
    through 4001 at t = 1-5, any depth). The one
    measure of the surface both taxel checks take: the side check and the edge check each had
    their own (27.1047 and 27.0794 mm at t = 3, depth 1), so a side the first called valid the
    second refused."""
    S = np.linspace(-lim, lim, 801)
    jac = coords.frame(S, np.full(S.size, depth))[3]
    return S, np.concatenate([[0.0], np.cumsum(0.5 * (jac[1:] + jac[:-1]) * np.diff(S))])


def _check_side(where, side: float, depth: float, lim: float, arc: float) -> None:
    """A taxel longer than the skin's whole surface at its depth (`arc` mm): its edges lie past
    the skin wherever it sits (a side in um, 800 for 0.8 mm, was named by an edge found on the
    surface's extension past the nail, 's +- taxel/2=-270.47', neither the taxel nor an edge)."""
    if side > arc + _TOL:
        raise ParameterError(f"{where} taxel", float(side), f"(0, {arc:.6g}] mm: the surface at depth {depth:g} mm, "
                             f"s in [{-lim:.6g}, {lim:.6g}] mm, is {arc:.6g} mm long", hint="sides are in mm")


def _check_edges(where, s, side: float, table, depth: float, note: str) -> None:
    """Each taxel's edges, side/2 of arc length either side of its centre on the surface at
    `depth`, within the skin: measured on `table` (_surface_arc), as the side check is. An edge
    past an end is named by its s, extended past the end at the end's area element."""
    S, A = table
    a = np.interp(s, S, A)
    lo, hi = a - 0.5 * side, a + 0.5 * side
    bad = (lo < -_TOL) | (hi > A[-1] + _TOL)
    if not np.any(bad):
        return
    i = int(np.argmax(bad))
    if lo[i] < -_TOL:
        edge = S[0] + lo[i] / ((A[1] - A[0]) / (S[1] - S[0]))
    else:
        edge = S[-1] + (hi[i] - A[-1]) / ((A[-1] - A[-2]) / (S[-1] - S[-2]))
    raise ParameterError(f"{where} s +- taxel/2", float(edge), f"[{S[0]:.6g}, {S[-1]:.6g}] mm{note}")


def resolve(lays, coords, dim: int, z_range: tuple[float, float] | None = None) -> Sites:
    """Sites of the layouts in the skin coordinates `coords`; a sensor (or a taxel's edge)
    outside the skin is a ParameterError naming the layout and the valid range."""
    t, smax = coords.thickness, coords.s_max
    local = getattr(coords, "local", False)  # skins.file_coordinates.FileCoordinates: checks its own points
    ids, names, S, Z, D, layout_of = [], [], [], [], [], []
    for lay in lays:
        where = f"sensor layout {lay.name!r}"
        if dim == 2 and (lay.kind == "grid"):
            raise ParameterError(f"{where} kind", "grid", "points or line in 2D (plane strain is uniform "
                                 "along z: a grid is a line)")
        if dim == 2 and lay.z and any(v != 0 for v in lay.z):
            raise ParameterError(f"{where} z", list(lay.z), "omitted in 2D (plane strain)")
        s, z = lay.positions()
        h = 0.5 * lay.taxel
        n0 = len(ids)
        ids += [f"{lay.name}-{i}" for i in range(len(s))]
        names += [lay.name] * len(s)
        layout_of.append((lay, n0, len(s)))
        if local:  # a user's skin: the surface, the bonded face and the skin's extent vary
            if dim == 2:
                z = np.zeros_like(z)
            if h:  # the taxel's edges (in 3D its corners) are in the skin
                ox = np.array([-1.0, 1.0] if dim == 2 else [-1.0, 1.0, -1.0, 1.0])
                oz = np.zeros(2) if dim == 2 else np.array([-1.0, -1.0, 1.0, 1.0])
                coords.depths(where, lay, (s[:, None] + h * ox).ravel(), (z[:, None] + h * oz).ravel(),
                              np.repeat(np.arange(len(s)), len(ox)), what=" +- taxel/2")
            S.append(s), Z.append(z), D.append(coords.depths(where, lay, s, z, np.arange(len(s))))
            continue
        d = lay.depth_in(t)
        if lay.depth is not None:
            _check_range(where, "depth", d, 0.0, t)
        else:
            _check_range(where, "height", lay.height, 0.0, t)
        lim = coords.s_limit(d) if hasattr(coords, "s_limit") else smax
        at_nail = f" at depth {d:g} mm (the skin ends at the nail)" if lim < smax - _TOL else ""
        _check_range(where, "s", s, -lim, lim, note=at_nail)
        if h:  # the taxel's edges: taxel/2 of arc length on the depth surface each side
            table = _surface_arc(coords, d, lim)
            _check_side(where, lay.taxel, d, lim, float(table[1][-1]))
            _check_edges(where, s, lay.taxel, table, d, at_nail)
        if dim == 3 and z_range is not None:
            _check_range(where, "z" + (" +- taxel/2" if h else ""), np.concatenate([z - h, z + h]), *z_range)
        S.append(s), Z.append(z), D.append(np.full(len(s), d))
    s, z, depth = np.concatenate(S), np.concatenate(Z), np.concatenate(D)
    if dim == 2:
        z = np.zeros_like(z)
    xy, n2, t2d, _ = coords.frame(s, depth, z) if local else coords.frame(s, depth)
    # a file skin's 3D frame gives z too: the solve may move a rim sensor onto its mesh
    xyz = xy if xy.shape[1] == 3 else np.column_stack([xy, z])
    # a section's frame lies in the x-y plane; a file skin's 3D one follows its surface out of it
    normal = n2 if n2.shape[1] == 3 else np.column_stack([n2, np.zeros(len(s))])
    t1 = t2d if t2d.shape[1] == 3 else np.column_stack([t2d, np.zeros(len(s))])
    t2 = np.cross(t1, normal)
    for lay, i0, cnt in layout_of:
        cos = normal[i0:i0 + cnt, 1]
        if local and lay.taxel and cos.min() < TAXEL_SLOPE_COS:
            i = int(np.argmin(cos))
            _sloped_taxel(lay.name, ids[i0 + i], int(round(np.degrees(np.arccos(min(cos[i], 1.0))))), dim)
    # taxel samples: Gauss-Legendre in (s, z) on the depth surface, area-weighted
    kmax = max((lay.taxel_points ** (dim - 1) if lay.taxel else 1) for lay, _, _ in layout_of)
    samples = np.repeat(xyz[:, None, :], kmax, axis=1)
    weights = np.zeros((len(s), kmax))
    weights[:, 0] = 1.0
    for lay, i0, cnt in layout_of:
        if not lay.taxel:
            continue
        g, w = np.polynomial.legendre.leggauss(lay.taxel_points)
        # Gauss points equally weighted in arc length on the depth surface (the taxel's own
        # plane), so the side is the chip's: in s (the bone's arc length) a side at depth d of
        # a convex section is shorter by the area element (1 - d k) / (1 - t k); along z straight
        if dim == 2:
            gs, gz, wq = g, np.zeros_like(g), w
        else:
            gs, gz = (m.ravel() for m in np.meshgrid(g, g))
            wq = np.outer(w, w).ravel()
        k = len(gs)
        rows = slice(i0, i0 + cnt)
        ss = taxel_s(coords, s[rows], float(depth[i0]), gs, lay.taxel).ravel()
        zz = (z[rows, None] + 0.5 * lay.taxel * gz[None, :]).ravel() if dim == 3 else np.zeros(len(ss))
        if local:  # each point at the layout's depth (or height) at its own (x, z)
            dq = coords.depths(f"sensor layout {lay.name!r}", lay, ss, zz, np.repeat(np.arange(cnt), k))
            pq = coords.frame(ss, dq, zz, normals=False)[0]
        else:
            pq, _, _, _ = coords.frame(ss, np.repeat(depth[rows], k))
        samples[rows, :k] = (pq if pq.shape[1] == 3 else np.column_stack([pq, zz])).reshape(cnt, k, 3)
        weights[rows, :k] = np.broadcast_to(wq / wq.sum(), (cnt, k))
        weights[rows, k:] = 0.0
    # every skin's depth is along the surface's normal now (a file skin's and the dome's was
    # vertical, depth * n_y along it: 0.71 mm for depth 1 under a 45 degree slope)
    normal_depth = depth.copy()
    return Sites(ids, names, s, z, depth, xyz, normal, t1, t2, samples, weights, dim, normal_depth)


def taxel_s(coords, s_centre, depth: float, g, side: float, n: int = 17) -> np.ndarray:
    """(len(s_centre), len(g)) values of s at the points g * side / 2 of arc length (g in
    [-1, 1]) from each centre along the depth surface: the inverse of the arc length
    int jac ds, jac = |d point / ds| (coords.frame's area element; 1 on a flat layer). Each
    side of a centre has its own table, so a taxel centred on the symmetry line is mirrored
    exactly."""
    sc = np.atleast_1d(np.asarray(s_centre, float))
    g = np.asarray(g, float)
    half = 0.5 * float(side)
    if getattr(coords, "straight", False):  # s is arc length on every depth surface
        return sc[:, None] + half * g[None, :]
    _, _, _, j0 = coords.frame(sc, np.full(sc.shape, depth))
    out = np.empty((sc.size, g.size))
    u = np.linspace(0.0, 1.0, n)
    for sign, pick in ((1.0, g >= 0), (-1.0, g < 0)):
        if not pick.any():
            continue
        reach = 1.5 * half / np.maximum(j0, 1e-6)  # covers the half side where jac varies slowly
        for _ in range(8):  # widen where it falls off faster than that
            S = sc[:, None] + sign * reach[:, None] * u[None, :]
            _, _, _, jac = coords.frame(S.ravel(), np.full(S.size, depth))
            jac = jac.reshape(S.shape)
            arc = np.concatenate([np.zeros((sc.size, 1)), np.cumsum(
                0.5 * (jac[:, 1:] + jac[:, :-1]) * np.abs(np.diff(S, axis=1)), axis=1)], axis=1)
            short = arc[:, -1] < half
            if not short.any():
                break
            reach = np.where(short, 2.0 * reach, reach)
        # invert every row's arc length table at once (arc increases along each row)
        uniq, inv = np.unique(np.abs(g[pick]), return_inverse=True)
        T = uniq * half
        idx = np.clip((arc[:, :, None] < T[None, None, :]).sum(axis=1), 1, n - 1)
        a0, a1 = np.take_along_axis(arc, idx - 1, 1), np.take_along_axis(arc, idx, 1)
        s0, s1 = np.take_along_axis(S, idx - 1, 1), np.take_along_axis(S, idx, 1)
        frac = np.clip((T[None, :] - a0) / np.where(a1 > a0, a1 - a0, 1.0), 0.0, 1.0)
        out[:, pick] = (s0 + frac * (s1 - s0))[:, inv.ravel()]
    return out


def sites_for(scene, z_range=None, coords=None) -> Sites:
    """Sites of a scene's layouts (validated against its skin; z_range: the 3D slab's z; coords:
    other coordinates than the scene's, e.g. skin_kind.mesh_coordinates)."""
    if z_range is None and scene.dim == 3:
        L = scene.sample_length
        z_range = (-0.5 * L, 0.5 * L)
    return resolve(scene.sensors, coordinates_for(scene) if coords is None else coords, scene.dim, z_range)


# --- sampling and readings ----------------------------------------------------------------------

def symmetric_sampler(sampler, *, mirror_x: bool = True, mirror_z: bool = False):
    """A sampler of the whole skin from one of the modelled part: a point with x < 0 (z < 0 when
    mirror_z) is sampled at its mirror image and the tensor reflected (sigma' = R sigma R); a
    point on a mirror plane gets the even part (the shears across the plane zero)."""

    def sample(points):
        pts = np.array(points, float)
        flips = []
        if mirror_x:
            flips.append((0, pts[:, 0] < 0))
        if mirror_z and pts.shape[1] == 3:
            flips.append((2, pts[:, 2] < 0))
        for ax, neg in flips:
            pts[neg, ax] *= -1
        sig = np.array(sampler(pts), float)
        for ax, neg in flips:
            r = np.ones(3)
            r[ax] = -1
            sig[neg] *= r[:, None] * r[None, :]
            # on the plane itself the field is its own mirror image: the shears across it (odd)
            # vanish exactly, which the discrete field only approaches (sxy ~4 % of the largest
            # shear at the symmetry line on a preview mesh)
            on = np.abs(pts[:, ax]) <= _TOL
            sig[on] = 0.5 * (sig[on] + sig[on] * (r[:, None] * r[None, :]))
        return sig

    return sample


def read(sites: Sites, sampler) -> "SensorReadings":
    """Readings at the sites: sampler(points (N, dim)) -> Cauchy stress (N, 3, 3)."""
    n, k, _ = sites.samples.shape
    pts = sites.samples.reshape(-1, 3)[:, :sites.dim]
    sig = np.asarray(sampler(pts), float).reshape(n, k, 3, 3)
    sig = np.einsum("nk,nkij->nij", sites.weights, sig)
    return readings_from_stress(sites, sig)


def readings_from_stress(sites: Sites, sig: np.ndarray) -> "SensorReadings":
    """Readings of the (taxel-averaged) Cauchy stresses (n, 3, 3) at the sites."""
    n = sites.normal
    tn = np.einsum("kij,kj->ki", sig, n)            # traction on the sensor plane
    return SensorReadings(
        ids=list(sites.ids), layout=list(sites.layout), xyz=sites.xyz.copy(), s=sites.s.copy(),
        depth=sites.depth.copy(), normal=n.copy(),
        normal_depth=(np.full(len(n), np.nan) if sites.normal_depth is None else sites.normal_depth.copy()),
        pressure=-np.trace(sig, axis1=1, axis2=2) / 3.0,
        sigma_nn=np.einsum("ki,ki->k", n, tn), tau_1=np.einsum("ki,ki->k", sites.t1, tn),
        tau_2=np.einsum("ki,ki->k", sites.t2, tn),
        taxel_points=(sites.weights > 0).sum(axis=1))


# appended (a reader of the first twelve columns reads them as before): nx, ny, nz, the sensor
# plane's unit normal (the frame the stresses are resolved in), and normal_depth_mm, the sensor's
# distance from the surface along that normal (= depth_mm on every skin; it was depth * ny while a
# file skin's and the dome's depth was vertical)
OLD_COLUMNS = ("sensor_id", "layout", "x_mm", "y_mm", "z_mm", "s_mm", "depth_mm", "pressure_mpa",
               "sigma_nn_mpa", "tau_1_mpa", "tau_2_mpa", "taxel_points")
COLUMNS = OLD_COLUMNS + ("nx", "ny", "nz", "normal_depth_mm")


@dataclass
class SensorReadings:
    """One row per sensor: ids, layout, centre xyz (mm), s and depth (mm, skin coordinates),
    plane normal, and P, sigma_nn, tau_1, tau_2 (MPa), the taxel's sample count."""

    ids: list
    layout: list
    xyz: np.ndarray
    s: np.ndarray
    depth: np.ndarray
    normal: np.ndarray
    pressure: np.ndarray
    sigma_nn: np.ndarray
    tau_1: np.ndarray
    tau_2: np.ndarray
    taxel_points: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    normal_depth: np.ndarray | None = None  # Sites.normal_depth (None: NaN)

    def __post_init__(self):
        if self.normal_depth is None:
            self.normal_depth = np.full(len(self.ids), np.nan)
        from tactileskin.errors import ConvergenceError

        for name in ("pressure", "sigma_nn", "tau_1", "tau_2"):
            v = np.asarray(getattr(self, name), float)
            if not np.all(np.isfinite(v)):
                raise ConvergenceError(f"non-finite sensor reading {name!r}", {"field": name})
            setattr(self, name, v)

    def __len__(self):
        return len(self.ids)

    def select(self, layout: str) -> "SensorReadings":
        """The rows of one layout."""
        keep = np.array([name == layout for name in self.layout])
        return SensorReadings(
            [i for i, k in zip(self.ids, keep) if k], [layout] * int(keep.sum()), self.xyz[keep],
            self.s[keep], self.depth[keep], self.normal[keep], self.pressure[keep], self.sigma_nn[keep],
            self.tau_1[keep], self.tau_2[keep], np.asarray(self.taxel_points)[keep], self.normal_depth[keep])

    def summary(self) -> dict:
        """Summary fields: sensor count, the largest sensor pressure, its sensor and position."""
        i = int(np.argmax(self.pressure))
        return {"sensors": len(self), "peak_sensor_pressure_mpa": float(self.pressure[i]),
                "peak_sensor_id": self.ids[i], "peak_sensor_xyz_mm": [float(v) for v in self.xyz[i]],
                "max_abs_sensor_shear_mpa": float(np.max(np.hypot(self.tau_1, self.tau_2)))}

    def to_csv(self) -> str:
        """Tidy table, one row per sensor (COLUMNS)."""
        buf = io.StringIO()
        buf.write(",".join(COLUMNS) + "\n")
        for i in range(len(self)):
            x, y, z = self.xyz[i]
            vals = (x, y, z, self.s[i], self.depth[i], self.pressure[i], self.sigma_nn[i], self.tau_1[i],
                    self.tau_2[i])
            buf.write(",".join([self.ids[i], self.layout[i], *(f"{v:.10g}" for v in vals),
                                str(int(self.taxel_points[i])),
                                *(f"{v + 0.0:.10g}" for v in self.normal[i]),  # + 0.0: no "-0"
                                f"{self.normal_depth[i]:.10g}"]) + "\n")
        return buf.getvalue()


def read_sensors_csv(path) -> SensorReadings:
    """The SensorReadings of a sensors.csv (as Result.write writes it; one written before the
    normal columns reads NaN normals and normal depths); a file that is not one raises ParameterError naming it."""
    import csv
    from pathlib import Path

    path = Path(path)
    from tactileskin.results import without_status

    valid = "a sensors.csv written by tactileskin solve (" + ", ".join(COLUMNS) + "[, status])"
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
        # the result's status (last column since it was added) is the summary's, not a reading
        cols = tuple(without_status(list(rows[0].keys()))) if rows else ()
        if not rows or cols not in (COLUMNS, OLD_COLUMNS):
            raise ValueError("unexpected header")
        f = {c: np.array([float(r[c]) for r in rows]) for c in cols[2:]}
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise ParameterError("sensors file", str(path), valid, hint=str(e)) from None
    xyz = np.column_stack([f["x_mm"], f["y_mm"], f["z_mm"]])
    return SensorReadings([r["sensor_id"] for r in rows], [r["layout"] for r in rows], xyz, f["s_mm"],
                          f["depth_mm"], (np.column_stack([f["nx"], f["ny"], f["nz"]]) if "nx" in f
                                          else np.full((len(rows), 3), np.nan)), f["pressure_mpa"],
                          f["sigma_nn_mpa"], f["tau_1_mpa"], f["tau_2_mpa"], f["taxel_points"].astype(int),
                          f.get("normal_depth_mm"))
