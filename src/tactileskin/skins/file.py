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
profile z = 0. Sensors (`FileCoordinates`, skins.file_coordinates): s = x - x_top and z of the contact surface's point
over (x, z), depth along its inward normal there (as on the fingertip), height along the same
line from where it leaves the skin through the bonded surface, the sensor plane along the
contact surface there (normal: that surface's, t1 along it in the x-y plane); the surfaces read
on the analysed mesh's boundary facets (quadratic on a P2 .msh, as the solver's), a STEP's on its
CAD faces.
The model is the half x >= 0 when a .msh names a `symmetry` group, or when a STEP solid and its
bonded faces are mirror-symmetric about x = 0 (mesh.skinfile.step_symmetry) and so is the
indenter (geometry.indenters.indenter_symmetry): the solid is cut there; likewise z = 0 (3D).
The geometry checks above read the whole solid.
"""

from __future__ import annotations

import functools
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tactileskin.errors import ParameterError
from tactileskin.fileio import read_unchanged
from tactileskin.skins.base import Skin
from tactileskin.skins.file_coordinates import BONDED, OUTER, FileCoordinates, FileGeometry
from tactileskin.skins.registry import register

logger = logging.getLogger(__name__)
DEFAULT_THICKNESS = 3.0  # Scene's default: taken as "not given"
AXIS_GAP = 0.02  # of t: how far the outer surface on the axis may lie below the top point

# the bonded surfaces held fixed: the fingertip's nail and the dome's bone under its tip, as
# `tactileskin mesh` writes them, where the file has them
FIXED = ("bone_interface", "nail_edge", "bone_tip")


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


def boundary_facets(skinmesh) -> tuple[np.ndarray, np.ndarray]:
    """(nodes (n, nn, dim), kind (n,)) of a skin mesh's boundary facets (FileGeometry.facets)."""
    m, b = skinmesh.mesh, skinmesh.boundaries
    every = m.boundary_facets()
    nodes = m.facets[:, every]
    if m.doflocs.shape[1] > m.nvertices:  # P2: the curved facets' mid-edge nodes (skfem's order)
        if skinmesh.dim == 2:
            nodes = np.vstack([nodes, m.nvertices + every])
        else:
            e = m.f2e[:, every]
            ends = np.sort(m.edges[:, e], axis=0)                   # (2, 3, n)
            mids = []
            for i, j in ((0, 1), (1, 2), (2, 0)):
                pair = np.sort(nodes[[i, j]], axis=0)[:, None, :]
                k = np.argmax(np.all(ends == pair, axis=0), axis=0)
                mids.append(m.nvertices + e[k, np.arange(len(every))])
            nodes = np.vstack([nodes, mids])
    kind = np.zeros(len(every), int)
    kind[np.isin(every, b["outer_surface"])] = OUTER
    kind[np.isin(every, np.concatenate([b[n] for n in FIXED if n in b]))] = BONDED
    return m.doflocs[:, nodes].T.copy(), kind


def measure(skinmesh, groups=()) -> FileGeometry:
    """The FileGeometry of a loaded skin mesh."""
    m, b = skinmesh.mesh, skinmesh.boundaries
    X = m.doflocs
    facets, kind = boundary_facets(skinmesh)
    # the contact surface's nodes, a P2 mesh's mid-edge ones too: a curved top with no vertex on
    # the axis has its highest node there, and its vertices alone (1.995 mm under a 2 mm crown)
    # read it as lower than the skin, "upside down"
    pts = np.unique(facets[kind == OUTER].reshape(-1, skinmesh.dim), axis=0)
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
    geo = FileGeometry(dim=skinmesh.dim, top_point=tuple(float(c) for c in top), thickness=t,
                       lo=tuple(lo.tolist()), hi=tuple(hi.tolist()), outer_xy=pts[:, :2].copy(),
                       symmetric="symmetry" in b, groups=tuple(groups),
                       z_symmetric=bool(getattr(skinmesh, "z_symmetric", False)),
                       axis_y=_axis_height(m, b["outer_surface"], size),
                       facets=facets, facet_kind=kind)
    if facets.shape[1] > skinmesh.dim:
        # P2: the top is read on the nodes, so the axis height is read on the curved facets (the
        # solver's surface), not their chords: a crown's mid-edge node on the axis lay the chord's
        # sag (0.017 mm, t = 0.5) above them and was refused as highest off the axis
        geo = FileGeometry(**{**geo.__dict__, "axis_y": _curved_axis_height(geo)})
    return geo


