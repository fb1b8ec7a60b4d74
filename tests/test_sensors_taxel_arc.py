"""A taxel's side is the chip's: arc length on its own depth surface, not the bone's arc length
(at t = 5 mm, depth 2.5 mm, s = 4 mm a '2 mm' taxel spanned 6.4 mm of its plane)."""

import numpy as np
import pytest

from tactileskin import sensors
from tactileskin.scene import Scene


def _arc(coords, s0, s1, depth):
    ss = np.linspace(s0, s1, 4001)
    p = coords.frame(ss, np.full(ss.shape, depth))[0]
    return float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))


@pytest.mark.parametrize("t,depth,s", [(5.0, 2.5, 4.0), (3.0, 0.0, 2.0), (3.0, 3.0, 2.0), (1.0, 0.5, 0.0)])
def test_taxel_samples_span_its_side_on_the_depth_surface(t, depth, s):
    coords = sensors.coordinates_for(Scene(thickness=t))
    lay = sensors.SensorLayout.from_dict({"name": "a", "s": [s], "depth": depth, "taxel": 2.0, "taxel_points": 5})
    sites = sensors.resolve([lay], coords, 2)
    g = np.polynomial.legendre.leggauss(5)[0]
    # the outer Gauss points sit at +-g_max * side/2 of arc length from the centre
    pts = sites.samples[0, :5, :2]
    centre = sites.xyz[0, :2]
    arc_lo = _arc(coords, float(sensors.taxel_s(coords, [s], depth, [g[0]], 2.0)[0, 0]), s, depth)
    assert arc_lo == pytest.approx(-g[0] * 1.0, rel=2e-3)
    # every Gauss point at its arc length from the centre (the chord, within 2 %)
    assert np.allclose(np.sort(np.hypot(*(pts - centre).T)), np.sort(np.abs(g)), rtol=0.02, atol=1e-9)
    assert sites.weights[0, :5] == pytest.approx(np.polynomial.legendre.leggauss(5)[1] / 2)


def test_a_taxel_near_the_nail_end_is_judged_by_its_physical_side():
    coords = sensors.coordinates_for(Scene(thickness=5.0))
    lim = coords.s_limit(2.5)
    # at depth 2.5 mm the surface is ~3x longer than the bone there: a 2 mm chip 0.5 mm of bone
    # arc inside the end fits (it was refused, its side read in the bone's arc), one 0.1 mm does not
    fits = sensors.SensorLayout.from_dict({"name": "a", "s": [lim - 0.5], "depth": 2.5, "taxel": 2.0})
    sensors.resolve([fits], coords, 2)
    over = sensors.SensorLayout.from_dict({"name": "a", "s": [lim - 0.1], "depth": 2.5, "taxel": 2.0})
    with pytest.raises(Exception, match="taxel"):
        sensors.resolve([over], coords, 2)


@pytest.mark.parametrize("t,depth", [(3.0, 1.0), (5.0, 2.5), (3.0, 0.0)])
def test_the_side_and_edge_checks_take_one_surface_length(t, depth):
    """The side check said the surface at depth 1 mm (t = 3) is 27.1047 mm long, the edge
    check refused a centred taxel from 27.0794 mm (its own coarser arc table): a side the
    message called valid was refused. Both now measure one table of the surface."""
    coords = sensors.coordinates_for(Scene(thickness=t))
    lim = coords.s_limit(depth)
    arc = _arc(coords, -lim, lim, depth)  # the surface's polyline, independently of sensors.py

    def fits(s, side):
        lay = sensors.SensorLayout.from_dict({"name": "a", "s": [s], "depth": depth, "taxel": float(side)})
        try:
            sensors.resolve([lay], coords, 2)
        except Exception as e:
            assert "taxel" in str(e)
            return False
        return True

    with pytest.raises(Exception, match=r"valid: \(0, ([\d.]+)\] mm") as e:
        sensors.resolve([sensors.SensorLayout.from_dict({"name": "a", "s": [0.0], "depth": depth,
                                                        "taxel": 1e3})], coords, 2)
    stated = float(str(e.value).split("valid: (0, ")[1].split("]")[0])
    assert stated == pytest.approx(arc, abs=2e-4)
    assert fits(0.0, stated - 1e-3) and not fits(0.0, stated + 1e-3)
    # off centre: the edge nearer the end decides, at the surface's own arc from the centre
    s = 0.4 * lim
    room = 2 * _arc(coords, s, lim, depth)
    assert fits(s, room - 1e-3) and not fits(s, room + 1e-3)


@pytest.mark.parametrize("t", [1.0, 3.0, 5.0])
def test_the_surface_arc_table_is_within_its_stated_bound(t):
    """_surface_arc is within 1e-4 mm of the polyline, as it says: on 401 points it was 1.7e-4 mm
    short over the whole contact surface at t = 5 (2.2e-4 mm part way along it)."""
    coords = sensors.coordinates_for(Scene(thickness=t))
    for depth in np.linspace(0.0, t, 5):
        lim = coords.s_limit(depth)
        S, A = sensors._surface_arc(coords, depth, lim)
        for s in np.linspace(-lim, lim, 9)[1:]:
            assert np.interp(s, S, A) == pytest.approx(_arc(coords, -lim, s, depth), abs=1e-4), (depth, s)
