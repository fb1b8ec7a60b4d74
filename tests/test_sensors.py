"""Sensor layouts and readings (tactileskin.sensors, fe.probe): positions, sampling inside the
elements, stress rotation to the sensor plane, taxel averaging, validation, scene and cache."""

import numpy as np
import pytest
from scipy.optimize import brentq
from skfem import MeshTet, MeshTri

from tactileskin import results, sensors
from tactileskin.cache import cache_key
from tactileskin.errors import ParameterError
from tactileskin.fe import Dirichlet, Model, SolverOptions, material_law, run, solve
from tactileskin.fe.output import nodal_fields
from tactileskin.fe.probe import stress_sampler
from tactileskin.materials import cauchy_principal, get_material
from tactileskin.scene import Scene

# these exact discrete solutions are checked to 1e-6: Newton solved to 1e-8 of the force (the
# solver's default, 1e-5, leaves ~1e-6 in the stress)
TIGHT = 1e-8

# coarse 2D fingertip (about 1 s per solve)
COARSE = dict(thickness=3.0, indenter="curved", mesh_size=0.5, refinement=2)


@pytest.fixture(scope="module")
def plain():
    return solve(Scene(**COARSE))


def _rotated(sig, n, t1, t2):
    """Closed-form readings of a stress tensor on a plane (normal n, tangents t1, t2)."""
    return n @ sig @ n, t1 @ sig @ n, t2 @ sig @ n


# --- sampling a homogeneous state ------------------------------------------------------------

def _faces(m, dim):
    names = {0: ("left", "right"), 1: ("bottom", "top"), 2: ("back", "front")}
    out = {}
    for ax in range(dim):
        out[names[ax][0]] = m.facets_satisfying(lambda x, a=ax: x[a] < 1e-9)
        out[names[ax][1]] = m.facets_satisfying(lambda x, a=ax: x[a] > 1 - 1e-9)
    return out


def test_homogeneous_2d_block_sampled_anywhere_rotates_exactly():
    # uniaxial compression of a free-sided block: sigma = diag(0, sy, sz) everywhere, an exact
    # discrete solution on any mesh; the only errors are Newton's (rtol TIGHT) and round-off,
    # so 1e-6 of |sy| is a wide margin that still catches a wrong interpolation or rotation
    m = MeshTri.init_tensor(np.linspace(0, 1, 4), np.linspace(0, 1, 3))
    hf = get_material("polyurethane").hyperfoam
    lam = 0.85
    bcs = [Dirichlet("left", (0,)), Dirichlet("bottom", (1,)), Dirichlet("top", (1,), value=lambda t: (lam - 1) * t)]
    model = Model(m, _faces(m, 2), material_law(hf), bcs)
    ev, _ = run(model, 1.0, SolverOptions(rtol=TIGHT, dt0_fraction=0.5))
    lx = brentq(lambda v: cauchy_principal(hf, np.array([v, lam, 1.0]))[0], 1.0, 1.5, xtol=1e-14)
    sig = np.diag(cauchy_principal(hf, np.array([lx, lam, 1.0])))
    rng = np.random.default_rng(1)
    pts = rng.uniform(0, 1, (25, 2))
    pts[:3] = [[0.0, 0.0], [1.0, 1.0], [0.5, 1.0]]  # corners and edges are inside too
    ang = rng.uniform(0, 2 * np.pi, 25)
    normals = np.column_stack([np.cos(ang), np.sin(ang)])
    sites = sensors.Sites.at(pts, normals)
    r = sensors.read(sites, stress_sampler(model, nodal_fields(model, ev)))
    tol = 1e-6 * abs(sig[1, 1])
    assert np.allclose(r.pressure, -np.trace(sig) / 3, atol=tol)
    for k in range(len(pts)):
        nn, t1, t2 = _rotated(sig, sites.normal[k], sites.t1[k], sites.t2[k])
        assert r.sigma_nn[k] == pytest.approx(nn, abs=tol)
        assert r.tau_1[k] == pytest.approx(t1, abs=tol)
        assert r.tau_2[k] == 0.0  # plane strain: sigma_xz = sigma_yz = 0
    # a rotated plane really sees shear: at 45 degrees tau_1 = (sy - sx)/2 in magnitude
    k45 = sensors.Sites.at([[0.3, 0.4]], [[1.0, 1.0]])
    r45 = sensors.read(k45, stress_sampler(model, nodal_fields(model, ev)))
    assert abs(r45.tau_1[0]) == pytest.approx(abs(sig[1, 1] - sig[0, 0]) / 2, rel=1e-6)


