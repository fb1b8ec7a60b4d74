"""Sensor coordinates inside a user's file skin (skins.file): `FileGeometry`, what a skin file's
analysis measured, and `FileCoordinates`, the normal lines a sensor layout hangs from the contact
surface (its heights read on the analysed mesh's boundary facets, or a STEP's CAD faces).
Units: mm."""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError

logger = logging.getLogger(__name__)
_TOL = 1e-9  # mm: a sensor on a range's end is inside (sensors._TOL)

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
    # (n, nn, dim): the boundary facets' nodes (sensor columns): their dim vertices, then on a P2
    # mesh the mid-edge nodes (2D: 1; 3D: ab, bc, ca), which curve them as the solver's mesh
    facets: np.ndarray | None = None
    facet_kind: np.ndarray | None = None  # (n,): OUTER, BONDED or 0 (another boundary)
    facet_face: np.ndarray | None = None  # (n,): a STEP analysis mesh's facets' CAD face tags


# over this fraction of the skin's size (2e-3 mm on a 20 mm skin: within one facet, and the
# quadratic faces' curvature changes the slope by ~(step / R)^2), and slopes below FLAT_SLOPE are
# rounding (a flat face's heights differ by ~1e-16 of the size: ~1e-12 in slope)
SLOPE_STEP = 1e-4
FLAT_SLOPE = 1e-9
OUTER, BONDED = 1, 2  # FileGeometry.facet_kind
# a STEP analysis mesh's facet within ~6 degrees of vertical is a wall (the disc's wall chords
# inside its R 5 rim: |n_y| 0.024-0.032); crossed where the line misses its CAD face it is the mesh's
WALL_NY = 0.1
# a sensor the scene held at a curved rim can lie past the solved mesh's rim, whose straight
# chords cut inside the edge (a disc R 5, P1 h = 2: 69 of the 178 lines at r = 4.98 the scene
# held crossed no face): the solve moves it onto the nearest point over the mesh's contact
# surface, at most RIM_SHIFT of that edge's length (a chord's sagitta is L / (8 R) of its length L)
RIM_SHIFT = 0.25
# samples along a sensor's line (FileCoordinates._exit) per stretch, before its exit is bisected:
# a gap in the skin thinner than the stretch / EXIT_SAMPLES between two samples may be missed
EXIT_SAMPLES = 16


