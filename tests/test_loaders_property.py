"""Property tests of the scene, material and sweep loaders (issue #12): every generated
input, of right or wrong types and keys, or arbitrary bytes, either loads or raises the
project's ParameterError (nothing else), and a loaded scene survives a TOML round trip with
the same key."""

from __future__ import annotations

import dataclasses

import pytest
import tomli_w
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from tactileskin import sweep
from tactileskin.errors import ParameterError
from tactileskin.geometry.fingertip import OVERRIDES
from tactileskin.materials.presets import Material
from tactileskin.scene import Scene

SETTINGS = settings(max_examples=100, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])

# --- TOML-able values: right and wrong types --------------------------------------------------

_text = st.text(st.characters(blacklist_categories=("Cs",)), max_size=12)
scalars = st.one_of(st.booleans(), st.integers(-10, 10), st.floats(allow_nan=True, allow_infinity=True),
                    st.floats(-10, 10), _text)
junk = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                     st.dictionaries(_text, inner, max_size=3)),
                    max_leaves=8)


def _maybe(good):
    """Mostly (6 in 7) values of the right kind, sometimes anything."""
    return st.sampled_from([True] * 6 + [False]).flatmap(lambda ok: good if ok else junk)


def _rarely():
    """True about one time in ten (shrinks to False)."""
    return st.sampled_from([False] * 9 + [True])


SCENE_FIELDS = {
    "thickness": _maybe(st.floats(0.3, 6.0)),
    "material": _maybe(st.sampled_from(["silicone", "polyurethane", "rubber"])),
    "indenter": _maybe(st.sampled_from(["flat", "curved", "braille", "round"])),
    "braille_text": _maybe(st.text(alphabet="abcXYZ19 ,.\n[]", max_size=6)),
    "braille_standard": _maybe(st.sampled_from(["standard_american", "ada_2010", "nope"])),
    "depth": _maybe(st.floats(0.01, 3.0)),
    "depth_fraction": _maybe(st.floats(0.0, 0.7)),
    "rate": _maybe(st.floats(1e-7, 1e7)),
    "dim": _maybe(st.sampled_from([2, 3, 4, 2.0])),
    "order": _maybe(st.sampled_from([1, 2, 3])),
    "mesh_size": _maybe(st.floats(0.005, 6.0)),
    "refinement": _maybe(st.floats(0.5, 25.0)),
    "formulation": _maybe(st.sampled_from(["mixed", "displacement", "fbar"])),
    "viscoelastic": _maybe(st.booleans()),
    "fingertip": _maybe(st.dictionaries(st.sampled_from(list(OVERRIDES) + ["hieght"]),
                                        st.floats(0.1, 200.0), max_size=2)),
}


@st.composite
def scene_dicts(draw):
    keys = draw(st.sets(st.sampled_from(sorted(SCENE_FIELDS)), max_size=6))
    d = {k: draw(SCENE_FIELDS[k]) for k in keys}
    if draw(_rarely()):  # an unknown key or table
        d[draw(_text.filter(lambda k: k not in SCENE_FIELDS))] = draw(junk)
    return d


def _toml_file(tmp_path, d, name):
    try:
        text = tomli_w.dumps(d)
    except (TypeError, ValueError):  # not representable in TOML (e.g. a mixed-type array)
        assume(False)
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


@SETTINGS
@given(d=scene_dicts())
def test_scene_file_loads_or_is_a_parameter_error_and_round_trips(tmp_path, d):
    tmp = tmp_path
    try:
        scene = Scene.from_toml(_toml_file(tmp, d, "scene.toml"))
    except ParameterError:
        return
    # loaded: every field has its declared type, and the TOML round trip keeps it
    assert isinstance(scene.thickness, float) and isinstance(scene.viscoelastic, bool)
    assert type(scene.dim) is int and type(scene.order) is int
    scene.to_toml(tmp / "back.toml")
    back = Scene.from_toml(tmp / "back.toml")
    assert back == scene and back.key() == scene.key()
    assert dataclasses.asdict(back) == dataclasses.asdict(scene)


# --- materials ---------------------------------------------------------------------------------

_numbers = st.lists(st.floats(-5, 20), min_size=0, max_size=14)
_positive = st.lists(st.floats(1e-3, 0.2), min_size=0, max_size=14)