def test_homogeneous_3d_block_tiny():
    # confined compression of a tet block (lateral faces held): diag(sx, sy, sx), exact
    m = MeshTet.init_tensor(*(np.linspace(0, 1, 3),) * 3)
    hf = get_material("polyurethane").hyperfoam
    lam = 0.9
    bcs = [Dirichlet("left", (0,)), Dirichlet("right", (0,)), Dirichlet("back", (2,)), Dirichlet("front", (2,)),
           Dirichlet("bottom", (1,)), Dirichlet("top", (1,), value=lambda t: (lam - 1) * t)]
    model = Model(m, _faces(m, 3), material_law(hf), bcs)
    ev, _ = run(model, 1.0, SolverOptions(rtol=TIGHT, dt0_fraction=0.5))
    sig = np.diag(cauchy_principal(hf, np.array([1.0, lam, 1.0])))
    rng = np.random.default_rng(2)
    pts = rng.uniform(0, 1, (12, 3))
    normals = rng.normal(size=(12, 3))
    sites = sensors.Sites.at(pts, normals)
    r = sensors.read(sites, stress_sampler(model, nodal_fields(model, ev)))
    tol = 1e-6 * abs(sig[1, 1])
    for k in range(len(pts)):
        nn, t1, t2 = _rotated(sig, sites.normal[k], sites.t1[k], sites.t2[k])
        assert (r.sigma_nn[k], r.tau_1[k], r.tau_2[k]) == pytest.approx((nn, t1, t2), abs=tol)
    # not a trivial check: oblique planes of this anisotropic state carry shear
    assert np.max(np.abs(r.tau_1)) > 0.1 * abs(sig[1, 1] - sig[0, 0])


def test_many_sample_points_are_read_in_bounded_memory():
    """The sampler located all points at once (~160 kB each on a 3D P2 mesh while searching)
    and scikit-fem's isoparametric mapping kept every Jacobian it evaluated (~27 kB a point,
    never freed): a valid sensor file (19881 taxels of 16 x 16 points) was killed at 20 GB."""
    import tracemalloc

    from skfem import MeshTet2

    from tactileskin.fe.output import STRESS_COMPONENTS

    m = MeshTet2.from_mesh(MeshTet.init_tensor(*(np.linspace(0, 1, 3),) * 3))  # curved-capable, as the solver's
    model = Model(m, _faces(m, 3), material_law(get_material("silicone").hyperfoam), [Dirichlet("bottom", (1,))])
    # constant fields: interpolated exactly anywhere (the shape functions sum to 1)
    sampler = stress_sampler(model, {n: np.full(model.nsdof, i + 1.0) for i, n in enumerate(STRESS_COMPONENTS)})
    want = np.zeros((3, 3))
    for i, (a, b) in enumerate(STRESS_COMPONENTS.values()):
        want[a, b] = want[b, a] = i + 1.0
    rng = np.random.default_rng(3)
    sampler(rng.uniform(0, 1, (10, 3)))  # first-call set-up (the KD tree) outside the count
    tracemalloc.start()
    try:
        sig = sampler(rng.uniform(0, 1, (6000, 3)))
        kept, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert sig.shape == (6000, 3, 3) and np.allclose(sig, want, rtol=0, atol=1e-12)
    assert kept < sig.nbytes + 2e6  # the result (0.4 MB), not the search's Jacobians (was 26 MB)
    assert peak < 60e6  # one chunk of the search (was 100+ MB)


# --- taxel averaging ---------------------------------------------------------------------------

def _linear_sampler(points):
    # a stress field linear in x, y (and z): each component a + b.x
    pts = np.asarray(points, float)
    pts = pts if pts.shape[1] == 3 else np.column_stack([pts, np.zeros(len(pts))])
    A = np.array([[1.0, 0.2, -0.3], [0.2, -2.0, 0.4], [-0.3, 0.4, 0.5]])
    B = np.arange(27, dtype=float).reshape(3, 3, 3) / 10.0
    B = B + np.swapaxes(B, 0, 1)
    return A + np.einsum("ijk,nk->nij", B, pts)


