"""SkinMesh: a scikit-fem mesh of the skin with named boundaries, quality and export."""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactileskin import fileio
from tactileskin.errors import MeshError, ParameterError

logger = logging.getLogger(__name__)

BOUNDARIES_2D = ("bone_interface", "outer_surface", "symmetry", "nail_edge")
BOUNDARIES_3D = BOUNDARIES_2D + ("end_front", "end_back")
SYMMETRY_Z = "symmetry_z"  # name of a z-symmetric slab's mid-plane z = 0 in written mesh files
# meshio format names by suffix
FORMATS = {".msh": "gmsh", ".vtu": "vtu", ".inp": "abaqus"}  # .inp: own writer (abaqus.py)


@dataclass
class SkinMesh:
    """The meshed skin.

    mesh: skfem MeshTri2/MeshTri1 (2D) or MeshTet2/MeshTet1 (3D); its `boundaries` hold the
      same named facet sets as `boundaries` here.
    boundaries: name -> facet indices into `mesh.facets` (`bone_interface`, `outer_surface`,
      `symmetry` (plane x = 0), `nail_edge`, and in 3D `end_front`, `end_back`).
    dim: 2 (plane-strain half section) or 3 (slab along z).
    quality: `min_sicn`/`mean_sicn` (gmsh shape quality of the straight-sided cells, 1 =
      equilateral), `min_scaled_jacobian` (min over cells of min/max det J at quadrature
      points of the curved cells; 1 = straight, <= 0 inverted), `elements`, `nodes`
      (all P2 nodes), `vertices`, `wall_s`.
    z_symmetric (3D): True if the slab is the half z >= 0 and `end_back` is the mid-plane
      z = 0 (a symmetry plane: u_z = 0); False if `end_back` is the free end z = -length/2.
    sizes: the size plan that made the mesh (coarse, fine, contact zone, estimate).
    """

    mesh: object
    boundaries: dict[str, np.ndarray]
    dim: int
    quality: dict
    section: object = None
    z_symmetric: bool = False
    length: float | None = None
    sizes: dict = field(default_factory=dict)

    @property
    def order(self) -> int:
        return 2 if type(self.mesh).__name__.endswith("2") else 1

    @property
    def cell(self) -> str:
        return "quad" if "Quad" in type(self.mesh).__name__ else "tri"

    @property
    def halved(self) -> bool:
        """The half x >= 0 with its symmetry line / plane x = 0 (else the whole width: a user's
        skin without a symmetry group, a pad under an x-asymmetric indenter)."""
        return len(self.boundaries.get("symmetry", ())) > 0

    def file_name(self, name: str) -> str:
        """A boundary's name in written mesh files: a z-symmetric slab's end_back is its
        mid-plane, written as `symmetry_z` (a file skin reads it as u_z = 0; an `end_back`
        would be a free end)."""
        return SYMMETRY_Z if name == "end_back" and self.dim == 3 and self.z_symmetric else name

    # --- export ----------------------------------------------------------------------
    def to_meshio(self):
        """meshio.Mesh with the cells, the named boundary facets (cell sets, gmsh physical
        tags) and node sets per boundary; second-order cells as triangle6 / tetra10."""
        import meshio

        m = self.mesh
        pts = m.doflocs.T
        if self.dim == 2:
            pts = np.column_stack([pts, np.zeros(len(pts))])
        key = (self.dim, self.order, self.cell)
        cell_nodes = m.dofs.element_dofs[: _CELL_NODES[key][1]].T
        ctype = _CELL_NODES[key][0]
        ftype = {(2, 1): "line", (2, 2): "line3", (3, 1): "triangle", (3, 2): "triangle6"}[(self.dim, self.order)]
        cells = [(ctype, cell_nodes)]
        phys = [np.zeros(len(cell_nodes), dtype=int)]
        field_data = {"skin": np.array([len(self.boundaries) + 1, self.dim])}
        phys[0][:] = len(self.boundaries) + 1
        cell_sets = {"skin": [np.arange(len(cell_nodes))] + [np.array([], dtype=int)] * len(self.boundaries)}
        point_sets = {}
        for i, (name, facets) in enumerate(self.boundaries.items()):
            name = self.file_name(name)
            fn = facet_nodes(m, facets, self.dim, self.order)
            cells.append((ftype, fn))
            phys.append(np.full(len(fn), i + 1))
            field_data[name] = np.array([i + 1, self.dim - 1])
            sets = [np.array([], dtype=int)] * (len(self.boundaries) + 1)
            sets[i + 1] = np.arange(len(fn))
            cell_sets[name] = sets
            point_sets[name] = np.unique(fn)
        return meshio.Mesh(pts, cells, cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                           field_data=field_data, cell_sets=cell_sets, point_sets=point_sets)

    def write(self, path: str | os.PathLike) -> Path:
        """Write by suffix (.msh, .vtu, .inp) atomically (fileio.atomic_path)."""
        path = Path(path)
        fmt = FORMATS.get(path.suffix.lower())
        if fmt is None:
            raise ParameterError("path", str(path), "a file name ending in " + ", ".join(FORMATS))
        out = self.to_meshio()
        names = {}
        if fmt == "vtu":  # the boundary names go in as VTK field data after meshio (it drops them)
            names = out.field_data
            out.cell_sets, out.point_sets, out.field_data = {}, {}, {}
        with fileio.atomic_path(path) as tmp, fileio.os_errors(path):  # a .tmp name, known to clean_stale
            try:
                if fmt == "abaqus":
                    from tactileskin.mesh.abaqus import inp_text

                    tmp.write_text(inp_text(out.points[:, : self.dim], out.cells[0].type,
                                            out.cells[0].data, out.point_sets))
                elif fmt == "gmsh":
                    out.write(tmp, file_format="gmsh22", binary=False)
                else:
                    out.write(tmp, file_format=fmt)
                    if names:
                        from tactileskin.results import add_vtu_field_data

                        add_vtu_field_data(Path(tmp), names)
            except OSError:
                raise  # an OutputError naming the path (os_errors)
            except Exception as e:
                raise MeshError(f"could not write {path} ({fmt}): {e}") from e
        logger.info("wrote %s", path)
        return path

    # --- checks ----------------------------------------------------------------------
    def boundary_measure(self, name: str) -> float:
        """Length (2D) or area (3D) of a named boundary, integrated on the curved facets."""
        from skfem import Functional, FacetBasis

        fb = FacetBasis(self.mesh, self.mesh.elem(), facets=self.boundaries[name])
        return float(Functional(lambda w: 1.0 + 0.0 * w.x[0]).assemble(fb))

    def measure(self) -> float:
        """Area (2D) or volume (3D) of the mesh on the curved cells."""
        from skfem import Functional, CellBasis

        cb = CellBasis(self.mesh, self.mesh.elem())
        return float(Functional(lambda w: 1.0 + 0.0 * w.x[0]).assemble(cb))

    def min_jacobian(self) -> float:
        """Smallest Jacobian determinant over the quadrature points (> 0: no inverted cell)."""
        from skfem.quadrature import get_quadrature

        X, _ = get_quadrature(self.mesh.elem.refdom, 2 * self.order)
        return float(np.min(self.mesh._mapping().detDF(X)))


