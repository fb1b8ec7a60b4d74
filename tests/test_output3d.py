"""3D bone-pressure profile: the nodal field on the section plane z = const (fe.output.plane_profile)."""

from types import SimpleNamespace

import numpy as np
import pytest

from tactileskin.errors import ParameterError
from tactileskin.fe import model_for_scene
from tactileskin.fe.output import plane_profile, profile_plane_z
from tactileskin.geometry.indenters import indenter_for_scene
from tactileskin.scene import Scene

PLANES = (0.0, 0.37, 1.0)  # the z-symmetry face, an interior plane cutting facets, the free end


@pytest.fixture(scope="module")
def slabs():
    """Two short slabs (t = 3 mm, 2 mm long, quarter model) at h = 1 and 0.5 mm."""
    from tactileskin.mesh.slab3d import build_slab_mesh

    out = []
    for h in (1.0, 0.5):
        sc = Scene(thickness=3, indenter="flat", dim=3, mesh_size=h, refinement=1)
        model, _ = model_for_scene(sc, build_slab_mesh(sc, length=2.0))
        out.append((h, model, sc.section()))
    return out


def _errors(model, section, f):
    X = model.basis.doflocs
    errs = []
    for z in PLANES:
        s, v = plane_profile(model, f(X), "bone_interface", section.s_of_point, z)
        assert np.all(np.diff(s) > 0) and s[0] < 1e-9 and s[-1] > section.interface_length - 0.5
        xy = section.point_at_s(s).reshape(len(s), 2)
        errs.append(np.abs(v - f(np.vstack([xy.T, np.full(len(s), z)]))).max())
    return np.array(errs)


def test_linear_field_reproduced_on_every_plane(slabs):
    # The isoparametric P2 facet reproduces a linear field exactly at its own points; what is
    # left is |grad f| (0.62) times the distance between the meshed (snapped P2) interface and
    # the true curve on which the reference values are taken, O(h^3): measured 7e-5 at h = 1.
    f = lambda X: 0.3 * X[0] - 0.2 * X[1] + 0.5 * X[2]  # noqa: E731
    for h, model, section in slabs:
        assert _errors(model, section, f).max() < 1e-4


def test_z_varying_field_converges_at_interpolation_order(slabs):
    # A smooth field varying along z: the error on each plane is the facet's P2 interpolation
    # error, O(h^3) (measured ratio 7 for h 1 -> 0.5). Mixing nodes from other z would not
    # converge at all (the field changes by ~0.2 between nodes one element apart in z).
    f = lambda X: np.sin(X[0]) * np.cos(0.7 * X[2]) + X[1]  # noqa: E731
    (_, m1, s1), (_, m2, s2) = slabs
    e1, e2 = _errors(m1, s1, f), _errors(m2, s2, f)
    assert e1.max() < 0.01
    assert np.all(e1 / e2 > 4.0)  # observed order >= 2 on every plane


def test_plane_outside_slab_is_an_error(slabs):
    _, model, section = slabs[0]
    with pytest.raises(ParameterError, match="profile plane z"):
        plane_profile(model, model.basis.doflocs[0], "bone_interface", section.s_of_point, 5.0)


@pytest.mark.parametrize("text, z", [("a", 0.0), ("\u283f", 0.0), ("b", 1.17), ("e", 1.17)])
def test_profile_plane_is_the_2d_section_row(text, z):
    # the 3D profile is taken where the 2D model cuts its section: the dot row nearest z = 0;
    # of two such rows the text's upper one, at z > 0 (braille.dot_centres: -z down the lines),
    # which a z-symmetric pattern's quarter model holds ('b'); 'e' (rows differ) is meshed whole
    sc = Scene(thickness=3, indenter="braille", braille_text=text, dim=3)
    model = SimpleNamespace(contact=SimpleNamespace(indenter=indenter_for_scene(sc)))
    assert profile_plane_z(model) == pytest.approx(z)
    flat = SimpleNamespace(contact=SimpleNamespace(indenter=indenter_for_scene(sc.replace(indenter="flat"))))
    assert profile_plane_z(flat) == 0.0


def test_make_result_3d_takes_the_section_plane(slabs):
    # unloaded state (zero pressure): what is checked is the 3D path of make_result, i.e. the
    # profile comes from plane_profile on the default plane and the plane is recorded
    from tactileskin.fe import make_result
    from tactileskin.fe.solver import Stats

    _, model, section = slabs[0]
    ev = model.evaluate(model.u, 0.0, 0.0)
    res = make_result(model, ev, Stats(), s_of_point=section.s_of_point)
    s_ref, _ = plane_profile(model, model.basis.doflocs[0], "bone_interface", section.s_of_point, 0.0)
    np.testing.assert_array_equal(res.s, s_ref)
    assert res.stats["profile_plane_z"] == 0.0 and res.summary()["profile_plane_z"] == 0.0
    assert np.all(res.pressure == 0.0)