class FileCoordinates:
    """Sensor coordinates of a file skin (the `coordinates` duck type of sensors.resolve): s =
    x - x_top, z (3D) of the contact surface's point P over (x, z); the sensor at P - depth n,
    n that surface's outward unit normal at P (+y where it is flat: straight down, as it was
    everywhere), height along the same line from where it leaves the skin (through a bonded
    face); the sensor plane lies along the contact surface at P: normal n, t1 = n x e_z
    normalised (+x on a flat top), t2 = t1 x n (+z).
    The vertical line through (x, z) must have the contact surface on top, and the normal line
    must stay in the skin to the depth: each of its points between its own vertical line's top
    and the first boundary under that (_exit); the heights are read on the mesh's boundary facets, quadratic on a P2
    mesh as the solver's (on their chords a bone sensor of the fingertip's own mesh lay inside
    the bone, and the solve failed reading it); a STEP's on its CAD faces (`cad`: the file; its
    P1 analysis mesh's chords find the faces) for the scene's check, and on the mesh solved for
    the readings (mesh_coordinates), whose `reference` (the scene's coordinates) decides which
    sensors are in the skin: the solve accepts what the scene accepted (one past its mesh's rim
    moves onto it: `placed`). A half model
    (`symmetry`, `symmetry_z`) answers for its mirror image by reflection, as the solver's
    sampler does."""

    straight = True  # sensors.taxel_s: s is arc length on every depth surface (a side along x)
    local = True     # sensors.resolve: depth, thickness and extent vary with (x, z): self.depths
    reference = None  # (subclasses that set their own fields: skins.dome.DomeCoordinates)
    _face = None      # the facets' CAD faces (a STEP's: read there), None: the facets' own heights

    def __init__(self, geo: FileGeometry, cad=None, reference: "FileCoordinates | None" = None):
        self.geo, self.dim = geo, geo.dim
        self.cad, self.reference = cad, reference
        self.thickness = float(geo.thickness)
        self.x_top = float(geo.top_point[0])
        lat = [0] if geo.dim == 2 else [0, 2]
        size = float(np.max(np.subtract(geo.hi, geo.lo)))
        self.tol = 1e-7 * size  # mm: heights this close are one surface (a shared vertex)
        ext = [(-geo.hi[k] if half else geo.lo[k], geo.hi[k]) for k, half in
               zip(lat, (geo.symmetric, geo.z_symmetric))]
        self.s_range = (ext[0][0] - self.x_top, ext[0][1] - self.x_top)
        self.s_max = float(max(abs(v) for v in self.s_range))
        self.z_range = ext[1] if geo.dim == 3 else (0.0, 0.0)
        F = np.asarray(geo.facets, float)
        L = F[:, :, lat]                                    # (n, nn, k): the facets seen from above
        if geo.dim == 2:
            area = np.abs(L[:, 1, 0] - L[:, 0, 0])
        else:
            area = 0.5 * np.abs((L[:, 1, 0] - L[:, 0, 0]) * (L[:, 2, 1] - L[:, 0, 1])
                                - (L[:, 2, 0] - L[:, 0, 0]) * (L[:, 1, 1] - L[:, 0, 1]))
        # a vertical facet (a side, a symmetry plane) holds no height of its own: its edges
        # are its neighbours' (a sensor on a side's line reads the top and bottom facets)
        keep = area > 1e-9 * size ** (geo.dim - 1)
        # the steep walls (|n_y| < WALL_NY of their straight facet's normal; none in 2D)
        wall = np.zeros(len(F), bool)
        if geo.dim == 3:
            P = F[:, :3, :]
            nrm = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
            wall = np.abs(nrm[:, 1]) < WALL_NY * np.linalg.norm(nrm, axis=1)
        if reference is not None:
            # the solved mesh's walls are no top: a vertical line crosses their chords where
            # they lean, not where the skin's surface is (the disc R 5 on a P1 h = 2 mesh: at
            # r = 4.95, 128 of 181 lines took a wall chord for the top, and their depth-0.2
            # sensors went up to 0.48 mm deeper than the CAD's); the reference decides
            keep &= ~wall
        self._wall = wall[keep]
        self._L, self._y, self._kind = L[keep], F[keep][:, :, 1], np.asarray(geo.facet_kind)[keep]
        self._face = None if cad is None or geo.facet_face is None else np.asarray(geo.facet_face)[keep]
        self._curved = F.shape[1] > geo.dim
        box = self._L
        if self._curved:  # a quadratic edge lies in the hull of its ends and 2 mid - (a + b) / 2
            v = self._L[:, :geo.dim]
            ends = [(0, 1)] if geo.dim == 2 else [(0, 1), (1, 2), (2, 0)]
            ctrl = [2.0 * self._L[:, geo.dim + i] - 0.5 * (v[:, a] + v[:, b]) for i, (a, b) in enumerate(ends)]
            box = np.concatenate([self._L, np.stack(ctrl, axis=1)], axis=1)
        # a uniform grid over the facets' bounding boxes (seen from above) finds each point's few
        # candidate facets
        lo, hi = box.min(axis=(0, 1)), box.max(axis=(0, 1))
        span = np.maximum(hi - lo, 1e-12)
        ncell = np.clip((span / max(np.median(box.max(axis=1) - box.min(axis=1)), 1e-12)).astype(int),
                        1, 4096 if geo.dim == 2 else 256)
        self._lo, self._cell, self._ncell = lo, span / ncell, ncell
        self._size = size
        i0 = self._cell_index(box.min(axis=1))
        i1 = self._cell_index(box.max(axis=1))
        cells, owner = [], []
        for f, (a, b) in enumerate(zip(i0, i1)):
            grid = np.meshgrid(*(np.arange(a[k], b[k] + 1) for k in range(len(a))), indexing="ij")
            flat = np.ravel_multi_index([g.ravel() for g in grid], tuple(ncell))
            cells.append(flat)
            owner.append(np.full(flat.size, f))
        cells, owner = np.concatenate(cells), np.concatenate(owner)
        order = np.argsort(cells, kind="stable")
        self._owner = owner[order]
        self._start = np.searchsorted(cells[order], np.arange(int(np.prod(ncell)) + 1))

    def _cell_index(self, q):
        return np.clip(np.floor((q - self._lo) / self._cell).astype(int), 0, self._ncell - 1)

    def column(self, s, z=None) -> dict:
        """Heights (mm, NaN where none) on the vertical line through each (s, z): `top` (the
        highest boundary), `outer` (the highest contact surface), `floor` (the first boundary
        under the top) and `bonded` (whether that floor is a bonded surface). A line along a
        wall (a step's edge between two top faces) meets the boundary an odd number of times:
        it slides down the wall from the higher face's edge and touches the lower face's edge
        while still in the skin, and that edge was its floor: a height there was refused ("a
        face that is not bonded") and a depth held to the step's height. Such a line is the
        higher face's (its top is that face's edge): its floor is read just beside the wall on
        that side (self.tol away, where the line meets the boundary an even number of times)."""
        col, odd = self._column(s, z)
        if not odd.any():
            return col
        i = np.flatnonzero(odd)
        s = np.atleast_1d(np.asarray(s, float))[i]
        z = None if self.dim == 2 else np.broadcast_to(np.asarray(0.0 if z is None else z, float), odd.shape)[i]
        left = np.ones(len(i), bool)
        sides = [(1.0, 0.0), (-1.0, 0.0)] + ([(0.0, 1.0), (0.0, -1.0)] if self.dim == 3 else [])
        for ds, dz in sides:
            nb, nb_odd = self._column(s + ds * self.tol, None if z is None else z + dz * self.tol)
            # the same top (to the slope of a wall over that step, as _top_normal): the higher face
            take = left & ~nb_odd & np.isfinite(nb["floor"]) & \
                (np.abs(nb["top"] - col["top"][i]) <= self.tol / WALL_NY)
            col["floor"][i[take]], col["bonded"][i[take]] = nb["floor"][take], nb["bonded"][take]
            left &= ~take
        return col

    def _column(self, s, z=None) -> tuple:
        """(column's dict, whether each line meets the boundary an odd number of times: its
        distinct crossings, those within tol one)."""
        s = np.atleast_1d(np.asarray(s, float))
        x = self.x_top + s
        if self.geo.symmetric:
            x = np.abs(x)
        q = x[:, None]
        if self.dim == 3:
            z = np.broadcast_to(np.asarray(0.0 if z is None else z, float), s.shape)
            q = np.column_stack([x, np.abs(z) if self.geo.z_symmetric else z])
        n = len(q)
        top, outer, floor, bond = (np.full(n, -np.inf) for _ in range(4))
        lo, hi = self._lo - self.tol, self._lo + self._cell * self._ncell + self.tol
        inside = np.all((q >= lo) & (q <= hi), axis=1)
        hits, near = [], []
        for a in range(0, n, 4096):  # bounded memory: a few candidate facets per point
            rows = np.flatnonzero(inside[a:a + 4096]) + a
            if not rows.size:
                continue
            c = np.ravel_multi_index(tuple(self._cell_index(q[rows]).T), tuple(self._ncell))
            cnt = self._start[c + 1] - self._start[c]
            pt = np.repeat(rows, cnt)
            off = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
            f = self._owner[np.repeat(self._start[c], cnt) + off]
            found = self._cross_curved(q[pt], f) if self._curved else [self._cross(q[pt], f)]
            y = np.concatenate([yy[hit] for hit, yy in found])
            hits.append([np.concatenate([v[hit] for hit, _ in found]) for v in (pt, f)] + [y])
            if self._face is not None:  # every candidate facet of each point that crossed a facet
                on = np.isin(pt, hits[-1][0])
                near.append((pt[on], f[on]))
        if not hits:
            hits = [[np.zeros(0, int), np.zeros(0, int), np.zeros(0)]]
        pt, f, y = (np.concatenate(v) for v in zip(*hits))
        if self._face is not None:  # all the points' crossings read on the CAD at once: one STEP import
            pt, f, y = self._on_cad(q, pt, f, y, tuple(np.concatenate(v) for v in zip(*near)) if near
                                    else (np.zeros(0, int), np.zeros(0, int)))
        np.maximum.at(top, pt, y)
        out = self._kind[f] == OUTER
        np.maximum.at(outer, pt[out], y[out])
        below = y < top[pt] - self.tol
        np.maximum.at(floor, pt[below], y[below])
        bonded = below & (self._kind[f] == BONDED)
        np.maximum.at(bond, pt[bonded], y[bonded])
        # a line crossing a closed skin meets its boundary an even number of times; a vertex
        # shared by facets is one crossing (its facets' heights within tol). Only lines of 3 or
        # more crossings are sorted (a line through the top and the floor has 2)
        odd = np.zeros(n, bool)
        cnt = np.bincount(pt, minlength=n)
        many = cnt[pt] >= 3
        if many.any():
            p, yy = pt[many], y[many]
            o = np.lexsort((yy, p))
            p, yy = p[o], yy[o]
            new = np.ones(len(p), bool)
            new[1:] = (p[1:] != p[:-1]) | (yy[1:] - yy[:-1] > self.tol)
            odd = np.bincount(p[new], minlength=n) % 2 == 1
        nan = lambda v: np.where(np.isfinite(v), v, np.nan)  # noqa: E731
        return {"top": nan(top), "outer": nan(outer), "floor": nan(floor),
                "bonded": np.isfinite(floor) & (bond >= floor - self.tol)}, odd

    def _query(self, s, z):
        """The points (m, k) the columns are read at: x (and z), mirrored on a half model."""
        x = self.x_top + np.atleast_1d(np.asarray(s, float))
        if self.geo.symmetric:
            x = np.abs(x)
        if self.dim == 2:
            return x[:, None]
        z = np.broadcast_to(np.asarray(0.0 if z is None else z, float), x.shape)
        return np.column_stack([x, np.abs(z) if self.geo.z_symmetric else z])

    def nearest_skin(self, s, z=None) -> tuple:
        """(s, z, distance, edge length): the nearest point over the contact surface's facets
        seen from above to each (s, z) (nudged just inside its facet; the same sides of the
        mirror planes), its distance and the length of the facet edge it lies on (0 where the
        point is over a facet already)."""
        q = self._query(s, z)
        m, k = q.shape
        out = self._L[self._kind == OUTER][:, :self.dim]  # the vertices: the chords of the rim
        if not len(out):
            return np.array(s, float), z, np.full(m, np.inf), np.zeros(m)
        a = out if k == 1 else out[:, [0, 1, 2]]
        b = out[:, ::-1] if k == 1 else out[:, [1, 2, 0]]
        cen = np.repeat(out.mean(axis=1), a.shape[1], axis=0)
        a, b = a.reshape(-1, k), b.reshape(-1, k)
        best, size, dist = np.empty((m, k)), np.empty(m), np.empty(m)
        for c in range(0, m, 64):  # bounded memory: 64 points x every edge
            p = q[c:c + 64, None, :]
            ab = b - a
            u = np.clip(np.sum((p - a) * ab, axis=2) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
            foot = a + u[..., None] * ab
            d = np.linalg.norm(foot - p, axis=2)
            j = np.argmin(d, axis=1)
            r = np.arange(len(j))
            # a hair towards the facet's centre, so the vertical line crosses it (tolerance 1e-9)
            best[c:c + 64] = foot[r, j] + 1e-6 * (cen[j] - foot[r, j])
            dist[c:c + 64], size[c:c + 64] = d[r, j], np.linalg.norm(ab[j], axis=1)
        inside = np.isfinite(self.column(s, z)["top"])
        best[inside], dist[inside], size[inside] = q[inside], 0.0, 0.0
        x = np.atleast_1d(np.asarray(s, float)) + self.x_top
        zz = np.broadcast_to(np.asarray(0.0 if z is None else z, float), x.shape)
        nx = np.where(x < 0, -1.0, 1.0) * best[:, 0] if self.geo.symmetric else best[:, 0]
        nz = None if k == 1 else (np.where(zz < 0, -1.0, 1.0) * best[:, 1] if self.geo.z_symmetric else best[:, 1])
        return nx - self.x_top, nz, dist, size

    def placed(self, s, z=None) -> tuple:
        """(s, z) where this mesh reads each sensor: as given, but with a `reference` (the solved
        mesh's coordinates) a point the reference held past this mesh's rim moves onto the
        nearest point over its contact surface, at most RIM_SHIFT of that rim's edge (beyond that
        depths() refuses it, naming the remedy), and the distance moved (0 where none)."""
        s = np.atleast_1d(np.asarray(s, float))
        z = None if self.dim == 2 else np.broadcast_to(np.asarray(0.0 if z is None else z, float), s.shape)
        moved = np.zeros(len(s))
        if self.reference is None:
            return s, z, moved
        miss = ~np.isfinite(self.column(s, z)["top"])
        if not miss.any():
            return s, z, moved
        ns, nz, d, size = self.nearest_skin(s[miss], None if z is None else z[miss])
        ok = d <= RIM_SHIFT * size
        s, i = s.copy(), np.flatnonzero(miss)[ok]
        s[i], moved[i] = ns[ok], d[ok]
        if z is not None:
            z = z.copy()
            z[i] = nz[ok]
        return s, z, moved

    def _on_cad(self, q, pt, f, y, near) -> tuple:
        """(pt, f, y): the crossings y of the lines through the points q[pt] and the chords f read
        on the chords' CAD faces (the chord's where the line misses its face: the face's trim ends
        there). A steep chord (a wall's: |n_y| < WALL_NY) whose face the line misses is the coarse
        mesh's, not the skin's: inside a curved rim the lines crossed a disc's wall chords (0.308 mm
        apart at r = 4.99 of R 5) and missed its top and bottom chords. Those points' lines are
        read on the CAD faces of the facets `near` (pt, f) them instead (the trimmed face's, or none)."""
        from tactileskin.mesh.skinfile import line_heights, step_open

        cad = line_heights(self.cad, self._face[f], np.column_stack([q[pt, 0], y, q[pt, 1]]))
        miss = np.isnan(cad)
        wall = miss & self._wall[f]
        y = np.where(miss, y, cad)
        if not miss.any():
            return pt, f, y
        # one probe per point and face near it, at the height of one of that face's chords there
        npt, nf = near
        on = np.isin(npt, pt[miss])
        pairs = np.unique(np.column_stack([npt[on], self._face[nf[on]]]), axis=0, return_index=True)[1]
        npt, nf = npt[on][pairs], nf[on][pairs]
        with step_open(self.cad):
            ny = line_heights(self.cad, self._face[nf], np.column_stack([q[npt, 0], self._y[nf].mean(axis=1),
                                                                         q[npt, 1]]))
            y, f = self._off_trim(pt, f, y, miss & ~wall, npt, nf, ny)
        hit = np.isfinite(ny) & np.isin(npt, pt[wall])
        keep = ~wall
        return (np.concatenate([pt[keep], npt[hit]]), np.concatenate([f[keep], nf[hit]]),
                np.concatenate([y[keep], ny[hit]]))

    def _off_trim(self, pt, f, y, off, npt, nf, ny) -> tuple:
        """(y, f) with each crossing `off` (a chord that is no wall, whose trimmed face the line
        misses) read on another face of the same kind near its point where the line meets it
        within the chord's size (the nearest such): inside a curved rim between two top faces the
        lower face's chords stick out past their face, under the higher face, and the line kept
        their height (a pad's flat top read 0.04-0.08 mm under an R 3 cap within 0.1 mm of its rim,
        and flat). Where none is met the chord's height stays (a line grazing its face's trim)."""
        y, f = y.copy(), f.copy()
        for i in np.flatnonzero(off):
            c = (npt == pt[i]) & np.isfinite(ny) & (self._face[nf] != self._face[f[i]]) & \
                (self._kind[nf] == self._kind[f[i]]) & ~self._wall[nf]
            size = float(np.ptp(self._L[f[i]], axis=0).max())
            c &= np.abs(ny - y[i]) <= size
            if c.any():
                j = np.flatnonzero(c)[np.argmin(np.abs(ny[c] - y[i]))]
                y[i], f[i] = ny[j], nf[j]
        return y, f

    def _cross(self, q, f):
        """(hit, y) of the vertical lines through the points q (m, k) and the facets f (m,)."""
        L, Y = self._L[f], self._y[f]
        tol = 1e-9
        if self.dim == 2:
            a, b = L[:, 0, 0], L[:, 1, 0]
            u = (q[:, 0] - a) / (b - a)
            hit = (u >= -tol) & (u <= 1 + tol)
            u = np.clip(u, 0.0, 1.0)
            return hit, Y[:, 0] + u * (Y[:, 1] - Y[:, 0])
        l1, l2 = _barycentric(L, q)
        hit = (l1 >= -tol) & (l2 >= -tol) & (l1 + l2 <= 1 + tol)
        return hit, Y[:, 0] + l1 * (Y[:, 1] - Y[:, 0]) + l2 * (Y[:, 2] - Y[:, 0])

    def _cross_curved(self, q, f) -> list:
        """[(hit, y), ...] of the vertical lines through q (m, k) and the quadratic facets f (m,):
        2D both roots of x(u) = q on the edge (one that turns back in x is crossed twice), 3D
        Newton on the triangle's (u, v) from the straight facet's answer."""
        L, Y = self._L[f], self._y[f]
        tol = 1e-9
        if self.dim == 2:
            x0, x1, xm = L[:, 0, 0], L[:, 1, 0], L[:, 2, 0]
            b, a, c = -3.0 * x0 - x1 + 4.0 * xm, 2.0 * x0 + 2.0 * x1 - 4.0 * xm, x0 - q[:, 0]
            lin = np.abs(a) <= 1e-9 * np.maximum(np.abs(b), 1e-300)
            disc = b * b - 4.0 * a * c
            root = np.sqrt(np.maximum(disc, 0.0))
            # the stable pair of roots (no cancellation); a straight edge has the one root -c / b
            qq = -0.5 * (b + np.where(b >= 0, root, -root))
            with np.errstate(divide="ignore", invalid="ignore"):
                r1 = np.where(lin, -c / np.where(b == 0, 1.0, b), qq / np.where(a == 0, 1.0, a))
                r2 = np.where(lin | (qq == 0), np.nan, c / np.where(qq == 0, 1.0, qq))
            out = []
            for u, ok in ((r1, disc >= 0), (r2, (disc >= 0) & ~lin)):
                hit = ok & np.isfinite(u) & (u >= -tol) & (u <= 1 + tol)
                u = np.clip(np.nan_to_num(u), 0.0, 1.0)
                y = Y[:, 0] * (1 - u) * (1 - 2 * u) + Y[:, 1] * u * (2 * u - 1) + Y[:, 2] * 4 * u * (1 - u)
                out.append((hit, y))
            return out
        u, v = _barycentric(L, q)  # the straight facet's (u, v) start Newton

        def shape(u, v):
            w = 1.0 - u - v
            N = np.stack([w * (2 * w - 1), u * (2 * u - 1), v * (2 * v - 1), 4 * w * u, 4 * u * v, 4 * v * w], 1)
            du = np.stack([1 - 4 * w, 4 * u - 1, 0 * u, 4 * (w - u), 4 * v, -4 * v], 1)
            dv = np.stack([1 - 4 * w, 0 * u, 4 * v - 1, -4 * u, 4 * u, 4 * (w - v)], 1)
            return N, du, dv

        for _ in range(8):
            N, du, dv = shape(u, v)
            r = np.einsum("ni,nik->nk", N, L) - q
            Ju, Jv = np.einsum("ni,nik->nk", du, L), np.einsum("ni,nik->nk", dv, L)
            J = Ju[:, 0] * Jv[:, 1] - Jv[:, 0] * Ju[:, 1]
            J = np.where(np.abs(J) > 1e-300, J, 1e-300)
            u, v = u - (Jv[:, 1] * r[:, 0] - Jv[:, 0] * r[:, 1]) / J, v - (Ju[:, 0] * r[:, 1] - Ju[:, 1] * r[:, 0]) / J
        N, _, _ = shape(u, v)
        close = np.linalg.norm(np.einsum("ni,nik->nk", N, L) - q, axis=1) <= 1e-9 * self._size
        hit = close & (u >= -tol) & (v >= -tol) & (u + v <= 1 + tol)
        return [(hit, np.einsum("ni,ni->n", N, Y))]

    def depths(self, where: str, lay, s, z, idx, what: str = "") -> np.ndarray:
        """The depth along the contact surface's inward normal at each point (s, z) of the
        layout `lay` (its depth, or the line's length in the skin less its height); a point outside the skin is a
        ParameterError naming the layout, the sensor (`idx`: its index in the layout) and the
        valid range there. With a `reference` (mesh_coordinates) its check decides, and the
        depths it accepts are clamped into this mesh's columns."""
        if self._face is None:
            return self._depths(where, lay, s, z, idx, what)
        from tactileskin.mesh.skinfile import step_open

        with step_open(self.cad):  # the STEP imported once for all the columns read here
            return self._depths(where, lay, s, z, idx, what)

    def _depths(self, where: str, lay, s, z, idx, what: str = "") -> np.ndarray:
        s = np.atleast_1d(np.asarray(s, float))
        z = np.broadcast_to(np.asarray(z, float), s.shape)
        if self.reference is not None:
            # the scene's check on the CAD, its answer and message: a STEP's solved faces lie off
            # the CAD (on a sphere cap R 6 at h = 1 up to 5.4e-4 mm P2, 0.040 mm P1) and a sensor
            # the scene held within that of a face was refused after meshing
            self.reference.depths(where, lay, s, z, idx, what)
            s, zq, moved = self.placed(s, z)
            z = z if zq is None else zq
            if moved.max(initial=0.0) > 0.0:
                logger.info("sensor layout %r: %d point(s) past the solved mesh's rim moved up to %.3g mm onto "
                            "it", lay.name, int(np.sum(moved > 0)), float(moved.max()))
        col = self.column(s, z if self.dim == 3 else None)

        def at(i):
            return f"s = {s[i]:.6g}" + (f", z = {z[i]:.6g}" if self.dim == 3 else "") + " mm"

        def sensor(i):
            return f"sensor {lay.name}-{int(np.atleast_1d(idx)[i])}" + (f" (taxel edge at {at(i)})" if what else "")

        def first(bad):
            return int(np.flatnonzero(bad)[0])

        over = np.isfinite(col["top"]) & np.isfinite(col["floor"])
        if not over.all():
            i = first(~over)
            where_s = "s" + (", z" if self.dim == 3 else "")
            value = float(s[i]) if self.dim == 2 else (float(s[i]), float(z[i]))
            z_text = f", z in [{self.z_range[0]:.6g}, {self.z_range[1]:.6g}]" if self.dim == 3 else ""
            raise ParameterError(f"{where} {where_s}{what}", value,
                                 f"over the skin (it spans s in [{self.s_range[0]:.6g}, {self.s_range[1]:.6g}]"
                                 f"{z_text} mm)", f"{sensor(i)}: no skin under it" + self._remedy(s[i], z[i]))
        up = col["outer"] >= col["top"] - self.tol
        if not up.all():
            i = first(~up)
            raise ParameterError(f"{where} s{what}", float(s[i]), "under the contact surface",
                                 f"{sensor(i)}: at {at(i)} the skin's top is not its contact surface "
                                 "(skin_outer)")
        # the line along the contact surface's inward normal at (s, z): a depth is measured on
        # it, as on the fingertip (the common normal of its surface and bone), so a skin of
        # uniform thickness holds depth d at d from its surface everywhere (vertically, 0.5 under
        # a 45 degree slope lay 0.354 mm from the surface); a height from where it meets the
        # bonded face (the fingertip's height = t - depth)
        P, nrm = self._surface(s, z, col["top"])
        if lay.depth is not None:
            d = np.full(len(s), float(lay.depth))
            ex = self._exit(P, nrm, np.maximum(d, 0.0))  # inf where the line stays in the skin to d
            if self.reference is not None:
                return self._clamped(lay, d, ex)
            bad = (d < -_TOL) | (d > ex + _TOL)
            if bad.any():
                i = first(bad)
                reach = self._exit(P[i:i + 1], nrm[i:i + 1])[0]
                raise ParameterError(f"{where} depth", float(d[i]), f"[0, {reach:.6g}] mm at {at(i)} (along the "
                                     "contact surface's inward normal there, to where that line leaves the skin)",
                                     sensor(i))
            return d
        h = float(lay.height)
        ex, bonded = self._exit(P, nrm, bonded=True)
        if self.reference is not None:
            return self._clamped(lay, ex - h, ex)
        if not bonded.all():
            i = first(~bonded)
            raise ParameterError(f"{where} height", h, "a depth instead where no bonded surface is under the "
                                 "sensor", f"{sensor(i)}: at {at(i)} the line along the contact surface's "
                                 "inward normal leaves the skin through a face that is not bonded")
        bad = (h < -_TOL) | (h > ex + _TOL)
        if bad.any():
            i = first(bad)
            raise ParameterError(f"{where} height", h, f"[0, {ex[i]:.6g}] mm at {at(i)} (the skin's thickness "
                                 "along the contact surface's inward normal there)", sensor(i))
        return np.maximum(ex - h, 0.0)

    def _surface(self, s, z, top=None) -> tuple:
        """(P, n): the contact surface's point over each (s, z) ((m, dim): x, y(, z)) and its
        outward unit normal there ((m, dim)); `top`: the columns' tops there, where read already."""
        s = np.atleast_1d(np.asarray(s, float))
        zz = np.broadcast_to(np.asarray(0.0 if z is None else z, float), s.shape) if self.dim == 3 else None
        # frame() reads the points depths() just read (a sensor's, its taxel's): each a few CAD
        # queries on a STEP (gmsh isInside, ~10 us a point and face), so the last answer is kept
        key = (s.tobytes(), None if zz is None else zz.tobytes())
        memo = getattr(self, "_surface_memo", None)
        if memo is None or memo[0] != key:
            if self.reference is None and type(self).surface_normal is FileCoordinates.surface_normal:
                top, nrm = self._top_normal(s, zz, top)
            else:  # the reference's normal, the dome's exact one
                top, nrm = self.column(s, zz)["top"] if top is None else top, self.surface_normal(s, zz)
            cols = [self.x_top + s, top] + ([zz] if self.dim == 3 else [])
            memo = self._surface_memo = (key, np.column_stack(cols), nrm if self.dim == 3 else nrm[:, :2])
        return memo[1].copy(), memo[2].copy()

    def _inside(self, pts, gap: bool = False) -> np.ndarray:
        """Whether each point (m, dim) lies in the skin's first layer: on its column, at most the
        top (+ tol: a point on the surface) and at least the first boundary under it (strictly:
        a line's exit is the last point in the skin, so a height 0 lies on the bonded face).
        gap=True: how far inside (mm, vertical; < 0 outside, NaN off the skin) instead."""
        q = np.column_stack([pts[:, 0] - self.x_top] + ([pts[:, 2]] if self.dim == 3 else []))
        # each column read once (a CAD query on a STEP): a vertical line's (a flat top's, n = +y
        # exactly) samples all stand on its own column, 16 reads of one
        key = np.ascontiguousarray(q).view(np.dtype((np.void, q.dtype.itemsize * q.shape[1])))[:, 0]
        _, first, back = np.unique(key, return_index=True, return_inverse=True)
        col = self.column(q[first, 0], q[first, 1] if self.dim == 3 else None)
        g = np.minimum(col["top"][back] + self.tol - pts[:, 1], pts[:, 1] - col["floor"][back])
        if gap:
            return g
        with np.errstate(invalid="ignore"):
            return np.isfinite(g) & (g >= 0.0)

    def _exit(self, P, n, limit=None, bonded: bool = False):
        """The distance along -n from each surface point P to where that line leaves the skin
        (the first boundary under the contact surface, or a side): within `limit` (inf where it
        stays in the skin that far), or (None) however far (inf: not within twice the skin's
        size). The line is sampled at EXIT_SAMPLES points per stretch (a stretch: the limit, or
        the vertical thickness there, doubled until the line leaves), then the exit found to
        1e-13 of the size (the point returned is in the skin). bonded=True: also whether it
        leaves through a bonded face."""
        m = len(P)
        out, lo, hi = np.full(m, np.inf), np.zeros(m), np.full(m, np.nan)
        glo, ghi = np.full(m, np.inf), np.full(m, np.nan)  # the gaps there (inf: the surface point)
        full = limit is None
        if full:
            col = self.column(P[:, 0] - self.x_top, P[:, 2] if self.dim == 3 else None)
            lim = np.where(np.isfinite(col["floor"]), col["top"] - col["floor"], self.thickness)
            lim = np.maximum(lim, self.tol)
        else:
            lim = np.broadcast_to(np.asarray(limit, float), (m,)).copy()
        live = lim > 0.0
        k = np.arange(1, EXIT_SAMPLES + 1) / EXIT_SAMPLES
        for _ in range(12 if full else 1):
            idx = np.flatnonzero(live)
            if not idx.size:
                break
            lam = lo[idx, None] + (lim[idx] - lo[idx])[:, None] * k[None, :]
            g = self._inside((P[idx, None, :] - lam[..., None] * n[idx, None, :]).reshape(-1, P.shape[1]), gap=True)
            g = g.reshape(lam.shape)
            with np.errstate(invalid="ignore"):
                ins = g >= 0.0
            left = ~ins.all(axis=1)
            j = np.argmax(~ins, axis=1)
            r = np.arange(len(idx))
            hi[idx[left]], ghi[idx[left]] = lam[r, j][left], g[r, j][left]
            before = np.maximum(j - 1, 0)
            lo[idx[left]] = np.where(j > 0, lam[r, before], lo[idx])[left]
            glo[idx[left]] = np.where(j > 0, g[r, before], glo[idx])[left]
            live[idx[left]] = False
            stay = idx[~left]
            lo[stay], glo[stay] = lim[stay], g[~left, -1]
            lim[stay] *= 2.0
            live[stay] &= full & (lim[stay] <= 4.0 * self._size)
        go = np.isfinite(hi)
        # the exit between lo (in) and hi (out): regula falsi (Illinois) on the vertical gap, a
        # smooth function of the distance across a face (a few column reads, each a CAD query
        # on a STEP), halving where it is unknown (off the skin's side) or stalls
        last = np.zeros(m, int)
        for _ in range(100):
            act = go & (hi - lo > 1e-13 * self._size) & (glo > 1e-13 * self._size)
            if not act.any():
                break
            ok = np.isfinite(glo) & np.isfinite(ghi) & (ghi < 0.0)
            with np.errstate(invalid="ignore", divide="ignore"):
                mid = np.where(ok, (lo * ghi - hi * glo) / (ghi - glo), 0.5 * (lo + hi))
            span = hi - lo
            mid = np.clip(np.where(np.isfinite(mid), mid, 0.5 * (lo + hi)), lo + 1e-3 * span, hi - 1e-3 * span)
            g = np.full(m, np.nan)
            g[act] = self._inside(P[act] - mid[act, None] * n[act], gap=True)
            with np.errstate(invalid="ignore"):
                ins = act & (g >= 0.0)
                out_ = act & ~(g >= 0.0)
            lo, glo = np.where(ins, mid, lo), np.where(ins, g, glo)
            hi, ghi = np.where(out_, mid, hi), np.where(out_, g, ghi)
            # Illinois: the end kept twice has its gap halved, so the next step moves it
            ghi = np.where(ins & (last == 1), 0.5 * ghi, ghi)
            glo = np.where(out_ & (last == -1), 0.5 * glo, glo)
            last = np.where(ins, 1, np.where(out_, -1, last))
        out[go] = lo[go]
        if not bonded:
            return out
        # at the exit the floor of its column is what it meets (not its top, not a side), bonded
        q = P - np.where(go, lo, 0.0)[:, None] * n
        col = self.column(q[:, 0] - self.x_top, q[:, 2] if self.dim == 3 else None)
        with np.errstate(invalid="ignore"):
            through = go & (q[:, 1] - col["floor"] <= self.tol) & col["bonded"]
        return out, through

    def _remedy(self, s, z) -> str:
        """What to do about a point over no skin: move it to the nearest skin, which a mesh's
        straight chords put inside a curved rim (a STEP's analysis mesh, a solved P1 mesh)."""
        if not hasattr(self, "_L"):  # analytic surfaces (skins.dome.DomeCoordinates)
            return ""
        ns, nz, d, _ = self.nearest_skin([s], None if self.dim == 2 else [z])
        if not np.isfinite(d[0]) or d[0] <= 0.0:
            return ""
        at = f"s = {ns[0]:.6g}" + (f", z = {nz[0]:.6g}" if self.dim == 3 else "")
        if self.reference is None:  # the scene's mesh (a STEP's analysis mesh: size / 8, fixed)
            return f"; the nearest skin is {d[0]:.3g} mm away (at {at} mm): move the sensor in by that"
        return (f"; the solved mesh's nearest skin is {d[0]:.3g} mm away (at {at} mm), its rim's chords inside "
                "the skin's: a finer mesh_size or order 2, or the sensor that much further in")

    def _clamped(self, lay, d, t) -> np.ndarray:
        """The depths d (the reference's check held them) moved into this mesh's skin along
        each sensor's line, [0, t]: at most as far as its faces lie off the reference's there."""
        out = np.clip(d, 0.0, t)
        moved = float(np.max(np.abs(out - d), initial=0.0))
        if moved > self.tol:
            logger.info("sensor layout %r: %d point(s) moved up to %.3g mm onto the solved mesh's faces (they "
                        "lie that far off the CAD's there)", lay.name, int(np.sum(np.abs(out - d) > self.tol)),
                        moved)
        return out

    def frame(self, s, depth, z=None, normals: bool = True):
        """(xy (n, 2; in 3D xyz (n, 3)), the contact surface's outward unit normal n at (s, z)
        (n, 2; in 3D (n, 3)), t1 along that surface in the x-y plane (n, 2 / 3), area element 1):
        the point at `depth` along -n from the contact surface's point over (s, z), as on the
        fingertip (it stood on the vertical line: 0.5 under a 45 degree slope lay 0.354 mm from the
        surface; on a flat top, n = +y, the point is the same to the bit). The sensor plane lies
        along the surface there (a depth layout's surface is that one moved in along n), as a chip
        embedded under a slope does: with it horizontal, 0.5 mm under 20-45 degree slopes of a half
        tube (R 8, t 2) and of the dome, beside a flat plate's contact, sensors read sigma_yy,
        0.009-0.016 MPa where sigma_nn is ~0 (5-8 % of the reading at 10 degrees under the
        contact, itself 3-4 % off). normals=False: NaN normals (the points of taxel samples)."""
        s = np.atleast_1d(np.asarray(s, float))
        depth = np.broadcast_to(np.asarray(depth, float), s.shape)
        s, z, _ = self.placed(s, z)  # the solved mesh's rim: as depths() placed them
        P, nrm = self._surface(s, z)
        n = len(s)
        xy = P - depth[:, None] * nrm
        if not normals:
            return xy, np.full((n, 2), np.nan), np.full((n, 2), np.nan), np.ones(n)
        nrm = nrm if self.dim == 3 else np.column_stack([nrm, np.zeros(n)])
        t1 = np.column_stack([nrm[:, 1], -nrm[:, 0]] + ([np.zeros(n)] if self.dim == 3 else []))
        t1 /= np.linalg.norm(t1, axis=1, keepdims=True)  # n x e_z: +x where the surface is flat
        return xy, nrm if self.dim == 3 else nrm[:, :2], t1 if self.dim == 3 else t1[:, :2], np.ones(n)

    def surface_normal(self, s, z=None) -> np.ndarray:
        """(n, 3) outward unit normal of the contact surface y = top(x, z) over each (s, z): by
        central differences of the column's top over SLOPE_STEP of the skin's size (one-sided at
        the skin's edge, and where the other side's crosses a step between two top faces: steeper
        than a wall; a mirror half's top is even, so its symmetry line reads flat). A slope
        under FLAT_SLOPE (rounding: heights of a flat P2 face differ by ~1e-16 of the size) is
        flat: normal exactly +y, so a flat top reads as it always did. With a `reference` (the
        solved mesh's coordinates) the reference's: a sensor's line runs along it, and the P2
        dome's faces tilt the central difference by ~1.2e-4 (2.4e-4 mm along a 2 mm line, where
        a bone sensor read the bone map 5e-4 mm off its point)."""
        if self.reference is not None:
            return self.reference.surface_normal(s, z)
        return self._top_normal(s, z)[1]

    def _top_normal(self, s, z=None, top=None) -> tuple:
        """(top, n): the column's top over each (s, z) (`top`, where read already) and
        surface_normal there, the top read once, with the central differences' points (it was
        read once more in each direction)."""
        s = np.atleast_1d(np.asarray(s, float))
        z = np.broadcast_to(np.asarray(0.0 if z is None else z, float), s.shape)
        zz = z if self.dim == 3 else None
        h = SLOPE_STEP * self._size
        steps = ((h, 0.0),) + (((0.0, h),) if self.dim == 3 else ())
        # one read of every point (each a CAD query on a STEP): up and down in each direction, mid
        mid = top
        ss = np.concatenate([v for ds, _ in steps for v in (s + ds, s - ds)] + ([s] if mid is None else []))
        top = self.column(ss, None if zz is None else np.concatenate(
            [v for _, dz in steps for v in (zz + dz, zz - dz)] + ([zz] if mid is None else [])))["top"]
        top = top.reshape(2 * len(steps) + (mid is None), len(s))
        mid = top[-1] if mid is None else mid
        grads = []
        for k in range(len(steps)):
            up, down = top[2 * k], top[2 * k + 1]
            fwd, back = (up - mid) / h, (mid - down) / h
            # a one-sided slope steeper than a wall's (|n_y| < WALL_NY) where the other is not
            # crosses a jump of the top (a step between two top faces), not the surface: the
            # other side's (the central difference at a step's edge read a slope of ~312 and a
            # depth-0.5 sensor lay 0.5 mm sideways, 0.0016 mm under the surface)
            with np.errstate(invalid="ignore"):
                jf, jb = np.abs(fwd) > 1.0 / WALL_NY, np.abs(back) > 1.0 / WALL_NY
            g = np.where(np.isfinite(up) & np.isfinite(down),
                         np.where(jf & ~jb, back, np.where(jb & ~jf, fwd, (up - down) / (2 * h))),
                         np.where(np.isfinite(up), fwd, back))
            g = np.where(np.isfinite(g) & (np.abs(g) > FLAT_SLOPE), g, 0.0)
            grads.append(g)
        gx, gz = grads[0], (grads[1] if self.dim == 3 else np.zeros_like(s))
        nrm = np.column_stack([-gx, np.ones_like(gx), -gz])
        return mid, nrm / np.linalg.norm(nrm, axis=1, keepdims=True)


def _barycentric(L, q) -> tuple[np.ndarray, np.ndarray]:
    """(l1, l2): the points q (m, 2) in the triangles L (m, >= 3, 2) of their first three
    nodes, q = a + l1 (b - a) + l2 (c - a)."""
    a, b, c = L[:, 0], L[:, 1], L[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    p = q - a
    return ((p[:, 0] * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * p[:, 1]) / det,
            ((b[:, 0] - a[:, 0]) * p[:, 1] - p[:, 0] * (b[:, 1] - a[:, 1])) / det)
