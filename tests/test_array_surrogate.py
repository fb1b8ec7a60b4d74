"""Superposition of single-dot responses on analytic kernels, and the chart's map helpers."""

import numpy as np
import pytest

from tactileskin.array import chart, config, maps, surrogate
from tactileskin.errors import ParameterError
from tactileskin.geometry import braille
from tactileskin.scene import Scene

SEC = Scene(thickness=1.0).section()


def _reaction(sc):
    """A fake solve's summary: load ~ depth^1.5 (Hertz), for surrogate.load_exponent."""
    return {"reaction_n_per_mm": float(sc.indentation) ** 1.5}


def _fake_solver(monkeypatch, asked: list, path=None, grid=np.linspace(-8, 8, 161)):
    """Replace chart.solve_cached and chart.bone_map_of by analytic stand-ins: every scene
    asked is appended to `asked` and gets a record whose bone map is a Gaussian dot."""
    from types import SimpleNamespace

    def fake_solve(scenes, cache, on_event=None, workers=None):
        asked.extend(scenes)
        return {sc: SimpleNamespace(s=grid, pressure=np.exp(-grid ** 2), scene=sc, path=path,
                                    summary=_reaction(sc)) for sc in scenes}

    monkeypatch.setattr(chart, "solve_cached", fake_solve)
    monkeypatch.setattr(chart, "bone_map_of", lambda rec: maps.on_grid(_gauss(w=0.5), grid, grid))


def _gauss(cs=0.0, cz=0.0, w=0.4):
    return lambda s, z: np.exp(-((s - cs) ** 2 + (z - cz) ** 2) / (2 * w * w))


def test_bone_s_under_is_odd_and_shorter_than_the_outer_arc():
    s = surrogate.bone_s_under(np.array([-1.5, 0.0, 1.5]), SEC)
    assert s[1] == 0.0 and s[0] == pytest.approx(-s[2])
    # the bone lies inside the skin: its arc under x is shorter than x (the outer chord ~ x)
    assert 0.8 * 1.5 < s[2] < 1.5


def test_superposition_of_gaussian_kernel_is_sum_of_gaussians():
    grid = np.linspace(-6, 6, 481)  # h = 0.025: bilinear error <= h^2/8 max|f''| = 1e-3 per dot
    kernel = maps.on_grid(_gauss(), grid, grid)
    centres = surrogate.cell_centres(surrogate.FULL_CELL)
    got = surrogate.superpose(kernel, centres, SEC)
    sk = surrogate.bone_s_under(centres[:, 0], SEC)
    expect = maps.on_grid(lambda s, z: sum(_gauss(a, b)(s, z) for a, b in zip(sk, centres[:, 1])), grid, grid)
    assert np.max(np.abs(got.pressure - expect.pressure)) < 6e-3  # six dots x 1e-3
    err = maps.relative_error(got, expect)
    assert err["rel_l2"] < 5e-3 and abs(err["peak_rel"]) < 5e-3


def test_cell_centres_in_the_full_cell_frame():
    full = braille.dot_centres(chr(0x283F))
    a = surrogate.cell_centres(braille.LETTERS["a"])           # dot 1: top left
    assert np.allclose(a, full[:1]) and a[0, 0] < 0 and a[0, 1] > 0  # top: +z
    assert len(surrogate.cell_centres(braille.LETTERS["y"])) == 5
    with pytest.raises(ParameterError):
        surrogate.cell_centres(0)


def test_a_digit_is_the_number_sign_and_its_a_to_j_cell_in_a_two_cell_frame():
    std = braille.get_standard("standard_american")
    one = surrogate.char_centres("1")      # number sign (dots 3, 4, 5, 6) + a (dot 1)
    two_full = braille.dot_centres(chr(0x283F) * 2)
    assert len(one) == 5 and np.isclose(two_full[:, 0].min(), -0.5 * (std.cell_pitch + std.dot_pitch))
    assert np.allclose(one[:4], two_full[[2, 3, 4, 5]]) and np.allclose(one[4], two_full[6])
    # the digit's own cell is a's, one cell pitch right of the number sign
    assert np.allclose(one[4] - surrogate.char_centres("a")[0], [0.5 * std.cell_pitch, 0.0])
    assert np.allclose(surrogate.char_centres("0")[4:], two_full[[7, 9, 10]])  # 0 = j: dots 2, 4, 5
    assert np.allclose(surrogate.char_centres("k"), surrogate.cell_centres(braille.LETTERS["k"]))
    for bad in ("A", "ab", "?"):
        with pytest.raises(ParameterError):
            surrogate.char_centres(bad)
    with pytest.raises(ParameterError, match="letters"):
        chart.ChartConfig(letters="ab#")
    assert chart.ChartConfig().letters == config.LETTERS + config.DIGITS


def test_extruded_profile_is_uniform_along_z_and_mirrored():
    s = np.linspace(0, 5, 51)
    m = chart.extruded(s, np.exp(-s), np.linspace(-2, 2, 9))
    assert m.s[0] == pytest.approx(-5) and np.allclose(m.pressure, m.pressure[0])
    assert np.allclose(m.pressure[0], np.exp(-np.abs(m.s)))


def test_chart_config_refuses_bad_values():
    with pytest.raises(ParameterError):
        chart.ChartConfig(pitches=(0.0,))
    with pytest.raises(ParameterError):
        chart.ChartConfig(sets=("nope",))
    with pytest.raises(ParameterError, match="sphere_radius"):
        chart.ChartConfig(sphere_radius=0.0)
    with pytest.raises(ParameterError, match="sphere_quality"):
        chart.ChartConfig(sphere_quality="rough")
    assert chart.ChartConfig().spec(0.5).n == 17


PAD = Scene(skin="pad", thickness=1.0).section()


def test_on_the_pad_a_dot_is_translated_exactly_to_its_face_position():
    grid = np.linspace(-6, 6, 481)
    kernel = maps.on_grid(_gauss(), grid, grid)
    centres = surrogate.cell_centres(braille.LETTERS["r"])   # x-asymmetric: 3 dots left, 1 right
    assert np.array_equal(surrogate.bone_s_under(centres[:, 0], PAD), centres[:, 0])
    got = surrogate.superpose(kernel, centres, PAD)
    expect = maps.on_grid(lambda s, z: sum(_gauss(a, b)(s, z) for a, b in centres), grid, grid)
    assert np.max(np.abs(got.pressure - expect.pressure)) < 4e-3  # four dots x 1e-3 (bilinear, h = 0.025)


def test_interaction_weights_closed_forms():
    c = np.array([[-1.25, 0.0], [1.25, 0.0]])
    w0, heave = 0.2, 0.01
    alone = surrogate.interaction_weights(c, lambda dx, dz: np.where((dx == 0) & (dz == 0), w0, 0.0))
    assert np.allclose(alone, 1.0)  # no interaction: each dot carries a lone dot's load
    # the surface heaves by `heave` at the neighbour: w0 f1 - heave f2 = w0 -> f = w0 / (w0 - heave)
    up = surrogate.interaction_weights(c, lambda dx, dz: np.where((dx == 0) & (dz == 0), w0, -heave))
    assert np.allclose(up, w0 / (w0 - heave)) and np.all(up > 1)
    with pytest.raises(ParameterError):
        surrogate.interaction_weights(c, lambda dx, dz: np.zeros_like(dx))