# Smallest scaled Jacobian (see `jacobian_ratio`) a mesh may have to be solved on. At 0 a
# curved cell folds over itself (gmsh: "elements with jac. < 0"; `--mesh-size 5
# --refinement 1` on 1 mm skin gives -0.21 and a peak 73 % off); just above 0 its edge
# nearly touches the opposite side and the cell's stress there is meaningless. Every mesh
# the quality presets and the tests build stays above 0.2 (most above 0.8).
MIN_SCALED_JACOBIAN = 0.05


def _lattice(dim: int, n: int) -> np.ndarray:
    """(dim, k) points i/n of the reference simplex (vertices, edge and face points)."""
    idx = np.stack(np.meshgrid(*[np.arange(n + 1)] * dim, indexing="ij"), axis=-1).reshape(-1, dim)
    return (idx[idx.sum(axis=1) <= n] / n).T


def jacobian_ratio(mesh) -> float:
    """min over cells of (min / max Jacobian determinant over the cell): 1 for
    straight-sided simplices, <= 0 for an inverted (or folded) curved cell
    (`cell_jacobian_ratios`)."""
    return float(np.min(cell_jacobian_ratios(mesh)))


def cell_jacobian_ratios(mesh) -> np.ndarray:
    """Per cell, min / max Jacobian determinant over the cell (see `jacobian_ratio`).

    det J of a P2 cell is a polynomial (degree 2 in 2D, 3 in 3D) that is often smallest at
    a vertex, where no quadrature point lies: it is evaluated at the quadrature points of
    degree 4 and at the lattice points i/4 of the cell (vertices, edges, faces). A cell
    whose largest det J is not positive counts as -1."""
    from skfem.quadrature import get_quadrature

    Xq, _ = get_quadrature(mesh.elem.refdom, 4)
    X = np.concatenate([Xq, _lattice(mesh.dim(), 4)], axis=1)
    mapping = mesh._mapping()
    if hasattr(mapping, "J"):  # isoparametric (curved) cells
        J = [[mapping.J(i, j, X) for j in range(mesh.dim())] for i in range(mesh.dim())]
        d = np.linalg.det(np.moveaxis(np.array(J), (0, 1), (-2, -1)))  # (cells, points)
    else:  # affine (straight) cells: det J is constant per cell
        d = np.asarray(mapping.detDF(X))
    dmax = d.max(axis=1)
    return np.where(dmax > 0, d.min(axis=1) / np.where(dmax > 0, dmax, 1.0), -1.0)


