"""`--sensor-depth`: the chart's taxels at a depth below the contact surface, their maps read
from each cached solve's result.vtu (fe.probe.result_sampler), as a sensor layout at that
depth reads them, instead of the bone maps only."""

from pathlib import Path
from types import SimpleNamespace

import meshio
import numpy as np
import pytest
import skfem

from tactileskin.array import chart, maps, validity
from tactileskin.cli import main
from tactileskin.errors import ParameterError
from tactileskin.scene import Scene

# coarse 2D fingertip (about 1 s per solve), as tests/test_sensors.py
COARSE = dict(thickness=3.0, indenter="curved", mesh_size=0.5, refinement=2)
DEPTH = 1.25


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    """The chart's kind of solve (no sensors) written as the cache holds it, and the same scene
    solved with a sensor line at DEPTH: what the solver's own sensors read there."""
    from tactileskin.fe import solve

    plain = Scene(**COARSE)
    res = solve(plain)
    path = tmp_path_factory.mktemp("case")
    res.write(path)
    line = {"name": "d", "kind": "line", "s": [0, 6], "pitch": 0.1, "depth": DEPTH}
    read = solve(Scene(**COARSE, sensors=[line])).sensors.select("d")
    return SimpleNamespace(scene=plain, path=path, s=res.s, pressure=res.pressure), read


def test_a_cached_2d_solve_read_at_depth_is_what_a_sensor_line_there_reads(solved):
    rec, line = solved
    s, P = chart._at_depth(rec, line.s, None, DEPTH)
    # the same nodal stresses, interpolated in the same elements: equal to round-off
    assert np.allclose(P, line.pressure, rtol=0, atol=1e-9 * line.pressure.max())
    # s is the arc length on the depth surface: on this convex section it is longer than the
    # bone's arc length by the depth surface's own polyline
    from tactileskin.sensors import coordinates_for

    fine = np.linspace(0, 6, 6001)
    pts = coordinates_for(rec.scene).frame(fine, np.full(fine.size, DEPTH))[0]
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    assert np.allclose(s, np.interp(line.s, fine, arc), atol=1e-5)
    assert s[-1] > 6.0 * 1.05
    # at the bonded surface the same reading is the solve's bone profile
    sb, Pb = chart.profile_of(rec, COARSE["thickness"] - 1e-12)
    assert np.allclose(Pb, rec.pressure, rtol=0, atol=1e-9 * rec.pressure.max())
    assert np.allclose(sb, rec.s, atol=1e-9)
    assert chart.profile_of(rec) == (rec.s, rec.pressure)  # no depth: the bone profile itself


def test_a_3d_map_at_depth_follows_the_z_rows_of_the_bone_map(tmp_path):
    """A 3D result.vtu (as fe.output writes it) of a linear stress field on a P2 mesh of the
    pad: the map at depth is that field on the plane y = t - d, row j at z_j (the bone map's
    z-major layout), exactly (P2 holds a linear field)."""
    t = 1.0
    rec, _ = _linear_pad(tmp_path, t)
    s, zg = np.linspace(0, 3, 7), np.linspace(0, 2, 5)
    d = 0.3
    sa, P = chart._at_depth(rec, s, zg, d)
    S, Z = np.meshgrid(s, zg)
    exact = (1 + S + 2 * (t - d) + 3 * Z + 2 - (t - d) + 0.5 + Z) / 3
    assert np.array_equal(sa, s)  # flat: s stays x
    assert P.shape == (zg.size, s.size) and np.allclose(P, exact, atol=1e-12)