def test_interaction_weights_follow_the_lone_dots_load_approach_law():
    """With load ~ approach^p two dots a heave h apart carry f = ((w0 + h f) / w0)^p each
    (a scalar fixed point, solved here by bisection); p = 1 is the linear model; a neighbour
    that pushes the surface below a dot's reach leaves it no load."""
    c = np.array([[-1.25, 0.0], [1.25, 0.0]])
    w0, heave = 0.2, 0.01
    defl = lambda dx, dz: np.where((dx == 0) & (dz == 0), w0, -heave)  # noqa: E731
    lin = surrogate.interaction_weights(c, defl)
    assert np.array_equal(surrogate.interaction_weights(c, defl, 1.0), lin)
    for p in (1.5, 2.0, 0.7):
        lo, hi = 0.5, 2.0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if mid < ((w0 + heave * mid) / w0) ** p else (lo, mid)
        got = surrogate.interaction_weights(c, defl, p)
        assert np.allclose(got, 0.5 * (lo + hi), rtol=1e-12)
        # a stiffening law (p > 1) amplifies the interaction beyond the linear model's
        assert (got[0] - 1.0) / (lin[0] - 1.0) == pytest.approx(p, rel=0.1)
    # three in a row, the middle one shielded: its neighbours press the surface down past it
    c3 = np.array([[-1.0, 0.0], [0.0, 0.0], [1.0, 0.0]])
    r = lambda dx, dz: np.hypot(dx, dz)  # noqa: E731
    sink = lambda dx, dz: np.where(r(dx, dz) < 0.5, w0, np.where(r(dx, dz) < 1.5, 0.6 * w0, 0.0))  # noqa: E731
    f3 = surrogate.interaction_weights(c3, sink, 2.0)   # outer: (1 - 0.6 f1)^2 = 1; middle: 1 - 1.2 < 0
    assert np.allclose(f3, [1.0, 0.0, 1.0], atol=1e-12)
    with pytest.raises(ParameterError, match="load exponent"):
        surrogate.interaction_weights(c, defl, 7.0)


def test_load_exponent_of_a_power_law():
    for p in (1.0, 1.5, 2.3):
        d = 0.4
        assert surrogate.load_exponent(3.0 * d ** p, 3.0 * (surrogate.SHALLOW * d) ** p) == pytest.approx(p, rel=1e-12)
    for bad in ((1.0, 1.0), (1.0, 1.2), (1.0, 0.0), (float("nan"), 0.5), (1.0, 1e-6)):
        with pytest.raises(ParameterError, match="lone-dot loads"):
            surrogate.load_exponent(*bad)


def test_fit_scale_recovers_a_known_factor_and_weights_scale_the_sum():
    grid = np.linspace(-6, 6, 241)
    kernel = maps.on_grid(_gauss(), grid, grid)
    fulls = {}
    for text in ("l", "r"):
        c = braille.dot_centres(text)
        s = surrogate.superpose(kernel, c, PAD, weights=np.full(len(c), 1.3))
        fulls[text] = s
    assert surrogate.fit_scale(kernel, fulls, PAD) == pytest.approx(1.3, rel=1e-12)
    err = surrogate.validate(kernel, fulls["r"], "r", PAD, scale=1.3)
    assert err["max_abs_over_peak"] < 1e-12 and err["within_tolerance"]
    assert not surrogate.validate(kernel, fulls["r"], "r", PAD)["within_tolerance"]  # 1 / 1.3: 23 % off


def test_validation_counts_only_the_square_the_arrays_read():
    """A difference beyond the chart's read square (the skin's far edge) is not an error of
    what the chart reads; one inside it is, in the chart's frame (the letter 'a' sits off the
    cell's centre: the square is shifted by chart_shift in the solver's frame; a shift of the
    wrong sign would take in one of the outside bumps, 1.5 mm < 2 x 1.17 mm beyond)."""
    grid = np.linspace(-11, 11, 441)
    kernel = maps.on_grid(_gauss(), grid, grid)
    cfg = chart.ChartConfig()
    ext = cfg.read_extent
    assert ext == pytest.approx(4.0 + 0.5 * 4.0 * 1.8)          # window 8, pitch 4, taxels 0.8 x pitch
    ds, dz = surrogate.chart_shift("a", PAD)
    assert ds == pytest.approx(-1.17) and dz == pytest.approx(2.34)   # dot 1: left, top row (+z)
    exact = surrogate.superpose(kernel, braille.dot_centres("a"), PAD, grid, grid)
    for where, inside in ((ext + 1.5, False), (-ext - 1.5, False), (ext - 1.0, True), (-ext + 1.0, True)):
        bump = 0.2 * _gauss(where - ds, -dz, 0.2)(*np.meshgrid(grid, grid))   # at (where, 0) in the chart frame
        full = maps.BoneMap(grid, grid, exact.pressure + bump, 0.0)
        whole = surrogate.validate(kernel, full, "a", PAD, taxel=0.4)
        read = surrogate.validate(kernel, full, "a", PAD, taxel=0.4, extent=ext)
        assert whole["max_abs_over_peak"] > 0.1 and read["extent_mm"] == ext
        if inside:
            assert read["max_abs_over_peak"] == pytest.approx(whole["max_abs_over_peak"], rel=1e-9)
        else:
            assert read["max_abs_over_peak"] < 1e-6 and read["within_tolerance_taxel"]


def test_fingertip_validation_refuses_an_x_asymmetric_text_and_the_skin_is_checked():
    cfg = chart.ChartConfig(skin="fingertip")
    with pytest.raises(ParameterError, match="mirror-symmetric"):
        chart.validate_surrogate([1.0], "silicone", ["l", "r"], cfg, cache=None)
    with pytest.raises(ParameterError, match="skin"):
        chart.ChartConfig(skin="glove")
    assert chart.ChartConfig().skin == "pad"


def test_validation_refuses_a_text_too_large_to_mesh_before_any_solve(monkeypatch):
    # "abc" on the 20 mm pad at t = 1 mm: 6e5 dofs against the 4e5 cap; the mesh refused it
    # only when its case came up, after the lone dot's and the other texts' solves
    def refuse(*a, **k):
        raise AssertionError("solving started")

    monkeypatch.setattr(chart, "solve_cached", refuse)
    texts = ["l", "abc"]
    with pytest.raises(ParameterError, match=r"validate text='abc'.*t = 1 mm fits the mesh limit.*dofs"):
        chart.validate_surrogate([1.0], "silicone", texts, chart.ChartConfig(), cache=None)


@pytest.mark.parametrize("text", ["", "ab\ncd"])
def test_validation_refuses_a_text_the_comparison_cannot_read_before_any_solve(monkeypatch, text):
    # the comparison (surrogate.chart_shift) reads one line of cells: the empty text (the lone
    # dot) and two lines were refused only after the solves (3.6 min for "" at t = 1 mm)
    def refuse(*a, **k):
        raise AssertionError("solving started")

    monkeypatch.setattr(chart, "solve_cached", refuse)
    cfg = chart.ChartConfig(mesh_size=2.0, refinement=2.0)  # coarse: both texts fit the mesh limit
    with pytest.raises(ParameterError, match=r"validate text=.*one line of Braille cells"):
        chart.validate_surrogate([1.0], "silicone", ["l", text], cfg, cache=None)


