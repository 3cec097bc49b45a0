"""What every shot of a Monte Carlo study starts from, computed once per study's scene:
the nominal rig, the calibration an experimenter applies to every shot, the leading window
and the template rig whose parts the shots take over.

One cache (``nominal``) keeps these per (scene, overrides); the values are computed on
first use, from the nominal scene and its nominal shot (instrument seed NOMINAL_SEED).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

from rig.experiment import scene as scene_io
from rig.experiment.measure import midway_static_force
from rig.experiment.shot import Rig

TAIL_FWHM = 3.0    # the leading window ends this many widths after the last gauge's leading peak
NOMINAL_SEED = 0   # the instrument draws of the nominal shot that times the trigger


@dataclass(frozen=True)
class Window:
    """What a study simulates and records: duration (s), scope record length (samples) and
    pre-trigger fraction."""

    duration: float
    record_length: int
    pre_trigger: float


class Nominal:
    """The nominal scene of a study (its fixed overrides applied), and what follows from it."""

    def __init__(self, scene: str, overrides: tuple):
        self.rig = Rig(scene_io.load(scene, overrides))  # validates
        self._templates = {}

    @functools.cached_property
    def calibration(self) -> tuple:
        """(beta, F_0 in N) of the nominal numerics: what an experimenter applies to every
        shot (each shot's own truth is unknown to the analysis)."""
        return self.rig.truth_analysis().beta, midway_static_force(self.rig)

    @functools.cached_property
    def leading_window(self) -> Window:
        """Simulated until TAIL_FWHM full widths after the nominal leading pulse peaks at the
        last gauge (the cross-correlation searches 2 widths around it; the third covers the
        shot-to-shot spread of its arrival); the scope keeps the scene's pre-trigger samples
        (the baseline comes from them) and records after the trigger only as long as the
        simulation lasts, the trigger taken at the nominal shot's time + 5% (spread). The
        scene's own window where the nominal shot shows no leading pulse or no trigger."""
        rig = self.rig
        tb, pre = rig.scope.timebase, rig.scope.trigger.pre_trigger
        whole = Window(rig.solver.duration, tb.record_length, pre)
        lead = rig.truth_analysis().leading
        last = lead.get("lower") or lead.get("upper")
        shot = rig.fire(seed=NOMINAL_SEED, truth=False)
        if not last or not last.get("fwhm") or not shot.scope.triggered:
            return whole
        duration = min(rig.solver.duration, last["time"] + TAIL_FWHM * last["fwhm"])
        n_pre = int(round(pre * tb.record_length))
        n_post = int((duration - 1.05 * shot.scope.trigger_time) / tb.sample_interval)
        if n_post <= 0 or n_pre + n_post >= tb.record_length:
            return whole
        return Window(duration, n_pre + n_post, n_pre / (n_pre + n_post))

    def window(self, kind: str) -> Window:
        """The study's window: "leading" or "record" (the scene's own)."""
        if kind == "leading":
            return self.leading_window
        tb = self.rig.scope.timebase
        return Window(self.rig.solver.duration, tb.record_length, self.rig.scope.trigger.pre_trigger)

    def template(self, kind: str) -> Rig:
        """The rig every shot starts from: the solver recording at the scope's sampling rate
        (the scope reads nothing finer) and, in the leading window, the window's duration
        and record; its parts are taken over by the shots."""
        if kind not in self._templates:
            v = dict(self.rig.values)
            solver, scope = copied_table(v, ["solver"]), copied_table(v, ["scope"])
            scope_dt = scope.get("sample_interval")
            if scope_dt and scope_dt > solver.get("sample_interval", 1e-7):
                solver["sample_interval"] = scope_dt
            if kind == "leading":
                w = self.leading_window
                solver["duration"], scope["record_length"] = w.duration, w.record_length
                copied_table(v, ["scope", "trigger"])["pre_trigger"] = w.pre_trigger
            self._templates[kind] = Rig(self.rig.scene.with_values(v), like=self.rig)
        return self._templates[kind]


@functools.lru_cache(maxsize=4)
def nominal(scene: str, overrides: tuple) -> Nominal:
    """The Nominal of a study's scene (one per scene and overrides in a process)."""
    return Nominal(scene, tuple(overrides))


def copied_table(v: dict, path) -> dict:
    """The table at ``path`` in v, after copying every table along it (copy on write: the
    scene's other tables stay shared with the nominal values, which nothing modifies)."""
    node = v
    for p in path:
        node[p] = dict(node.get(p, {}))
        node = node[p]
    return node