def test_the_chart_reads_every_map_at_the_sensor_depth(monkeypatch):
    """compute() with sensor_depth: every solve's map (the dots, the 2D sections) is read at
    that depth, the half-space comparison is at that depth, and the letters, whose surrogate
    was validated on the bone only, are not shown as validated there."""
    grid = np.linspace(-8, 8, 161)
    width = {"flat": 3.0, "curved": 1.5, "braille": 0.4}

    def fake_solve(scenes, cache, on_event=None, workers=None):
        return {sc: SimpleNamespace(s=grid, pressure=np.exp(-grid ** 2 / width[sc.indenter] ** 2), scene=sc,
                                    path=Path("unread"), summary={"reaction_n_per_mm": float(sc.indentation) ** 1.5})
                for sc in scenes}

    read = []

    def at_depth(rec, s, z, depth):  # the map a depth reading gives: wider than the bone's
        read.append((rec.scene.dim, rec.scene.indenter, depth))
        w = 1.5 * width[rec.scene.indenter]
        if z is None:
            return s, np.exp(-s ** 2 / w ** 2)
        S, Z = np.meshgrid(s, z)
        return s, np.exp(-(S ** 2 + Z ** 2) / w ** 2)

    monkeypatch.setattr(chart, "solve_cached", fake_solve)
    monkeypatch.setattr(chart, "read_bone_map", lambda path: maps.on_grid(lambda s, z: 0 * s, grid[80:], grid[80:]))
    monkeypatch.setattr(chart, "_at_depth", at_depth)
    monkeypatch.setattr(chart, "surface_deflection", lambda rec, top: lambda dx, dz: 0.0 * np.asarray(dx))
    cfg = chart.ChartConfig(thicknesses=(1.0,), sets=("paper", "letters"), letters="abl", pitches=(0.5,),
                            noise_fs=(0.01,), n_train=4, n_test=4, template_grid=2, sensor_depth=0.4)
    ch = chart.compute(cfg, cache=None)
    assert sorted(set(read)) == [(2, "curved", 0.4), (2, "flat", 0.4), (3, "braille", 0.4)]
    # accuracies.csv read on its own names the plane: 0.4 mm, not the bonded surface's depth t
    import csv
    import io

    got = list(csv.DictReader(io.StringIO(ch.to_csv())))
    assert got and {r["sensor_depth_mm"] for r in got} == {"0.4"}
    assert len([r for r in read if r[0] == 3]) == 2  # the pad's dot and the fingertip's
    (c,) = {c["halfspace_nyquist_pitch_mm"] for c in ch.cutoffs}
    from tactileskin.array import halfspace

    assert c == pytest.approx(halfspace.nyquist_pitch(0.4)) and c != pytest.approx(halfspace.nyquist_pitch(1.0))
    # the project's measurements are bone maps: at 0.4 mm the letters are not validated ...
    assert chart.surrogate_trust(cfg, "silicone", 1.0, "interaction")["status"] == "not validated"
    # ... unless this run validated them at that depth
    row = {"material": "silicone", "thickness_mm": 1.0, "depth_mm": 0.2, "text": "l", "model": "interaction",
           "taxel_mm": 0.4, "max_abs_over_peak_taxel": 0.02}
    assert chart.surrogate_trust(cfg, "silicone", 1.0, "interaction", [row])["status"] == "not validated"
    assert chart.surrogate_trust(cfg, "silicone", 1.0, "interaction",
                                 [{**row, "sensor_depth_mm": 0.4}])["status"] == "within"
    # and a bone chart does not take a row read at a depth
    assert validity.measured("silicone", "pad", cfg.mesh_for(1.0), 1.0, 0.2, [{**row, "sensor_depth_mm": 0.4}],
                             model="interaction", taxel=0.4)["source"] != validity.RUN_SOURCE
    from tactileskin.report.array_chart import markdown

    md = markdown(ch)
    assert "Sensor plane: 0.4 mm below the contact surface (`--sensor-depth`; t - 0.4 mm above the bone" in md
    assert "half-space Nyquist pitch at depth 0.4 mm (mm)" in md
    assert "flat and curved: 2D profiles at that depth extruded along z" in md


@pytest.mark.parametrize("value, words", [
    (0.0, ["sensor_depth (--sensor-depth)=0.0", "(0, 1) mm below the contact surface"]),
    (1.0, ["sensor_depth (--sensor-depth)=1.0", "(0, 1) mm", "the thinnest skin is 1 mm"]),
    (2.0, ["sensor_depth (--sensor-depth)=2.0", "(0, 1) mm"]),
    (float("nan"), ["sensor_depth (--sensor-depth)=nan"]),
])
def test_a_sensor_depth_outside_every_skin_is_one_line_before_any_solve(tmp_path, capsys, monkeypatch, value, words):
    def refuse(*a, **k):
        raise AssertionError("the chart started solving")

    monkeypatch.setattr(chart, "compute", refuse)
    out = tmp_path / "o"
    assert main(["array", "-o", str(out), "--set", "paper", "-t", "1,3", "--sensor-depth", str(value)]) == 2
    raw = capsys.readouterr().err
    err = " ".join(raw.split())
    assert raw.startswith("error:") and all(w in err for w in words) and "Traceback" not in err, err
    assert not out.exists()
    with pytest.raises(ParameterError, match="sensor_depth"):
        chart.ChartConfig(thicknesses=(1.0, 3.0), sets=("paper",), sensor_depth=value)


