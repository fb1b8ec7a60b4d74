"""Braille standards, text -> cells (6-bit dot masks) and dot centres on the indenter face.

Pure python/numpy. The standards table lives in data/geometry/braille.toml (one source of truth);
the CAD solids (build123d) and the analytic indenter surface (indenters.py) both place their
dots with `dot_centres`.

Cell layout (dot numbers):   1 4
                             2 5
                             3 6
A cell is a 6-bit mask, bit k-1 set when dot k is raised; the Unicode braille character
of a cell is chr(0x2800 + mask). Face coordinates (mm): x across the text (left to right),
-z down the lines, so that the text reads as written from the dots' side (dots toward -y, at
the skin); the whole dot pattern is centred on the origin.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np

from tactileskin import params
from tactileskin.errors import ParameterError

log = logging.getLogger(__name__)

_FIELDS = ("base_diameter", "height", "dot_pitch", "cell_pitch", "line_pitch")


@dataclass(frozen=True)
class BrailleStandard:
    """Nominal cell dimensions (mm). A dot is a spherical cap of base `base_diameter`, height `height`."""

    name: str
    base_diameter: float
    height: float
    dot_pitch: float
    cell_pitch: float
    line_pitch: float
    source: str = ""
    ranges: tuple[tuple[str, float, float], ...] = field(default_factory=tuple)  # (field, min, max)

    def __post_init__(self):
        for f in _FIELDS:
            v = getattr(self, f)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ParameterError(f"{self.name}.{f}", v, "a finite number > 0 mm")
        r = 0.5 * self.base_diameter
        # h <= r keeps the centre on or above the base plane: no overhang (printable) and the
        # union-of-parts gap in indenters.py stays exact outside the solid.
        if self.height > r:
            raise ParameterError(f"{self.name}.height", self.height, f"(0, {r:g}] mm (at most the base radius)")
        if self.dot_pitch <= self.base_diameter:
            raise ParameterError(f"{self.name}.dot_pitch", self.dot_pitch,
                                 f"> base_diameter = {self.base_diameter:g} mm (dots must not overlap)")
        if self.cell_pitch < self.dot_pitch + self.base_diameter:
            raise ParameterError(f"{self.name}.cell_pitch", self.cell_pitch,
                                 f">= dot_pitch + base_diameter = {self.dot_pitch + self.base_diameter:g} mm")
        if self.line_pitch < 2 * self.dot_pitch + self.base_diameter:
            raise ParameterError(f"{self.name}.line_pitch", self.line_pitch,
                                 f">= 2 dot_pitch + base_diameter = {2 * self.dot_pitch + self.base_diameter:g} mm")

    @property
    def base_radius(self) -> float:
        return 0.5 * self.base_diameter

    @property
    def sphere_radius(self) -> float:
        """Radius R of the cap's sphere: R = (r^2 + h^2) / 2h (r base radius, h height)."""
        r, h = self.base_radius, self.height
        return (r * r + h * h) / (2.0 * h)

    @property
    def centre_offset(self) -> float:
        """R - h: the sphere centre lies this far above the base plane, inside the indenter."""
        return self.sphere_radius - self.height


def standard_names() -> list[str]:
    return sorted(params.load("braille"))


def get_standard(name: str) -> BrailleStandard:
    """The named standard from data/geometry/braille.toml; unknown name -> ParameterError."""
    table = params.load("braille")
    if not isinstance(name, str) or name not in table:
        raise ParameterError("braille_standard", name, "one of " + ", ".join(sorted(table)))
    entry = table[name]
    missing = [f for f in _FIELDS if f not in entry]
    if missing:
        raise ParameterError(f"braille.toml [{name}]", missing[0], "a value for each of " + ", ".join(_FIELDS))
    ranges = tuple((k, float(v[0]), float(v[1])) for k, v in sorted(entry.get("range", {}).items()))
    return BrailleStandard(name=name, source=entry.get("source", ""), ranges=ranges,
                           **{f: float(entry[f]) for f in _FIELDS})