@pytest.mark.parametrize("dim", [2, 3])
def test_taxel_mean_of_linear_field_is_centre_value(dim):
    coords = sensors.FlatCoordinates(top=2.0, thickness=2.0, half_width=5.0)
    kind = {"kind": "line", "s": [-2, 2], "pitch": 1.0} if dim == 2 else \
        {"kind": "grid", "s": [-2, 2], "z": [-1, 1], "pitch": [1.0, 0.5]}
    lays = sensors.layouts([{"name": "a", **kind, "depth": 0.7, "taxel": 0.8, "taxel_points": 3},
                            {"name": "c", **kind, "depth": 0.7}])
    sites = sensors.resolve(lays, coords, dim, z_range=(-3, 3))
    r = sensors.read(sites, _linear_sampler)
    a, c = r.select("a"), r.select("c")
    assert set(a.taxel_points) == {3 ** (dim - 1)} and set(c.taxel_points) == {1}
    for q in ("pressure", "sigma_nn", "tau_1", "tau_2"):
        assert np.allclose(getattr(a, q), getattr(c, q), rtol=0, atol=1e-12)
    # the samples really spread over the taxel (a quadratic field would differ)
    spread = np.ptp(sites.samples[0, :3, 0])
    assert spread == pytest.approx(0.8 * np.sqrt(3 / 5), rel=1e-12)


# --- on the fingertip --------------------------------------------------------------------------

DEPTHS = (0.5, 1.25, 2.0, 2.75)


@pytest.fixture(scope="module")
def with_sensors(plain):
    """One solve of the coarse scene with every layout the tests below read."""
    s, _ = plain._profile()
    lays = [{"name": "bone", "s": list(s), "height": 0.0},
            {"name": "mirror", "kind": "line", "s": [-3, 3], "pitch": 0.5, "depth": 1.0, "taxel": 0.5},
            *({"name": f"d{k}", "kind": "line", "s": [0, 6], "pitch": 0.1, "depth": d}
              for k, d in enumerate(DEPTHS))]
    sc = Scene(**COARSE, sensors=lays)
    return sc, solve(sc)


def test_bone_layout_equals_bone_profile(plain, with_sensors):
    sc, res = with_sensors
    s, p = plain._profile()
    assert np.array_equal(res.pressure, plain.pressure)  # sensors do not change the answer
    b = res.sensors.select("bone")
    # the sensor points come from s by the section's arc-length table (positions within ~1e-9
    # mm of the mesh nodes); with |dP/ds| < 0.1 MPa/mm that is < 1e-10 MPa
    assert np.allclose(b.pressure, p, rtol=0, atol=1e-9)
    assert np.allclose(b.xyz[:, :2], sc.section().point_at_s(s), atol=1e-12)
    # the bone's sensor plane is the interface: its normal stress carries the pressure's sign
    assert np.all(b.sigma_nn[p > 0.5 * p.max()] < 0)
    assert np.all(b.tau_2 == 0.0)


def test_mirror_half_reads_the_mirror_image(with_sensors):
    r = with_sensors[1].sensors.select("mirror")
    assert len(r) == 13 and np.allclose(r.s, np.arange(-3, 3.01, 0.5))
    i = np.argsort(-r.s)  # s -> -s
    assert np.allclose(r.pressure, r.pressure[i], atol=1e-12)
    assert np.allclose(r.sigma_nn, r.sigma_nn[i], atol=1e-12)
    assert np.allclose(r.xyz[:, 0], -r.xyz[i, 0]) and np.allclose(r.xyz[:, 1], r.xyz[i, 1])
    assert np.allclose(r.tau_1, -r.tau_1[i], atol=1e-12)  # tau_1 is odd in s
    # so it vanishes on the symmetry line: exactly (the even part of the field there; the
    # discrete sxy itself is only near zero: ~4 % of the largest shear at preview)
    assert r.tau_1[r.s == 0][0] == 0.0
    b = with_sensors[1].sensors.select("bone")
    assert b.tau_1[np.argmin(np.abs(b.s))] == 0.0 and np.max(np.abs(b.tau_1)) > 0


