"""The horizontal group of the emulated scope (programmer manuals, "Horizontal Command
Group"): time per division, record length, sample rate and position, tied by the record's
ten divisions: s/div = record length / (10 x sample rate). The scale is snapped to the
model's steps (scene key scope.sample_interval follows), the record length to its list.

- TDS2000 and MDO3000 (no HORizontal:MODe in their manuals: 113 there): ``HORizontal:SCAle``
  keeps the record length, ``HORizontal:RECOrdlength`` keeps the scale; the sample rate
  follows. On the MDO3000 it follows up to the model's real-time rate
  (configuration.analog_sample_rate: MDO3012 to MDO3034 2.5 GS/s, MDO3052 to MDO3104 5 GS/s):
  a record that would need more is the longest of the model's within it, the shortest (1,000
  points) where even that needs more (below 40 ns/div at 2.5 GS/s: a real scope
  interpolates there, the emulated one samples its input that finely); its
  ``HORizontal:SAMPLERate`` "The command form is ignored. The query returns the sample rate
  for analog channels in samples per second" (MDO3000 manual). The TDS2000's one record
  length, 2,500 points, cannot shrink: its rate is not bounded here; its time base runs
  from 5 ns/div to 50 s/div (Personality.scale_range), a scale beyond taken at the nearer
  end. Below 100 ns/div a real TDS2000 interpolates (sin x / x) between samples taken at its
  real-time rate (500 MS/s to 2 GS/s by model); the emulated one samples its input at the
  record's interval, so its noise is not correlated between those points.
- 4 Series, ``HORizontal:MODe {AUTO|MANual}``, AUTO after ``*RST``. AUTO "automatically
  adjusts the sample rate and record length" (its manual): the scale is the client's and is
  kept; ``RECOrdlength`` and ``SAMPLERate`` set the record length at that scale; the rate
  follows, at most the model's real-time rate (Personality.max_sample_rate, MSO44 6.25 GS/s):
  a record that would need more is the longest of the model's within it (below 16 ns/div,
  where even 1,000 points need more, the shortest: the 4 Series interpolates there, the
  emulated scope samples its input that finely). MANual "lets you change the sample rate,
  horizontal scale, and record length. These values interact. For example, when you change
  record length then the horizontal scale also changes": the sample rate is kept;
  ``RECOrdlength`` moves the scale, ``SCAle`` the record length (the model's nearest), and
  ``SAMPLERate`` (at most the model's) moves what ``HORizontal:MODe:MANual:CONFIGure`` names
  ("which horizontal control (scale or record length) will primarily change when the sample
  rate is changed in Manual mode"): HORIZontalscale (until set) or RECORDLength.
- ``HORizontal:POSition``: the TDS2000's seconds from the trigger to the screen's centre,
  the others' percent of the record before the trigger."""
from __future__ import annotations

import math

from ..scpi.engine import Call, Word
from ..scpi.status import ScpiError
from .commands import positive
from .configuration import max_sample_rate
from .personalities import snap_record_length, snap_to_steps

MODES = ("AUTO", "MANual")
CONFIGURE = ("HORIZontalscale", "RECORDLength")


def register(tree, scope) -> None:
    """Add the horizontal commands of ``scope`` (a VirtualScope) to a command tree."""
    p = scope.personality
    top = max_sample_rate(p)
    top_rate = math.inf if top is None else top

    def lengths() -> list:
        return [n for n in p.record_lengths if n <= scope.max_record_length]

    def length() -> int:
        return scope.settings["scope.record_length"]

    def interval() -> float:
        return scope.settings["scope.sample_interval"]

    def s_div() -> float:
        return interval() * length() / 10

    def manual() -> bool:
        return p.horizontal_modes and scope.horizontal_mode == "MANual"

    def longest(rate: float, s: float) -> int:
        """The longest record at s/div sampled at most at ``rate``, else the shortest."""
        fit = [n for n in lengths() if n <= rate * 10 * s * (1 + 1e-9)]
        return fit[-1] if fit else lengths()[0]

    def nearest(points: float) -> int:
        return min(lengths(), key=lambda n: abs(math.log(n / points)))

    def set_time(n: int, dt: float) -> None:
        scope.change({"scope.record_length": n, "scope.sample_interval": dt}, code=-222)

    def at_scale(n: int, s: float) -> None:
        """n points over ten divisions of s (AUTO and the models without modes), at most the
        model's rate."""
        if top is not None:
            n = min(n, longest(top_rate, s))
        set_time(n, s * 10 / n)

    def set_scale(c: Call):
        s = positive(c, c.number("S"))
        if p.scale_range is not None:  # forced to the time base's range (Personality.scale_range)
            s = min(max(s, p.scale_range[0]), p.scale_range[1])
        s = snap_to_steps(s, p.time_steps)
        if manual():
            set_time(nearest(s * 10 / interval()), interval())
        else:
            at_scale(length(), s)

    def set_length(c: Call):
        n = snap_record_length(positive(c, c.number()), p.record_lengths)
        if n is None:
            raise ScpiError(-222, f"{c.header} {c.arg().text}: the {p.name} takes "
                                  f"{', '.join(str(x) for x in p.record_lengths)}")
        if n > scope.max_record_length:
            raise ScpiError(-221, f"{c.header} {c.arg().text}: this virtual scope keeps records of at most "
                                  f"{scope.max_record_length} points (max_record_length)")
        if manual():
            set_time(n, interval())
        else:
            at_scale(n, s_div())

    def set_rate(c: Call):
        rate = min(positive(c, c.number("HZ")), top_rate)
        if p.name == "mdo3000":  # its manual: "The command form is ignored"
            return
        if p.horizontal_modes and not manual():
            at_scale(longest(rate, s_div()), s_div())
        elif manual() and scope.manual_configure == "RECORDLength":
            set_time(nearest(rate * 10 * s_div()), 1.0 / rate)
        else:
            set_time(length(), 1.0 / rate)

    def sample_rate() -> float:
        """S/s, to 12 digits (1 / 5e-10 s is 2 GS/s, not 1.9999999999999998E+9)."""
        return float(f"{1.0 / interval():.12g}")

    def set_position(c: Call):
        span = interval() * length()
        pre = 0.5 - c.number("S") / span if p.name == "tds2000" else c.number() / 100
        scope.change({"scope.trigger.pre_trigger": pre}, code=-222)

    def read_position(c: Call) -> str:
        pre = scope.settings["scope.trigger.pre_trigger"]
        return p.number((0.5 - pre) * interval() * length() if p.name == "tds2000" else pre * 100)

    heads = ("HORizontal", "HORizontal:MODe") if p.horizontal_modes else ("HORizontal",)
    for head in (*heads, "HORizontal:MAIn"):
        tree.add(f"{head}:SCAle", write=set_scale, read=lambda c: p.number(s_div()))
    for head in ("HORizontal", "HORizontal:MAIn"):
        tree.add(f"{head}:POSition", write=set_position, read=read_position)
    for head in heads:
        tree.add(f"{head}:RECOrdlength", write=set_length, read=lambda c: str(length()))
        tree.add(f"{head}:SAMPLERate", read=lambda c: p.number(sample_rate()),
                 write=set_rate if p.name != "tds2000" else None)
    if p.horizontal_modes:
        tree.add("HORizontal:MODe", write=lambda c: setattr(scope, "horizontal_mode", c.word(MODES)),
                 read=lambda c: Word(scope.horizontal_mode))
        tree.add("HORizontal:MODe:MANual:CONFIGure", read=lambda c: Word(scope.manual_configure),
                 write=lambda c: setattr(scope, "manual_configure", c.word(CONFIGURE)))
