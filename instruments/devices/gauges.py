"""Embedded piezo gauges and the wall sensor: force (N) in, volts out.

A gauge bead's plate reads the mean of the bead's two contact forces (rigid bead). Its
signal chain: sensitivity (V/N, with a calibration error drawn per shot and unknown to
the analysis) -> one-pole RC high-pass in voltage mode (tau about 1 ms: slow loads droop
and undershoot) -> additive white noise (V rms). Misalignment: the plate's true position
differs from the nominal one by a draw (m), which delays the arrival of a pulse travelling
down the chain by misalignment / wave speed.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import check
from ._kernels.acquisition import gauge_signal
from .frontend import highpass_coefficients


@dataclass(frozen=True)
class GaugeSettings:
    """Front panel of a piezo gauge.

    sensitivity: V/N (> 0); calibration_error: relative sd of the true sensitivity around
    the nominal one (>= 0); tau: RC time constant (s, > 0); noise: additive rms (V, >= 0);
    misalignment_sd: sd of the position error along the chain (m, >= 0).
    """

    sensitivity: float = 0.05
    calibration_error: float = 0.05
    tau: float = 1e-3
    noise: float = 1e-3
    misalignment_sd: float = 1e-3

    def __post_init__(self):
        check("gauge.sensitivity", self.sensitivity, lo=0, unit="V/N")
        check("gauge.calibration_error", self.calibration_error, lo=0, hi=0.5, lo_closed=True)
        check("gauge.tau", self.tau, lo=0, unit="s")
        check("gauge.noise", self.noise, lo=0, lo_closed=True, unit="V")
        check("gauge.misalignment_sd", self.misalignment_sd, lo=0, hi=0.01, lo_closed=True, unit="m")


@dataclass(frozen=True)
class GaugeDraw:
    """What one shot drew for a gauge: its true gain factor and position error (m)."""

    gain: float
    misalignment: float

    @classmethod
    def draw(cls, s: GaugeSettings, rng: np.random.Generator) -> GaugeDraw:
        return cls(1.0 + s.calibration_error * rng.standard_normal(),
                   s.misalignment_sd * rng.standard_normal())


class PiezoGauge:
    """A gauge (in a bead, or the wall sensor without misalignment) with fixed settings."""

    def __init__(self, settings: GaugeSettings):
        self.settings = settings

    def read(self, force: np.ndarray, h: float, draw: GaugeDraw, rng: np.random.Generator,
             wave_speed: float | None = None) -> np.ndarray:
        """Volts for a force history (N) sampled every h seconds.

        wave_speed (m/s): speed of the pulse along the chain, to turn the drawn position
        error into a delay; None (the wall sensor) means no misalignment.
        """
        s = self.settings
        force = np.ascontiguousarray(force, dtype=float)
        shift = 0.0 if wave_speed is None else draw.misalignment / wave_speed
        noise = rng.standard_normal(force.size) if s.noise else np.empty(0)
        return gauge_signal(force, float(h), float(shift), s.sensitivity * draw.gain, *highpass_coefficients(h, s.tau),
                            float(s.noise), noise)