def test_deeper_sensors_see_lower_wider_pressure(with_sensors):
    # the skin spreads the load: the compressive normal stress on the sensor plane (-sigma_nn)
    # peaks lower and spreads wider (half-maximum width) the deeper the sensor line. The mean
    # pressure P widens too, but its peak is not monotone: near the bonded bone the lateral
    # confinement raises it again (0.102, 0.087, 0.089, 0.109 MPa on this mesh), so only its
    # width is asserted.
    r = with_sensors[1].sensors
    peaks, spans, pspans = [], [], []
    for k in range(len(DEPTHS)):
        row = r.select(f"d{k}")
        q = -row.sigma_nn
        peaks.append(q.max())
        spans.append(results.span(row.s, q, 0.5))
        pspans.append(results.span(row.s, row.pressure, 0.5))
    assert np.all(np.diff(peaks) < 0), peaks
    assert np.all(np.diff(spans) > 0), spans
    assert np.all(np.diff(pspans) > 0), pspans


def test_sensors_csv_and_summary(plain, with_sensors, tmp_path):
    res = with_sensors[1]
    res.write(tmp_path)
    back = sensors.read_sensors_csv(tmp_path / "sensors.csv")
    assert back.ids == res.sensors.ids and back.layout == res.sensors.layout
    assert np.allclose(back.pressure, res.sensors.pressure, rtol=1e-9)
    summ = res.summary()
    assert summ["peak_sensor_pressure_mpa"] == pytest.approx(res.sensors.pressure.max())
    assert summ["sensors"] == len(res.sensors)
    plain.write(tmp_path)  # a result without sensors removes the stale table
    assert not (tmp_path / "sensors.csv").exists()


def test_default_taxel_points_follow_the_taxel_not_a_fixed_three():
    """A taxel over a peak narrower than itself (the bone pressure under a 1 mm skin's ridge,
    width ~ t): the default points (one per 0.25 mm of side) average a Gaussian bump of
    sigma 0.3 mm over 2 mm taxels to 1 % of the exact mean (erf), where a fixed 3 points read
    it 12-24 % off; taxels wider than 4 mm take the 16-point cap, smaller ones at least 3."""
    from math import erf, sqrt

    assert [sensors.default_taxel_points(a) for a in (0.1, 0.75, 0.8, 2.0, 4.0, 10.0)] == [3, 3, 4, 8, 16, 16]
    # the same default for a layout given as an object as for one given as a table
    as_object = sensors.layouts([sensors.SensorLayout("a", taxel=2.0, height=0.0)])[0]
    assert as_object.taxel_points == sensors.layouts([{"name": "a", "taxel": 2.0, "height": 0.0}])[0].taxel_points == 8
    sig = 0.3
    coords = sensors.FlatCoordinates(top=2.0, thickness=2.0, half_width=10.0)

    def bump(points):
        x = np.asarray(points, float)[:, 0]
        return -np.exp(-0.5 * (x / sig) ** 2)[:, None, None] * np.eye(3)

    def exact(c, a):  # mean of the bump over [c - a/2, c + a/2]
        f = lambda u: erf(u / (sqrt(2.0) * sig))  # noqa: E731
        return sig * sqrt(np.pi / 2.0) * (f(c + a / 2) - f(c - a / 2)) / a

    centres = [0.0, 0.5, 1.0]
    errs = {}
    for name, extra in (("auto", {}), ("three", {"taxel_points": 3})):
        lays = sensors.layouts([{"name": name, "s": centres, "height": 0.0, "taxel": 2.0, **extra}])
        r = sensors.read(sensors.resolve(lays, coords, 2), bump)
        errs[name] = [abs(p / exact(c, 2.0) - 1.0) for p, c in zip(r.pressure, centres)]
    assert max(errs["auto"]) < 0.01
    assert max(errs["three"]) > 0.1


