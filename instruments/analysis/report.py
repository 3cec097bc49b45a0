"""The pipeline's answer for one shot: its figures, and for each one it cannot give, why."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

FIGURES = ("speed_m_per_s", "speed_xcorr_m_per_s", "averaged_amplitude_N", "amplitude_N", "total_force_N",
           "pulses", "duration_s", "base_duration_s", "width_diameters")
SPEED_FIGURES = ("speed_m_per_s", "speed_xcorr_m_per_s", "pulses", "width_diameters")


@dataclass
class Report:
    """The analysis of one shot (SI units). A figure the analysis cannot give is None and
    ``reasons`` maps its name to why. snr: channel -> the leading pulse's amplitude over
    the noise (where no pulse passed the rule, the largest excursion over the noise);
    noise: channel -> the pre-trigger noise (force units; see analysis.noise_level)."""

    speed_m_per_s: float | None = None
    speed_xcorr_m_per_s: float | None = None
    averaged_amplitude_N: float | None = None
    amplitude_N: float | None = None
    total_force_N: float | None = None
    beta: float | None = None
    static_force_N: float | None = None
    pulses: int | None = None
    duration_s: float | None = None
    base_duration_s: float | None = None
    width_diameters: float | None = None
    leading: dict = field(default_factory=dict)
    snr: dict = field(default_factory=dict)
    noise: dict = field(default_factory=dict)
    reasons: dict = field(default_factory=dict)

    def refuse(self, why: str, figures=FIGURES) -> Report:
        """Leave ``figures`` out (None), each with ``why`` unless it has a reason already."""
        for name in figures:
            setattr(self, name, None)
            self.reasons.setdefault(name, why)
        return self

    def give(self, name: str, value: float, why: str) -> None:
        """Set figure ``name`` to value if it is finite, else leave it None with ``why``."""
        if math.isfinite(value):
            setattr(self, name, float(value))
        else:
            self.refuse(why, (name,))

    def as_dict(self) -> dict:
        """JSON-ready: non-finite floats (at the top and in snr, noise, leading) as None."""
        return {k: ({kk: _finite(vv) for kk, vv in v.items()} if k in ("snr", "noise") else _finite(v))
                for k, v in asdict(self).items()}


def _finite(v):
    return None if isinstance(v, float) and not math.isfinite(v) else v
