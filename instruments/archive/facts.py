"""The facts of a virtual shot that the archive keeps beside its truth: a declared,
versioned structure that the writer (the rig) builds and the reader (the analysis of an
archive) checks. Stored as JSON with its ``version``; a stored record without one is the
layout of version 1 (archives written before the version was recorded)."""
from __future__ import annotations

from dataclasses import dataclass, field, fields

from ..errors import InstrumentError

FACTS_VERSION = 1


@dataclass(frozen=True)
class GaugeFact:
    """A gauge bead: chain index (0 = top), scope channel, nominal position (m, down from
    the top bead's centre) and the static forces (N) of its two contacts."""

    bead: int
    channel: str
    position_m: float
    static_above_N: float
    static_below_N: float


@dataclass(frozen=True)
class ShotFacts:
    """sample_interval_s: the truth's grid (s); gauges: {name: GaugeFact}; analysis: the
    pipeline on the noise-free truth (its JSON block), or for a Monte Carlo study's traces
    the calibration its analysis applied ({"beta", "static_force_N", "basis"}), or None;
    wave_speed_m_per_s; draws:
    {part: {draw: value}} of the instruments; trigger_time_after_impact_s; solver: the
    solver's statistics; overrides: the scene overrides; study_shot, study: the shot's
    index and the study's digest when a Monte Carlo study archived it."""

    sample_interval_s: float
    gauges: dict
    analysis: dict | None
    wave_speed_m_per_s: float | None
    draws: dict
    trigger_time_after_impact_s: float | None
    solver: dict
    overrides: tuple = ()
    study_shot: int | None = None
    study: str | None = None
    version: int = field(default=FACTS_VERSION)

    def to_dict(self) -> dict:
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["gauges"] = {name: dict(vars(g)) for name, g in self.gauges.items()}
        out["overrides"] = list(self.overrides)
        return out

    @classmethod
    def from_dict(cls, d, where: str = "facts") -> ShotFacts:
        """Check and read stored facts; InstrumentError naming the field otherwise."""
        if not isinstance(d, dict):
            raise InstrumentError(f"{where} = {d!r}: expected a table of shot facts")
        d = dict(d)
        version = d.pop("version", 1)  # unversioned: the layout of version 1
        if type(version) is not int or version != FACTS_VERSION:
            raise InstrumentError(f"{where}.version = {version!r}: this version reads version {FACTS_VERSION}")
        names = {f.name for f in fields(cls)} - {"version"}
        required = {f.name for f in fields(cls) if f.name not in ("overrides", "study_shot", "study", "version")}
        unknown, missing = sorted(set(d) - names), sorted(required - set(d))
        if unknown:
            raise InstrumentError(f"{where}.{unknown[0]}: unknown key (known: {', '.join(sorted(names))})")
        if missing:
            raise InstrumentError(f"{where}.{missing[0]}: missing")
        _typed(where, d, "sample_interval_s", (int, float))
        for key in ("wave_speed_m_per_s", "trigger_time_after_impact_s"):
            _typed(where, d, key, (int, float, type(None)))
        for key in ("draws", "solver", "gauges"):
            _typed(where, d, key, (dict,))
        _typed(where, d, "analysis", (dict, type(None)))
        _typed(where, d, "study_shot", (int, type(None)))
        _typed(where, d, "study", (str, type(None)))
        _typed(where, d, "overrides", (list, tuple))
        for i, o in enumerate(d.get("overrides", ())):
            _typed(where, {f"overrides[{i}]": o}, f"overrides[{i}]", (str,))
        gauges = {}
        keys = [f.name for f in fields(GaugeFact)]
        for name, g in d["gauges"].items():
            if not isinstance(g, dict):
                raise InstrumentError(f"{where}.gauges.{name} = {g!r}: expected a table of {', '.join(keys)}")
            unknown, missing = sorted(set(g) - set(keys)), [k for k in keys if k not in g]
            if unknown:
                raise InstrumentError(f"{where}.gauges.{name}.{unknown[0]}: unknown key (known: {', '.join(keys)})")
            if missing:
                raise InstrumentError(f"{where}.gauges.{name}.{missing[0]}: missing")
            for key, types in (("bead", (int,)), ("channel", (str,)), ("position_m", (int, float)),
                               ("static_above_N", (int, float)), ("static_below_N", (int, float))):
                _typed(f"{where}.gauges.{name}", g, key, types)
            gauges[name] = GaugeFact(**g)
        return cls(**{**d, "gauges": gauges, "overrides": tuple(d.get("overrides", ()))})


def _typed(where: str, d: dict, key: str, types: tuple):
    if key in d and (not isinstance(d[key], types) or isinstance(d[key], bool)):
        allowed = " or ".join("null" if t is type(None) else t.__name__ for t in types)
        raise InstrumentError(f"{where}.{key} = {d[key]!r}: expected {allowed}")