def _heave(dx, dz):
    """A lone dot's surface deflection (mm, downward positive): 0.1 under the dot, heaving up
    (-0.01) at the neighbours' 2.3-2.5 mm, as on a thin bonded layer."""
    r = np.hypot(dx, dz)
    return np.where(r < 1.0, 0.1, np.where(r < 3.0, -0.01, 0.0))


def test_interaction_letters_weigh_each_dot_by_its_neighbours():
    """stimulus_maps with letter_weights: each dot of a letter carries interaction_weights' load;
    a lone-dot letter ('a') is the kernel itself, and where the surface heaves beside a dot
    (w < 0) its neighbours carry more than a lone dot: 'b' (two dots 2.3-2.5 mm apart) by
    1 / (1 + w(d) / w0) = 1 / 0.9 each, the closed form of the 2 x 2 system."""
    grid = np.linspace(-6, 6, 241)
    kernel = maps.on_grid(_gauss(w=0.3), grid, grid)
    sec = chart.dot_scene(1.0, "silicone", chart.ChartConfig()).section()
    cfg = chart.ChartConfig(letters="ab", sets=("letters",))
    plain = chart.stimulus_maps(kernel, sec, {}, cfg)["letters"]
    weighed = chart.stimulus_maps(kernel, sec, {}, cfg, weights=chart.letter_weights(cfg, _heave))["letters"]
    assert np.allclose(weighed["a"].pressure, plain["a"].pressure)
    assert np.allclose(weighed["b"].pressure, plain["b"].pressure / 0.9)
    # a deflection that leaves a dot no load (neighbours lifting the surface by more than the
    # dot presses it) is refused by name; compute() then falls back to the sum with a note
    with pytest.raises(ParameterError, match="interaction weights of 'b'"):
        chart.letter_weights(cfg, lambda dx, dz: np.where(np.hypot(dx, dz) < 1, 0.1, -0.2))


def test_chart_letters_on_the_pad_and_the_paper_set_on_the_fingertip(monkeypatch):
    """compute() on analytic maps (no solve): which skin each set's scenes use, the letters
    told apart by a fine array, and the plate note when the depth reaches the dot height."""
    asked = []
    _fake_solver(monkeypatch, asked)
    deflected = []
    monkeypatch.setattr(chart, "surface_deflection", lambda rec, top: deflected.append(rec.scene) or _heave)
    # fallback off: the plate-aware surrogate at t = 3 (measured 50 % off, so by default its
    # letters are solved in full: below)
    cfg = chart.ChartConfig(thicknesses=(1.0, 3.0), pitches=(0.5,), noise_fs=(0.01,), letters="abcr1",
                            n_train=4, n_test=4, template_grid=2, fallback=False)
    ch = chart.compute(cfg, cache=None)
    assert ch.labels["letters"] == list("abcr1")  # '1' = number sign + a's cell: told apart from 'a' below
    # the interaction weights on the pad below the dot height (t = 1); past it (t = 3) the plate-aware sum
    assert ch.letters_models == {("silicone", 1.0): "interaction", ("silicone", 3.0): "plate + sum"}
    assert [(sc.thickness, sc.skin, sc.braille_text) for sc in deflected] == [(1.0, "pad", "")]
    skins = {(sc.dim, sc.indenter, sc.skin) for sc in asked}
    # t = 3 also asks the blank plate on the pad (flat, 3D) at the plate's own depth
    assert skins == {(3, "braille", "pad"), (3, "braille", "fingertip"), (2, "flat", "fingertip"),
                     (2, "curved", "fingertip"), (3, "flat", "pad"), (3, "sphere", "fingertip")}
    (blank,) = [sc for sc in asked if sc.indenter == "flat" and sc.dim == 3]
    assert blank.thickness == 3.0 and blank.indentation == pytest.approx(0.6 - 0.48)
    assert ch.accuracy("silicone", 1.0, "letters", 0.5, 0.01) >= 0.95  # separable dots at 0.5 mm pitch
    # t = 3: depth 0.6 mm > the dot height 0.48 mm: plate-aware letters, noted; t = 1 (0.2 mm) is not
    assert len(ch.notes) == 1 and ch.notes[0].startswith("t = 3 mm")
    # with a depth cap below the dot height no scene of t = 3 passes it and no blank plate is asked
    asked.clear()
    ch = chart.compute(chart.ChartConfig(**{**cfg.__dict__, "max_depth": 0.4}), cache=None)
    assert not ch.notes and not any(sc.indenter == "flat" and sc.dim == 3 for sc in asked)
    assert set(ch.letters_models.values()) == {"interaction"}
    depths = {(sc.thickness, round(sc.indentation, 9)) for sc in asked}
    # t = 1 keeps its 20 %; each lone dot on the pad also at 0.9 x its depth (its load exponent)
    assert depths == {(1.0, 0.2), (1.0, 0.18), (3.0, 0.4), (3.0, 0.36)}
    assert [c["depth_mm"] for c in ch.cutoffs if c["thickness_mm"] == 3.0] == [0.4, 0.4]
    # with the fallback (default) the project's measurements send t = 3 at 0.6 mm to full solves
    dot, _, blank, _, _ = chart._chart_scenes(cfg, "silicone", 3.0)
    why = chart.fallback_reason(chart.ChartConfig(**{**cfg.__dict__, "fallback": True}), "silicone", 3.0, dot, blank)
    assert why["status"] == "exceeds" and why["error"] > 0.3


def test_chart_progress_names_the_material_thickness_and_noise_of_each_accuracy(monkeypatch):
    """The progress printed 'letters pitch 0.5 mm: 1.00, 1.00' once per thickness: which
    thickness (and material) each line was, and that the numbers are accuracies per noise level,
    was not said."""
    _fake_solver(monkeypatch, [])
    monkeypatch.setattr(chart, "surface_deflection", lambda rec, top: _heave)
    cfg = chart.ChartConfig(thicknesses=(1.0, 2.0), sets=("letters",), pitches=(0.5,), noise_fs=(0.01, 0.05),
                            letters="ab", n_train=2, n_test=2, template_grid=1)
    said = []
    ch = chart.compute(cfg, cache=None, progress=said.append)
    lines = said[said.index("  silicone, t = 1 mm, letters: accuracy at noise 0.01, 0.05 x full scale"):]
    a = {t: ", ".join(f"{ch.accuracy('silicone', t, 'letters', 0.5, n):.2f}" for n in (0.01, 0.05)) for t in (1.0, 2.0)}
    assert lines == ["  silicone, t = 1 mm, letters: accuracy at noise 0.01, 0.05 x full scale",
                     f"    pitch 0.5 mm: {a[1.0]}",
                     "  silicone, t = 2 mm, letters: accuracy at noise 0.01, 0.05 x full scale",
                     f"    pitch 0.5 mm: {a[2.0]}"]


