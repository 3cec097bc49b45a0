"""How long and how fine a served scope's record needs the chain solved (rig/lab/shots.py
asks): the time its scope records after the trigger, the bytes its record holds while it is
acquired, and the solver items (``solver.duration``, ``solver.sample_interval``) that give
the record, with the margin a fine record's estimated trigger is given."""
from __future__ import annotations

import math

from rig.experiment.shot import Rig


def after_trigger(rig: Rig) -> float:
    """Seconds the rig's scope records after its trigger: (1 - pre_trigger) x the record's span."""
    tb = rig.scope.timebase
    return (1.0 - rig.scope.trigger.pre_trigger) * tb.record_length * tb.sample_interval


RECORD_BYTES_PER_POINT = 32
"""Bytes a scope record holds at once per point and channel while it is acquired: the noise
draw and the sampled input (float64 each), the codes, the reply's 2-byte words, with room."""


def record_bytes(rig: Rig) -> float:
    """Bytes the scope side of a shot holds at once (RECORD_BYTES_PER_POINT per point and
    recorded channel)."""
    return float(RECORD_BYTES_PER_POINT * rig.scope.timebase.record_length * len(rig.scope.channels))


def record_solver(rig: Rig, trigger_by: float) -> tuple:
    """The solver items ("key=value") the rig's scope record needs beyond its solver settings:
    a solve lasting ``trigger_by`` (s, when the record triggers at the latest) plus what
    this scope records after its trigger, and recorded at the scope's sample interval where
    that is finer. Where the scope samples finer than the solver records, the solve lasts
    just that long (shorter than the scene's, if so: every sample of it is held at the fine
    interval); otherwise it is only ever lengthened. () when the rig's solver already gives
    the record."""
    s, dt = rig.solver, rig.scope.timebase.sample_interval
    items = []
    finer = s.sample_interval > dt * (1 + 1e-9)
    grid = dt if finer else s.sample_interval  # the solve's record ends on its last sample
    needed = math.ceil((trigger_by + after_trigger(rig)) / grid * (1 - 1e-12)) * grid
    if needed > s.duration * (1 + 1e-12) or (finer and needed < s.duration * (1 - 1e-12)):
        items.append(f"solver.duration={needed!r} s")
    if finer:
        items.append(f"solver.sample_interval={float(dt)!r} s")
    return tuple(items)


TRIGGER_MARGIN = 0.25
"""How much later than its estimate (a fraction of the estimated time after the impact) a
record sampled finer than the scene's solver may trigger: the estimate is the trigger of
the scene's own time base at seed ESTIMATE_SEED, and a shot at another seed triggers
earlier or later by its draws (the gauges' gains and misalignments, the noise). For the
published PTFE scene (trigger 0.39 ms after the impact) 30 seeds spread +-3%; a shot that
triggers later still is refused as a late trigger, naming the solve to lengthen."""

ESTIMATE_SEED = 0
"""The seed of the shot that estimates when a fine record triggers (trigger_estimate)."""
