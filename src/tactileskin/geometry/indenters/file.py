"""file: a user's rigid indenter from a closed triangle surface (STL, OBJ, PLY, OFF) or a
STEP solid (tessellated through build123d at 0.005 mm), in millimetres, working face
towards -y.

Placement: the surface is translated along y so that its lowest point starts at y0 (touching
the skin top); x and z are used as given (x = 0 is the skin's symmetry plane, z = 0 its
mid-plane), so an off-centre press is modelled where the file puts it. 3D only.

Gap: the distance to the nearest triangle, exact: a k-d tree of the vertices bounds it from
above (nearest vertex), a k-d tree of the triangle centroids gives every triangle that can
be that near (centroid within the bound plus the largest centroid-to-vertex radius), and
`trimesh.triangles.closest_point` gives the closest point on each candidate. The sign is that
of (p - c) . n_t on the nearest triangle (of tied ones at a shared edge or vertex, the one
with the largest |(p - c) . n_t|, which is right for any edge and for the convex and concave
vertices a smooth-ish indenter has); the normal is sign (p - c) / |p - c|, the gradient of g.

This is the one indenter file that uses trimesh (imported lazily: loading and closest points
on triangles); tests/test_import_rules.py checks that no other indenter module names it and
that importing the package does not load it. rtree is not needed.
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from tactileskin.errors import CadError, ParameterError
from tactileskin.fileio import read_unchanged
from tactileskin.geometry.indenters.base import Indenter, hertz_halfwidth, stem_params
from tactileskin.geometry.indenters.registry import register

log = logging.getLogger(__name__)

MESH_SUFFIXES = (".stl", ".obj", ".ply", ".off")
STEP_SUFFIXES = (".step", ".stp")
SIZE_RANGE = (0.1, 1000.0)  # mm: largest bounding-box extent of a plausible indenter
STEP_TOLERANCE = 0.005      # mm, as geometry/export.py meshes the project's own solids
MAX_PATCHES = 100           # contact spots the local mesh plan takes; more: the strip plan
MAX_PLANES = 50             # planes of first touch tested (contact_planes)
_PAIR_CHUNK = 200_000       # (point, triangle) pairs per closest-point batch (memory)
_VALID = "a closed triangle surface in mm (" + ", ".join(MESH_SUFFIXES + STEP_SUFFIXES) + ")"


# a folder given for the file (the folder of a CAD export): named as such, not 'no such file'
_FOLDER = "it is a folder: give the indenter's STL, OBJ, PLY, OFF or STEP file itself"


def file_digest(path) -> str:
    if Path(path).is_dir():
        raise ParameterError("indenter_file", str(path), _VALID, _FOLDER)
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError as e:
        raise ParameterError("indenter_file", str(path), _VALID, f"cannot read it: {e.strerror or e}") from None


def _read(path: Path):
    """(vertices, faces) of the file, merged, oriented outwards."""
    import trimesh

    suffix = path.suffix.lower()
    try:
        if suffix in STEP_SUFFIXES:
            from tactileskin.geometry.occ import bd

            shape = bd.import_step(str(path))
            verts, tris = shape.tessellate(STEP_TOLERANCE, 0.1)
            mesh = trimesh.Trimesh(np.array([tuple(v) for v in verts], float), np.asarray(tris, int))
        else:
            mesh = trimesh.load_mesh(str(path), file_type=suffix[1:], process=True)
    except Exception as e:  # the readers raise many types on a damaged file
        raise ParameterError("indenter_file", str(path), _VALID,
                             f"cannot read it: {type(e).__name__}: {e}") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ParameterError("indenter_file", str(path), _VALID, "it holds no triangles")
    mesh.merge_vertices()
    if not mesh.is_watertight:
        edges = trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1)
        raise ParameterError("indenter_file", str(path), "a closed (watertight) triangle surface",
                             f"{len(edges)} edges belong to one triangle only (holes or gaps); close it "
                             "in the CAD tool or with trimesh.repair.fill_holes")
    extent = float(np.max(mesh.extents))
    lo, hi = SIZE_RANGE
    if not lo <= extent <= hi:
        guess = "metres (scale by 1000)" if extent < lo else "micrometres (scale by 0.001)"
        raise ParameterError("indenter_file", str(path), f"a solid in mm, largest extent {lo:g} mm to {hi:g} mm",
                             f"its largest extent is {extent:g}: the file looks like it is in {guess}")
    if mesh.volume < 0:
        mesh.invert()  # faces wound inwards: the normals must point out of the solid
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, int)


@functools.lru_cache(maxsize=8)
def _load(path: str, digest: str):
    """Cached by content: the same bytes load once per process (fileio.read_unchanged)."""
    return read_unchanged(_read, Path(path), digest, file_digest, "indenter_file", _VALID)


def load_surface(path) -> tuple[np.ndarray, np.ndarray]:
    p = Path(path)
    if p.is_dir():
        raise ParameterError("indenter_file", str(path), _VALID, _FOLDER)
    if p.suffix.lower() not in MESH_SUFFIXES + STEP_SUFFIXES:
        raise ParameterError("indenter_file", str(path), _VALID, f"unsupported suffix {p.suffix!r}")
    if not p.is_file():
        raise ParameterError("indenter_file", str(path), _VALID, "no such file")
    return _load(*_source(p))


def _source(p: Path) -> tuple[str, str]:
    """(resolved path, sha256): the key the loaded surface and its search trees are cached by."""
    return str(p.resolve()), file_digest(p)


@functools.lru_cache(maxsize=8)
def _trees_of(path: str, digest: str):
    """The gap's search structures of a file's surface as loaded (before placement; cached by
    content: every indenter made from the same bytes shares them, so the mesher's and the
    planner's symmetry questions do not rebuild them)."""
    v, f = _load(path, digest)
    return _search_trees(v[f])


def _search_trees(tri: np.ndarray):
    tri = _split_long(tri)                                 # (T, 3, 3), the same surface
    cen = tri.mean(axis=1)
    rmax = float(np.max(np.linalg.norm(tri - cen[:, None, :], axis=2)))
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1), 1e-300)[:, None]
    return cKDTree(tri.reshape(-1, 3)), cKDTree(cen), rmax, tri, nrm


