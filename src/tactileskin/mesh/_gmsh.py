"""gmsh session handling and the hand-off of gmsh's second-order mesh to scikit-fem.

gmsh keeps global state, so every build runs inside `session()`: one lock per process,
`initialize(interruptible=False)` (works off the main thread, e.g. in Dask workers),
terminal output silenced unless this logger is at DEBUG, and always finalized.

Second-order nodes are read straight from the gmsh API (no file round trip): scikit-fem's
meshio import drops second-order boundary tags, so the named facet sets are rebuilt here by
matching the vertex tuples of gmsh's boundary elements against `mesh.facets`.
"""

from __future__ import annotations

import contextlib
import logging
import os
import pickle
import subprocess
import sys
import threading

import numpy as np

from tactileskin.errors import MeshError, TactileSkinError

logger = logging.getLogger(__name__)
_LOCK = threading.Lock()
# pid of the process that made a 3D mesh: gmsh's OpenCASCADE starts a thread pool there (the
# surface triangulations behind the Distance size fields), which does not survive fork(): a
# child fork()ed after it (multiprocessing's default on Linux, a Pool.map of solves) waited
# forever for the parent's pool thread in its own 3D meshing (mesh.build_mesh meshes there in
# a fresh Python instead, in_fresh_process)
_meshed_3d_in: int | None = None

# gmsh element type ids
LINE2, LINE3, TRI3, TRI6, TET4, TET10, QUAD4, QUAD9 = 1, 8, 2, 9, 4, 11, 3, 10
CELL_TYPE = {(2, 1): TRI3, (2, 2): TRI6, (3, 1): TET4, (3, 2): TET10,
             (2, 1, "quad"): QUAD4, (2, 2, "quad"): QUAD9}
NODES = {TRI3: 3, TRI6: 6, TET4: 4, TET10: 10, QUAD4: 4, QUAD9: 9}
FACET_TYPE = {(2, 1): LINE2, (2, 2): LINE3, (3, 1): TRI3, (3, 2): TRI6}
# gmsh tetra10 edges: (0,1) (1,2) (0,2) (0,3) (2,3) (1,3); scikit-fem (RefTet.edges):
# (0,1) (1,2) (0,2) (0,3) (1,3) (2,3) -> swap the last two mid-nodes.
_TET10_GMSH_TO_SKFEM = np.array([0, 1, 2, 3, 4, 5, 6, 7, 9, 8])


class InnerFacetError(MeshError):
    """A named group has a facet between two cells (not on the mesh's boundary); `name` and
    `entity` (the gmsh entity tag) let a caller name the user's group (mesh.skinfile)."""

    def __init__(self, name: str, entity: int):
        self.name, self.entity = name, int(entity)
        super().__init__(f"boundary '{name}': a gmsh facet is not a boundary facet of the mesh")


@contextlib.contextmanager
def session(name: str, params: dict):
    """A fresh gmsh model; gmsh errors become MeshError naming `params`."""
    import gmsh

    with _LOCK:
        owned = not gmsh.isInitialized()
        if owned:
            with _signals_kept():
                gmsh.initialize(interruptible=False)
        try:
            gmsh.option.setNumber("General.Terminal", 1 if logger.isEnabledFor(logging.DEBUG) else 0)
            gmsh.option.setNumber("General.Verbosity", 5 if logger.isEnabledFor(logging.DEBUG) else 2)
            gmsh.option.setNumber("General.NumThreads", 1)  # reproducible meshes (cache keys)
            gmsh.logger.start()
            gmsh.model.add(name)
            try:
                yield gmsh
            except TactileSkinError:  # MeshError, or a ParameterError on the user's file
                raise
            except Exception as e:  # gmsh raises plain Exception
                log = [m for m in _log(gmsh) if m.startswith(("Error", "Warning"))][-5:]
                raise MeshError(f"gmsh failed to mesh {name} with {params}: {e}"
                                + (f" (gmsh log: {' | '.join(log)})" if log else "")) from e
            finally:
                _note_3d(gmsh)
                for msg in _log(gmsh):
                    if msg.startswith("Warning"):
                        logger.warning("gmsh (%s): %s", name, msg)
                gmsh.logger.stop()
                gmsh.model.remove()
        finally:
            if owned:
                with _signals_kept():
                    gmsh.finalize()


def _note_3d(gmsh) -> None:
    global _meshed_3d_in
    if _meshed_3d_in is None and gmsh.model.getDimension() == 3:
        _meshed_3d_in = os.getpid()


def forked_after_3d_mesh() -> bool:
    """True in a fork()ed child (or a later descendant) of a process that made a 3D mesh."""
    return _meshed_3d_in is not None and _meshed_3d_in != os.getpid()


