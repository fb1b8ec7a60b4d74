"""The sensor-array design chart's configuration (`ChartConfig`): the axes (thickness x pitch x
noise), the stimulus sets, the readout and the chart's meshes, each checked against its valid range
on construction. Units: mm, MPa."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tactileskin.array.sampler import MAX_TAXELS, ArraySpec, Readout
from tactileskin.errors import ParameterError, check_range, range_text
from tactileskin.geometry.braille import DIGITS as BRAILLE_DIGITS
from tactileskin.geometry.braille import LETTERS as BRAILLE_LETTERS
from tactileskin.geometry.braille import get_standard

# the characters of the letters set, from the Braille tables (geometry.braille): a-z, and the
# digits 1-9, 0, each the number sign and a-j's cell (surrogate.char_centres)
LETTERS = "".join(sorted(BRAILLE_LETTERS))
DIGITS = "".join(BRAILLE_DIGITS)
CHARACTERS = LETTERS + DIGITS
NOISE_FS = (0.01, 0.05, 0.1)  # the default noise axis (x full scale)
SETS = ("paper", "letters", "shapes")  # the index seeds each set's offsets: append only
SKINS = ("pad", "fingertip")
LETTERS_MODELS = ("interaction", "sum", "full")


# The chart's default single-dot mesh. Below t = 3 mm the 3D `default` preset (0.8 / 8) is finer
# and mesh_for takes it: on 1.2 / 8 the t = 1 mm full cell reads 5 % low (convergence3d.md), and
# the letters' surrogate is 5.5 % (t = 1, silicone, f) and 5.2 % (t = 0.5) off full solves on
# finer meshes; on 0.8 / 8 it reads 3.5 and 3.6 % (data/surrogate_validation.json)
CHART_MESH = (1.2, 8.0)


# x full scale: a noise std as large as the largest reading (accuracy near chance); a fraction,
# so --noise 5 meant as 5 % (500 % noise, a chart at chance after all its solves) is refused
NOISE_FS_MAX = 1.0

# MPa: a noise std past any skin's pressure (a unit slip; 1e308 was charted with noise_fs = inf)
NOISE_MPA_MAX = 1e4


PITCH = (0.05, 20.0)  # mm: the taxel pitch (a finer one where the window and memory allow none finer)


def _numbers(v, name: str, lo: float, hi: float | None, unit: str, lo_open: bool = False) -> tuple:
    """A non-empty list of distinct numbers within [lo, hi] as a tuple (a repeated value wrote
    every row of accuracies.csv twice; [1, 3, 1] is likely a typo for [1, 3, 5], refused as a
    sweep refuses it); a string is refused (it would iterate per character)."""
    from tactileskin import validate
    from tactileskin.sweep import MAX_AXIS_VALUES

    if isinstance(v, np.ndarray):
        v = v.tolist()
    rng = range_text(lo, hi, lo_open=lo_open, unit=unit)
    items = validate.sequence(v, name, ("numbers in " if rng[0] in "[(" else "numbers ") + rng, MAX_AXIS_VALUES)
    if not items:
        raise ParameterError(name, v, "at least one value")
    return _distinct(name, tuple(check_range(name, x, lo, hi, lo_open=lo_open, unit=unit) for x in items))


def _distinct(name: str, values: tuple) -> tuple:
    """values, refused where one is listed twice."""
    for i, v in enumerate(values):
        if v in values[:i]:
            raise ParameterError(name, list(values), "distinct values", f"{v!r} is listed twice")
    return values


def _names(v, name: str, choices: tuple | None) -> tuple:
    """A non-empty list of distinct strings (of `choices` where given) as a tuple."""
    from tactileskin import validate
    from tactileskin.sweep import MAX_AXIS_VALUES

    kind = "strings" if choices is None else ", ".join(choices[:-1]) + " or " + choices[-1]
    items = validate.sequence(v, name, kind, MAX_AXIS_VALUES)
    if not items:
        raise ParameterError(name, v, "at least one value")
    for x in items:
        if not isinstance(x, str) or (choices is not None and x not in choices):
            raise ParameterError(name, x, "a string" if choices is None else " or ".join(choices),
                                 validate.did_you_mean(x, choices) if choices and isinstance(x, str) else "")
    return _distinct(name, tuple(items))


@dataclass(frozen=True)
class ChartConfig:
    thicknesses: tuple = (1.0, 3.0)
    materials: tuple = ("silicone",)
    pitches: tuple = (0.5, 0.75, 1.0, 1.5, 2.0, 4.0)
    # noise std as a fraction of each set's full scale (None: NOISE_FS unless noise_mpa is given)
    noise_fs: tuple | None = None
    # or a fixed noise std in MPa, the same at every thickness and set (a real sensor's noise
    # floor does not scale with the stimulus); not with noise_fs
    noise_mpa: tuple | None = None
    taxel_fraction: float = 0.8            # taxel side / pitch (area averaging)
    bits: int | None = 12
    window: float = 8.0                    # array side (mm): n = floor(window / pitch) + 1 taxels a side
    sets: tuple = SETS
    letters: str = CHARACTERS              # the letters set: a-z and the digits 0-9
    n_train: int = 16
    n_test: int = 16
    template_grid: int = 4
    seed: int = 0
    # 3D single-dot solves on the local plan (fine = size / refinement at the dot); None, None:
    # mesh_for's rule (CHART_MESH, or the 3D Braille `default` preset where that is finer)
    mesh_size: float | None = None
    refinement: float | None = None
    standard: str = "standard_american"
    skin: str = "pad"                      # pad: translation exact (surrogate.py); fingertip: the paper's
    # depth cap (mm): a thickness whose 20 % depth exceeds it is indented by max_depth instead (all
    # its stimuli, 2D and 3D); None: the paper's 20 % everywhere (t >= 2.4 mm: the plate touches)
    max_depth: float | None = None
    # the letters' maps: "interaction" superposes the single dot with each dot's load from the
    # lone dot's surface deflection and load-approach law (surrogate.interaction_weights; on the
    # pad below the dot height, else the plain sum; two lone-dot solves per t), "sum" adds lone
    # dots (one 3D solve per t; measured errors of both in data/surrogate_validation.json,
    # silicone on the default meshes (mesh_for): interaction 3.6, 3.5, 4.3, 2.8, 3.2 % against
    # the sum's 4.3, 6.4, 14.5, 5.7, 13.7 % at t = 0.5, 1, 2, 3, 5 mm), "full" solves every letter
    # in 3D (one solve per letter and t: where the surrogates are not within 5 %)
    letters_model: str = "interaction"
    # where the surrogate's measured error (this run's validation rows and
    # data/surrogate_validation.json, the worse; array.validity) exceeds its tolerance, solve that
    # thickness's letters in full instead (one 3D solve per letter); False: keep the surrogate,
    # marked indicative
    fallback: bool = True
    # the shapes set's sphere (mm) and the 3D preset it is meshed at (the local plan at its
    # spot; preview at t = 1 silicone, R 2.5: peak -0.8 %, span +3.8 %, map 3.5 % from the
    # finest level of benchmarks/results/convergence3d.md, 3 s CPU)
    sphere_radius: float = 2.5
    sphere_quality: str = "preview"
    # where the taxels sit: None (and sensor_height None), the bonded surface (the paper's film on the bone, the solves'
    # bone maps); else this depth (mm) below the contact surface, in the undeformed skin, the
    # maps read from each cached solve's result.vtu (map_of: no solve again)
    sensor_depth: float | None = None
    # or this height (mm) above the bonded surface in every skin (a sensor sheet on a board with a
    # fixed stand-off, the skin cast over it): read at the depth t - sensor_height (sensor_depth_at);
    # not with sensor_depth
    sensor_height: float | None = None

    def __post_init__(self):
        # every field's type and range before any solve: a config file's `pitches = "abc"` or
        # `window = -1` must fail here, naming the key, not after minutes of solves
        from tactileskin import validate
        from tactileskin.presets import QUALITIES
        from tactileskin.scene import MESH_SIZE, REFINEMENT

        set_ = lambda name, v: object.__setattr__(self, name, v)  # noqa: E731 (frozen)
        if self.noise_mpa is not None:  # one noise axis: a fraction and an MPa value would be two
            if self.noise_fs is not None:
                raise ParameterError("noise_mpa (--noise-mpa)", self.noise_mpa,
                                     "not with noise_fs (--noise): the noise is either in MPa or x full scale")
            set_("noise_mpa", _numbers(self.noise_mpa, "noise_mpa (--noise-mpa)", 0.0, NOISE_MPA_MAX, "MPa", True))
        elif self.noise_fs is None:
            set_("noise_fs", NOISE_FS)
        # the finest pitch the checks below keep (window, memory), so the range states no pitch they refuse
        plo, punit = self._pitch_floor()
        for name, flag, lo, hi, lo_open, unit in (("thicknesses", "-t", 0.0, None, True, "mm"),  # the skin: its range
                                                  ("pitches", "--pitch", plo, PITCH[1], False, punit),
                                                  ("noise_fs", "--noise", 0.0, NOISE_FS_MAX, False,
                                                   "x full scale (a fraction: 0.05 is 5 %)")):
            if getattr(self, name) is not None:  # noise_fs: None with noise_mpa
                set_(name, _numbers(getattr(self, name), f"{name} ({flag})", lo, hi, unit, lo_open))
        if self.sensor_depth is not None:  # inside every skin of the chart: below its surface, above its bone
            thin = min(self.thicknesses)
            set_("sensor_depth", check_range("sensor_depth (--sensor-depth)", self.sensor_depth, 0.0, thin,
                                             lo_open=True, hi_open=True,
                                             unit=f"mm below the contact surface (the thinnest skin is {thin:g} mm; "
                                                  "leave it out for the bonded surface)"))
        if self.sensor_height is not None:  # the same skins from the bone's side
            if self.sensor_depth is not None:
                raise ParameterError("sensor_height (--sensor-height)", self.sensor_height,
                                     "not with sensor_depth (--sensor-depth): the taxels sit either a depth below "
                                     "the contact surface or a height above the bonded surface")
            thin = min(self.thicknesses)
            set_("sensor_height", check_range("sensor_height (--sensor-height)", self.sensor_height, 0.0, thin,
                                              lo_open=True, hi_open=True,
                                              unit=f"mm above the bonded surface (the thinnest skin is {thin:g} mm; "
                                                   "leave it out for the bonded surface)"))
        for name, flag, choices in (("materials", "-m", None), ("sets", "--set", SETS)):
            set_(name, _names(getattr(self, name), f"{name} ({flag})", choices))
        set_("taxel_fraction", check_range("taxel_fraction (--taxel)", self.taxel_fraction, 0.0, 1.0,
                                           unit="of the pitch"))
        set_("window", check_range("window", self.window, 0.0, unit="mm (array side)"))
        # the sampler's lattice has at most MAX_TAXELS a side: a finer pitch over this window would
        # be cut to a smaller array than the window the report states (it was, silently)
        fine = [p for p in self.pitches if int(np.floor(self.window / p + 1e-9)) + 1 > MAX_TAXELS]
        if fine:
            raise ParameterError("window", self.window, f"at most {(MAX_TAXELS - 1) * min(self.pitches):g} mm at the "
                                 f"pitch {min(self.pitches):g} mm ({MAX_TAXELS} taxels a side)")
        if not isinstance(self.fallback, bool):
            raise ParameterError("fallback", self.fallback, "true or false")
        for name, choices in (("letters_model", LETTERS_MODELS), ("sphere_quality", QUALITIES), ("skin", SKINS)):
            if not isinstance(getattr(self, name), str) or getattr(self, name) not in choices:
                raise ParameterError(name, getattr(self, name), " or ".join(choices))
        from tactileskin.geometry.indenters.base import RADIUS
        from tactileskin.geometry.indenters.sphere import MAX_RADIUS

        check_range("sphere_radius", self.sphere_radius, RADIUS[0], MAX_RADIUS, lo_open=True, unit="mm")  # the sphere kind's range
        if self.max_depth is not None:
            set_("max_depth", check_range("max_depth", self.max_depth, 0.0, lo_open=True,
                                          unit="mm (or none: 20 % of t)"))
        for name, rng, unit in (("mesh_size", MESH_SIZE, "mm"), ("refinement", REFINEMENT, "")):
            if getattr(self, name) is not None:  # the Scene's ranges, named by the chart's key
                set_(name, check_range(name, getattr(self, name), *rng, unit=unit))
        validate.string(self.standard, "standard", "a Braille standard name")
        if "shapes" in self.sets:  # the ball presses within its cap (indenters.sphere.CAP), at every thickness
            from tactileskin.geometry.indenters.sphere import CAP
            from tactileskin.scene import Scene

            deepest = max((self.depth_for(t) or Scene.depth_fraction * t) for t in self.thicknesses)
            if deepest > CAP * self.sphere_radius:
                raise ParameterError("sphere_radius", self.sphere_radius,
                                     f">= {deepest / CAP:.3g} mm for the chart's deepest press ({deepest:g} mm; "
                                     f"the ball's working cap is {CAP:g} R high)", "or a smaller --max-depth")
        try:
            get_standard(self.standard)
        except ParameterError as e:
            raise ParameterError("standard", self.standard, e.valid) from None
        # checked here, before any solve (the classifiers would refuse them after hours of solves)
        if self.bits is not None and not (isinstance(self.bits, (int, np.integer)) and not isinstance(self.bits, bool)
                                          and 1 <= self.bits <= 32):
            raise ParameterError("bits", self.bits, "an integer in [1, 32] (None from Python: no quantisation)")
        # n_train >= 2: LDA needs more training readings than classes (two offsets per stimulus)
        for name, lo in (("n_train (--offsets)", 2), ("n_test (--offsets)", 1), ("template_grid", 1), ("seed", 0)):
            v = getattr(self, name.split()[0])
            if not (isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= lo):
                raise ParameterError(name, v, f"an integer >= {lo}")
        if not isinstance(self.letters, str):
            raise ParameterError("letters", self.letters, "a string of characters a-z, 0-9, e.g. 'abc1'")
        # "a,b,l" or "a b l" as the other list options are written: the separators are no characters
        set_("letters", "".join(c for c in self.letters if c not in ", "))
        bad = [c for c in self.letters if c not in CHARACTERS]
        if bad or len(set(self.letters)) < 2:
            raise ParameterError("letters", self.letters, "at least two distinct characters a-z, 0-9",
                                 hint=f"not characters of the set: {''.join(dict.fromkeys(bad))}" if bad else "")
        self._check_memory()

    def _pitch_floor(self) -> tuple[float, str]:
        """(finest pitch, unit text) this chart allows: PITCH[0], or coarser where the sampler's
        MAX_TAXELS a side or _check_memory would refuse a finer one over the window (for the
        pitch's range message; read before the other fields are checked: PITCH[0] if they are not
        numbers of the right kind, their own checks then name them)."""
        import math

        from tactileskin.array import classify

        try:
            window = float(self.window)
            letters = {c for c in self.letters if c not in ", "}
            ncls = max({"paper": 3, "shapes": 4, "letters": len(letters)}[s] for s in _names(self.sets, "sets", SETS))
            tr, te, g = (int(v) for v in (self.n_train, self.n_test, self.template_grid))
            if not (window > 0.0 and math.isfinite(window) and tr >= 2 and te >= 1 and g >= 1):
                return PITCH[0], "mm"
        except (TypeError, ValueError, ParameterError):
            return PITCH[0], "mm"
        need = lambda k, a, b, c: classify.memory_bytes(ncls, k * k, a, b, c)  # noqa: E731
        # taxels a side that fit (as _check_memory: the offsets' and templates' if any, else LDA's alone)
        kmax = 2
        fits = (lambda k: need(k, tr, te, g) <= classify.MAX_BYTES) if need(2, tr, te, g) <= classify.MAX_BYTES \
            else (lambda k: need(k, 2, 1, 1) <= classify.MAX_BYTES)
        while kmax < MAX_TAXELS and fits(kmax + 1):
            kmax += 1
        pmin = window / (kmax - 1)
        e = 10.0 ** (math.floor(math.log10(pmin)) - 2)
        pmin = math.ceil(pmin / e) * e
        if pmin <= PITCH[0] or pmin > PITCH[1]:  # above PITCH[1]: the window's own check names it
            return PITCH[0], "mm"
        why = "the sampler's" if kmax == MAX_TAXELS else "the memory of one pitch's classification"
        return float(f"{pmin:.3g}"), f"mm over the {window:g} mm window ({kmax} x {kmax} taxels at most: {why})"

    def _check_memory(self) -> None:
        """Refuse, before any solve, a chart whose classification of one (set, pitch) would
        not fit in classify.MAX_BYTES: pitch 0.05 mm over the 8 mm window (LDA's covariance
        of 161^2 taxels, 5 GB a copy) or --offsets 100000000 ran out of memory after the
        solves, with a traceback."""
        import math

        from tactileskin.array import classify

        ncls = max({"paper": 3, "shapes": 4, "letters": len(set(self.letters))}[s] for s in self.sets)
        need = lambda k, tr, te, g: classify.memory_bytes(ncls, k * k, tr, te, g)  # noqa: E731
        top, pitch = classify.MAX_BYTES, min(self.pitches)
        k = self.spec(pitch).n
        if need(k, self.n_train, self.n_test, self.template_grid) <= top:
            return
        cap = f"the {top / 2**30:g} GiB the classification of one pitch may hold in memory"
        if need(k, 2, 1, 1) > top:  # LDA's covariance alone: the pitch is too fine for the window
            # the finest lattice these offsets and templates fit on (else the least they need)
            fits = [j for j in range(2, k) if need(j, self.n_train, self.n_test, self.template_grid) <= top]
            kmax = max(fits or [j for j in range(2, k) if need(j, 2, 1, 1) <= top])
            pmin = self.window / (kmax - 1)
            e = 10.0 ** (math.floor(math.log10(pmin)) - 2)
            raise ParameterError("pitches (--pitch)", pitch, f">= {math.ceil(pmin / e) * e:.3g} mm over the "
                                 f"{self.window:g} mm window (at most {kmax} x {kmax} taxels)",
                                 hint=f"{k} x {k} taxels: LDA's taxel covariance alone exceeds {cap}")
        # the fewest offsets the offsets' rule below can name: 2 each (--offsets sets both); with
        # (2, 1) here a template_grid that fits only there was blamed on n_train, "in [2, 1]"
        if need(k, 2, 2, self.template_grid) > top:
            gmax = max((g for g in range(1, self.template_grid) if need(k, 2, 2, g) <= top), default=1)
            raise ParameterError("template_grid", self.template_grid, f"an integer in [1, {gmax}] at the pitch "
                                 f"{pitch:g} mm ({k} x {k} taxels)", hint=f"its templates would exceed {cap}")
        fixed = need(k, 0, 0, self.template_grid)
        nmax = int((top - fixed) // (need(k, 1, 1, self.template_grid) - fixed))
        raise ParameterError("n_train (--offsets)", max(self.n_train, self.n_test),
                             f"an integer in [2, {nmax}] at the pitch {pitch:g} mm ({k} x {k} taxels) and "
                             f"{ncls} stimuli", hint=f"their readings would exceed {cap}")

    def mesh_for(self, thickness: float) -> tuple[float, float]:
        """(mesh_size, refinement) of the chart's 3D single dots at a thickness: the user's
        where either is given (the other from CHART_MESH), else CHART_MESH, or the 3D Braille
        `default` preset where its fine size is smaller (0.8 / 8 below t = 3 mm)."""
        if self.mesh_size is not None or self.refinement is not None:
            return (float(CHART_MESH[0] if self.mesh_size is None else self.mesh_size),
                    float(CHART_MESH[1] if self.refinement is None else self.refinement))
        from tactileskin.presets import mesh

        size, ratio = mesh(3, "default", braille=True, thickness=thickness)
        return (float(size), float(ratio)) if size / ratio < CHART_MESH[0] / CHART_MESH[1] else CHART_MESH

    def depth_for(self, thickness: float) -> float | None:
        """The depth (mm) a chart scene of this thickness is given: None (the scene's 20 % of t)
        unless that exceeds max_depth."""
        from tactileskin.scene import Scene

        # the scenes' default depth (Scene.depth_fraction x t, the paper's 20 %)
        if self.max_depth is None or Scene.depth_fraction * thickness <= self.max_depth:
            return None
        return float(self.max_depth)

    def sensor_depth_at(self, thickness: float) -> float | None:
        """The taxels' depth (mm) below the contact surface of the skin of this thickness: None
        on the bonded surface (the bone maps), sensor_depth, or t - sensor_height."""
        if self.sensor_height is not None:
            return float(thickness) - self.sensor_height
        return self.sensor_depth

    def sensor_height_at(self, thickness: float) -> float:
        """The taxels' height (mm) above the bonded surface of the skin of this thickness."""
        if self.sensor_height is not None:
            return self.sensor_height
        return 0.0 if self.sensor_depth is None else float(thickness) - self.sensor_depth

    @property
    def noise_levels(self) -> tuple:
        """The noise axis: noise_mpa (MPa) where given, else noise_fs (x full scale)."""
        return self.noise_fs if self.noise_mpa is None else self.noise_mpa

    @property
    def noise_key(self) -> str:
        """The accuracy rows' column the noise axis is: "noise_mpa" or "noise_fs"."""
        return "noise_fs" if self.noise_mpa is None else "noise_mpa"

    @property
    def noise_unit(self) -> str:
        return "x full scale" if self.noise_mpa is None else "MPa"

    def readout(self, full_scale: float, noise: float) -> Readout:
        """The electronics at one level of the noise axis over a set's full scale."""
        if self.noise_mpa is None:
            return Readout(full_scale=full_scale, noise_fs=noise, bits=self.bits)
        return Readout(full_scale=full_scale, noise_mpa=noise, bits=self.bits)

    @property
    def min_taxel(self) -> float:
        """The smallest taxel side of the chart (mm)."""
        return self.taxel_fraction * min(self.pitches)

    @property
    def read_extent(self) -> float:
        """Half side (mm) of the square around the cell's centre that any array of the chart
        reads: the farthest taxel centre (window / 2), plus the largest sub-pitch offset
        (pitch / 2) and half a taxel, at the coarsest pitch."""
        return 0.5 * self.window + max(0.5 * p * (1.0 + self.taxel_fraction) for p in self.pitches)

    def spec(self, pitch: float) -> ArraySpec:
        n = int(np.floor(self.window / pitch + 1e-9)) + 1
        return ArraySpec(pitch=pitch, taxel=self.taxel_fraction * pitch, n=n)