def test_the_pitch_help_does_not_put_every_lattice_on_the_bonded_surface():
    """--pitch's help said the lattice lies on the bonded surface, which --sensor-depth moves."""
    from click.testing import CliRunner

    from tactileskin.cli.array import command

    text = " ".join(CliRunner().invoke(command, ["--help"], terminal_width=200).output.split())
    pitch = text.split("--pitch TEXT")[1].split("--noise TEXT")[0]
    assert "--sensor-depth" in pitch, pitch


# --- --sensor-height: a sensor sheet at a fixed height above the bonded surface ----------------

def _linear_pad(path, t):
    """A 3D pad result (result.vtu of a linear stress field on P2, exact there) and its
    bone_map.csv (the field on y = 0); returns the record and P(x, y, z) = -tr(sigma) / 3."""
    from tactileskin.results import BoneMap

    m = skfem.MeshTet1.init_tensor(np.linspace(0, 3, 4), np.linspace(0, t, 3), np.linspace(0, 2, 3))
    basis = skfem.Basis(m, skfem.ElementTetP2())
    x, y, z = basis.doflocs
    f = {"sxx": -(1 + x + 2 * y + 3 * z), "syy": -(2 - y), "szz": -(0.5 + z), "sxy": 0 * x, "syz": 0 * x, "sxz": 0 * x}
    meshio.write(path / "result.vtu", meshio.Mesh(basis.doflocs.T, [("tetra10", basis.element_dofs.T)],
                                                  point_data={f"{k}_MPa": v for k, v in f.items()}))
    P = lambda x, y, z: (1 + x + 2 * y + 3 * z + 2 - y + 0.5 + z) / 3  # noqa: E731
    s, zg = np.linspace(0, 3, 7), np.linspace(0, 2, 5)
    S, Z = np.meshgrid(s, zg)
    (path / "bone_map.csv").write_text(BoneMap(s, zg, P(S, 0.0, Z)).to_csv(), encoding="utf-8")
    return SimpleNamespace(scene=Scene(dim=3, skin="pad", indenter="braille", thickness=t), path=path), P


def test_a_sensor_height_reads_the_bone_maps_at_the_bone_and_a_sensor_there_above_it(solved, tmp_path):
    """H -> 0 is the bonded surface: the 2D bone profile and the 3D bone map; a mid height H
    is the depth t - H: what the solver's own sensor line there reads, and the field at y = H."""
    rec, line = solved
    t = COARSE["thickness"]
    at_bone = chart.ChartConfig(thicknesses=(t,), sets=("paper",), sensor_height=1e-12).sensor_depth_at(t)
    sb, Pb = chart.profile_of(rec, at_bone)
    assert np.allclose(Pb, rec.pressure, rtol=0, atol=1e-9 * rec.pressure.max())
    assert np.allclose(sb, rec.s, atol=1e-9)
    mid = chart.ChartConfig(thicknesses=(t,), sets=("paper",), sensor_height=t - DEPTH)
    assert mid.sensor_depth_at(t) == DEPTH and mid.sensor_height_at(t) == t - DEPTH
    _, P = chart._at_depth(rec, line.s, None, mid.sensor_depth_at(t))  # at the line's own s
    assert np.allclose(P, line.pressure, rtol=0, atol=1e-9 * line.pressure.max())

    t3 = 1.0
    rec3, field = _linear_pad(tmp_path, t3)
    bone = chart.map_of(rec3)
    near = chart.map_of(rec3, chart.ChartConfig(thicknesses=(t3,), sets=("paper",),
                                                sensor_height=1e-9).sensor_depth_at(t3))
    assert np.allclose(near.s, bone.s) and np.allclose(near.z, bone.z)
    assert np.allclose(near.pressure, bone.pressure, rtol=0, atol=1e-8 * bone.pressure.max())
    h = 0.3
    up = chart.map_of(rec3, chart.ChartConfig(thicknesses=(t3,), sets=("paper",), sensor_height=h).sensor_depth_at(t3))
    S, Z = np.meshgrid(up.s, up.z)
    assert np.allclose(up.pressure, field(np.abs(S), h, np.abs(Z)), atol=1e-12)
    assert not np.allclose(up.pressure, bone.pressure, atol=1e-3)  # the height moved the plane


