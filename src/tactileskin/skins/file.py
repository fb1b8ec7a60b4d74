"""file: a user's skin geometry, a gmsh .msh with named physical groups or a STEP solid whose
bonded faces a rule picks (mesh.skinfile; docs/architecture.md, "skins").

Scene fields: `skin_file` (the path; its bytes, not its path, enter the cache key),
`skin_bonded` (.msh: comma-separated physical-group names of the bonded surface(s), default
the first of bone_interface, bonded, board, bone, base, fixed; STEP: a rule, default
"normal:-y"), `skin_outer` (.msh: the contact surface's group(s), default outer_surface,
outer, contact, skin_surface or top, else the rest of the boundary). Groups named `nail_edge`
or `bone_tip` (the fingertip's and the dome's other bonded surfaces, as `tactileskin mesh`
writes them) are held fixed as well.

What the file fixes: `dim` (a 3D file makes the scene 3D; dim = 3 with a 2D file is refused),
`thickness` (measured: the distance from the top point to the bonded surface; a different
value given is refused), the top point (highest point of the outer surface, nearest the axis
x = z = 0 among equals; of a STEP, the CAD surface's point on that axis), where indenters start (y0 = its y; indenters stay centred on
x = z = 0; `check_placement` refuses a skin upside down, off the axis or highest off it). s
along the bonded surface is x - x_top (signed), the section plane of a 3D
profile z = 0. Sensor layouts are refused on a file skin (its sensor frames are undefined).
The model is the half x >= 0 only when the file names a `symmetry` group.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tactileskin.errors import ParameterError
from tactileskin.skins.base import Skin
from tactileskin.skins.registry import register

DEFAULT_THICKNESS = 3.0  # Scene's default: taken as "not given"


@dataclass(frozen=True)
class FileGeometry:
    """What the Scene needs from a skin file (measured on its mesh)."""

    dim: int
    top_point: tuple          # (x, y) or (x, y, z)
    thickness: float
    lo: tuple
    hi: tuple
    outer_xy: np.ndarray      # (n, 2): (x, y) of the outer surface's nodes (first-contact estimate)
    symmetric: bool           # the file names a `symmetry` group (half model x >= 0)
    groups: tuple = ()
    z_symmetric: bool = False  # 3D: the file names a `symmetry_z` group (half model z >= 0)
    axis_y: float | None = None  # y of the outer surface on the indenters' axis (None: it misses it)


AXIS_GAP = 0.02  # of t: how far the outer surface on the axis may lie below the top point


def _axis_height(mesh, facets, size: float):
    """Highest y where the axis x = 0 (2D) or x = z = 0 (3D) crosses the straight facets (None
    where it crosses none)."""
    v = mesh.p[:, mesh.facets[:, facets]].T            # (n, nv, dim)
    eps = 1e-9 * size
    if v.shape[-1] == 2:
        x0, x1, y0, y1 = v[:, 0, 0], v[:, 1, 0], v[:, 0, 1], v[:, 1, 1]
        hit = (np.minimum(x0, x1) <= eps) & (np.maximum(x0, x1) >= -eps)
        dx = np.where(np.abs(x1 - x0) > eps, x1 - x0, 1.0)
        u = np.clip(np.where(np.abs(x1 - x0) > eps, -x0 / dx, 1.0), 0.0, 1.0)
        y = np.where(np.abs(x1 - x0) > eps, y0 + u * (y1 - y0), np.maximum(y0, y1))
    else:
        a, b, c = (v[:, k][:, [0, 2]] for k in range(3))
        det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        ok = np.abs(det) > eps * size
        det = np.where(ok, det, 1.0)
        l1 = ((-a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (-a[:, 1])) / det
        l2 = ((b[:, 0] - a[:, 0]) * (-a[:, 1]) - (-a[:, 0]) * (b[:, 1] - a[:, 1])) / det
        tol = 1e-9
        hit = ok & (l1 >= -tol) & (l2 >= -tol) & (l1 + l2 <= 1 + tol)
        y = v[:, 0, 1] + l1 * (v[:, 1, 1] - v[:, 0, 1]) + l2 * (v[:, 2, 1] - v[:, 0, 1])
    return float(y[hit].max()) if hit.any() else None


def _distance_to_facets(point, mesh, facets) -> float:
    """Smallest distance from `point` to the straight facets (segments or triangles)."""
    v = mesh.p[:, mesh.facets[:, facets]].T            # (n, nv, dim)
    p = np.asarray(point, float)
    if v.shape[-1] == 2:
        a, b = v[:, 0], v[:, 1]
        ab = b - a
        u = np.clip(np.sum((p - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
        return float(np.min(np.linalg.norm(a + u[:, None] * ab - p, axis=1)))
    import trimesh

    closest = trimesh.triangles.closest_point(v, np.tile(p, (len(v), 1)))
    return float(np.min(np.linalg.norm(closest - p, axis=1)))


def measure(skinmesh, groups=()) -> FileGeometry:
    """The FileGeometry of a loaded skin mesh."""
    m, b = skinmesh.mesh, skinmesh.boundaries
    X = m.doflocs
    nodes = np.unique(m.facets[:, b["outer_surface"]])
    pts = m.p[:, nodes].T
    lo, hi = X.min(axis=1), X.max(axis=1)
    size = float(np.max(hi - lo))
    ymax = pts[:, 1].max()
    near = pts[pts[:, 1] >= ymax - 1e-9 * size]
    axis = near.copy()
    axis[:, 1] = 0.0
    top = near[np.argmin(np.linalg.norm(axis, axis=1))]
    lateral = [0] if skinmesh.dim == 2 else [0, 2]
    if all(near[:, k].min() < 0.0 < near[:, k].max() for k in lateral):
        # a flat top across the axis: the top point is on the axis, under the indenters (the
        # node nearest it is up to half a cell off, and s = x - x_top would be shifted by that)
        top = np.zeros(pts.shape[1])
        top[1] = ymax
    t = _distance_to_facets(top, m, b["bone_interface"])
    return FileGeometry(dim=skinmesh.dim, top_point=tuple(float(c) for c in top), thickness=t,
                        lo=tuple(lo.tolist()), hi=tuple(hi.tolist()), outer_xy=pts[:, :2].copy(),
                        symmetric="symmetry" in b, groups=tuple(groups),
                        z_symmetric=bool(getattr(skinmesh, "z_symmetric", False)),
                        axis_y=_axis_height(m, b["outer_surface"], size))


def check_placement(geo: FileGeometry, path, kind: str, bonded, outer) -> None:
    """ParameterError unless the skin lies as the indenters expect it: its contact surface on
    top (they press down, -y, from above), the bonded surface below it, the axis x = 0 (and
    z = 0 in 3D) through the skin (the model's edge where it is a symmetric half, which lies on
    x >= 0 / z >= 0) and the contact surface's highest point on that axis (indenters are centred
    there and start at its height)."""
    name = Path(str(path)).name
    size = float(np.max(np.subtract(geo.hi, geo.lo)))
    eps = 1e-6 * size
    x, y = geo.top_point[0], geo.top_point[1]
    if geo.hi[1] > y + eps:
        raise ParameterError("skin_outer" if kind == "msh" else "skin_bonded",
                             (outer or "its default") if kind == "msh" else (bonded or "normal:-y"),
                             "a contact surface on top of the skin (indenters press down, -y, from above)",
                             f"{name}'s contact surface reaches y = {y:.4g} mm, its skin y = {geo.hi[1]:.4g} mm: "
                             "is the skin upside down, or the contact group the inner face?")
    if geo.thickness <= eps:
        raise ParameterError("skin_bonded", bonded or ("the default group" if kind == "msh" else "normal:-y"),
                             "a bonded surface below the contact surface's highest point",
                             f"that point ({', '.join(f'{c:.4g}' for c in geo.top_point)}) of {name} lies on the "
                             "bonded surface (thickness 0): is the skin upside down?")
    axes = [(0, "x", geo.symmetric, "symmetry")] + ([(2, "z", geo.z_symmetric, "symmetry_z")] if geo.dim == 3 else [])
    for k, a, half, group in axes:
        lo, hi = geo.lo[k], geo.hi[k]
        if half and lo < -eps:
            raise ParameterError("skin_file", str(path), f"a half model on {a} >= 0 (its {group!r} group on {a} = 0)",
                                 f"{name} spans {a} in [{lo:.4g}, {hi:.4g}] mm: mirror it to {a} >= 0")
        if not half and not (lo < -eps and hi > eps):
            raise ParameterError("skin_file", str(path), f"a skin across the indenters' axis {a} = 0 (or a half "
                                 f"model with a {group!r} group on {a} = 0)",
                                 f"{name} spans {a} in [{lo:.4g}, {hi:.4g}] mm: the indenter would press its edge; "
                                 "centre the skin on the axis")
    gap = y - geo.axis_y if geo.axis_y is not None else float("inf")
    if gap > AXIS_GAP * geo.thickness:
        where = "misses the contact surface" if geo.axis_y is None else f"meets it {gap:.4g} mm lower"
        raise ParameterError("skin_file", str(path), "a skin whose contact surface is highest on the indenters' "
                             "axis x = 0" + (", z = 0" if geo.dim == 3 else "") + f" (within {AXIS_GAP:.0%} of t)",
                             f"{name}'s highest point is at x = {x:.4g}"
                             + (f", z = {geo.top_point[2]:.4g}" if geo.dim == 3 else "")
                             + f" mm and the axis {where}: the indenters start at that height on the axis, so "
                             "the depth would be short by the gap; move the skin's top to the axis")


@functools.lru_cache(maxsize=16)
def _analyse(kind: str, path: str, digest: str, bonded, outer) -> FileGeometry:
    from tactileskin.mesh import skinfile

    if kind == "msh":
        sm, groups = skinfile.load_msh(path, bonded=bonded, outer=outer)
        g = measure(sm, groups)
    else:
        sm = skinfile.mesh_step(path, bonded=bonded, mesh_size=None, order=1)  # a coarse mesh (size / 8)
        g = measure(sm)
        top, on_axis = skinfile.refine_top(path, g.top_point)
        t = _distance_to_facets(top, sm.mesh, sm.boundaries["bone_interface"])
        g = FileGeometry(**{**g.__dict__, "top_point": tuple(float(c) for c in top), "thickness": t,
                            "axis_y": None if on_axis is None else float(on_axis[1])})
        check_placement(g, path, kind, bonded, outer)  # the highest point, against the axis
        # indenters start on the axis (within AXIS_GAP of the highest point, checked): the top is
        # the CAD point there, not the highest node's refinement (0.34 mm off it on a sphere cap,
        # t 0.5 % short; 3.2 mm along a crown's top line)
        t = _distance_to_facets(on_axis, sm.mesh, sm.boundaries["bone_interface"])
        # the facets are chords of the CAD: read t on the bonded faces themselves
        cad = skinfile.distance_to_faces(path, on_axis, sm.bonded_faces)
        t = t if cad is None else cad
        return FileGeometry(**{**g.__dict__, "top_point": tuple(float(c) for c in on_axis), "thickness": t})
    check_placement(g, path, kind, bonded, outer)
    return g


def geometry(scene) -> FileGeometry:
    from tactileskin.mesh import skinfile

    path = scene.skin_file
    if not path:
        raise ParameterError("skin_file", path, "a .msh or STEP file of the skin", "skin = 'file' needs it")
    kind = skinfile.file_kind(path)
    digest = skinfile.file_digest(path)
    if kind == "step":
        skinfile.parse_rule(scene.skin_bonded)
        if scene.skin_outer is not None:
            raise ParameterError("skin_outer", scene.skin_outer, "not set for a STEP file",
                                 "every face that is not bonded is the outer surface")
    return _analyse(kind, str(Path(path).resolve()), digest, scene.skin_bonded, scene.skin_outer)


@dataclass(frozen=True)
class FileSection:
    """The `Section` duck type of a file skin: s = x - x_top along the bonded surface."""

    geo: FileGeometry

    @property
    def thickness(self) -> float:
        return self.geo.thickness

    @property
    def top(self) -> float:
        return self.geo.top_point[1]

    @property
    def half_width(self) -> float:
        return float(max(abs(self.geo.lo[0]), abs(self.geo.hi[0])))

    @property
    def interface_length(self) -> float:
        return float(self.geo.hi[0] - self.geo.top_point[0])

    @property
    def min_radius_of_curvature(self) -> float:
        return float("inf")

    def contact_radius(self, indenter) -> float:
        r = getattr(indenter, "radius", None)
        return float(r) if r else 1e6

    def outer_length_to_x(self, x: float) -> float:
        return float(x)

    def s_of_point(self, points) -> np.ndarray:
        pts = np.atleast_2d(np.asarray(points, float))
        return pts[:, 0] - self.geo.top_point[0]

    def point_at_s(self, s):
        raise ParameterError("s", s, "no points by s on a file skin", "its bonded surface has no path")

    def outer_points(self, n: int = 200) -> np.ndarray:
        """(x, y) of the outer surface's nodes (in 3D projected along z: a first-contact
        estimate that can only be early)."""
        return self.geo.outer_xy

    def area(self) -> float:
        raise ParameterError("skin", "file", "a built-in skin", "a file skin has no section area")


@register
class FileSkin(Skin):
    name = "file"
    order = 3
    scene_params = ("skin_file", "skin_bonded", "skin_outer")
    # the other bonded surfaces `tactileskin mesh` writes (the fingertip's nail, the dome's bone
    # under its tip) are held fixed too where the file has them
    fixed_boundaries = ("bone_interface", "nail_edge", "bone_tip")
    fixes_thickness = True
    s_axis = "s = x - x_top along the bonded surface"

    @classmethod
    def check_scene(cls, scene) -> dict:
        geo = geometry(scene)
        if scene.dim == 3 and geo.dim == 2:
            raise ParameterError("dim", 3, "2 for this 2D skin file", f"{scene.skin_file} is a 2D mesh")
        t = float(scene.thickness)
        if t != DEFAULT_THICKNESS and abs(t - geo.thickness) > 1e-6 * max(1.0, geo.thickness):
            raise ParameterError("thickness", t, f"{geo.thickness:.6g} mm (measured from {scene.skin_file}) or left out",
                                 "the file fixes it")
        if scene.sensors:
            raise ParameterError("sensors", f"{len(scene.sensors)} layout(s)", "none with skin = file",
                                 "a user's skin has no sensor coordinates (s and depth) yet")
        return {"thickness": geo.thickness, "dim": geo.dim, "skin_file": str(scene.skin_file)}

    @classmethod
    def section(cls, scene) -> FileSection:
        return FileSection(geometry(scene))

    @classmethod
    def sample_length(cls, scene) -> float:
        geo = geometry(scene)
        if geo.dim == 2:
            return 20.0
        return float(2.0 * max(abs(geo.lo[2]), abs(geo.hi[2])))

    @classmethod
    def coordinates(cls, scene):
        raise ParameterError("sensors", "a layout", "none with skin = file",
                             "a user's skin has no sensor coordinates (s and depth) yet")

    @classmethod
    def cache_content(cls, scene) -> dict:
        from tactileskin.mesh.skinfile import file_digest

        return {"skin_file": file_digest(scene.skin_file)}

    @classmethod
    def build_mesh(cls, scene, *, cell: str = "tri", mesh_size=None, refinement=None, order=None, **_):
        from tactileskin.mesh import skinfile

        if cell != "tri":
            raise ParameterError("cell", cell, "'tri' for a file skin")
        order = scene.order if order is None else order
        geo = geometry(scene)
        if skinfile.file_kind(scene.skin_file) == "msh":
            sm, _ = skinfile.load_msh(scene.skin_file, bonded=scene.skin_bonded, outer=scene.skin_outer,
                                      order=order)
        else:
            h = scene.mesh_size if mesh_size is None else mesh_size
            r = scene.refinement if refinement is None else refinement
            sm = skinfile.mesh_step(scene.skin_file, bonded=scene.skin_bonded, mesh_size=h, refinement=r,
                                    order=order, centre=geo.top_point,
                                    radius=max(2.0 * geo.thickness, 3.0 * h / r))
        sm.section = FileSection(geo)
        sm.length = cls.sample_length(scene) if sm.dim == 3 else None
        return sm

    @classmethod
    def build_parts(cls, thickness, *, molds=True, skin_file=None, skin_bonded=None, **_):
        """The STEP skin as read and its casting mold (geometry.file_parts): for a skin bonded on
        one flat face; `thickness` is the file's (measured)."""
        from tactileskin.geometry.file_parts import build_file_parts

        if not skin_file:
            raise ParameterError("skin_file", skin_file, "a STEP file of the skin", "skin = 'file' needs it")
        return build_file_parts(skin_file, skin_bonded, molds=molds)

    @classmethod
    def label(cls, scene) -> str:
        return f"file-{Path(scene.skin_file).stem}-"
