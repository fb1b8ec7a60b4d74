"""Braille standards, Grade-1/Unicode transcription and dot layout."""

import math

import numpy as np
import pytest

from tactileskin.errors import ParameterError
from tactileskin.geometry import braille
from tactileskin.geometry.braille import BrailleStandard, dot_centres, get_standard, text_to_cells

# Standard English braille in Unicode (independent of our table: published code points).
ALPHABET_UNICODE = "⠁⠃⠉⠙⠑⠋⠛⠓⠊⠚⠅⠇⠍⠝⠕⠏⠟⠗⠎⠞⠥⠧⠺⠭⠽⠵"
PUNCT_UNICODE = "⠂⠆⠒⠲⠖⠦⠄⠤⠶⠶"  # , ; : . ! ? ' - ( )


def test_letters_match_unicode_braille():
    assert text_to_cells("abc") == [[1, 3, 9]]
    assert text_to_cells("abcdefghijklmnopqrstuvwxyz") == text_to_cells(ALPHABET_UNICODE)
    assert text_to_cells(",;:.!?'-()") == text_to_cells(PUNCT_UNICODE)


def test_unicode_passes_through_and_round_trips():
    assert text_to_cells("⠁⠃") == text_to_cells("ab") == [[1, 3]]
    masks = list(range(64))
    text = "".join(chr(0x2800 + m) for m in masks)
    assert text_to_cells(text) == [masks]
    assert braille.cells_to_unicode(text_to_cells("hi\nyou")) == "⠓⠊\n⠽⠕⠥"


def test_number_capital_and_letter_signs():
    ns, cap, ls = 0b111100, 0b100000, 0b110000   # dots 3456, 6, 56
    assert text_to_cells("a1") == [[1, ns, 1]]
    assert text_to_cells("1990") == [[ns, 1, 10, 10, 26]]      # one sign per run; 0 = j
    assert text_to_cells("1 2") == [[ns, 1, 0, ns, 3]]         # a space ends the run
    assert text_to_cells("2b") == [[ns, 3, ls, 3]]            # b after digits needs the letter sign
    assert text_to_cells("2k") == [[ns, 3, 5]]                # k cannot be read as a digit
    assert text_to_cells("Ab") == [[cap, 1, 3]]
    assert text_to_cells("a\n\nb") == [[1], [], [3]]
    assert text_to_cells("") == [[]]


@pytest.mark.parametrize("text, char, pos", [("ab€", "€", 2), ("x\nyé", "é", 3), ("a\u2840", "\u2840", 1)])
def test_unknown_character_is_an_error(text, char, pos):
    with pytest.raises(ParameterError) as e:
        text_to_cells(text)
    msg = str(e.value)
    assert repr(char) in msg and f"position {pos}" in msg and "braille_text" in msg


def test_standards_table():
    sa = get_standard("standard_american")
    assert (sa.base_diameter, sa.height, sa.dot_pitch, sa.cell_pitch, sa.line_pitch) == (1.44, 0.48, 2.34, 6.2, 10.0)
    # design.md: R = (r^2 + h^2)/2h ~ 0.78 mm, centre 0.30 mm from the base plane
    assert sa.sphere_radius == pytest.approx(0.78, abs=0.005)
    assert sa.centre_offset == pytest.approx(0.30, abs=1e-12)
    ada = get_standard("ada_2010")
    assert dict((k, (lo, hi)) for k, lo, hi in ada.ranges) == {
        "base_diameter": (1.5, 1.6), "height": (0.6, 0.9), "dot_pitch": (2.3, 2.5),
        "cell_pitch": (6.1, 7.6), "line_pitch": (10.0, 10.2)}
    for k, lo, hi in ada.ranges:  # nominal = midpoint
        assert getattr(ada, k) == pytest.approx(0.5 * (lo + hi), abs=1e-12)
    mm = get_standard("marburg_medium")
    assert (mm.dot_pitch, mm.cell_pitch, mm.line_pitch) == (2.5, 6.0, 10.0)
    assert 1.3 <= mm.base_diameter <= 1.6 and "ASSUMPTION" in mm.source
    assert all(get_standard(n).source for n in braille.standard_names())


@pytest.mark.parametrize("name", ["standard_american", "ada_2010", "marburg_medium"])
def test_cap_geometry_consistent(name):
    s = get_standard(name)
    # the sphere centred centre_offset above the base plane cuts it in a circle of the base
    # radius, and its lowest point is `height` below the plane (closed form, round-off only)
    assert math.sqrt(s.sphere_radius**2 - s.centre_offset**2) == pytest.approx(s.base_radius, abs=1e-12)
    assert s.sphere_radius - s.centre_offset == pytest.approx(s.height, abs=1e-12)
    assert s.centre_offset >= 0.0