# --- text -> cells ---------------------------------------------------------------------------

def _mask(*dots: int) -> int:
    return sum(1 << (k - 1) for k in dots)


_LETTER_DOTS = {
    "a": (1,), "b": (1, 2), "c": (1, 4), "d": (1, 4, 5), "e": (1, 5),
    "f": (1, 2, 4), "g": (1, 2, 4, 5), "h": (1, 2, 5), "i": (2, 4), "j": (2, 4, 5),
}
# k-t add dot 3 to a-j; u v x y z add dots 3 and 6 to a-e; w is its own (French origin).
for _i, _c in enumerate("klmnopqrst"):
    _LETTER_DOTS[_c] = _LETTER_DOTS["abcdefghij"[_i]] + (3,)
for _i, _c in enumerate("uvxyz"):
    _LETTER_DOTS[_c] = _LETTER_DOTS["abcde"[_i]] + (3, 6)
_LETTER_DOTS["w"] = (2, 4, 5, 6)

LETTERS = {c: _mask(*d) for c, d in _LETTER_DOTS.items()}
DIGITS = {d: LETTERS["abcdefghij"[(int(d) - 1) % 10]] for d in "1234567890"}  # 1-9 = a-i, 0 = j
PUNCTUATION = {  # English Braille (EBAE) Grade 1
    " ": 0, ",": _mask(2), ";": _mask(2, 3), ":": _mask(2, 5), ".": _mask(2, 5, 6),
    "!": _mask(2, 3, 5), "?": _mask(2, 3, 6), "'": _mask(3), "-": _mask(3, 6),
    "(": _mask(2, 3, 5, 6), ")": _mask(2, 3, 5, 6),
}
NUMBER_SIGN = _mask(3, 4, 5, 6)   # before a run of digits
CAPITAL_SIGN = _mask(6)           # before each capital letter
LETTER_SIGN = _mask(5, 6)         # before a-j right after a digit run, so it is not read as a digit

# One line of a braille page (40 cells; 248 mm at the American cell pitch, 15x the 16 mm wide
# fingertip). Cells beyond the skin never touch it, but each adds dots to the indenter's
# solid, its contact search and the contact zone's refined mesh: 200 characters built a
# 1,244 mm indenter using 2.5 GB and 1,000 crashed.
MAX_CELLS = 40

_VALID = ("Unicode braille U+2800..U+283F, letters a-z A-Z, digits 0-9, space and , ; : . ! ? ' - ( )")


def text_to_cells(text: str) -> list[list[int]]:
    """Lines (split on newline) of cells, each a 6-bit dot mask (bit k-1 = dot k).

    Unicode braille characters pass through as their masks. Grade-1 characters are
    transcribed: capital sign before each capital, number sign before each run of digits,
    letter sign between a digit run and a following letter a-j. Any other character raises
    ParameterError naming it and its position.
    """
    if not isinstance(text, str):
        raise ParameterError("braille_text", text, "a string")
    lines: list[list[int]] = []
    pos = 0
    for line in text.split("\n"):
        cells: list[int] = []
        in_number = False
        for col, ch in enumerate(line):
            code = ord(ch)
            low = ch.lower()
            if 0x2800 <= code <= 0x283F:
                cells.append(code - 0x2800)
                in_number = False
            elif ch in DIGITS:
                if not in_number:
                    cells.append(NUMBER_SIGN)
                    in_number = True
                cells.append(DIGITS[ch])
            elif low in LETTERS and ch.isascii():
                if ch.isupper():
                    cells.append(CAPITAL_SIGN)
                elif in_number and low in "abcdefghij":
                    cells.append(LETTER_SIGN)
                cells.append(LETTERS[low])
                in_number = False
            elif ch in PUNCTUATION:
                cells.append(PUNCTUATION[ch])
                in_number = False
            else:
                raise ParameterError(
                    "braille_text", _short(text), _VALID,
                    hint=f"unknown character {ch!r} (U+{code:04X}) at position {pos + col} "
                         f"(line {len(lines) + 1}, column {col + 1})")
        lines.append(cells)
        pos += len(line) + 1
    return lines


