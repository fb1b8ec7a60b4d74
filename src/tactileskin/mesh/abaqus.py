"""Abaqus / CalculiX input deck of the skin mesh: nodes, continuum elements, node sets.

Written directly rather than through meshio, whose Abaqus writer maps triangle6 / quad9 /
tetra10 to CPE6 / S9R5 (a shell) / C3D10MH and writes boundary facets as beam elements
(B33H). Here: plane-strain CPE3/CPE6/CPE4/CPE8 in 2D (quad9 is written as its 8-node
serendipity part, CPE8; Abaqus has no 9-node continuum element), C3D4/C3D10 in 3D, one
*ELSET "skin", and one *NSET per named boundary (all nodes of its facets).
"""

from __future__ import annotations

import io

import numpy as np

_TYPES = {"triangle": ("CPE3", 3), "triangle6": ("CPE6", 6), "quad": ("CPE4", 4),
          "quad9": ("CPE8", 8), "tetra": ("C3D4", 4), "tetra10": ("C3D10", 10)}


def _rows(fh, ids: np.ndarray, per_line: int = 16) -> None:
    for i in range(0, len(ids), per_line):
        fh.write(", ".join(str(int(k)) for k in ids[i:i + per_line]) + "\n")


def inp_text(points: np.ndarray, cell_type: str, cells: np.ndarray, node_sets: dict[str, np.ndarray]) -> str:
    """The deck as text; points (n, 2|3), cells (m, k) 0-based in meshio node order."""
    etype, k = _TYPES[cell_type]
    fh = io.StringIO()
    fh.write("*HEADING\ntactileskin skin mesh (units mm)\n*NODE, NSET=NALL\n")
    for i, p in enumerate(points):
        fh.write(f"{i + 1}, " + ", ".join(f"{c:.15g}" for c in p) + "\n")
    fh.write(f"*ELEMENT, TYPE={etype}, ELSET=skin\n")
    for i, c in enumerate(cells[:, :k]):
        fh.write(f"{i + 1}, " + ", ".join(str(int(n) + 1) for n in c) + "\n")
    for name, nodes in node_sets.items():
        fh.write(f"*NSET, NSET={name}\n")
        _rows(fh, np.asarray(nodes) + 1)
    return fh.getvalue()


def read_inp_sets(text: str) -> tuple[np.ndarray, str, np.ndarray, dict[str, np.ndarray]]:
    """Parse a deck written by `inp_text` (for round-trip tests): points, element type,
    cells (0-based), node sets (0-based)."""
    pts, cells, sets, etype = [], [], {}, None
    mode, name = None, None
    for line in text.splitlines():
        if line.startswith("*"):
            kw = line.upper()
            if kw.startswith("*NODE"):
                mode = "node"
            elif kw.startswith("*ELEMENT"):
                mode, etype = "elem", line.split("TYPE=")[1].split(",")[0].strip()
            elif kw.startswith("*NSET"):
                mode, name = "nset", line.split("NSET=")[1].strip()
                sets[name] = []
            else:
                mode = None
            continue
        vals = [v for v in line.split(",") if v.strip()]
        if mode == "node":
            pts.append([float(v) for v in vals[1:]])
        elif mode == "elem":
            cells.append([int(v) - 1 for v in vals[1:]])
        elif mode == "nset":
            sets[name].extend(int(v) - 1 for v in vals)
    return np.array(pts), etype, np.array(cells), {k: np.array(v) for k, v in sets.items()}