@pytest.mark.slow
def test_3d_bone_points_grid_and_z_mirror():
    # tiny 3D slab (~15k dofs, ~30 s CPU); z-symmetric single dot: z < 0 is read by reflection
    lays = [{"name": "bone", "s": [0.0], "z": [0.0], "height": 0.0},
            {"name": "g", "kind": "grid", "s": [-2, 2], "z": [-3, 3], "pitch": [1.0, 1.5], "depth": 0.5,
             "taxel": 0.4}]
    sc = Scene(dim=3, thickness=1, indenter="braille", mesh_size=1.2, refinement=2, sensors=lays)
    res = solve(sc)
    b = res.sensors.select("bone")
    # s = 0, z = 0 is a mesh node on the section plane: the profile's value there, exactly
    assert b.pressure[0] == pytest.approx(res.pressure[np.argmin(np.abs(res.s))], rel=1e-9)
    g = res.sensors.select("g")
    assert len(g) == 25 and set(g.taxel_points) == {9}
    P = g.pressure.reshape(5, 5)                         # rows z, columns s
    assert np.allclose(P, P[::-1], atol=1e-12) and np.allclose(P, P[:, ::-1], atol=1e-12)
    t2 = g.tau_2.reshape(5, 5)  # sigma_nz is odd in z (row z = 0 reads the model's own plane)
    assert np.allclose(t2[:2], -t2[::-1][:2], atol=1e-12) and np.max(np.abs(t2)) > 0
    assert np.argmax(g.pressure) == 12                   # the dot is over the grid's centre


# --- scene, cache, validation ------------------------------------------------------------------

def test_scene_default_has_no_sensors_and_sensors_enter_the_key(tmp_path):
    a = Scene(**COARSE)
    assert "sensors" not in a.to_dict() and a.sensors == ()
    assert cache_key(a) == cache_key(Scene(**COARSE, sensors=[]))
    b = a.replace(sensors=[{"name": "l", "kind": "line", "s": [0, 2], "pitch": 0.5, "depth": 1.0}])
    c = a.replace(sensors=[{"name": "l", "kind": "line", "s": [0, 2], "pitch": 0.5, "depth": 1.5}])
    assert len({cache_key(a), cache_key(b), cache_key(c)}) == 3
    b.to_toml(tmp_path / "s.toml")
    assert Scene.from_toml(tmp_path / "s.toml") == b
    assert Scene.from_dict(b.to_dict()).key() == b.key()


