"""What every shot of a Monte Carlo study starts from, computed once per study's scene:
the nominal rig, the calibration an experimenter applies to every shot, the leading window
and the template rig whose parts the shots take over.

One cache (``nominal``) keeps these per (scene, overrides) in a process; the values are
computed on first use, from the nominal scene's noise-free solution and from its nominal
shot (``nominal_trigger_time``: the one shot a study fires outside its design, with the
instrument draws of NOMINAL_SEED). Each of these solves runs through the batched kernel
that the study's shots take, as a batch of one (rig.solver.ensemble.solved_as_batches; the
same bits as the single-shot kernel): a study compiles and loads one chain kernel.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

from rig.experiment import scene as scene_io
from rig.experiment.measure import leading_end, midway_static_force
from rig.experiment.shot import Rig
from rig.solver.ensemble import solved_as_batches

NOMINAL_SEED = 0
"""The seed of the nominal shot's instrument draws (gains, misalignments, noise, the scope's
noise floor): the shot that times the scope's trigger for the leading window. Every study's
window, hence every result, depends on it."""


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
        self._templates: dict[str, Rig] = {}
        self._pilots: dict[tuple, object] = {}

    @functools.cached_property
    def calibration(self) -> tuple:
        """(beta, F_0 in N) of the nominal numerics: what an experimenter applies to every
        shot (each shot's own truth is unknown to the analysis)."""
        with solved_as_batches():
            return self.rig.truth_analysis().beta, midway_static_force(self.rig)

    @property
    def record_window(self) -> Window:
        """The scene's own window."""
        rig = self.rig
        return Window(rig.solver.duration, rig.scope.timebase.record_length, rig.scope.trigger.pre_trigger)

    @functools.cached_property
    def leading_window(self) -> Window:
        """Simulated until the nominal leading pulse has passed the last gauge (leading_end:
        TAIL_FWHM full widths after it peaks there; the cross-correlation searches 2 widths
        around it, the third covers the shot-to-shot spread of its arrival); the scope keeps
        the scene's pre-trigger samples (the baseline comes from them) and records after the
        trigger only as long as the simulation lasts, the trigger taken at the nominal shot's time + 5% (spread). The
        scene's own window where the nominal shot shows no leading pulse (or one cut off by
        the record's end) or no trigger."""
        rig = self.rig
        tb, pre = rig.scope.timebase, rig.scope.trigger.pre_trigger
        with solved_as_batches():
            end = leading_end(rig.truth_analysis())
            trigger = nominal_trigger_time(rig)
        if end is None or trigger is None:
            return self.record_window
        duration = min(rig.solver.duration, end)
        n_pre = int(round(pre * tb.record_length))
        n_post = int((duration - 1.05 * trigger) / tb.sample_interval)
        if n_post <= 0 or n_pre + n_post >= tb.record_length:
            return self.record_window
        return Window(duration, n_pre + n_post, n_pre / (n_pre + n_post))

    def window(self, kind: str) -> Window:
        """The study's window: "leading" or "record" (the scene's own)."""
        return self.leading_window if kind == "leading" else self.record_window

    def pilot(self, kind: str, save, accuracy: float | None):
        """The study's step, calibrated once (not per shot): the accuracy control run on the
        nominal shot over the study's window, recording what the shots record (``save``) at
        ``accuracy`` (None: the scene's). Its Solution: stats.dt_s is the step every shot
        takes, stats.error_estimate the estimate the shots carry."""
        key = (kind, save.names, accuracy)
        if key not in self._pilots:
            from rig.solver.problem import ChainProblem
            from rig.solver.solve import solve

            rig = self.template(kind)
            with solved_as_batches():
                self._pilots[key] = solve(ChainProblem.from_chain(rig.chain), rig.solver.duration, save=save,
                                          method=rig.solver.method, accuracy=accuracy or rig.solver.accuracy)
        return self._pilots[key]

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


def nominal_trigger_time(rig: Rig) -> float | None:
    """When the scope triggers (s) in the nominal shot of ``rig``, None where it does not.
    The nominal shot is the rig's noise-free solution read by instruments whose draws come
    from NOMINAL_SEED: the trigger fires on what the instruments read, so their draws take
    part. The truth analysis is skipped (the shot is only timed)."""
    shot = rig.fire(seed=NOMINAL_SEED, truth=False)
    return shot.scope.trigger_time if shot.scope.triggered else None


@functools.lru_cache(maxsize=4)
def nominal(scene: str, overrides: tuple) -> Nominal:
    """The Nominal of a study's scene: the one cache of what the shots start from, one
    Nominal per (scene, overrides) in a process (each worker process builds its own)."""
    return Nominal(scene, tuple(overrides))


def copied_table(v: dict, path) -> dict:
    """The table at ``path`` in v, after copying every table along it (copy on write: the
    scene's other tables stay shared with the nominal values, which nothing modifies)."""
    node = v
    for p in path:
        node[p] = dict(node.get(p, {}))
        node = node[p]
    return node
