"""Loading histories: what the indenter does over time (pure Python, no solver import).

A history is a list of segments, run one after the other from first touch (travel 0,
force 0, t = 0):

- `Segment("depth", target=d, rate=r | time=T)`: the travel moves linearly to d (mm) at
  r (mm/s) or in T (s) (displacement control; d = 0 releases to first touch);
- `Segment("force", target=F, rate=r | time=T)`: the indenter's reaction force goes
  linearly to F (N in 3D, N/mm in plane strain) at r (N/s, N/mm/s) or in T (s); the
  travel is found (force control);
- `Segment("hold", time=T)`: the last segment's control is held for T (s): the travel
  stays (the reaction relaxes) after a depth segment, the force stays (the indenter creeps)
  after a force segment.

The scene's own fields give the first segment (depth / depth_fraction at `rate`, or
`force` at `force_rate` / in `load_time`); `Scene.loading` (TOML `[[loading]]` tables:
`depth = 0.6` or `force = 0.5` with `rate =` or `time =`, or `hold = 10`) appends the rest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tactileskin import validate
from tactileskin.errors import ParameterError, check_range

KINDS = ("depth", "force", "hold")
MAX_SEGMENTS = 20
MAX_TIME = 1e6       # s: a segment longer than ~11 days is a units mistake
# s: the shortest depth or force ramp given by `time`; a shorter one can end where it starts in
# float time (t0 + 1e-20 == t0 after a 0.2 s ramp: the solve divided by zero). Far above the
# spacing of floats at the longest history (20 x MAX_TIME: 4e-9 s)
MIN_RAMP_TIME = 1e-6
RATE = (1e-6, 1e6)   # mm/s or N/s (N/mm/s): any ramp's rate, the scene's `rate` and `force_rate` too
MAX_FORCE = 1e4      # N (N/mm): far beyond any soft skin under a fingertip-sized indenter
# N (N/mm): below it the ramp's first targets are within the reaction's own resolution (1 mm
# silicone under the flat plate in 2D: 1e-7 N/mm stalled in its first increment, its reaction
# not within 1e-12 of 4.7e-11 N/mm; 3D preview, an R 2.5 sphere on 2 mm silicone: 1e-5 N
# stalled, 1e-4 solves, as do the 1 mm dot, an R 0.5 sphere and the 5 mm flat plate)
MIN_FORCE = 1e-4


def force_unit(dim: int) -> str:
    """A force's unit: N on the whole indenter in 3D, N/mm of the half section in 2D (plane strain)."""
    return "N" if dim == 3 else "N/mm"


@dataclass(frozen=True)
class Segment:
    kind: str                    # "depth" | "force" | "hold"
    target: float | None = None  # depth (mm) or force (N, N/mm); None for hold
    rate: float | None = None    # mm/s or N/s (N/mm/s); None: `time` gives the duration
    time: float | None = None    # s: duration (hold) or ramp time

    def to_dict(self) -> dict:
        if self.kind == "hold":
            return {"hold": self.time}
        d = {self.kind: self.target}
        d.update({"rate": self.rate} if self.rate is not None else {"time": self.time})
        return d

    def duration(self, start: float) -> float:
        """Time (s) the segment takes from the value `start` of its controlled quantity."""
        if self.rate is None:
            return float(self.time)
        return abs(self.target - start) / self.rate

    def describe(self, dim: int) -> str:
        """The segment in words; a force is N on the whole indenter in 3D, N/mm of the half
        section in 2D (plane strain), so the scene's `dim` is needed."""
        if self.kind == "hold":
            return f"hold {self.time:g} s"
        unit = "mm" if self.kind == "depth" else force_unit(dim)
        how = f"at {self.rate:g} {unit}/s" if self.rate is not None else f"in {self.time:g} s"
        return f"{self.kind} to {self.target:g} {unit} {how}"