@st.composite
def material_dicts(draw):
    n = draw(st.integers(1, 10))
    hf = {"mu": draw(_maybe(st.lists(st.floats(-0.1, 0.5), min_size=n, max_size=n))),
          "alpha": draw(_maybe(st.lists(st.floats(-5, 20), min_size=n, max_size=n))),
          "nu": draw(_maybe(st.floats(-1.2, 0.6)))}
    if draw(_rarely()):
        del hf[draw(st.sampled_from(["mu", "alpha", "nu"]))]
    d = {"hyperfoam": draw(_maybe(st.just(hf)))}
    if draw(st.booleans()):
        m = draw(st.integers(0, 14))
        d[draw(st.sampled_from(["prony"] * 5 + ["prnoy"]))] = {
            "g": draw(_maybe(st.lists(st.floats(0.0, 1.5 / max(m, 1)), min_size=m, max_size=m))),
            "tau": draw(_maybe(st.lists(st.floats(-1.0, 100.0), min_size=m, max_size=m)))}
    if draw(st.booleans()):
        d["source"] = draw(_maybe(_text))
    if draw(_rarely()):
        d[draw(_text)] = draw(junk)
    return d


@SETTINGS
@given(d=material_dicts())
def test_material_loads_or_is_a_parameter_error(tmp_path, d):
    tmp = tmp_path
    for load in (lambda: Material.from_dict("m", d),
                 lambda: Material.from_toml(_toml_file(tmp, d, "m.toml"))):
        try:
            m = load()
        except ParameterError:
            continue
        # loaded: the checked ranges hold
        assert 1 <= m.hyperfoam.n_terms <= 8 and m.prony.n_terms <= 12
        assert -1.0 < m.hyperfoam.nu < 0.5 and m.hyperfoam.mu0 > 0 and all(mu != 0 for mu in m.hyperfoam.mu)
        assert sum(m.prony.g) < 1.0 and all(t > 0 for t in m.prony.tau)


# --- sweeps ------------------------------------------------------------------------------------

SWEEP_LISTS = {
    "thicknesses": _maybe(st.lists(st.floats(0.3, 6.0), min_size=0, max_size=3)),
    "depths": _maybe(st.lists(st.floats(0.01, 2.0), min_size=0, max_size=2)),
    "materials": _maybe(st.lists(st.sampled_from(["silicone", "polyurethane", "bogus"]), max_size=2)
                        | st.just("silicone")),
    "indenters": _maybe(st.lists(st.sampled_from(["flat", "curved", "braille", "cone"]), max_size=2)),
    "braille_texts": _maybe(st.lists(st.text(alphabet="ab1 [", max_size=4), max_size=2)),
}


@st.composite
def sweep_dicts(draw):
    d = {}
    if draw(st.integers(0, 4)):
        keys = draw(st.sets(st.sampled_from(sorted(SWEEP_LISTS) + ["material"]), max_size=4))
        d[draw(st.sampled_from(["sweep"] * 9 + ["sweeep"]))] = {
            k: draw(SWEEP_LISTS.get(k, junk)) for k in keys}
    if draw(st.booleans()):
        d["scene"] = draw(_maybe(scene_dicts()))
    return d


@SETTINGS
@given(d=sweep_dicts())
def test_sweep_spec_loads_or_is_a_parameter_error(tmp_path, d):
    tmp = tmp_path
    try:
        spec = sweep.load_spec(_toml_file(tmp, d, "sweep.toml"))
        scenes = sweep.expand_grid(**spec)
    except ParameterError:
        return
    assert scenes and all(isinstance(s, Scene) for s in scenes)
    for k in ("thicknesses", "materials", "indenters"):
        if k in spec:
            assert isinstance(spec[k], tuple) and all(not isinstance(v, bool) for v in spec[k])


# --- arbitrary bytes -----------------------------------------------------------------------------

@SETTINGS
@given(data=st.one_of(st.binary(max_size=200),
                      st.text(max_size=200).map(lambda s: s.encode("utf-8", "surrogatepass")),
                      st.sampled_from([b"\xff\xfe[sweep]", b"a = [[[[[[[[", b"[scene]\nthickness = 3",
                                       b"[sweep]\nmaterials = 'silicone'", b"\x00" * 10])))
def test_any_bytes_load_or_are_a_parameter_error(tmp_path, data):
    p = tmp_path / "f.toml"
    p.write_bytes(data)
    for load in (Scene.from_toml, Material.from_toml, sweep.load_spec):
        try:
            load(p)
        except ParameterError:
            pass


@pytest.mark.parametrize("d", [{}, {"thickness": 1.0, "fingertip": {"height": 6.5}, "depth": 0.6},
                               {"indenter": "braille", "braille_text": "ab\nc", "dim": 3, "viscoelastic": False}])
def test_scene_round_trip_examples(tmp_path, d):
    scene = Scene.from_dict(d)
    scene.to_toml(tmp_path / "s.toml")
    assert Scene.from_toml(tmp_path / "s.toml").key() == scene.key()