def _fake_chart(monkeypatch):
    """compute() on fake solves whose maps at a depth depend on the depth (narrower and
    weaker the deeper); returns the list of (dim, indenter, depth) read."""
    grid = np.linspace(-8, 8, 161)
    width = {"flat": 3.0, "curved": 1.5, "braille": 0.4, "sphere": 1.0}

    def fake_solve(scenes, cache, on_event=None, workers=None):
        return {sc: SimpleNamespace(s=grid, pressure=np.exp(-grid ** 2 / width[sc.indenter] ** 2), scene=sc,
                                    path=Path("unread"), summary={"reaction_n_per_mm": float(sc.indentation) ** 1.5})
                for sc in scenes}

    read = []

    def at_depth(rec, s, z, depth):
        read.append((rec.scene.dim, rec.scene.indenter, depth))
        w = (2.0 - 0.3 * depth) * width[rec.scene.indenter]
        if z is None:
            return s, np.exp(-depth) * np.exp(-s ** 2 / w ** 2)
        S, Z = np.meshgrid(s, z)
        return s, np.exp(-depth) * np.exp(-(S ** 2 + Z ** 2) / w ** 2)

    monkeypatch.setattr(chart, "solve_cached", fake_solve)
    monkeypatch.setattr(chart, "read_bone_map", lambda path: maps.on_grid(lambda s, z: 0 * s, grid[80:], grid[80:]))
    monkeypatch.setattr(chart, "_at_depth", at_depth)
    monkeypatch.setattr(chart, "surface_deflection", lambda rec, top: lambda dx, dz: 0.0 * np.asarray(dx))
    return read


def _csv_rows(ch):
    import csv
    import io

    return list(csv.DictReader(io.StringIO(ch.to_csv())))


def test_a_sensor_height_is_the_depth_t_minus_h_in_every_skin_and_the_csv_says_both(monkeypatch):
    read = _fake_chart(monkeypatch)
    small = dict(sets=("paper", "letters"), letters="abl", pitches=(0.5, 1.0), noise_fs=(0.01,), n_train=4, n_test=4,
                 template_grid=2)
    # one thickness: --sensor-height 0.4 is --sensor-depth 0.6, row for row
    by_height = chart.compute(chart.ChartConfig(thicknesses=(1.0,), sensor_height=0.4, **small), cache=None)
    read_h = sorted(set(read))
    read.clear()
    by_depth = chart.compute(chart.ChartConfig(thicknesses=(1.0,), sensor_depth=0.6, **small), cache=None)
    assert read_h == sorted(set(read)) and {d for *_, d in read_h} == {0.6}
    assert by_height.rows == by_depth.rows and _csv_rows(by_height) == _csv_rows(by_depth)
    assert {(r["sensor_depth_mm"], r["sensor_height_mm"]) for r in _csv_rows(by_height)} == {("0.6", "0.4")}
    assert by_height.cutoffs == by_depth.cutoffs
    # this run's validation at the depth t - H answers for the letters, as at --sensor-depth
    cfg = by_height.config
    row = {"material": "silicone", "thickness_mm": 1.0, "depth_mm": 0.2, "text": "l", "model": "interaction",
           "taxel_mm": 0.4, "max_abs_over_peak_taxel": 0.02, "sensor_depth_mm": 0.6}
    assert chart.surrogate_trust(cfg, "silicone", 1.0, "interaction", [row])["status"] == "within"
    assert chart.surrogate_trust(cfg, "silicone", 1.0, "interaction")["status"] == "not validated"

    # two thicknesses: the same height, so each skin is read at its own depth t - H
    read.clear()
    ch = chart.compute(chart.ChartConfig(thicknesses=(1.0, 3.0), sensor_height=0.4, **{**small, "sets": ("paper",)}),
                       cache=None)
    assert sorted({d for *_, d in read}) == [0.6, 2.6]
    got = {(r["thickness_mm"], r["sensor_depth_mm"], r["sensor_height_mm"]) for r in _csv_rows(ch)}
    assert got == {("1", "0.6", "0.4"), ("3", "2.6", "0.4")}
    from tactileskin.array import halfspace

    assert [c["halfspace_nyquist_pitch_mm"] for c in ch.cutoffs] == \
        [pytest.approx(halfspace.nyquist_pitch(0.6)), pytest.approx(halfspace.nyquist_pitch(2.6))]
    from tactileskin.report.array_chart import markdown

    md = " ".join(markdown(ch).split())
    assert "Sensor plane: 0.4 mm above the bonded surface (`--sensor-height`; t - 0.4 mm below the contact" in md
    assert "half-space Nyquist pitch at depth t - 0.4 mm (mm)" in md
    # a bone chart's rows: on the bonded surface, height 0
    read.clear()
    bone = chart.compute(chart.ChartConfig(thicknesses=(1.0,), **{**small, "sets": ("paper",)}), cache=None)
    assert not read and {(r["sensor_depth_mm"], r["sensor_height_mm"]) for r in _csv_rows(bone)} == {("1", "0")}


