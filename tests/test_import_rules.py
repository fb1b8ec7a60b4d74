"""The solver core must not import CAD, meshing or rendering libraries (design rule)."""

import subprocess
import sys

import pytest

HEAVY = ("build123d", "OCP", "gmsh", "pyvista", "vtk", "matplotlib")

CORE = ["tactileskin.scene", "tactileskin.geometry.fingertip", "tactileskin.sweep",
        "tactileskin.discrimination"]
LATER = ["tactileskin.materials", "tactileskin.fe", "tactileskin.results",
         "tactileskin.geometry.indenters", "tactileskin.geometry.braille"]


def _imports(module):
    code = (f"import sys, {module}; print(','.join(m for m in {HEAVY!r} if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout.strip()


@pytest.mark.parametrize("module", CORE + LATER)
def test_core_stays_light(module):
    assert _imports(module) == ""