def test_compute_takes_a_cache_folder_as_ts_sweep_does(monkeypatch, tmp_path):
    """compute(cfg, "cache") failed with "AttributeError: 'str' object has no attribute 'key'"
    (a traceback from the solver's cache lookup); it takes a folder path, a ResultCache, or
    None (the default cache folder), and refuses anything else by name."""
    import tactileskin.sweep as sweep_mod
    from tactileskin.cache import ResultCache

    seen = []
    monkeypatch.setattr(sweep_mod, "run_sweep", lambda scenes, cache, **kw: seen.append(cache) or [])
    monkeypatch.setenv("TACTILESKIN_CACHE", str(tmp_path / "default"))
    for given, root in ((str(tmp_path / "c"), tmp_path / "c"), (tmp_path / "p", tmp_path / "p"),
                        (ResultCache(tmp_path / "r"), tmp_path / "r"), (None, tmp_path / "default")):
        assert chart.solve_cached([], given) == {}
        assert isinstance(seen[-1], ResultCache) and seen[-1].root == root
    with pytest.raises(ParameterError, match="cache=.3.* is invalid; valid: a folder path"):
        chart.compute(chart.ChartConfig(sets=("letters",), thicknesses=(1.0,), pitches=(1.0,)), 3)


def test_shapes_set_adds_a_3d_sphere_on_the_fingertip_and_tells_four_distinct_maps_apart(monkeypatch):
    """The shapes set: the paper's three and a sphere solved in 3D on the fingertip (radius and
    mesh preset from the config, the chart's depth cap); distinct maps are told apart by a fine
    array, and a sphere whose map equals the dot's is confused with it."""
    from types import SimpleNamespace

    from tactileskin.planner import quality_mesh

    asked = []
    grid = np.linspace(-8, 8, 161)
    widths = {"flat": 3.0, "curved": 1.5}

    def fake_solve(scenes, cache, on_event=None, workers=None):
        asked.extend(scenes)
        return {sc: SimpleNamespace(s=grid, pressure=np.exp(-(grid / widths.get(sc.indenter, 1.0)) ** 2), scene=sc)
                for sc in scenes}

    sphere_w = {"w": 1.0}
    monkeypatch.setattr(chart, "solve_cached", fake_solve)
    monkeypatch.setattr(chart, "bone_map_of", lambda rec: maps.on_grid(
        _gauss(w=sphere_w["w"] if rec.scene.indenter == "sphere" else 0.3), grid, grid))
    cfg = chart.ChartConfig(thicknesses=(3.0,), pitches=(0.5,), noise_fs=(0.01,), sets=("shapes",), n_train=4,
                            n_test=8, template_grid=2, max_depth=0.4, sphere_radius=4.0, sphere_quality="default")
    ch = chart.compute(cfg, cache=None)
    (sph,) = [sc for sc in asked if sc.indenter == "sphere"]
    assert (sph.dim, sph.skin, sph.indenter_radius, round(sph.indentation, 9)) == (3, "fingertip", 4.0, 0.4)
    assert (sph.mesh_size, sph.refinement) == quality_mesh("default", "sphere", 3, sph.thickness)
    assert ch.labels == {"shapes": ["flat", "curved", "braille", "sphere"]}
    assert ch.accuracy("silicone", 3.0, "shapes", 0.5, 0.01) >= 0.95
    from tactileskin.report.array_chart import markdown

    md = markdown(ch)
    assert "### silicone: flat / curved / Braille dot / sphere R4 (chance 0.25)" in md
    assert "sphere (R 4 mm): 3D at the `default` preset. Array: square taxels of 0.8 x pitch" in md
    sphere_w["w"] = 0.3  # the sphere reads exactly as the dot: those two cannot be told apart
    ch = chart.compute(cfg, cache=None)
    assert ch.accuracy("silicone", 3.0, "shapes", 0.5, 0.01) < 0.9


def test_plate_aware_superposition_counts_the_plate_once():
    """A lone dot with its plate = plate + g; a cell = plate + sum of g translated: the
    plate-aware model is exact, the plate-blind sum counts the plate once per dot."""
    # h = 0.025: bilinear error per dot <= h^2/8 (|f_ss| + |f_zz|) = 1e-3 (w = 0.4), over a peak > 1.5
    grid = np.linspace(-8, 8, 641)
    plate = maps.on_grid(lambda s, z: np.full(np.shape(s), 0.5), grid, grid)
    dot = maps.on_grid(lambda s, z: 0.5 + _gauss()(s, z), grid, grid)
    k = surrogate.plate_kernel(dot, plate)
    assert np.allclose(k.pressure, _gauss()(*np.meshgrid(grid, grid)))
    sec = Scene(skin="pad", thickness=3.0).section()
    text = "\u283f"
    c = braille.dot_centres(text)
    full = maps.on_grid(lambda s, z: 0.5 + sum(_gauss(a, b)(s, z) for a, b in c), grid, grid)
    aware = surrogate.validate(k, full, text, sec, base=plate)
    blind = surrogate.validate(dot, full, text, sec)
    assert aware["max_abs_over_peak"] < 2e-3 and aware["within_tolerance"]
    # six dots count the plate (0.5) six times: error 5 x 0.5 over the peak ~1.5
    assert blind["max_abs_over_peak"] > 1.0
    assert surrogate.fit_scale(k, {text: full}, sec, base=plate) == pytest.approx(1.0, abs=2e-3)


def test_taxel_average_keeps_a_linear_map_and_matches_the_box_average_of_a_gaussian():
    from scipy.special import erf

    g = np.linspace(-4, 4, 321)
    a, w = 0.4, 0.5
    lin = maps.taxel_averaged(maps.on_grid(lambda s, z: 1 + 0.3 * s - 0.2 * z, g, g), a)
    # a symmetric box average of a linear map is the map itself (away from the zero-padded edge)
    assert maps.interpolator(lin)(np.array(1.0), np.array(-0.5)) == pytest.approx(1.4, abs=1e-9)
    gauss = maps.taxel_averaged(maps.on_grid(_gauss(w=w), g, g), a)
    exact = (np.sqrt(2 * np.pi) * w / a * erf(a / (2 * np.sqrt(2) * w))) ** 2  # box mean of the Gaussian at 0
    # trapezoid with h = a / 8 and bilinear sampling on h = 0.025: error ~ h^2 max|f''| / 12 ~ 2e-3
    assert maps.interpolator(gauss)(np.array(0.0), np.array(0.0)) == pytest.approx(exact, abs=3e-3)
    # ripple finer than the taxel is averaged out: +-5 % at wavelength a / 2 leaves < 0.5 %
    rip = maps.on_grid(lambda s, z: 1 + 0.05 * np.cos(4 * np.pi * s / a), g, g)
    r = maps.taxel_averaged(rip, a)
    inner = r.pressure[np.ix_(np.abs(r.z) < 3, np.abs(r.s) < 3)]
    assert inner.size > 100 and np.ptp(inner) < 0.01
    with pytest.raises(ParameterError):
        maps.taxel_averaged(lin, 0.0)