def test_unknown_standard_lists_names():
    with pytest.raises(ParameterError, match="ada_2010.*marburg_medium.*standard_american"):
        get_standard("grade3")


def test_invalid_standard_values():
    with pytest.raises(ParameterError, match="height"):  # taller than the base radius: overhang
        BrailleStandard("x", base_diameter=1.44, height=0.8, dot_pitch=2.34, cell_pitch=6.2, line_pitch=10.0)
    with pytest.raises(ParameterError, match="dot_pitch"):
        BrailleStandard("x", base_diameter=1.44, height=0.48, dot_pitch=1.0, cell_pitch=6.2, line_pitch=10.0)


def test_dot_centres_layout():
    sa = get_standard("standard_american")
    assert dot_centres("", sa).tolist() == [[0.0, 0.0]]       # paper default: one dot at the origin
    assert dot_centres("a", sa).tolist() == [[0.0, 0.0]]
    full = dot_centres("⠿", sa)                                 # dots 1..6 in order, -z down the lines
    p = sa.dot_pitch / 2
    np.testing.assert_allclose(full, [[-p, 2 * p], [-p, 0], [-p, -2 * p], [p, 2 * p], [p, 0], [p, -2 * p]], atol=1e-12)
    ab = dot_centres("ab", sa)                                 # a: dot 1; b: dots 1, 2
    c, q = sa.cell_pitch / 2, sa.dot_pitch / 2
    np.testing.assert_allclose(ab, [[-c, q], [c, q], [c, -q]], atol=1e-12)
    two_lines = dot_centres("a\na", sa)
    np.testing.assert_allclose(two_lines, [[0, sa.line_pitch / 2], [0, -sa.line_pitch / 2]], atol=1e-12)
    # read from the dots' side (they point to -y, at the skin and the reader) the text is not
    # mirrored: dot 1 -> dot 4 -> dot 5 of 'd' turns as on paper, (d14 x d45) . (dot direction) < 0
    d = dot_centres("d", sa)                                   # dots 1, 4, 5
    as3 = lambda v: np.array([v[0], 0.0, v[1]])  # noqa: E731  (x, z) -> (x, y, z)
    turn = np.cross(as3(d[1] - d[0]), as3(d[2] - d[1]))
    assert turn @ np.array([0.0, -1.0, 0.0]) < 0
    word = dot_centres("Braille 2", "marburg_medium")          # bounding box centred on the origin
    np.testing.assert_allclose(word.min(axis=0) + word.max(axis=0), 0.0, atol=1e-12)
    with pytest.raises(ParameterError, match="raised dot"):
        dot_centres("   ", sa)


def test_footprint():
    sa = get_standard("standard_american")
    r = sa.base_radius
    assert braille.footprint("", sa) == pytest.approx((-r, r, -r, r))
    xmin, xmax, zmin, zmax = braille.footprint("c", sa)        # dots 1 and 4
    assert (xmin, xmax) == pytest.approx((-sa.dot_pitch / 2 - r, sa.dot_pitch / 2 + r))
    assert (zmin, zmax) == pytest.approx((-r, r))


def test_the_cell_cap_message_reads_the_pitch_and_width_from_their_files(monkeypatch):
    """One source of truth: the message quoted a literal 6.2 mm pitch and a 16 mm fingertip."""
    from tactileskin import params

    real = params.load

    def load(name):
        p = real(name)
        if name == "braille":
            p = {**p, "standard_american": {**p["standard_american"], "cell_pitch": 7.0}}
        if name == "fingertip":
            p = {**p, "section": {**p["section"], "half_width": 9.0}}
        return p

    monkeypatch.setattr(params, "load", load)
    with pytest.raises(ParameterError, match=r"40 cells already span 280 mm at the American pitch, "
                                             r"the fingertip is 18 mm wide"):
        braille.check_text("a" * (braille.MAX_CELLS + 1))


@pytest.mark.parametrize("text", [" ", "⠀", "  \n "])
def test_a_text_without_a_raised_dot_is_refused_by_the_scene_not_by_the_solve(tmp_path, capsys, text):
    # a sweep TOML's braille_texts = [" "] passed the scene's checks and failed only in the
    # solve: the sweep claimed its folder, wrote a report of one failed case and exited 1
    from tactileskin.cli import main
    from tactileskin.scene import Scene

    with pytest.raises(ParameterError, match="braille_text.*raised dot"):
        Scene(indenter="braille", braille_text=text)
    f = tmp_path / "sweep.toml"
    f.write_text(f'[sweep]\nthicknesses = [1.0]\nindenters = ["braille"]\nbraille_texts = [{text!r}]\n'.replace("'", '"'))
    rc = main(["sweep", "--scene", str(f), "--out", str(tmp_path / "out"), "--serial", "--no-render"])
    err = capsys.readouterr().err
    assert rc == 2 and "raised dot" in err and not (tmp_path / "out").exists()