@register
@dataclass(frozen=True, eq=False)
class FileIndenter(Indenter):
    file: str = ""
    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # placed (lowest y = y0)
    faces: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), int))
    source: tuple = ()   # (resolved path, sha256) of the loaded surface: `_trees_of`'s key
    shift: float = 0.0   # y placement: vertices = loaded vertices + (0, shift, 0)

    name = "file"
    order = 20
    scene_params = ("indenter_file",)
    section_2d = None
    local_3d = True
    # the 3D profile is read through the bone map's peak (fe.output.make_result): a file can
    # press anywhere along the finger, and z = 0 may not be under it
    profile_at_map_peak = True

    @classmethod
    def check_scene(cls, scene) -> dict:
        if not scene.indenter_file:
            raise ParameterError("indenter_file", scene.indenter_file, _VALID, "the file is required")
        super().check_scene(scene)
        load_surface(scene.indenter_file)
        return {}

    @classmethod
    def label(cls, scene) -> str:
        return f"file-{Path(scene.indenter_file).stem}"

    @classmethod
    def cache_content(cls, scene) -> dict:
        return {"indenter_file": file_digest(scene.indenter_file)}

    @classmethod
    def from_params(cls, *, y0, dim, length, row=None, warn=True, indenter_file=None, **_):
        if not indenter_file:
            raise ParameterError("indenter_file", indenter_file, _VALID, "the file is required")
        v, f = load_surface(indenter_file)
        shift = float(y0 - v[:, 1].min())
        v = v + np.array([0.0, shift, 0.0])
        ext = v.max(axis=0) - v.min(axis=0)
        return cls(kind=cls.name, y0=y0, dim=dim, width=float(ext[0]), length=float(ext[2]),
                   file=str(indenter_file), vertices=v, faces=f, source=_source(Path(indenter_file)),
                   shift=shift, **stem_params())

    # -- geometry ----------------------------------------------------------------------------
    @functools.cached_property
    def _trees(self):
        """The search structures in the loaded frame (queries are shifted by -shift)."""
        if self.source:
            return _trees_of(*self.source)
        return _search_trees(self.vertices[self.faces] - np.array([0.0, self.shift, 0.0]))

    def _gap(self, p, d):
        """Signed distance to the nearest triangle: candidates are the triangles whose centroid
        lies within (distance to the nearest vertex) + (largest centroid-to-corner distance)."""
        from trimesh.triangles import closest_point

        if p.shape[1] == 2:  # the section z = 0
            p = np.column_stack([p, np.zeros(len(p))])
            g, n = self._gap(p, d)
            return g, n[:, :2]
        q = p + np.array([0.0, d - self.shift, 0.0])           # the indenter moved by -d (loaded frame)
        vtree, ctree, rmax, tri, nrm = self._trees
        bound, _ = vtree.query(q)
        cand = ctree.query_ball_point(q, bound * (1 + 1e-12) + rmax + 1e-12)
        counts = np.fromiter(map(len, cand), int, len(q))
        pi = np.repeat(np.arange(len(q)), counts)
        ti = np.fromiter(itertools.chain.from_iterable(cand), int, int(counts.sum()))
        c = np.empty((len(pi), 3))
        for s in range(0, len(pi), _PAIR_CHUNK):
            c[s:s + _PAIR_CHUNK] = closest_point(tri[ti[s:s + _PAIR_CHUNK]], q[pi[s:s + _PAIR_CHUNK]])
        v = q[pi] - c
        dist = np.linalg.norm(v, axis=1)
        dot = np.einsum("ij,ij->i", v, nrm[ti])
        dmin = np.full(len(q), np.inf)
        np.minimum.at(dmin, pi, dist)
        tol = 1e-9 * max(1.0, float(np.max(np.abs(self.vertices))))
        score = np.where(dist <= dmin[pi] + tol, np.abs(dot), -1.0)
        order = np.lexsort((-score, pi))
        best = order[np.concatenate([[0], np.flatnonzero(np.diff(pi[order])) + 1])]
        sign = np.where(dot[best] < 0.0, -1.0, 1.0)
        db = dist[best]
        tiny = db <= tol
        n = sign[:, None] * v[best] / np.where(tiny, 1.0, db)[:, None]
        n[tiny] = nrm[ti[best]][tiny]  # on the surface: the face normal
        return sign * db, n

    def _surface_y(self, x, z, d):
        raise ParameterError("surface_y", self.file, "an analytic indenter", "a file indenter has no height map")

    def symmetry(self, depth=None) -> tuple[bool, bool]:
        """A plane is a mirror plane if every mirrored vertex lies on the surface (within
        1e-5 of the size: STL stores 32-bit floats, ~1e-7 relative); with `depth`, every vertex
        of the triangles that reach below y0 + 2 depth (what can touch the skin, with room for
        the skin's bulge): a printed part's stem, tessellated unevenly 20 mm above the face
        (1e-3 mm off its mirror image), does not make the model the whole slab."""
        tol = 1e-5 * float(np.max(self.vertices.max(axis=0) - self.vertices.min(axis=0)))
        pts = self.vertices if depth is None else self._band(2.0 * float(depth))
        out = []
        for ax in (0, 2):
            m = pts.copy()
            m[:, ax] *= -1.0
            g, _ = self._gap(m, 0.0)
            out.append(bool(np.max(np.abs(g)) <= tol))
        return out[0], out[1]

    def _band_faces(self, depth: float) -> np.ndarray:
        """The triangles (vertex indices) that reach below y0 + depth (the part that can touch)."""
        return self.faces[self.vertices[self.faces][:, :, 1].min(axis=1) <= self.y0 + max(float(depth), 0.0)]

    def _band(self, depth: float) -> np.ndarray:
        """Vertices of the triangles that reach below y0 + depth."""
        return self.vertices[np.unique(self._band_faces(depth))]

    def contact_halfwidth(self, depth, r_top):
        b = self._band(depth)
        return max(1.5 * float(np.max(np.abs(b[:, 0]))), hertz_halfwidth(r_top, 0.25 * depth))

    def contact_zrange(self, depth):
        b = self._band(depth)
        lo, hi = float(b[:, 2].min()), float(b[:, 2].max())
        mid, half = 0.5 * (lo + hi), 0.75 * (hi - lo) + hertz_halfwidth(1.0, depth)
        return mid - half, mid + half

    def contact_planes(self) -> np.ndarray:
        """z of the tips that can touch first (to 0.001 mm, at most MAX_PLANES, lowest first):
        the vertices lowest in their neighbourhood (each bump's tip), less those with a lower
        tip at least as near x = 0 (the skin's top falls away from x = 0 and is uniform along
        z), so a bump past the slab's end does not hide one inside it (first_contact_travel
        clips the planes to the slab) and a ring gives its tips nearest x = 0, not 50."""
        v = self.vertices
        e = _edges(self.faces)
        e = np.concatenate([e, e[:, ::-1]])
        low = np.full(len(v), np.inf)
        np.minimum.at(low, e[:, 0], v[e[:, 1], 1])
        tips = v[v[:, 1] <= low]
        tips = tips[np.lexsort((np.abs(tips[:, 0]), tips[:, 1]))]
        ax = np.abs(tips[:, 0])
        keep = ax <= np.minimum.accumulate(np.concatenate([[np.inf], ax[:-1]])) + 1e-9
        z = np.round(tips[keep, 2], 3)
        _, first = np.unique(z, return_index=True)
        return z[np.sort(first)][:MAX_PLANES]

    def contact_patches(self, depth):
        """One spot per connected piece of the surface below y0 + depth (a piece's vertices
        there and its edges' crossings of that plane): the centre of the piece's (x, z) box and
        the largest distance of its points from it; a piece that does not cover its centre (a
        ring) is covered by spots of the ring's half-width instead (`_cover`). None (the strip plan)
        beyond MAX_PATCHES spots (a textured face)."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        v = self.vertices
        cut = self.y0 + max(float(depth), 0.0)
        band = self._band_faces(depth)
        e = _edges(band)
        g = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(len(v), len(v)))
        _, label = connected_components(g, directed=False)
        ya, yb = v[e[:, 0], 1], v[e[:, 1], 1]
        cross = (ya - cut) * (yb - cut) < 0.0
        w = ((cut - ya[cross]) / (yb[cross] - ya[cross]))[:, None]
        pts = np.concatenate([v[v[:, 1] <= cut], v[e[cross, 0]] + w * (v[e[cross, 1]] - v[e[cross, 0]])])
        lab = np.concatenate([label[v[:, 1] <= cut], label[e[cross, 0]]])
        out = []
        for k in np.unique(lab):
            out += _cover(pts[lab == k][:, [0, 2]], v[band[label[band[:, 0]] == k]][:, :, [0, 2]])
            if len(out) > MAX_PATCHES:
                return None
        return tuple(out)

    def describe(self) -> str:
        return f"indenter from {Path(self.file).name}"

    def solid(self):
        raise CadError(f"the file indenter's printable solid is the user's file itself ({self.file})")


def _edges(faces: np.ndarray) -> np.ndarray:
    """(3F, 2) vertex pairs of the triangles' edges (shared edges repeated)."""
    return np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])