def test_validation_past_the_dot_height_is_plate_aware(monkeypatch, tmp_path):
    """validate_surrogate at t = 3 (depth 0.6 mm > dot height): it asks the blank plate and
    its plate-aware model reproduces a full map built as plate + dots, the plate-blind sum not."""
    from types import SimpleNamespace

    grid = np.linspace(-8, 8, 641)  # h = 0.025 (see test_plate_aware_superposition_counts_the_plate_once)
    plate = maps.on_grid(lambda s, z: np.full(np.shape(s), 0.5), grid, grid)
    lone = maps.on_grid(lambda s, z: 0.5 + _gauss()(s, z), grid, grid)
    c = braille.dot_centres("l")
    full = maps.on_grid(lambda s, z: 0.5 + sum(_gauss(a, b)(s, z) for a, b in c), grid, grid)
    asked = []

    def fake_solve(scenes, cache, on_event=None, workers=None):
        asked.extend(scenes)
        return {sc: SimpleNamespace(scene=sc, path=tmp_path,
                                        summary=_reaction(sc)) for sc in scenes}

    def bone(rec):
        sc = rec.scene
        return plate if sc.indenter == "flat" else lone if sc.braille_text == "" else full

    monkeypatch.setattr(chart, "solve_cached", fake_solve)
    monkeypatch.setattr(chart, "bone_map_of", bone)
    monkeypatch.setattr(chart, "read_bone_map", lambda path: full)
    with pytest.raises(ParameterError):
        chart.blank_scene(chart.dot_scene(1.0, "silicone", chart.ChartConfig()))  # 0.2 mm: no plate
    rows = chart.validate_surrogate([3.0], "silicone", ["l"], chart.ChartConfig(), cache=None)
    (blank,) = [sc for sc in asked if sc.indenter == "flat"]
    assert blank.skin == "pad" and blank.dim == 3 and blank.indentation == pytest.approx(0.6 - 0.48)
    by = {r["model"].split(" x ")[0]: r for r in rows}
    assert set(by) == {"sum", "plate + sum"} and all(r["depth_mm"] == pytest.approx(0.6) for r in rows)
    assert by["plate + sum"]["max_abs_over_peak"] < 2e-3 and by["plate + sum"]["within_tolerance_taxel"]
    assert by["sum"]["max_abs_over_peak"] > 0.5  # three dots count the plate three times


def test_validation_against_flagged_solves_is_not_counted(monkeypatch, tmp_path):
    """A validation row judged against a full solve that quality flags (no contact, a coarse
    mesh, ...) showed the surrogate "within 5 %" all the same, the letters marked trusted. Now
    the row carries the solves' status, array.validity skips it, the table and the notes say so."""
    from types import SimpleNamespace

    from tactileskin.array import validity
    from tactileskin.report.array_chart import suspect, validation_table

    grid = np.linspace(-8, 8, 641)
    lone = maps.on_grid(_gauss(), grid, grid)
    full = maps.on_grid(lambda s, z: sum(_gauss(a, b)(s, z) for a, b in braille.dot_centres("l")), grid, grid)
    flag = {"text": "l"}

    def fake_solve(scenes, cache, on_event=None, workers=None):
        status = lambda sc: "suspect: coarse_mesh" if sc.braille_text == flag["text"] else "ok"  # noqa: E731
        return {sc: SimpleNamespace(scene=sc, path=tmp_path, summary={**_reaction(sc), "status": status(sc)})
                for sc in scenes}

    monkeypatch.setattr(chart, "solve_cached", fake_solve)
    monkeypatch.setattr(chart, "bone_map_of", lambda rec: lone)
    monkeypatch.setattr(chart, "read_bone_map", lambda path: full)
    monkeypatch.setattr(chart, "surface_deflection", lambda rec, top: _heave)
    cfg = chart.ChartConfig(skin="pad")
    args = ("silicone", "pad", cfg.mesh_for(1.0), 1.0, 0.2)
    for text, counted in (("l", False), ("", False), (None, True)):  # the full solve, the lone dot's, none
        flag["text"] = text
        rows = [r for r in chart.validate_surrogate([1.0], "silicone", ["l"], cfg, cache=None) if r["model"] == "sum"]
        assert (rows[0]["solve_status"] == "ok") is counted
        assert rows[0]["within_tolerance_taxel"]  # the sum is exact here: only the flag can refuse it
        m = validity.measured(*args, validation=rows, extent=cfg.read_extent, taxel=cfg.min_taxel)
        assert (validity.RUN_SOURCE in m["source"]) is counted, m  # beside the shipped measurements
        ch = SimpleNamespace(notes=[], config=SimpleNamespace(sets=()))
        assert any("not counted" in n and "coarse_mesh" in n for n in suspect(ch, rows)) is not counted
        assert ("not counted (suspect solves)" in "\n".join(validation_table(rows, "t"))) is not counted


@pytest.mark.slow
def test_solve_cached_on_two_workers_matches_one_and_solves_a_repeated_scene_once(tmp_path):
    """The chart's batch solve: two worker processes give the records one process gives (same
    cache keys, same peaks), and a scene asked twice (the same blank plate for two sets) is
    solved once."""
    from tactileskin.cache import ResultCache

    scenes = [Scene(thickness=t, indenter="flat", mesh_size=1.0, refinement=5.0) for t in (1.0, 3.0)]
    events = []
    par = chart.solve_cached(scenes + scenes[:1], ResultCache(tmp_path / "a"), on_event=events.append, workers=2)
    ser = chart.solve_cached(scenes, ResultCache(tmp_path / "b"), workers=1)
    assert [e.status for e in events] == ["done", "done"]
    assert set(par) == set(ser) == set(scenes)
    for sc in scenes:
        assert par[sc].summary["peak_mpa"] == pytest.approx(ser[sc].summary["peak_mpa"], rel=1e-12)
        assert np.allclose(par[sc].pressure, ser[sc].pressure, rtol=1e-12, atol=0)