@pytest.mark.parametrize("fields, words", [
    (dict(skin="pad", pad_width=10.0, braille_text="abcd"), ["|x| <= 5 mm", "pad_width >= 22.4 mm"]),
    (dict(skin="pad", pad_length=1.0, braille_text="l"), ["|z| <= 0.5 mm", "pad_length >= 6.12 mm"]),
    (dict(braille_text="abc"), ["fingertip skin's top (|x| <= 8 mm", "x -8.09 to 8.09 mm"]),
    (dict(braille_text="a b"), ["travel 0.6 t = 0.6 mm", "|x| = 6.2 mm first touch it after 1.81 mm"])])
def test_a_text_past_the_skins_top_is_refused_naming_the_room_it_needs(fields, words):
    # abcd on a 10 mm pad solved 'ok': its outer dots pressed nothing, the result a shorter text's
    from tactileskin.errors import ParameterError
    from tactileskin.scene import Scene

    with pytest.raises(ParameterError, match="braille_text") as e:
        Scene(dim=3, indenter="braille", thickness=1.0, **fields)
    assert all(w in str(e.value) for w in words), str(e.value)
    fits = {**fields, "braille_text": fields["braille_text"][:1]} if "pad_length" not in fields else \
        {**fields, "pad_length": 6.2}
    Scene(dim=3, indenter="braille", thickness=1.0, **fits)   # the text that fits is taken


def test_a_fingertip_text_whose_outer_dots_never_touch_is_refused():
    """The fingertip's top falls away inside its half width 8 mm: 'abc' (dot bases to +-8.09 mm)
    was refused, but 'a b' (a space cell: dots at x = +-6.2 mm, where the surface lies 2.6 mm
    below the top) was taken, and only its base plate pressed (it touches at the dot height
    0.48 mm). Each dot's first touch is read on the contour: refused by the scene where no
    depth (<= 0.6 t) reaches it, by the solve where the scene's depth does not."""
    from tactileskin.geometry.indenters import BrailleIndenter, first_contact_travel, require_contact
    from tactileskin.scene import Scene

    for t in (1.0, 2.0):
        for dim in (2, 3):
            with pytest.raises(ParameterError, match=r"braille_text='a b'.*travel 0.6 t.*6.2 mm first touch it after 1.81"):
                Scene(thickness=t, dim=dim, indenter="braille", braille_text="a b")
    far = Scene(thickness=5.0, indenter="braille", braille_text="a b")      # 3 mm of travel reaches the dots
    with pytest.raises(ParameterError, match=r"depth=1.0.*> 1.81 mm.*would press nothing") as e:
        require_contact(far)                                                 # but not its 1 mm depth
    assert e.value.name == "depth"
    require_contact(far.replace(depth=2.0))
    # the dots' first touch is the indenter's own: 'ab' (dots at +-3.1 mm only) touches with them
    ab = Scene(thickness=1.0, indenter="braille", braille_text="ab")
    x, touch = BrailleIndenter.dot_touch(ab, get_standard(ab.braille_standard))
    assert x.tolist() == [3.1] and touch[0] == pytest.approx(first_contact_travel(ab), abs=1e-3)
    require_contact(ab.replace(depth=0.55))


def test_a_dome_text_whose_outer_dots_never_touch_is_refused():
    """The dome's section is the fingertip's ellipse, but only the fingertip was checked: 'a b'
    (dots at x = +-6.2 mm, touching after 1.81 mm) was taken on the dome at t = 1 and, at
    depth 1 of t = 2, solved with its base plate pressing alone."""
    from tactileskin.geometry.indenters import require_contact
    from tactileskin.scene import Scene

    with pytest.raises(ParameterError, match=r"braille_text='a b'.*travel 0.6 t.*6.2 mm first touch it after 1.81"):
        Scene(skin="dome", dim=3, thickness=1.0, indenter="braille", braille_text="a b")
    far = Scene(skin="dome", dim=3, thickness=3.5, indenter="braille", braille_text="a b", depth=1.0)
    with pytest.raises(ParameterError, match=r"depth=1.0.*> 1.81 mm.*would press nothing"):
        require_contact(far)
    require_contact(far.replace(depth=2.0))  # 2.1 mm of travel reaches them
    # 'ab' (dots at +-3.1 mm, first touch 0.476 mm) is taken, as on the fingertip
    require_contact(Scene(skin="dome", dim=3, thickness=1.0, indenter="braille", braille_text="ab", depth=0.55))
