"""3D Braille on the flat pad meshes finely only at the dots (mesh.sizing.local_plan): balls at
each dot's contact point on the top y = t and at the bonded bottom y = 0 under it."""

import numpy as np
import pytest

from tactileskin.cache import cache_key
from tactileskin.geometry import braille
from tactileskin.mesh import build_mesh, sizing
from tactileskin.scene import Scene
from mesh_probe import edges_near

LOCAL = {"mesh_size": 1.2, "refinement": 4.0}  # fine 0.3 mm at the dot: ~1-5k cells, < 1 s


def _pad(text, t=1.0, **kw):
    return Scene(**{"skin": "pad", "dim": 3, "indenter": "braille", "thickness": t, "braille_text": text,
                    **LOCAL, **kw})


def test_single_dot_on_the_pad_is_fine_at_the_dot_and_coarse_far_away():
    t = 1.0
    sm = build_mesh(_pad(""))
    sizes = sm.sizes
    fine, coarse = sizes["fine"], sizes["coarse"]
    assert fine == pytest.approx(LOCAL["mesh_size"] / LOCAL["refinement"])
    assert sizes["strip"] == 0.0  # depth 0.2 mm < dot height 0.48 mm: the plate does not touch
    (x, y, z, r, h), = sizes["patches"]
    (xb, yb, zb, rb, hb), = sizes["bone_patches"]
    assert (x, y, z, h) == (0.0, t, 0.0, fine)          # the dot's contact point on the top
    assert (xb, yb, zb) == (0.0, 0.0, 0.0) and hb == fine  # the bonded bottom under it (t < dot diameter)
    # gmsh meets the field to ~20 % (Delaunay edges scatter around the target size); far from
    # the dot (z = 7 mm, ~4 mm beyond the ball's graded shell) the size is the coarse one,
    # capped by gmsh at about twice the skin thickness
    near_out, n_out = edges_near(sm, "outer_surface", (0, t, 0), 0.6)
    near_bone, n_bone = edges_near(sm, "bone_interface", (0, 0, 0), 1.0)
    far_out, _ = edges_near(sm, "outer_surface", (0, t, 7.0), 1.5)
    far_bone, _ = edges_near(sm, "bone_interface", (7.0, 0, 7.0), 1.5)
    assert near_out < 1.2 * fine and near_bone < 1.2 * hb and n_out > 5 and n_bone > 10
    assert far_out > 0.75 * min(coarse, 2 * t) and far_bone > 0.75 * min(coarse, 2 * t)
    # the strip plan refines the whole contact strip and 6 mm of the bonded bottom
    strip = build_mesh(_pad(""), local=False)
    assert strip.sizes["fine"] == fine and not strip.sizes["patches"]
    assert sm.mesh.nelements < 0.6 * strip.mesh.nelements
    r_est = sizes["estimate"] / sm.mesh.nelements
    assert 1.0 <= r_est <= 2.5, r_est  # the plan's estimate is on the upper side


def test_asymmetric_text_on_the_full_width_pad_is_fine_at_every_dot():
    t = 1.0
    sm = build_mesh(_pad("r"))  # dots 1, 2, 3 at x < 0, dot 5 at x > 0: the full width, z >= 0
    fine = sm.sizes["fine"]
    assert sm.mesh.p[0].min() < -5.0 and sm.z_symmetric
    xz = braille.dot_centres("r")
    inside = [(x, z) for x, z in xz if z >= 0]
    got = {(round(b[0], 6), round(b[2], 6)) for b in sm.sizes["patches"]}
    assert {(round(x, 6), round(z, 6)) for x, z in inside} == got  # dot 1 (z < 0) lies > a ball away
    for x, z in inside:
        near, n = edges_near(sm, "outer_surface", (x, t, z), 0.5)
        assert near < 1.2 * fine and n > 3, (x, z, near, n)
    # between the columns (x = 0) and beyond the cell the top is coarser than at the dots
    mid, _ = edges_near(sm, "outer_surface", (0.0, t, 6.0), 1.5)
    assert mid > 2.0 * fine


def test_plate_contact_on_a_thick_pad_refines_the_whole_top_at_the_strip_size():
    sc = _pad("", t=3.0)
    sec = sc.section()
    p = sizing.plan(sc, sec, dim=3, length=sec.length, z_symmetric=True, **LOCAL)
    # t = 3: depth 0.6 mm > dot height 0.48 mm: the base plate (>= 20 mm wide) presses the whole top
    assert sc.indentation > braille.get_standard("standard_american").height
    assert p.strip == pytest.approx(np.sqrt(p.fine * p.coarse)) and p.contact_x == pytest.approx(sec.half_width)
    # the bonded bottom's ball grows with t / dot diameter, centred at y = 0 under the dot
    assert p.bone_patches[0][1] == 0.0 and p.bone_patches[0][4] == pytest.approx(p.fine * 3.0 / 1.44)


def test_flat_indenters_on_the_pad_keep_the_strip_plan_and_the_local_plan_enters_the_cache_key():
    sc = Scene(skin="pad", dim=3, indenter="flat", thickness=1.0, **LOCAL)
    sec = sc.section()
    kw = dict(dim=3, length=sec.length, z_symmetric=True, **LOCAL)
    assert sizing.plan(sc, sec, **kw) == sizing.plan(sc, sec, local=False, **kw)
    from tactileskin.skins.pad import PadSkin

    assert PadSkin.cache_content(sc) == {}  # flat, curved ... keep their keys
    assert PadSkin.cache_content(_pad("")) == {"mesh_plan": "local"}
    assert cache_key(_pad("")) != cache_key(_pad("", dim=2))