@pytest.mark.parametrize("layout,dim,match", [
    ({"s": [0.0], "depth": 3.5}, 2, r"depth.*\[0, 3\] mm"),
    ({"s": [0.0], "height": -0.1}, 2, r"height.*\[0, 3\] mm"),
    ({"s": [99.0], "depth": 1.0}, 2, r"'x' s.*\[-\d"),
    # within the bone's arc length, but below the surface the skin ends earlier, at the nail cut
    # (this one passed the check and failed after the solve, "sample point ... inside the mesh")
    ({"s": [9.4], "depth": 1.0}, 2, r"'x' s=9.4.*\[-9.17\d*, 9.17\d*\] mm at depth 1 mm \(the skin ends at the nail\)"),
    ({"s": [-9.45], "depth": 1.0}, 3, "ends at the nail"),
    ({"kind": "line", "s": [0, 3], "pitch": 1.0, "depth": 1.0, "z": [0, 1]}, 2, "one z"),
    ({"kind": "grid", "s": [0, 3], "z": [0, 1], "pitch": 1.0, "depth": 1.0}, 2, "grid"),
    ({"s": [0.0], "z": [1.0], "depth": 1.0}, 2, "omitted in 2D"),
    ({"s": [0.0]}, 2, "exactly one"),
    ({"s": [0.0], "depth": 1.0, "height": 1.0}, 2, "exactly one"),
    ({"kind": "line", "s": [0, 3], "depth": 1.0}, 2, "pitch"),
    ({"kind": "ring", "s": [0.0], "depth": 1.0}, 2, "one of points, line, grid"),
    ({"s": [0.0], "depth": 1.0, "taxle": 0.5}, 2, "did you mean 'taxel'"),
    ({"s": [0.0], "depth": 1.0, "taxel": 0.5, "taxel_points": 20}, 2, "1..16"),
    # its default Gauss point count overflowed: an OverflowError, not the skin's range (now the
    # surface's length: a side longer than the whole surface at its depth)
    ({"s": [0.0], "depth": 1.0, "taxel": 1e308}, 2, r"taxel=1e\+308 is invalid; valid: \(0, 27.104\d*\] mm"),
    ({"kind": "grid", "s": [0, 2], "z": [0, 50], "pitch": 1.0, "depth": 1.0}, 3, r"z \+- taxel/2|z.*\[-10, 10\]"),
    # a file in metres (0.5 mm pitch written 0.0005) was solved and shown as ok
    ({"kind": "line", "s": [0, 0.003], "pitch": 0.0005, "depth": 0.001}, 2, r"pitch=\[0.0005\].*>= 0.01 mm.*metres"),
    ({"kind": "grid", "s": [0, 2], "z": [0, 2], "pitch": [1.0, 0.001], "depth": 1.0}, 3, r">= 0.01 mm.*metres"),
    ({"kind": "line", "s": [0, 3], "pitch": 0.0, "depth": 1.0}, 2, r"pitch=\[0.0\].*>= 0.01 mm$"),
    # a taxel in um (800 for 0.8 mm) was refused as "s +- taxel/2=-270.47", an edge the
    # edge search reached on the surface's extension past the nail, neither the taxel nor its edge; the
    # surface at depth 1 mm is 27.1048 mm long (its polyline through 20001 points of s in +-9.17656 mm)
    ({"s": [0.0], "depth": 1.0, "taxel": 800.0}, 2,
     r"'x' taxel=800.0 is invalid; valid: \(0, 27.104\d*\] mm: the surface at depth 1 mm, s in \[-9.17\d*, 9.17\d*\] mm"),
])
def test_sensor_validation_names_layout_and_range(layout, dim, match):
    with pytest.raises(ParameterError, match=match) as e:
        Scene(**{**COARSE, "dim": dim, "mesh_size": None, "refinement": None},
              sensors=[{"name": "x", **layout}])
    assert "sensor" in str(e.value)


def test_duplicate_layout_names_refused():
    lay = {"name": "a", "s": [0.0], "depth": 1.0}
    with pytest.raises(ParameterError, match="unique"):
        Scene(**COARSE, sensors=[lay, lay])


def test_a_sweep_gathers_its_cases_sensors(tmp_path):
    """A sweep's cases with sensors: their readings in the sweep's sensors.csv, one row per
    case and sensor with the case id first (they were only inside the cache), equal to each
    case's own; no sensors.csv when no case has sensors."""
    import csv

    from tactileskin.cache import ResultCache
    from tactileskin.report.outputs import write_outputs
    from tactileskin.sweep import run_sweep

    lays = [{"name": "bone", "kind": "line", "s": [0, 2], "pitch": 1.0, "height": 0.0}]
    scenes = [Scene(**{**COARSE, "thickness": t}, sensors=lays) for t in (2.0, 3.0)]
    cache = ResultCache(tmp_path / "cache")
    outs = run_sweep(scenes, cache, serial=True)
    res = write_outputs(tmp_path / "o", outs, cache, 1.0, render=False, figures=False)
    rows = list(csv.DictReader(open(tmp_path / "o" / "sensors.csv", encoding="utf-8")))
    assert [r["case"] for r in rows] == [c for c in sorted({r["case"] for r in res["rows"]}) for _ in range(3)]
    for rec in res["records"]:
        own = list(csv.DictReader(open(rec.path / "sensors.csv", encoding="utf-8")))
        assert [r["pressure_mpa"] for r in rows if r["case"] == rec.case] == [r["pressure_mpa"] for r in own]
    # results.csv names each case's dimension and variant, as results.parquet does
    table = list(csv.DictReader(open(tmp_path / "o" / "results.csv", encoding="utf-8")))
    assert [r["dim"] for r in table] == ["2", "2"] and all("variant" in r for r in table)
    plain = run_sweep([Scene(**COARSE)], cache, serial=True)
    write_outputs(tmp_path / "p", plain, cache, 1.0, render=False, figures=False)
    assert not (tmp_path / "p" / "sensors.csv").exists()