def check_quality(quality: dict, sizes: dict) -> None:
    """Refuse (MeshError) a mesh whose min scaled Jacobian is below MIN_SCALED_JACOBIAN:
    an inverted or folded curved cell gives wrong stresses, whatever the solver does."""
    q = float(quality["min_scaled_jacobian"])
    if q >= MIN_SCALED_JACOBIAN:
        return
    coarse = sizes.get("coarse")
    hint = (f"use a smaller --mesh-size (now {coarse:g} mm; try {0.5 * coarse:g} or less) or a larger "
            "--refinement" if coarse else "use a smaller element size")
    raise MeshError(f"the mesh has {'inverted' if q <= 0 else 'nearly folded'} curved cells: min scaled "
                    f"Jacobian {q:.3g} (needs >= {MIN_SCALED_JACOBIAN:g}: cells too large for the skin's "
                    f"thickness and curvature); {hint}")


# meshio cell type and node count; scikit-fem's element_dofs start with these nodes in
# meshio's order (vertices, edges in refdom order, then the quad centre)
_CELL_NODES = {(2, 1, "tri"): ("triangle", 3), (2, 2, "tri"): ("triangle6", 6),
               (3, 1, "tri"): ("tetra", 4), (3, 2, "tri"): ("tetra10", 10),
               (2, 1, "quad"): ("quad", 4), (2, 2, "quad"): ("quad9", 9)}


def facet_nodes(m, facets: np.ndarray, dim: int, order: int) -> np.ndarray:
    """Node indices (meshio line3/triangle6 order) of the given facets of a skfem mesh."""
    verts = m.facets[:, facets].T
    if order == 1:
        return verts
    if dim == 2:
        return np.column_stack([verts, m.dofs.facet_dofs[0, facets]])
    # triangle facet: edges (0,1) (1,2) (0,2) of the facet's own (sorted) vertices
    edges = m.f2e[:, facets]  # (3, nf), in brefdom edge order of the facet
    mids = m.dofs.edge_dofs[0, edges].T
    return np.column_stack([verts, mids])
