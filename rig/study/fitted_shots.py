"""The published shots of a fitted parameter set (`rig reproduce daraio2006 --fitted`): the
52-bead PTFE chain struck at 0.89 m/s, gravity only and with the 2.38 N magnet, measured as
Fig. 3's observations are (rig.fit.observations.kinds), on a fresh chain (the first shot)
and over the shots that follow on the same chain (chain.previous_shots: the contacts keep
their flattening, so a real campaign's later shots meet a settled chain).
"""
from __future__ import annotations

import math

import numpy as np

from rig.experiment import scene as scene_io
from rig.experiment.shot import Rig
from rig.fit.evaluate import calibrate, solve_rigs
from rig.fit.observations import measures
from rig.fit.observations.kinds import KINDS, WALL, look_until, signal
from rig.study.fitted_families import MAGNETIC_SCENE, SCENE

SHOTS = 3
"""The shots on one chain whose drift --fitted reports (the first and the two after it)."""


def fig3_figures(truths: dict) -> dict:
    """Fig. 3's figures of the fitted shots ({scene: Truth}), measured as the observation
    kinds measure them: speeds between the gauges, the full duration at the upper gauge
    (10% rise to 10% fall or first real dip), the pulses at the lower gauge (bead 29) above
    10% of the leading one, the ratio of the upper gauge READINGS' peaks (not F_d), the
    wall's peaks, and the magnetic shot's tail at the lower gauge relative to its leading
    pulse: its oscillation alone ("magnetic_tail_relative", the tail kind) and, beside it,
    its slow shoulder ("magnetic_tail_shoulder_relative", rig.fit.observations.measures.
    tail_shoulder: the mean over the tail's first period)."""
    g, m = truths[SCENE], truths[MAGNETIC_SCENE]

    def of(kind, truth, where=""):
        measure = KINDS[kind].measure
        assert measure is not None, f"a {kind} is measured on one truth (not a ratio)"
        return _finite(measure(truth, where))

    peaks = of("peak", m, "upper"), of("peak", g, "upper")
    duration = of("duration", g, "upper")
    return {"gravity_speed_m_per_s": of("speed", g),
            "gravity_duration_us": None if duration is None else 1e6 * duration,
            "gravity_pulses_lower_gauge": of("pulses", g, "lower"), "magnetic_speed_m_per_s": of("speed", m),
            "gauge_ratio_magnetic_to_gravity": peaks[0] / peaks[1] if None not in peaks and peaks[1] else None,
            "wall_peak_gravity_N": of("wall_peak", g, WALL), "wall_peak_magnetic_N": of("wall_peak", m, WALL),
            "magnetic_tail_relative": of("tail", m, "lower"),
            "magnetic_tail_shoulder_relative": _finite(measures.tail_shoulder(*signal(m, "lower"),
                                                                              until=look_until(m, "lower")))}


def _finite(x):
    return float(x) if x is not None and math.isfinite(x) else None


def fitted_shots(overrides: list, magnetic=()) -> dict:
    """The fitted model's published shots at 0.89 m/s: gravity only and with 2.38 N (with
    ``magnetic``, the overrides of the magnetic shot only), their whole records held to the
    scenes' accuracy (the accuracy control of a fit's pilot); "fig3": fig3_figures."""
    rigs = {SCENE: Rig.from_scene(SCENE, overrides),
            MAGNETIC_SCENE: Rig.from_scene(MAGNETIC_SCENE, list(overrides) + list(magnetic))}
    solve_rigs(list(rigs.values()), calibrate(list(rigs.values())))
    out = {}
    for name, rig in rigs.items():
        t = rig.truth_analysis()
        w = rig.truth().wall()
        out[name] = {"speed_m_per_s": t.speed_m_per_s, "amplitude_N": t.amplitude_N, "duration_s": t.duration_s,
                     "base_duration_s": t.base_duration_s, "pulses": t.pulses, "wall_peak_N": float(np.max(w) - w[0]),
                     "dissipated_energy_J": rig.solution().stats.dissipated_energy_J,
                     "error_estimate": rig.solution().stats.error_estimate}
    out["fig3"] = fig3_figures({name: rig.truth() for name, rig in rigs.items()})
    return out


def shot_history(overrides: list, magnetic=(), shots: int = SHOTS) -> list:
    """Fig. 3's figures (fig3_figures) of ``shots`` shots fired one after another on one
    chain of each scene (the first on a fresh chain, each next meeting the contacts the last
    left: Rig(after=...), the same bits as chain.previous_shots), each shot solved on its own
    at the scene's accuracy (the accuracy control): [{"shot": 1.., "previous_shots": 0..,
    "fig3": {...}}]."""
    last: dict = {}
    out = []
    for k in range(shots):
        rigs = {}
        for name, extra in ((SCENE, ()), (MAGNETIC_SCENE, tuple(magnetic))):
            scene = scene_io.load(name, list(overrides) + list(extra) + [f"chain.previous_shots={k}"])
            rigs[name] = Rig(scene, after=last.get(name))
        out.append({"shot": k + 1, "previous_shots": k, "fig3": fig3_figures({n: r.truth() for n, r in rigs.items()})})
        last = rigs
    return out