def test_a_line_whose_pitch_misses_its_end_says_so(caplog):
    """s = [0, 2] at pitch 5 is one sensor at 0: the layout says so once (it was silent)."""
    import logging

    with caplog.at_level(logging.WARNING, logger="tactileskin.sensors"):
        lay = sensors.layouts([{"name": "short", "kind": "line", "s": [0, 2], "pitch": 5.0, "depth": 1.0}])[0]
        assert lay.count() == 1 and lay.positions()[0].tolist() == [0.0]
        lay.positions()
    said = [r.getMessage() for r in caplog.records if "short" in r.getMessage()]
    assert len(said) == 1 and "last sensor is at 0 mm, 2 mm short of the end" in said[0]
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="tactileskin.sensors"):
        sensors.layouts([{"name": "exact", "kind": "line", "s": [0, 2], "pitch": 0.5, "depth": 1.0}])[0].positions()
    assert not caplog.records


def test_points_are_located_alike_by_the_affine_first_search(monkeypatch):
    """locate ranks a point's candidate elements by their affine coordinates and runs Newton
    on the AFFINE_FIRST best (a 3D point took ~0.4 ms with Newton on all 30; 0.07 ms now,
    benchmarks/sensor_sampling.py), and tries EXPAND x as many elements for a point outside
    all of them: on a graded mesh the element holding a point near a vertex of small elements
    can rank past the 30 nearest centroids, and such a point inside the skin was refused as off
    it (64 of 20000 points here, and some in no other element). Every point inside an element, and every boundary node of
    the curved outer surface, interpolates the coordinates exactly (P2 geometry), alike with
    Newton on all candidates; a point off the skin is still refused."""
    from tactileskin.fe import model_for_scene
    from tactileskin.fe import probe
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    model, _ = model_for_scene(with_quality(Scene(skin="pad", pad_width=10, pad_length=10, thickness=1.0,
                                                  indenter="sphere", indenter_radius=2.5, dim=3,
                                                  viscoelastic=False), "preview"))
    rng = np.random.default_rng(0)
    el = rng.integers(0, model.mesh.t.shape[1], 20000)
    b = rng.dirichlet(np.full(4, 0.3), 20000).T  # near the elements' vertices and edges
    inside = model.basis.mapping.F(b[1:][:, :, None], el)[:, :, 0].T
    probe.locate(model, inside[:1])  # builds the centroid tree
    _, near = model._probe_tree.query(inside, k=probe._CANDIDATES[3])
    far = ~np.any(near == el[:, None], axis=1)  # their own element is not among the 30 nearest
    assert far.sum() > 10
    bn = model.mesh.doflocs[:, model.mesh.boundary_nodes()].T
    pts = np.vstack([inside[far], inside[:500], bn[rng.integers(0, len(bn), 300)]])
    monkeypatch.setattr(probe, "EXPANSIONS", 0)  # the 30 nearest only, as before
    with pytest.raises(ParameterError, match="inside the meshed skin"):
        probe.locate(model, pts)
    monkeypatch.undo()
    got = {}
    for first in (probe.AFFINE_FIRST, 10 ** 6):  # the second: Newton on every candidate
        monkeypatch.setattr(probe, "AFFINE_FIRST", first)
        M = probe.interpolation_matrix(model, pts)
        got[first] = np.stack([M @ model.mesh.doflocs[i] for i in range(3)], axis=1)
        assert np.abs(got[first] - pts).max() < 1e-12
    assert np.abs(got[probe.AFFINE_FIRST] - got[10 ** 6]).max() < 1e-12
    monkeypatch.undo()
    top = model.mesh.doflocs[:, np.argmax(model.mesh.doflocs[1])]
    with pytest.raises(ParameterError, match="inside the meshed skin"):
        probe.locate(model, (top + [0.0, 0.05, 0.0])[None, :])