# run in a fresh Python by in_fresh_process: (sys.path, log level, (func, args, kwargs)) on
# stdin; (ok, result or exception as (type, message, attributes), log records) on the saved
# stdout (stray prints go to stderr)
_FRESH = """
import logging, os, pickle, sys
out = os.fdopen(os.dup(1), "wb")
os.dup2(2, 1)
sys.path[:0] = pickle.load(sys.stdin.buffer)
level = pickle.load(sys.stdin.buffer)
records = []
class Keep(logging.Handler):
    def emit(self, r):
        r.msg, r.args, r.exc_info, r.exc_text = r.getMessage(), None, None, None
        records.append(r)
log = logging.getLogger("tactileskin")
log.setLevel(level)
log.addHandler(Keep())
func, args, kwargs = pickle.load(sys.stdin.buffer)
try:
    res = (True, func(*args, **kwargs))
except Exception as e:
    attrs = dict(vars(e))
    if isinstance(e, OSError):  # not in its __dict__
        attrs.update((k, getattr(e, k)) for k in ("errno", "strerror", "filename", "filename2")
                     if getattr(e, k) is not None)
    res = (False, (type(e), str(e), attrs))
pickle.dump(res + (records,), out)
"""


def in_fresh_process(func, *args, **kwargs):
    """func(*args, **kwargs) in a new Python (not fork()ed: no inherited thread pools), its
    log records re-emitted here and its exception (type, message, attributes) raised here.
    A subprocess, not multiprocessing: a Pool's workers are daemons, which may not start
    multiprocessing children."""
    payload = b"".join(pickle.dumps(x) for x in ([p for p in sys.path if p],
                                                 logging.getLogger("tactileskin").getEffectiveLevel(),
                                                 (func, args, kwargs)))
    r = subprocess.run([sys.executable, "-c", _FRESH], input=payload, capture_output=True)
    try:
        ok, value, records = pickle.loads(r.stdout)
    except Exception:
        err = r.stderr.decode(errors="replace").strip().splitlines()[-3:]
        raise MeshError(f"meshing in a fresh Python (this process was fork()ed after a 3D mesh) "
                        f"failed, exit code {r.returncode}: {' | '.join(err)}") from None
    for rec in records:
        logging.getLogger(rec.name).handle(rec)
    if ok:
        return value
    cls, msg, attrs = value
    e = cls.__new__(cls)   # no __init__: ParameterError's takes (name, value, valid), not the message
    Exception.__init__(e, msg)
    for k, v in attrs.items():
        setattr(e, k, v)   # not __dict__: an OSError's errno and file name are descriptors
    raise e


def _log(gmsh) -> list[str]:
    """gmsh's log messages; [] if they cannot be decoded (gmsh's Python API decodes them as
    UTF-8: a binary file merged as .msh puts its bytes in them, and the UnicodeDecodeError
    replaced the one-line error on the file with a traceback)."""
    try:
        return list(gmsh.logger.get())
    except UnicodeDecodeError:
        return []


@contextlib.contextmanager
def _signals_kept():
    """Re-install Python's SIGINT / SIGTERM handlers after the block: gmsh's initialize puts
    its own C-level handlers in their place (Python still reports its own), so a SIGTERM
    killed the process outright, leaving its staging folder, instead of unwinding (cli)."""
    import signal
    import threading

    keep = {}
    if threading.current_thread() is threading.main_thread():
        keep = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in keep.items():
            if handler is not None:
                signal.signal(sig, handler)