def check_text(text: str) -> list[list[int]]:
    """text_to_cells(text), refused beyond MAX_CELLS cells: what an indenter may carry."""
    if isinstance(text, str):
        _check_cells(text, len(text) - text.count("\n"))  # each other character is >= 1 cell
    lines = text_to_cells(text)
    _check_cells(text, sum(map(len, lines)))
    return lines


def _check_cells(text: str, n: int) -> None:
    if n > MAX_CELLS:
        # the pitch and the width from their files (braille.toml, fingertip.toml), not copies
        pitch = get_standard("standard_american").cell_pitch
        width = 2.0 * float(params.load("fingertip")["section"]["half_width"])
        raise ParameterError("braille_text", _short(text),
                             f"at most {MAX_CELLS} braille cells (characters plus capital, number "
                             "and letter signs)",
                             f"the text needs at least {n} cells; {MAX_CELLS} cells already span "
                             f"{MAX_CELLS * pitch:.0f} mm at the American pitch, the fingertip is "
                             f"{width:g} mm wide")


def _short(text: str, n: int = 48) -> str:
    return text if len(text) <= n else text[:n] + f"... ({len(text)} characters)"


def cells_to_unicode(lines: list[list[int]]) -> str:
    """Inverse view: the Unicode braille text of a list of lines of cell masks."""
    return "\n".join("".join(chr(0x2800 + m) for m in cells) for cells in lines)


# --- dot centres ---------------------------------------------------------------------------

# (column, row) of dot k = index + 1 inside a cell
_DOT_POS = np.array([(0, 0), (0, 1), (0, 2), (1, 0), (1, 1), (1, 2)], dtype=float)


def dot_centres(text: str, standard: BrailleStandard | str = "standard_american") -> np.ndarray:
    """(n, 2) array of dot centres (x, z) in mm on the indenter face, pattern centred on the origin.

    x runs across the text (cells left to right), -z down the lines (a line's first row at the
    largest z): seen from the dots' side, the side that touches the skin and that a reader
    feels, the text reads as written (with z down the lines it read mirrored: "d" as "f", and
    the cells right to left). The bounding box of the dot centres is centred on (0, 0). Empty text is the paper's default section: a single
    dot at the origin. Text with no raised dot at all (only spaces) raises ParameterError.
    """
    std = get_standard(standard) if isinstance(standard, str) else standard
    if text == "":
        return np.zeros((1, 2))
    pts = []
    for li, cells in enumerate(check_text(text)):
        for ci, mask in enumerate(cells):
            for k in range(6):
                if mask >> k & 1:
                    col, row = _DOT_POS[k]
                    pts.append((ci * std.cell_pitch + col * std.dot_pitch,
                                -(li * std.line_pitch + row * std.dot_pitch)))
    if not pts:
        raise ParameterError("braille_text", text, "text with at least one raised dot (or empty for one dot)")
    xz = np.asarray(pts, dtype=float)
    xz -= 0.5 * (xz.min(axis=0) + xz.max(axis=0))
    xz[np.abs(xz) < 1e-12] = 0.0  # clean -0.0 / round-off so rows compare exactly
    return xz


def footprint(text: str, standard: BrailleStandard | str = "standard_american") -> tuple[float, float, float, float]:
    """(xmin, xmax, zmin, zmax) of the dot bases (centres +- base radius), mm."""
    std = get_standard(standard) if isinstance(standard, str) else standard
    xz = dot_centres(text, std)
    r = std.base_radius
    return (float(xz[:, 0].min() - r), float(xz[:, 0].max() + r),
            float(xz[:, 1].min() - r), float(xz[:, 1].max() + r))