@pytest.mark.parametrize("args, words", [
    (["--sensor-height", "0"], ["sensor_height (--sensor-height)=0.0", "(0, 1) mm above the bonded surface"]),
    (["--sensor-height", "1"], ["sensor_height (--sensor-height)=1.0", "(0, 1) mm", "the thinnest skin is 1 mm"]),
    (["--sensor-height", "-0.5"], ["sensor_height (--sensor-height)=-0.5", "(0, 1) mm"]),
    (["--sensor-height", "0.5", "--sensor-depth", "0.5"], ["sensor_height (--sensor-height)=0.5",
                                                           "not with sensor_depth (--sensor-depth)"]),
])
def test_a_sensor_height_outside_every_skin_or_with_a_depth_is_one_line_before_any_solve(tmp_path, capsys, monkeypatch,
                                                                                        args, words):
    def refuse(*a, **k):
        raise AssertionError("the chart started solving")

    monkeypatch.setattr(chart, "compute", refuse)
    out = tmp_path / "o"
    assert main(["array", "-o", str(out), "--set", "paper", "-t", "1,3", *args]) == 2
    raw = capsys.readouterr().err
    err = " ".join(raw.split())
    assert raw.startswith("error:") and len(raw.strip().splitlines()) == 1, raw
    assert all(w in err for w in words) and "Traceback" not in err, err
    assert not out.exists()


def test_a_sensor_height_flag_replaces_the_configs_sensor_plane(tmp_path, capsys, monkeypatch):
    """As a --noise flag replaces the config's noise axis: the config's sensor_depth with
    --sensor-height would otherwise be refused as both."""
    got = []

    def stop(cfg, *a, **k):
        got.append(cfg)
        raise ParameterError("stop", 0, "stopped by the test")

    monkeypatch.setattr(chart, "compute", stop)
    conf = tmp_path / "c.toml"
    conf.write_text("[array]\nthicknesses = [1]\nsets = ['paper']\nsensor_depth = 0.5\n", encoding="utf-8")
    main(["array", "-o", str(tmp_path / "o"), "--config", str(conf), "--sensor-height", "0.3"])
    assert got and (got[0].sensor_depth, got[0].sensor_height) == (None, 0.3)


@pytest.mark.parametrize("kw", [{"sensor_depth": 0.4}, {"sensor_height": 1.0}])
def test_a_chart_read_inside_a_thick_skin_keeps_the_contact_spot_fine(kw):
    """The t = 5 mm 3x contact spot (mesh.sizing.spot_factor) was measured on the bone map
    only; 0.4 mm under it a dot read +36 %. A chart read inside the skin meshes its dots as a
    scene with a sensor at that depth, so the spot keeps its fine size; a bone chart's dots keep
    the rule."""
    from tactileskin.mesh import sizing

    def spots(sc):
        sec = sc.section()
        return [b[4] for b in sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True).patches]

    cfg = {"thicknesses": (5.0,), "mesh_size": 1.6, "refinement": 8.0}
    inside = chart.dot_scene(5.0, "silicone", chart.ChartConfig(**cfg, **kw), skin="fingertip")
    bone = chart.dot_scene(5.0, "silicone", chart.ChartConfig(**cfg), skin="fingertip")
    assert sizing.sensors_inside(inside) and not sizing.sensors_inside(bone)
    assert spots(inside) == pytest.approx([0.2] * len(spots(inside)))
    assert spots(bone) == pytest.approx([0.6] * len(spots(bone)))


def test_a_shapes_sphere_read_inside_a_thick_skin_keeps_its_contact_spot_fine():
    """The shapes set's sphere is a contact spot too (R 1 mm pressed 0.3 mm: a = 0.71 mm, a dot's
    size): read 0.4 mm deep in a t = 5 mm skin its spot was meshed 3x coarse (0.6 mm against
    0.2), as the dots' were, since only the dot scenes carried the chart's sensor."""
    from tactileskin.mesh import sizing

    def spots(sc):
        sec = sc.section()
        return [b[4] for b in sizing.plan(sc, sec, dim=3, length=sec.fingertip.sample_length, z_symmetric=True).patches]

    cfg = dict(thicknesses=(5.0,), sets=("shapes",), sphere_radius=1.0, max_depth=0.3)
    inside = chart.sphere_scene(5.0, "silicone", chart.ChartConfig(**cfg, sensor_depth=0.4))
    bone = chart.sphere_scene(5.0, "silicone", chart.ChartConfig(**cfg))
    assert spots(inside) == pytest.approx([0.2]) and spots(bone) == pytest.approx([0.6])