def test_letters_trust_from_the_measurement_file_and_from_this_runs_validation():
    """array.validity: the worst measured taxel error of the plain sum at a (material, skin, mesh,
    t, depth), 'not validated' where nothing matches, and this run's validation rows first."""
    from tactileskin.array import validity

    mesh = (1.2, 8.0)
    t1 = validity.measured("silicone", "pad", mesh, 1.0, 0.2)  # the file's worst row there: f
    assert t1["status"] == "exceeds" and t1["error"] == pytest.approx(0.0849) and {"⠿", "l", "f"} <= set(t1["texts"])
    assert t1["reference_mesh"] == (0.8, 8.0) and validity.finer_reference(t1, mesh)
    # (against the full solves on 0.8 / 8, not the 10.3 % against 1.2 / 8 ones)
    t2 = validity.measured("silicone", "pad", mesh, 2.0, 0.4)
    assert t2["status"] == "exceeds" and t2["error"] > validity.tolerance()
    t2i = validity.measured("silicone", "pad", mesh, 2.0, 0.4, model="interaction", extent=7.6)
    # against full solves on 0.8 / 8 (4.2 %), not the 4.4 % against 1.2 / 8 ones
    assert t2i["status"] == "within" and t2i["error"] == pytest.approx(0.0416)
    assert t2i["reference_mesh"] == (0.8, 8.0)
    # t = 0.5: 4.6 % against full solves on the chart's 1.2 / 8, 7.3 % against 0.8 / 8 and 5.2 %
    # against 0.6 / 8 ones: the finest reference decides (marked, and no fallback); a 0.8 / 8
    # chart reads 6.1 % against its own mesh and 3.6 % against 0.6 / 8
    t05 = validity.measured("silicone", "pad", mesh, 0.5, 0.1, model="interaction", extent=7.6)
    assert t05["status"] == "exceeds" and t05["error"] == pytest.approx(0.052) and t05["reference_mesh"] == (0.6, 8.0)
    assert validity.finer_reference(t05, mesh)
    m08 = validity.measured("silicone", "pad", (0.8, 8.0), 0.5, 0.1, model="interaction", extent=7.6)
    assert m08["status"] == "within" and m08["error"] == pytest.approx(0.0356) and m08["reference_mesh"] == (0.6, 8.0)
    # the file's rows were measured inside 7.6 mm: a chart reading farther out is not covered
    assert validity.measured("silicone", "pad", mesh, 2.0, 0.4, model="interaction", extent=9.0)["status"] == \
        "not validated"
    # another depth, mesh, skin or material: not validated
    for args in (("silicone", "pad", mesh, 2.0, 0.3), ("silicone", "pad", (1.2, 4.0), 1.0, 0.2),
                 ("silicone", "fingertip", mesh, 1.0, 0.2), ("polyurethane", "fingertip", mesh, 1.0, 0.2)):
        assert validity.measured(*args)["status"] == "not validated"
    rows = [{"material": "polyurethane", "thickness_mm": 1.0, "depth_mm": 0.2, "text": "l", "model": "sum",
             "max_abs_over_peak_taxel": 0.03},
            {"material": "polyurethane", "thickness_mm": 1.0, "depth_mm": 0.2, "text": "l", "model": "interaction",
             "max_abs_over_peak_taxel": 0.5}]
    got = validity.measured("polyurethane", "fingertip", mesh, 1.0, 0.2, rows)
    assert got["status"] == "within" and got["error"] == 0.03 and got["source"] == "this run's validation"
    # rows against full solves on a finer mesh than the chart's take precedence (the coarse full
    # solve carries its own discretisation error), whatever their error
    fine = [dict(rows[0], text="⠿", max_abs_over_peak_taxel=0.031, reference_mesh=[0.8, 8.0]),
            dict(rows[0], text="l", max_abs_over_peak_taxel=0.029, reference_mesh=[0.8, 8.0]),
            dict(rows[0], text="⠿", max_abs_over_peak_taxel=0.068, reference_mesh=[1.2, 8.0])]
    got = validity.measured("polyurethane", "fingertip", mesh, 1.0, 0.2, fine)
    assert got["status"] == "within" and got["error"] == 0.031 and got["texts"] == ["⠿", "l"]
    worse = [dict(fine[0], max_abs_over_peak_taxel=0.09), fine[2]]
    assert validity.measured("polyurethane", "fingertip", mesh, 1.0, 0.2, worse)["error"] == 0.09
    # each character at its own finest reference: a coarser row of another character still counts
    other = [fine[0], dict(rows[0], text="k", max_abs_over_peak_taxel=0.06)]
    got = validity.measured("polyurethane", "fingertip", mesh, 1.0, 0.2, other)
    assert got["error"] == 0.06 and got["reference_mesh"] == mesh and not validity.finer_reference(got, mesh)
    # this run's rows join the project's measurements, never hide them: the file puts the sum
    # 8.5 % off at t = 1 on the silicone pad (f); a run that validated only the full cell within
    # 3 % (against the same 0.8 / 8 solves) leaves it at 8.5 %, a worse run row raises it
    mine = [dict(rows[0], material="silicone", text="⠿", reference_mesh=[0.8, 8.0])]
    got = validity.measured("silicone", "pad", mesh, 1.0, 0.2, mine)
    assert got["status"] == "exceeds" and got["error"] == pytest.approx(t1["error"]) and "⠿" in got["texts"]
    assert got["source"].startswith("this run's validation; ")
    got = validity.measured("silicone", "pad", mesh, 1.0, 0.2, [dict(mine[0], max_abs_over_peak_taxel=0.12)])
    assert got["error"] == 0.12
    # a row measured inside a smaller square than the chart reads does not answer for it
    rows[0]["extent_mm"] = 4.5
    assert validity.measured("polyurethane", "fingertip", mesh, 1.0, 0.2, rows, extent=4.5)["status"] == "within"
    assert validity.measured("polyurethane", "fingertip", mesh, 1.0, 0.2, rows, extent=7.6)["status"] == "not validated"


def test_chart_report_marks_letters_whose_surrogate_is_not_within_tolerance(monkeypatch, tmp_path):
    """The report flags (†, a trust table, a Suspect line, a qualified 0.75 mm verdict) every
    thickness whose letters rest on a surrogate not shown within 5 %; so does accuracies.csv."""
    from tactileskin.report.array_chart import markdown, write_outputs

    _fake_solver(monkeypatch, [])
    monkeypatch.setattr(chart, "surface_deflection", lambda rec, top: _heave)
    cfg = chart.ChartConfig(thicknesses=(1.0, 2.0), materials=("silicone",), pitches=(0.5, 0.75),
                            noise_fs=(0.01,), letters="abcr", n_train=4, n_test=4, template_grid=2,
                            mesh_size=1.2)
    ch = chart.compute(cfg, cache=None)
    # the file's interaction rows of a 1.2 / 8 chart: t = 1 5.5 % (f, against 0.8 / 8 full
    # solves: finer than the chart's mesh, so no fallback, marked), t = 2 4.2 % (against 0.8 / 8 too)
    md = markdown(ch)
    assert not ch.fallbacks and "| 1 † | 0.01 |" in md and "| 2 | 0.01 |" in md
    assert "| silicone | 1 | interaction | 5.5% |" in md and "| silicone | 2 | interaction | 4.2% |" in md
    assert "against full solves on the finer 0.8 / 8 mesh" in md
    assert ("**Suspect:** silicone: the letters' surrogate is not shown within 5% of full solves at t = 1 mm "
            "(5.5%); ") in md
    assert md.index("**Suspect:**") < md.index("### The skin as a spatial filter")  # at the top
    rows = (write_outputs(ch, tmp_path / "o")["csv"]).read_text().splitlines()
    assert rows[0].endswith(",status")
    letters = [r for r in rows[1:] if ",letters," in r and r.startswith("silicone,1,")]
    assert letters and all(r.endswith('"indicative: the letters\' surrogate is off by 5.5%"') for r in letters
                           if r.startswith("silicone,1,"))
    assert all(r.endswith(",ok") for r in rows[1:] if r.startswith("silicone,2,") or ",letters," not in r)
    assert ("| silicone | 0.75 mm pitch reads Braille at t = 1 mm | supported (indicative: the letters' surrogate "
            "is off by 5.5% at t = 1 mm) |") in md
    # the plain sum is judged by the sum's rows (t = 1 8.5 %, t = 2 14.6 %, both against 0.8 / 8): marked
    # where it is kept (no fallback to full solves)
    sum_cfg = chart.ChartConfig(**{**cfg.__dict__, "letters_model": "sum", "fallback": False})
    ch = chart.compute(sum_cfg, cache=None)
    md = markdown(ch)
    assert "| 1 † | 0.01 |" in md and "| 2 † | 0.01 |" in md
    assert "| silicone | 1 | sum | 8.5% |" in md and "| silicone | 2 | sum | 14.6% |" in md
    assert ("**Suspect:** silicone: the letters' surrogate is not shown within 5% of full solves at t = 1 mm "
            "(8.5%), t = 2 mm (14.6%)") in md
    assert ("| silicone | 0.75 mm pitch reads Braille at t = 1 mm | supported (indicative: the letters' surrogate "
            "is off by 8.5% at t = 1 mm) |") in md
    # this run's validation within 5 % at t = 1 does not hide the file's 8.5 % (f): still marked
    rows = [{"material": "silicone", "thickness_mm": 1.0, "depth_mm": 0.2, "text": "⠿", "model": "sum",
             "rel_l2": 0.02, "max_abs_over_peak": 0.04, "peak_rel": -0.01, "within_tolerance": True,
             "max_abs_over_peak_taxel": 0.03, "peak_rel_taxel": -0.01, "within_tolerance_taxel": True,
             "extent_mm": cfg.read_extent}]
    md = markdown(ch, rows)
    assert "| 1 † | 0.01 |" in md and "| 2 † | 0.01 |" in md and "| silicone | 1 | sum | 8.5% |" in md
    # a run row worse than the file's, of a character the file has not, raises it
    rows[0].update(text="k", max_abs_over_peak_taxel=0.11)
    assert "| silicone | 1 | sum | 11.0% |" in markdown(ch, rows)
    # ... unless it was measured in a smaller square than this chart reads: the file's rows alone
    rows[0]["extent_mm"] = cfg.read_extent - 1.0
    assert "| silicone | 1 | sum | 8.5% |" in markdown(ch, rows)
    ch = chart.compute(cfg, cache=None)
    # on the fingertip nothing is validated: every letters row marked, the 0.75 mm verdict qualified
    md = markdown(chart.compute(chart.ChartConfig(**{**cfg.__dict__, "skin": "fingertip"}), cache=None))
    assert "| 1 † | 0.01 |" in md and "(indicative: the letters' surrogate is not validated at t = 1 mm)" in md