def segment_from(value, where: str, *, max_depth: float, default_rate: float) -> Segment:
    """A Segment from a Segment or a table ({depth | force | hold} with rate | time);
    ParameterError names `where`.<key> and its valid range."""
    if isinstance(value, Segment):
        value = value.to_dict()
    d = validate.table(value, where)
    validate.known_keys(d, ("depth", "force", "hold", "rate", "time"), where)
    kinds = [k for k in KINDS if k in d]
    if len(kinds) != 1:
        raise ParameterError(where, d, "exactly one of depth = mm, force = N (N/mm in 2D), hold = s")
    kind = kinds[0]
    if kind == "hold":
        if "rate" in d or "time" in d:
            raise ParameterError(f"{where}.hold", d, "hold = seconds alone (no rate or time)")
        return Segment("hold", time=check_range(f"{where}.hold", d["hold"], 0.0, MAX_TIME, lo_open=True, unit="s"))
    if "rate" in d and "time" in d:
        raise ParameterError(f"{where}.rate", d, "rate or time, not both")
    if kind == "depth":
        target = check_range(f"{where}.depth", d["depth"], 0.0, max_depth, unit="mm")
        unit = "mm/s"
    else:
        target = check_range(f"{where}.force", d["force"], MIN_FORCE, MAX_FORCE, unit="N (N/mm in 2D)")
        unit = "N/s (N/mm/s in 2D)"
        if "rate" not in d and "time" not in d:
            raise ParameterError(f"{where}.rate", None, f"rate = {unit} or time = s for a force segment")
    if "time" in d:
        return Segment(kind, target, time=check_range(f"{where}.time", d["time"], MIN_RAMP_TIME, MAX_TIME,
                                                      unit="s"))
    rate = d.get("rate", default_rate)
    return Segment(kind, target, rate=check_range(f"{where}.rate", rate, *RATE, unit=unit))


def segments_from(value, *, max_depth: float, default_rate: float) -> tuple[Segment, ...]:
    """Scene.loading from a list of tables or Segments (may be empty)."""
    if isinstance(value, dict):
        value = [value]
    items = validate.sequence(value, "loading", "[[loading]] tables", MAX_SEGMENTS)
    return tuple(segment_from(v, f"loading[{i}]", max_depth=max_depth, default_rate=default_rate)
                 for i, v in enumerate(items))


def check_ramp(name: str, rate: float, start: float, target: float, unit: str) -> None:
    """Refuse a ramp from `start` to `target` at `rate` that takes under MIN_RAMP_TIME (as a
    `time` below it: the ramp can end where it starts in float time); names `name`."""
    duration = abs(target - start) / rate
    if duration < MIN_RAMP_TIME:
        most = abs(target - start) / MIN_RAMP_TIME
        shown = float(f"{most:.3g}")
        if shown > most:  # rounded up: the bound printed must itself be accepted
            e = 10.0 ** (math.floor(math.log10(most)) - 2)
            shown = float(f"{math.floor(most / e) * e:.3g}")
        raise ParameterError(name, rate, f"<= {shown:.3g} {unit}: "
                             f"the ramp from {start:.12g} to {target:.12g} takes {duration:.3g} s, "
                             f"under the shortest ramp, {MIN_RAMP_TIME:g} s")


def check_program(program: list[Segment]) -> None:
    """Refuse histories that cannot be run: a hold with nothing to hold, a segment of zero
    length that is not a hold (a depth or force ramp to where it already is)."""
    control, value = None, 0.0
    for i, seg in enumerate(program):
        where = "loading" if i == 0 else f"loading[{i - 1}]"
        if seg.kind == "hold":
            if control is None:
                raise ParameterError(f"{where}.hold", seg.time, "after a depth or force segment")
            continue
        start = value if seg.kind == control else None
        if start is not None and seg.rate is not None and math.isclose(seg.target, start, abs_tol=1e-12):
            raise ParameterError(f"{where}.{seg.kind}", seg.target, f"a value other than the previous {start:g}",
                                 "use hold = seconds to stay")
        if start is not None and seg.rate is not None:
            check_ramp(f"{where}.rate", seg.rate, start, seg.target,
                       "mm/s" if seg.kind == "depth" else "N/s (N/mm/s in 2D)")
        control, value = seg.kind, seg.target