def _cover(xz: np.ndarray, tri: np.ndarray) -> list[tuple[float, float, float]]:
    """Spots (x, z, a) covering a piece's points xz (n, 2) whose (x, z) triangles are tri
    (T, 3, 2): one around the box centre if a triangle covers it (a ball's cap, a plate);
    else (a ring) greedy spots of the ring's half-width (half the outer minus inner radius about
    the centre: the chord of its tube), so that their size follows the tube, not the ring's
    diameter. A torus (radii 2 and 0.8 mm) at t = 1 read 0.0645 MPa at preview as one spot,
    0.0730 / 0.0779 at 1.6 / 1.2 / 8 with spots of the whole width, and 0.0793 / 0.0764 /
    0.0757 at 1.6 / 1.2 / 0.8 / 8 with these (from above, +4.8 % at preview)."""
    c = 0.5 * (xz.min(axis=0) + xz.max(axis=0))
    r = np.linalg.norm(xz - c, axis=1)
    a, b, q = tri[:, 0], tri[:, 1], tri[:, 2]
    d = (b[:, 0] - a[:, 0]) * (q[:, 1] - a[:, 1]) - (q[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    u = ((b[:, 0] - c[0]) * (q[:, 1] - c[1]) - (q[:, 0] - c[0]) * (b[:, 1] - c[1])) / np.where(d == 0, 1, d)
    w = ((q[:, 0] - c[0]) * (a[:, 1] - c[1]) - (a[:, 0] - c[0]) * (q[:, 1] - c[1])) / np.where(d == 0, 1, d)
    covered = np.any((d != 0) & (u >= 0) & (w >= 0) & (u + w <= 1))
    if covered or len(xz) < 3:
        return [(float(c[0]), float(c[1]), float(r.max()))]
    width = max(0.5 * float(r.max() - r.min()), 1e-9)  # the half-width of the annulus: its chord
    out, left = [], xz
    while len(left):
        near = np.linalg.norm(left - left[0], axis=1) <= width
        sub = left[near]
        cc = 0.5 * (sub.min(axis=0) + sub.max(axis=0))
        out.append((float(cc[0]), float(cc[1]), float(np.max(np.linalg.norm(sub - cc, axis=1)))))
        left = left[~near]
    return out


def _split_long(tri: np.ndarray, factor: float = 4.0) -> np.ndarray:
    """The triangles bisected on their longest edge until none reaches farther than `factor` x
    the median centroid-to-corner distance: the same surface, but a few long triangles (a
    printed part's mounting stem, 13 mm against 0.3 mm at the face) no longer set the gap's
    candidate radius for every point (a built indenter's solve spent minutes on it)."""
    def reach(t):
        return np.max(np.linalg.norm(t - t.mean(axis=1)[:, None, :], axis=2), axis=1)

    r = reach(tri)
    cut = factor * float(np.median(r))
    for _ in range(30):
        big = r > cut
        if not big.any():
            break
        t = tri[big]
        edges = np.linalg.norm(t[:, [1, 2, 0]] - t, axis=2)   # edge k joins corners k, k+1
        k = np.argmax(edges, axis=1)
        i = np.arange(len(t))
        a, b, c = t[i, k], t[i, (k + 1) % 3], t[i, (k + 2) % 3]
        m = 0.5 * (a + b)
        halves = np.concatenate([np.stack([a, m, c], axis=1), np.stack([m, b, c], axis=1)])
        tri = np.concatenate([tri[~big], halves])
        r = np.concatenate([r[~big], reach(halves)])
    return tri