def _curved_axis_height(geo: FileGeometry) -> float | None:
    """Highest y where the axis x = 0 (z = 0) crosses the quadratic contact facets (the chords'
    answer, geo.axis_y, where it meets none of them: a line on a model's edge, within rounding)."""
    lat = [0] if geo.dim == 2 else [0, 2]
    L = geo.facets[:, :, lat]
    lo, hi = L.min(axis=1), L.max(axis=1)
    pad = hi - lo  # a quadratic facet lies within its nodes' box widened by its size
    near = (geo.facet_kind == OUTER) & np.all((lo - pad <= 0.0) & (hi + pad >= 0.0), axis=1)
    if not near.any():
        return geo.axis_y
    sub = FileGeometry(**{**geo.__dict__, "facets": geo.facets[near], "facet_kind": geo.facet_kind[near]})
    y = FileCoordinates(sub).column(np.array([-geo.top_point[0]]), 0.0)["outer"][0]
    return geo.axis_y if np.isnan(y) else float(y)


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
    """The file's geometry, memoised by its bytes' digest (fileio.read_unchanged)."""
    from tactileskin.mesh import skinfile

    return read_unchanged(lambda p: _analysed(kind, p, bonded, outer), path, digest, skinfile.file_digest,
                          "skin_file", skinfile._VALID_FILE)


def _analysed(kind: str, path: str, bonded, outer) -> FileGeometry:
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
        # the sensors' columns are read on those faces too (FileCoordinates(cad=path))
        tags = np.zeros(sm.mesh.facets.shape[1], int)
        for tag, f in sm.face_facets.items():
            tags[f] = tag
        return FileGeometry(**{**g.__dict__, "top_point": tuple(float(c) for c in on_axis), "thickness": t,
                               "facet_face": tags[sm.mesh.boundary_facets()]})
    check_placement(g, path, kind, bonded, outer)
    return g


def geometry(scene) -> FileGeometry:
    return _analyse(*_key(scene))


@functools.lru_cache(maxsize=16)
def _coordinates(*key) -> "FileCoordinates":
    return FileCoordinates(_analyse(*key), cad=key[1] if key[0] == "step" else None)


def _key(scene) -> tuple:
    """The memo key of a scene's skin file: (kind, resolved path, digest, bonded, outer)."""
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
    return kind, str(Path(path).resolve()), digest, scene.skin_bonded, scene.skin_outer


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
        """(x, y) of the outer surface's nodes (in 3D projected along z) and of its top point,
        where the indenters start: a first-contact estimate. The top is a STEP's CAD point on
        the axis, which its coarse mesh's nodes miss (under a curved top they lie lower, and a
        sphere seemed to touch only after their sag)."""
        top = np.asarray(self.geo.top_point[:2], float)[None, :]
        return np.vstack([self.geo.outer_xy, top])

    def area(self) -> float:
        raise ParameterError("skin", "file", "a built-in skin", "a file skin has no section area")


@register
class FileSkin(Skin):
    name = "file"
    order = 3
    scene_params = ("skin_file", "skin_bonded", "skin_outer")
    fixed_boundaries = FIXED
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
    def coordinates(cls, scene) -> FileCoordinates:
        return _coordinates(*_key(scene))

    @classmethod
    def mesh_coordinates(cls, scene, skinmesh) -> FileCoordinates:
        """The sensor coordinates on the mesh solved: a STEP's analysis mesh is coarse and
        straight, its solve mesh curved onto the CAD (bone sensors of a half tube's R 6 bonded
        face lay up to 0.077 mm inside the bone on the chords and the solve failed reading
        them); a .msh's is its own mesh (the same faces). Which sensors are in the skin is the
        scene's answer (`reference`: a STEP's CAD faces), so the solve refuses none the scene
        held (a sensor 0.002 mm under a sphere cap's top, on a P1 mesh whose chords lay 0.017
        mm low there) and holds none it refused."""
        import dataclasses

        facets, kind = boundary_facets(skinmesh)
        # the halves of the model solved: a symmetric STEP is cut at x = 0 / z = 0 for its solve
        # only, so its sensors on the other side read their mirror images there
        return FileCoordinates(dataclasses.replace(geometry(scene), facets=facets, facet_kind=kind,
                                                   facet_face=None,
                                                   symmetric=bool(skinmesh.halved),
                                                   z_symmetric=bool(getattr(skinmesh, "z_symmetric", False))),
                               reference=cls.coordinates(scene))

    @classmethod
    def cache_content(cls, scene) -> dict:
        from tactileskin.mesh.skinfile import file_digest

        return {"skin_file": file_digest(scene.skin_file)}

    @classmethod
    def step_halves(cls, scene) -> tuple[bool, bool]:
        """(x, z): cut a STEP skin at x = 0 (z = 0), where it and the scene's indenter are both
        mirror-symmetric about the plane (the indenter's test first: it costs no CAD work)."""
        from tactileskin.geometry.indenters import indenter_symmetry
        from tactileskin.mesh import skinfile

        ind = indenter_symmetry(scene)
        if not any(ind):
            return False, False
        solid = skinfile.step_symmetry(scene.skin_file, scene.skin_bonded)
        return ind[0] and solid[0], ind[1] and solid[1]

    @classmethod
    def build_mesh(cls, scene, *, cell: str = "tri", mesh_size=None, refinement=None, order=None,
                   use_symmetry: bool = True, **_):
        """use_symmetry=False: a STEP skin whole even where it and the indenter are symmetric."""
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
                                    radius=max(2.0 * geo.thickness, 3.0 * h / r),
                                    halve=cls.step_halves(scene) if use_symmetry else (False, False))
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