def to_skfem(gmsh, dim: int, order: int, groups: dict[str, list[int]], cell: str = "tri"):
    """Read the current gmsh mesh into scikit-fem.

    groups: boundary name -> list of gmsh entity tags of dimension dim-1.
    cell: "tri" (simplices) or "quad" (2D quadrilaterals: MeshQuad1 / 9-node MeshQuad2;
    gmsh's quad9 order -- vertices, edges (0,1) (1,2) (2,3) (3,0), centre -- is scikit-fem's).
    Returns (mesh, boundaries).
    """
    import skfem

    tags, coords, _ = gmsh.model.mesh.getNodes()
    coords = coords.reshape(-1, 3)[:, :dim]
    etype = CELL_TYPE[(dim, order, "quad") if cell == "quad" else (dim, order)]
    etags, enodes = gmsh.model.mesh.getElementsByType(etype)
    nper = NODES[etype]
    if len(etags) == 0:
        raise MeshError(f"gmsh produced no {dim}D elements of order {order}")
    # contiguous node numbering 0..N-1 over the nodes the cells use (drops stray nodes)
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    conn = index[enodes.astype(np.int64)].reshape(-1, nper)
    used = np.unique(conn)
    renum = np.full(len(tags), -1, dtype=np.int64)
    renum[used] = np.arange(len(used))
    conn = renum[conn]
    points = coords[used]
    node_of_tag = np.full_like(index, -1)
    node_of_tag[tags.astype(np.int64)] = renum
    if etype == TET10:
        conn = conn[:, _TET10_GMSH_TO_SKFEM]
    conn = _orient_positive(points, conn, dim)

    cls = {(2, 1): skfem.MeshTri1, (2, 2): skfem.MeshTri2, (3, 1): skfem.MeshTet1,
           (3, 2): skfem.MeshTet2, (2, 1, "quad"): skfem.MeshQuad1,
           (2, 2, "quad"): skfem.MeshQuad2}[(dim, order, "quad") if cell == "quad" else (dim, order)]
    # scikit-fem puts vertex nodes first and renumbers them in order of np.unique; the
    # extra rows of t are assigned to its own edge dofs in refdom edge order.
    # sort_t=False: keep gmsh's (positively oriented) vertex order; MeshTri1 would sort it
    mesh = cls(np.ascontiguousarray(points.T), np.ascontiguousarray(conn.T), sort_t=False)
    nv = 4 if cell == "quad" else dim + 1
    vert_orig = np.unique(conn[:, :nv])           # original index of skfem vertex k
    boundaries = {}
    bfacets = mesh.boundary_facets()
    fkeys = {tuple(k): f for k, f in zip(np.sort(mesh.facets[:, bfacets], axis=0).T.tolist(), bfacets)}
    ftype = FACET_TYPE[(dim, order)]
    for name, ents in groups.items():
        found = []
        for ent in ents:
            types, _, fnodes = gmsh.model.mesh.getElements(dim - 1, ent)
            for ty, nodes in zip(types, fnodes):
                if ty != ftype:
                    continue
                nper_f = _nnodes(ty)
                verts = node_of_tag[nodes.astype(np.int64)].reshape(-1, nper_f)[:, :dim]
                if np.any(verts < 0):
                    raise MeshError(f"boundary '{name}': gmsh facet nodes that no cell uses")
                verts = np.searchsorted(vert_orig, verts)
                for key in np.sort(verts, axis=1).tolist():
                    f = fkeys.get(tuple(key))
                    if f is None:
                        raise InnerFacetError(name, ent)
                    found.append(f)
        if not found:
            raise MeshError(f"boundary '{name}' has no facets (gmsh entities {ents})")
        boundaries[name] = np.unique(np.asarray(found, dtype=np.int64))
    return mesh, boundaries


def _nnodes(gmsh_type: int) -> int:
    return {LINE2: 2, LINE3: 3, TRI3: 3, TRI6: 6}[gmsh_type]


def _orient_positive(points: np.ndarray, conn: np.ndarray, dim: int) -> np.ndarray:
    """Flip cells whose vertex ordering has a negative (straight-sided) Jacobian."""
    quad = conn.shape[1] in (4, 9) and dim == 2
    v = points[conn[:, : 4 if quad else dim + 1]]
    cols = [1, 3] if quad else list(range(1, dim + 1))  # quads: the Jacobian at vertex 0
    J = np.stack([v[:, i] - v[:, 0] for i in cols], axis=-1)
    neg = np.linalg.det(J) < 0
    if not np.any(neg):
        return conn
    conn = conn.copy()
    if quad:
        # reverse the vertex cycle 0 1 2 3 -> 0 3 2 1; edges (0,1)(1,2)(2,3)(3,0) -> old 3 2 1 0
        perm = np.array([0, 3, 2, 1, 7, 6, 5, 4, 8]) if conn.shape[1] == 9 else np.array([0, 3, 2, 1])
    elif dim == 2:
        # swap vertices 1<->2; edges (0,1) (1,2) (0,2) -> (0,2) (2,1) (0,1)
        perm = np.array([0, 2, 1, 5, 4, 3]) if conn.shape[1] == 6 else np.array([0, 2, 1])
    else:
        # swap vertices 1<->2; edges (0,1)(1,2)(0,2)(0,3)(1,3)(2,3) -> (0,2)(2,1)(0,1)(0,3)(2,3)(1,3)
        perm = np.array([0, 2, 1, 3, 6, 5, 4, 7, 9, 8]) if conn.shape[1] == 10 else np.array([0, 2, 1, 3])
    conn[neg] = conn[neg][:, perm]
    return conn


def shape_quality(gmsh, dim: int) -> dict:
    """Shape quality of the straight-sided (first-order) cells: gmsh's signed inverse
    condition number (1 for the equilateral simplex, 0 degenerate, < 0 inverted). gmsh's
    minSJ is identically 1 on straight simplices, so the curving is measured separately
    (skinmesh.jacobian_ratio)."""
    etags = np.concatenate([gmsh.model.mesh.getElementsByType(CELL_TYPE[k])[0]
                            for k in CELL_TYPE if k[0] == dim and k[1] == 1])
    q = np.asarray(gmsh.model.mesh.getElementQualities(etags, "minSICN"))
    return {"min_sicn": float(q.min()), "mean_sicn": float(q.mean()), "n_sicn_lt_0.2": int(np.sum(q < 0.2))}
