"""The flat pad meshes its full width when the indenter is not mirror-symmetric about x = 0
(a half model with a symmetry plane would solve the mirrored indenter too)."""

import numpy as np
import pytest

from tactileskin.cache import cache_key
from tactileskin.fe import solve
from tactileskin.geometry.braille import dot_centres
from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene

W, L = 8.0, 8.0


def _pad(text, **kw):
    base = dict(skin="pad", pad_width=W, pad_length=L, thickness=1.0, indenter="braille", braille_text=text,
                viscoelastic=False)
    return Scene(**{**base, **kw})


def test_asymmetric_text_meshes_the_full_width_and_a_symmetric_one_the_half():
    # 'r' = dots 1,2,3,5: three dots at x < 0, one at x > 0 (symmetric in z only)
    assert not np.allclose(np.sort(dot_centres("r")[:, 0]), np.sort(-dot_centres("r")[:, 0]))
    full = build_mesh(_pad("r", dim=3, mesh_size=2.0, refinement=1.0))
    half = build_mesh(_pad("⠿", dim=3, mesh_size=2.0, refinement=1.0))
    x_full, x_half = full.mesh.p[0], half.mesh.p[0]
    assert x_full.min() == pytest.approx(-W / 2, abs=1e-12) and x_full.max() == pytest.approx(W / 2, abs=1e-12)
    assert x_half.min() == pytest.approx(0.0, abs=1e-12) and x_half.max() == pytest.approx(W / 2, abs=1e-12)
    assert "symmetry" not in full.boundaries and "symmetry" in half.boundaries
    # both are z-symmetric: z in [0, L/2]; the full model's two free sides are `side`
    assert full.z_symmetric and half.z_symmetric
    assert full.measure() == pytest.approx(W * 1.0 * L / 2, rel=1e-12)
    assert full.boundary_measure("side") == pytest.approx(2 * 1.0 * L / 2, rel=1e-12)
    assert full.boundary_measure("bone_interface") == pytest.approx(W * L / 2, rel=1e-12)
    assert half.measure() == pytest.approx(W / 2 * 1.0 * L / 2, rel=1e-12)


def test_full_width_enters_the_cache_key_of_asymmetric_scenes_only():
    sym = _pad("⠿", dim=3)
    from tactileskin.skins.pad import PadSkin

    assert PadSkin.cache_content(_pad("⠿", dim=2)) == {}  # symmetric scenes keep their keys
    # (3D Braille adds the local mesh plan's tag, tests/test_pad_local_mesh.py)
    assert PadSkin.cache_content(sym) == {"mesh_plan": "local"}
    assert PadSkin.cache_content(_pad("r", dim=3)) == {"model": "full_width", "mesh_plan": "local"}
    assert cache_key(_pad("r", dim=3)) != cache_key(_pad("r", dim=3, braille_text="⠿"))


def test_full_width_2d_solve_equals_the_mirrored_half_model():
    """'r' and the full cell cut the same 2D section (row z = 0: dots 2 and 5 at x = -+1.25),
    but 'r' is x-asymmetric as a pattern, so it is solved on the full width without a
    symmetry line: its profile must be even in s and equal the half model's mirrored (same
    sizes; the two meshes differ, so to the discretisation error)."""
    kw = dict(mesh_size=0.4, refinement=3.0)
    rf = solve(_pad("r", **kw))
    rh = solve(_pad("⠿", **kw))
    assert rf.s.min() == pytest.approx(-W / 2) and rh.s.min() == pytest.approx(0.0)
    peak = float(np.max(rh.pressure))
    s = np.linspace(0.0, 3.0, 121)  # a thickness short of the free side's corner (x = 4)
    left, right = np.interp(-s, rf.s, rf.pressure), np.interp(s, rf.s, rf.pressure)
    half = np.interp(s, rh.s, rh.pressure)
    # different triangulations of the same body: the peak of the dot (base radius 0.72 mm over
    # ~0.13 mm elements) is resolved to ~1 %; 3 % of the peak leaves room for the mesh only
    assert np.max(np.abs(left - right)) < 0.03 * peak
    assert np.max(np.abs(right - half)) < 0.03 * peak
    # the whole model reports per mm of the half section, like the half model: half its force,
    # half its profile's extent and area
    assert rf.reaction == pytest.approx(rh.reaction, rel=0.03)
    assert rf.sides == 2 and rh.sides == 1
    assert rf.span == pytest.approx(rh.span, rel=0.03)
    assert rf.auc == pytest.approx(rh.auc, rel=0.03)


def test_sensors_on_a_whole_pad_read_each_side_not_its_mirror():
    """'i' cuts a 2D section pressed on one side (its bone peak at s = +1.13 mm): the pad is
    modelled whole. Bone sensors at s = -1.17 and +1.17 read the profile at their own side,
    where x < 0 used to be sampled at its mirror image: the peak side, twice."""
    sens = [{"name": "bone", "s": [-1.17, 1.17], "height": 0.0}]
    r = solve(_pad("i", mesh_size=0.4, refinement=3.0, sensors=sens))
    assert r.sides == 2
    p = r.sensors.select("bone").pressure
    # between the profile's nodes: linear interpolation of its samples against the quadratic
    # field the sensors read (0.3 % apart here), so 1 %; the mirrored read was 100x off
    want = np.interp([-1.17, 1.17], r.s, r.pressure)
    assert p == pytest.approx(want, rel=1e-2)
    assert p[1] > 20 * p[0]                                    # the far side reads low, not the peak
