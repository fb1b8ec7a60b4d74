"""A custom Braille word indenter, printable, with its mounting stem.

Builds the word "Skin" (Grade 1, Standard American cell) as spherical-cap dots on a base
plate, writes STL + STEP + manifest.json into OUT_DIR (default: a temporary folder), and
measures the dots on the exported STL: their count, the deepest dot height below the plate
and the plate's base plane.

    python examples/braille_word_indenter.py [OUT_DIR]

"Skin" is the capital sign (dot 6) + s (2,3,4) + k (1,3) + i (2,4) + n (1,3,4,5): 12 dots.
Each dot is a cap of base 1.44 mm and height 0.48 mm (NLS Spec. 800).

EXPECT dots 12 12
EXPECT dot_height_mm 0.46 0.50
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import trimesh

from tactileskin.geometry.export import export_parts
from tactileskin.geometry.parts import build_parts

WORD = "Skin"


def main(out: Path) -> None:
    parts = build_parts(3.0, indenters="braille", braille_text=WORD, fingertip=False, molds=False)
    manifest = export_parts(parts, out / "skin_word")
    entry = manifest["parts"][0]
    mesh = trimesh.load(out / "skin_word" / entry["stl"], force="mesh")

    # Measure on the mesh: facets facing the skin (-y); the base plane is the highest of them,
    # the dots are the connected patches below it.
    down = np.flatnonzero(mesh.face_normals[:, 1] < -1e-3)
    y = mesh.vertices[mesh.faces[down]][:, :, 1]
    base = y.max()
    cap = set(down[(y < base - 1e-6).any(axis=1)].tolist())
    adjacency = [(i, j) for i, j in mesh.face_adjacency if i in cap and j in cap]
    dots = trimesh.graph.connected_components(adjacency, nodes=np.array(sorted(cap)), min_len=1)
    height = base - mesh.vertices[:, 1].min()

    print(f"{entry['description']}: {entry['stl']}, {entry['volume_mm3']:.1f} mm^3, "
          f"{entry['triangles']} triangles, watertight {entry['watertight']}")
    print(f"RESULT dots={len(dots)}")
    print(f"RESULT dot_height_mm={height:.4f}")


if __name__ == "__main__":
    if len(sys.argv) > 1:
        main(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as d:
            main(Path(d))