def test_a_full_solve_is_placed_in_the_full_cell_frame():
    """surrogate.placed: the map of a letter solved with its own dots centred (dot_centres) lands
    with a peak on each of its dots in the chart's full-cell frame (cell_centres); on the pad
    the translation is exact, so the superposition of Gaussians placed there matches it."""
    from tactileskin.geometry.braille import LETTERS as MASKS

    sec = chart.dot_scene(1.0, "silicone", chart.ChartConfig()).section()
    grid = np.linspace(-9, 9, 361)
    for letter in "abk1":
        own = braille.dot_centres(letter)
        cell = surrogate.char_centres(letter)
        if letter in MASKS:
            assert np.allclose(cell, surrogate.cell_centres(MASKS[letter]))
        assert not np.allclose(own.mean(axis=0), cell.mean(axis=0))  # the frames differ for these letters
        full = maps.on_grid(lambda s, z: sum(_gauss(a, b, w=0.3)(s, z) for a, b in own), grid, grid)
        got = surrogate.placed(full, letter, sec)
        want = maps.on_grid(lambda s, z: sum(_gauss(a, b, w=0.3)(s, z) for a, b in cell), grid, grid)
        # the grid moves by the frames' offset exactly (s = x on the pad) ...
        assert np.allclose(got.s - grid, cell[:, 0].mean() - own[:, 0].mean(), atol=1e-12)
        assert np.allclose(got.z - grid, cell[:, 1].mean() - own[:, 1].mean(), atol=1e-12)
        # ... and the values compare within the bilinear resampling error of relative_error:
        # h^2 / 8 |f''| per direction = 0.05^2 / 8 / 0.3^2 = 0.35 % of the peak, two directions
        assert maps.relative_error(got, want)["max_abs_over_peak"] < 0.01
    with pytest.raises(ParameterError):
        surrogate.placed(full, "a\nb", sec)


def test_chart_full_letters_model_solves_every_letter_and_is_not_marked(monkeypatch, tmp_path):
    """letters_model = "full": one 3D scene per letter and thickness is asked, the letters' maps
    come from those solves, and the report marks no letters row (no surrogate)."""
    from tactileskin.report.array_chart import markdown, suspect

    grid = np.linspace(-8, 8, 161)
    asked = []
    _fake_solver(monkeypatch, asked, tmp_path, grid)
    read = []
    monkeypatch.setattr(chart, "read_bone_map", lambda path: read.append(path) or maps.on_grid(_gauss(w=0.5), grid, grid))
    cfg = chart.ChartConfig(thicknesses=(2.0,), pitches=(0.5,), noise_fs=(0.01,), letters="abk", n_train=4,
                            n_test=4, template_grid=2, letters_model="full", sets=("letters",))
    ch = chart.compute(cfg, cache=None)
    texts = sorted(sc.braille_text for sc in asked if sc.dim == 3)
    assert texts == ["", "a", "b", "k"] and len(read) == 3
    md = markdown(ch)
    assert "| 2 | 0.01 |" in md and "full 3D solves of every letter" in md and not suspect(ch)
    with pytest.raises(ParameterError, match="letters_model"):
        chart.ChartConfig(letters_model="guess")


def test_chart_solves_the_letters_in_full_where_the_surrogate_is_measured_past_the_tolerance(monkeypatch, tmp_path):
    """Validation rows that put the surrogate at 7 % (> 5 %) at t = 2 and 3 % at t = 1: the
    letters of t = 2 alone are solved in full (one scene per letter), recorded as a fallback
    with its error, and the report trusts both thicknesses; with fallback off the t = 2
    letters stay on the surrogate and are marked indicative (suspect)."""
    from tactileskin.report.array_chart import letters_trust, markdown, suspect

    grid = np.linspace(-8, 8, 161)
    asked = []
    _fake_solver(monkeypatch, asked, tmp_path, grid)
    monkeypatch.setattr(chart, "read_bone_map", lambda path: maps.on_grid(_gauss(w=0.5), grid, grid))
    monkeypatch.setattr(chart, "surface_deflection", lambda rec, top: _heave)
    cfg = chart.ChartConfig(thicknesses=(1.0, 2.0), pitches=(0.5,), noise_fs=(0.01,), letters="abk", n_train=4,
                            n_test=4, template_grid=2, sets=("letters",))
    rows = [{"material": "silicone", "thickness_mm": t, "depth_mm": 0.2 * t, "text": "⠿", "model": "interaction",
             "max_abs_over_peak_taxel": e, "extent_mm": cfg.read_extent, "rel_l2": e / 2, "max_abs_over_peak": e,
             "peak_rel": -e / 2, "within_tolerance": e <= 0.05, "peak_rel_taxel": -e / 2,
             "within_tolerance_taxel": e <= 0.05} for t, e in ((1.0, 0.03), (2.0, 0.07))]
    ch = chart.compute(cfg, cache=None, validation=rows)
    full = sorted((sc.thickness, sc.braille_text) for sc in asked if sc.dim == 3 and sc.braille_text)
    assert full == [(2.0, "a"), (2.0, "b"), (2.0, "k")]
    assert ch.letters_models == {("silicone", 1.0): "interaction", ("silicone", 2.0): "full"}
    assert ch.fallbacks[("silicone", 2.0)]["error"] == pytest.approx(0.07)
    # no second lone-dot solve where the letters are solved in full
    assert sorted(round(sc.indentation, 9) for sc in asked if sc.dim == 3 and not sc.braille_text) == [0.18, 0.2, 0.4]
    trust = letters_trust(ch, rows)
    assert trust[("silicone", 1.0)]["status"] == "within" and trust[("silicone", 2.0)]["status"] == "full"
    assert "measured 7.0% off" in trust[("silicone", 2.0)]["source"] and not suspect(ch, rows)
    assert "| 2 | 0.01 |" in markdown(ch, rows)  # the t = 2 letters rows carry no † mark
    only2 = chart.compute(chart.ChartConfig(**{**cfg.__dict__, "thicknesses": (2.0,)}), cache=None, validation=rows)
    assert "full 3D solves of every letter (the surrogate is measured past the tolerance" in markdown(only2, rows)
    asked.clear()
    off = chart.compute(chart.ChartConfig(**{**cfg.__dict__, "fallback": False}), cache=None, validation=rows)
    assert not any(sc.braille_text for sc in asked) and not off.fallbacks
    assert any("t = 2 mm (7.0%)" in n for n in suspect(off, rows)) and "| 2 † | 0.01 |" in markdown(off, rows)
    with pytest.raises(ParameterError, match="fallback"):
        chart.ChartConfig(fallback="yes")