def test_a_sweep_marks_a_suspect_cases_sensor_readings(tmp_path):
    """The sweep's sensors.csv listed a suspect case's readings (t = 1 curved pressed 1e-3 mm:
    one contact point, bone sensor 1.25e-4 MPa) exactly like an ok case's: it had no status,
    while results.csv said suspect. Each row now carries its case's status, as results.csv."""
    import csv

    from tactileskin import quality
    from tactileskin.report.outputs import _write_sensors
    from tactileskin.sweep import CaseRecord

    head = "sensor_id,layout,x_mm,y_mm,z_mm,s_mm,depth_mm,pressure_mpa,sigma_nn_mpa,tau_1_mpa,tau_2_mpa,taxel_points\n"
    ok = dict(peak_mpa=0.22, reaction_n_per_mm=0.27, contact_points=20)
    recs = []
    for name, summary in (("ok", ok), ("none", dict(ok, peak_mpa=0.0, reaction_n_per_mm=0.0, contact_points=0))):
        d = tmp_path / name
        d.mkdir()
        (d / "sensors.csv").write_text(head + "bone-0,bone,0,6,0,0,1,0.1,-0.1,0,0,1\n")
        rec = CaseRecord(Scene(**COARSE), np.zeros(2), np.zeros(2), summary, d)
        rec.case = name
        recs.append(rec)
    _write_sensors(tmp_path / "sensors.csv", recs)
    rows = list(csv.DictReader(open(tmp_path / "sensors.csv", encoding="utf-8")))
    assert [r["status"] for r in rows] == [quality.status(r.summary) for r in recs]
    assert rows[0]["status"] == "ok" and rows[1]["status"].startswith("suspect: no contact")
    assert rows[1]["pressure_mpa"] == "0.1"  # the readings themselves unchanged


def test_the_sweep_report_names_sensors_csv_when_cases_have_sensors(tmp_path):
    """report.md never mentioned sensors.csv, which the sweep writes beside it for the cases
    with sensor layouts; it now names it (and says nothing without sensors)."""
    from tactileskin.report.markdown import build_report
    from tactileskin.sweep import CaseRecord

    lays = [dict(name="bone", kind="points", s=[0.0, 1.0], height=0.0)]
    summary = dict(peak_mpa=0.22, span_mm=2.0, auc_mpa_mm=0.3, reaction_n_per_mm=0.27, contact_points=20)
    texts = []
    for lay in (lays, None):
        rec = CaseRecord(Scene(**COARSE, sensors=lay or []), np.zeros(2), np.zeros(2), summary, tmp_path)
        rec.case = "t3-silicone-curved-2d"
        row = dict(case=rec.case, thickness_mm=3.0, material="silicone", indenter="curved", depth_mm=0.6,
                   status="ok", **summary)
        texts.append(build_report([row], [rec], [], [], [], 1.0))
    assert "`sensors.csv` (one row per case and sensor" in texts[0] and "sensors.csv" not in texts[1]


def test_sensors_csv_gives_each_sensors_plane_normal(tmp_path):
    """sensors.csv had no normal: the frame the stresses are resolved in (the sensor plane's
    unit normal, 55 degrees off +y at s = 5 on the t = 3 fingertip) could not be seen. nx, ny,
    nz are appended after the twelve columns it had, and a file of those twelve still reads."""
    sc = Scene(**COARSE, sensors=[{"name": "a", "kind": "points", "s": [0.0, -5.0, 5.0], "depth": 1.0}])
    st = sensors.sites_for(sc)
    assert st.normal[2, 0] > 0.8  # a normal well off +y (0.817)
    rd = sensors.readings_from_stress(st, np.tile(-0.1 * np.eye(3), (3, 1, 1)))
    text = rd.to_csv()
    head = text.splitlines()[0].split(",")
    assert head[:15] == list(sensors.OLD_COLUMNS) + ["nx", "ny", "nz"]
    assert ",".join(text.splitlines()[1].split(",")[12:15]) == "0,1,0"  # s = 0: +y, no "-0"
    (tmp_path / "sensors.csv").write_text(text)
    back = sensors.read_sensors_csv(tmp_path / "sensors.csv")
    assert np.allclose(back.normal, st.normal, rtol=0, atol=1e-9)
    assert np.allclose(np.linalg.norm(back.normal, axis=1), 1.0, rtol=0, atol=1e-9)
    old = "\n".join(",".join(r.split(",")[:12]) for r in text.splitlines()) + "\n"
    (tmp_path / "old.csv").write_text(old)
    back = sensors.read_sensors_csv(tmp_path / "old.csv")
    assert np.allclose(back.pressure, 0.1) and np.isnan(back.normal).all()
