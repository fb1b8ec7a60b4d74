"""result.vtu for ParaView: reference mesh + displacement, units in names, boundary names,
and result.pvd (a time series of the increments) when the history is asked for."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from tactileskin.fe import solve
from tactileskin.mesh import build_mesh
from tactileskin.planner import with_quality
from tactileskin.scene import Scene

SCENE = with_quality(Scene(thickness=1.0, material="silicone", indenter="flat"), "preview")


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    res = solve(SCENE, history=True)
    return res, res.write(tmp_path_factory.mktemp("vtu") / "r")


def test_points_are_the_reference_mesh_and_displacement_gives_the_deformed_one(written):
    res, out = written
    m = meshio.read(out / "result.vtu")
    X, u = m.points, m.point_data["displacement_mm"]
    # the undeformed outer top at x = 0 is the skin's top (bone top + t); the flat plate
    # pushes it down by the depth, to within the contact tolerance (1e-4 mm penetration)
    # and the solver's tolerance; a file with deformed points would show the top moved twice
    top = np.argmax(X[:, 1])
    assert abs(X[top, 0]) < 1e-9
    assert -u[top, 1] == pytest.approx(SCENE.indentation, abs=5e-4)
    # the bone interface is clamped: zero displacement on its nodes
    bone = m.cell_data_dict["boundary_id"]["line"] == _ids(out)["bone_interface"]
    nodes = np.unique(m.cells_dict["line"][bone])
    assert np.abs(u[nodes]).max() < 1e-12


def _ids(out) -> dict:
    root = ET.parse(out / "result.vtu").getroot()
    return {a.get("Name"): int(a.text.split()[0]) for a in root.iter("DataArray")
            if a.get("NumberOfTuples") == "1" and a.get("type") == "Int32"}


def test_boundaries_keep_their_names_and_fields_their_units(written):
    res, out = written
    m = meshio.read(out / "result.vtu")
    sm = build_mesh(SCENE)
    ids = _ids(out)
    assert set(ids) == set(sm.boundaries)
    bid = m.cell_data_dict["boundary_id"]
    assert (bid["triangle6"] == 0).all()
    for name, facets in sm.boundaries.items():  # one line cell per facet of the named boundary
        assert np.count_nonzero(bid["line"] == ids[name]) == len(facets)
    assert {"pressure_MPa", "displacement_mm", "sxx_MPa"} <= set(m.point_data)


def test_history_is_a_pvd_time_series_ending_in_the_final_state(written):
    res, out = written
    root = ET.parse(out / "result.pvd").getroot()
    sets = list(root.iter("DataSet"))
    t = [float(d.get("timestep")) for d in sets]
    assert len(sets) == res.stats["increments"] and np.all(np.diff(t) > 0)
    assert t[-1] == pytest.approx(SCENE.duration)
    last = meshio.read(out / sets[-1].get("file"))
    final = meshio.read(out / "result.vtu")
    np.testing.assert_array_equal(last.point_data["displacement_mm"], final.point_data["displacement_mm"])
    np.testing.assert_array_equal(last.points, final.points)


def test_a_write_without_history_removes_the_time_series(written, tmp_path):
    res, out = written
    d = res.write(tmp_path / "x")
    assert (d / "result.pvd").is_file()
    res.fields = {k: v for k, v in res.fields.items() if k != "steps"}
    res.write(d)
    assert not (d / "result.pvd").exists() and not (d / "result_steps").exists()


def test_contact_pressure_on_the_outer_surface_integrates_to_the_reaction(written):
    """contact_pressure_MPa is a facet field of the outer_surface cells (zero elsewhere), the
    contact force per reference area: summed over the facets times their (reference) length
    it is the force on the plate. The flat plate's normal is vertical, so that force is the
    vertical reaction of the supports (equilibrium; plane strain: N per mm)."""
    res, out = written
    m = meshio.read(out / "result.vtu")
    ids = _ids(out)
    bid = m.cell_data_dict["boundary_id"]["line"]
    cp = m.cell_data_dict["contact_pressure_MPa"]
    assert (cp["triangle6"] == 0).all()
    line_p = cp["line"]
    outer = bid == ids["outer_surface"]
    assert (line_p[~outer] == 0).all() and (line_p[outer] >= 0).all() and line_p[outer].max() > 0
    conn = m.cells_dict["line"][outer]
    chord = np.linalg.norm(m.points[conn[:, 1]] - m.points[conn[:, 0]], axis=1)
    force = float(np.sum(chord * line_p[outer]))
    # the cells are the facets' straight chords and the multipliers sit on the P2 facets'
    # quadrature points: the two lengths differ by (h kappa)^2 / 24 < 1e-3 for h <= 0.6 mm on
    # radii >= 4 mm; equilibrium holds to the Newton tolerance (far below)
    assert force == pytest.approx(abs(res.reaction), rel=1e-3)
    # the peak facet value is of the order of contact.csv's pressure (per current area,
    # at points, not averaged): within 30 %
    assert line_p.max() == pytest.approx(res.contact_pressure.max(), rel=0.3)
    # the increments of result.pvd carry the displacement only
    step = meshio.read(next((out / "result_steps").glob("step_*.vtu")))
    assert "contact_pressure_MPa" not in step.cell_data
