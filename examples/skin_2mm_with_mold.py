"""A 2 mm skin with its two-part casting mold, and a check that the mold casts that skin.

Writes the skin, the rigid base (the mold's core), the mold's lower and upper halves
(STL + STEP + manifest.json) into OUT_DIR (default: a temporary folder). Then, on the
exported STL files, assembles the mold with its core and measures the void left inside
the sample's box: it must be the skin's volume plus the designed gap around the printed
core (molds.toml [core] clearance: a printer cannot make an exact fit; the gap is a thin
flash to trim after demolding).

    python examples/skin_2mm_with_mold.py [OUT_DIR]

By hand: the half-section of a 2 mm shell under a 15.6 mm outer arc and an 11.5 mm bone
interface has an area of about 2 x (15.6 + 11.5) / 2 = 27 mm^2; both halves over the 20 mm
sample give about 1084 mm^3 (fingertip.Section.area gives 27.10 mm^2).

EXPECT skin_volume_mm3 1050 1120
EXPECT cavity_over_skin 1.0 1.03
EXPECT cavity_less_gap_over_skin 0.995 1.005
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import manifold3d
import numpy as np
import trimesh

from tactileskin.geometry import molds, solids
from tactileskin.geometry.export import export_parts, write_stl
from tactileskin.geometry.fingertip import Fingertip, Section
from tactileskin.geometry.parts import build_parts


def solid(path: Path) -> manifold3d.Manifold:
    m = trimesh.load(path, force="mesh")
    return manifold3d.Manifold(manifold3d.Mesh64(vert_properties=np.asarray(m.vertices, np.float64),
                                                 tri_verts=np.asarray(m.faces, np.uint64)))


def main(out: Path) -> None:
    folder = out / "skin_2mm"
    manifest = export_parts(build_parts(2.0, indenters="none"), folder, meta={"thickness": 2.0})
    for e in manifest["parts"]:
        print(f"{e['name']:11s} {e['volume_mm3']:9.1f} mm^3  {e['description']}")

    ft = Fingertip.from_params()
    a, b, half = ft.half_width, ft.height, ft.sample_length / 2
    box = manifold3d.Manifold.cube([2 * a, 2 * b, 2 * half]).translate([-a, -b, -half])
    cavity = box - solid(folder / "mold_lower.stl") - solid(folder / "mold_upper.stl") \
        - solid(folder / "rigid_base.stl")
    skin = solid(folder / "skin.stl")
    print(f"RESULT skin_volume_mm3={skin.volume():.2f}")
    print(f"RESULT cavity_over_skin={cavity.volume() / skin.volume():.5f}")
    # the core's clearance gap inside the box: the room its seat leaves, less the core and
    # the skin (the seat reaches past the nail edges for the core's corners)
    c = molds.MoldParams.from_params().core_clearance
    seat = solids._single(molds.core_seat(Section(ft, 2.0), c).intersect(
        solids.box(-a - 1, a + 1, -b - 1, b + 1, -half, half)))
    write_stl(seat, out / "core_seat.stl")
    gap = (solid(out / "core_seat.stl") - solid(folder / "rigid_base.stl") - skin).volume()
    print(f"core clearance {c:g} mm: gap {gap:.1f} mm^3")
    print(f"RESULT cavity_less_gap_over_skin={(cavity.volume() - gap) / skin.volume():.5f}")


if __name__ == "__main__":
    if len(sys.argv) > 1:
        main(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as d:
            main(Path(d))