def test_no_fallback_where_the_surrogate_exceeds_only_against_a_finer_mesh(monkeypatch, tmp_path):
    """Rows that put the surrogate 7 % off full solves on a finer mesh (0.8 / 8) than the
    chart's (1.2 / 8), and 3 % off its own: full solves on the chart's mesh would carry that
    mesh's error too, so the letters stay on the surrogate, marked indicative, and the report
    and the progress line say why; the same 7 % against the chart's own mesh falls back."""
    from tactileskin.report.array_chart import markdown, suspect

    grid = np.linspace(-8, 8, 161)
    asked, said = [], []
    _fake_solver(monkeypatch, asked, tmp_path, grid)
    monkeypatch.setattr(chart, "read_bone_map", lambda path: maps.on_grid(_gauss(w=0.5), grid, grid))
    monkeypatch.setattr(chart, "surface_deflection", lambda rec, top: _heave)
    cfg = chart.ChartConfig(thicknesses=(1.0,), pitches=(0.5,), noise_fs=(0.01,), letters="ab", n_train=4,
                            n_test=4, template_grid=2, sets=("letters",), mesh_size=1.2)

    def row(text, e, ref):
        return {"material": "silicone", "thickness_mm": 1.0, "depth_mm": 0.2, "text": text, "model": "interaction",
                "max_abs_over_peak_taxel": e, "extent_mm": cfg.read_extent, "reference_mesh": ref, "rel_l2": e / 2,
                "max_abs_over_peak": e, "peak_rel": -e / 2, "within_tolerance": e <= 0.05, "peak_rel_taxel": -e / 2,
                "within_tolerance_taxel": e <= 0.05}

    rows = [row("\u283f", 0.03, [1.2, 8.0]), row("f", 0.07, [0.8, 8.0]), row("l", 0.04, [0.8, 8.0])]
    ch = chart.compute(cfg, cache=None, validation=rows, progress=said.append)
    assert not ch.fallbacks and not any(sc.braille_text for sc in asked)
    assert any("7.0% off full solves on the finer 0.8 / 8 mesh" in m for m in said)
    md = markdown(ch, rows)
    assert "| 1 † | 0.01 |" in md and "against full solves on the finer 0.8 / 8 mesh" in md
    assert any("t = 1 mm (7.0%)" in n for n in suspect(ch, rows))
    # a character the project's file has not measured (k), 7 % off full solves on the chart's mesh
    own = [row("k", 0.07, [1.2, 8.0])]
    ch2 = chart.compute(cfg, cache=None, validation=own)
    assert ch2.fallbacks[("silicone", 1.0)]["error"] == pytest.approx(0.07)
    # ... and so does one 5.4 % off the chart's own mesh, though the project's file has a worse
    # character (f, 5.5 %) measured against the finer 0.8 / 8 only: the worst row is not the
    # only one that decides
    ch3 = chart.compute(cfg, cache=None, validation=[row("k", 0.054, [1.2, 8.0])])
    assert ("silicone", 1.0) in ch3.fallbacks


def test_chart_falls_back_to_the_sum_where_the_interaction_weights_fail(monkeypatch):
    """A deflection that gives a dot no load: the chart is still drawn, from the plain sum,
    with a note (suspect), and the trust table judges the sum's rows."""
    from tactileskin.report.array_chart import suspect

    _fake_solver(monkeypatch, [])
    monkeypatch.setattr(chart, "surface_deflection",
                        lambda rec, top: lambda dx, dz: np.where(np.hypot(dx, dz) < 1, 0.1, -0.2))
    cfg = chart.ChartConfig(thicknesses=(1.0,), pitches=(0.5,), noise_fs=(0.01,), letters="abc", n_train=4,
                            n_test=4, template_grid=2, sets=("letters",))
    ch = chart.compute(cfg, cache=None)
    assert ch.letters_models == {("silicone", 1.0): "sum"}
    assert any("fall back to the plain sum" in n for n in ch.notes)
    assert any("fall back to the plain sum" in n for n in suspect(ch))


def test_chart_mesh_follows_the_3d_default_where_that_is_finer():
    """The chart's single dots: the 3D Braille `default` preset below t = 3 mm (0.8 / 8, where
    1.2 / 8 reads the full cell 5 % low), CHART_MESH (1.2 / 8) from it; a user's mesh size or
    refinement applies at every thickness."""
    from tactileskin import presets

    cfg = chart.ChartConfig(thicknesses=(0.5, 1.0, 2.0, 3.0, 5.0))
    got = {t: cfg.mesh_for(t) for t in cfg.thicknesses}
    for t, m in got.items():
        preset = presets.mesh(3, "default", braille=True, thickness=t)
        finer = preset[0] / preset[1] < config.CHART_MESH[0] / config.CHART_MESH[1]
        assert m == (tuple(float(v) for v in preset) if finer else config.CHART_MESH), t
        sc = chart.dot_scene(t, "silicone", cfg)
        assert (sc.mesh_size, sc.refinement) == m
    assert got[1.0] == (0.8, 8.0) and got[3.0] == (1.2, 8.0)
    assert {chart.ChartConfig(mesh_size=1.0).mesh_for(t) for t in (1.0, 5.0)} == {(1.0, 8.0)}
    assert {chart.ChartConfig(refinement=4.0).mesh_for(t) for t in (1.0, 5.0)} == {(1.2, 4.0)}


def test_default_chart_reads_its_own_mesh_rows_below_3_mm():
    """The default chart judges t < 3 mm by the rows measured on its 0.8 / 8 single dots against
    full solves on that mesh (data/surrogate_validation.json), not by the 1.2 / 8 chart's."""
    cfg = chart.ChartConfig(thicknesses=(1.0,), materials=("silicone",))
    m = chart.surrogate_trust(cfg, "silicone", 1.0, "interaction")
    assert m["reference_mesh"] == (0.8, 8.0) == cfg.mesh_for(1.0)
    coarse = chart.surrogate_trust(chart.ChartConfig(thicknesses=(1.0,), mesh_size=1.2), "silicone", 1.0, "interaction")
    assert coarse["reference_mesh"] == (0.8, 8.0) and coarse["error"] != m["error"]
    assert "f" in m["texts"] and m["status"] in ("within", "exceeds")
