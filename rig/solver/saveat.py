"""SaveAt: what a solve records, given to ``solve`` beside the problem (as diffrax's SaveAt).

Named probes (rig.model.chain.Probe: weighted sums of contact forces) on the uniform grid
t = j * sample_interval, and bead positions every frame_interval only when asked for
(animations). Nothing else is stored.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from rig.errors import invalid
from rig.model.chain import Probe
from rig.units import is_real


@dataclass(frozen=True)
class SaveAt:
    """probes: {name: Probe}; sample_interval (s): the output grid, 1e-7 s serves a
    10 MS/s oscilloscope; frame_interval (s): bead positions every frame_interval, or None."""

    probes: dict = field(default_factory=dict)
    sample_interval: float = 1e-7
    frame_interval: float | None = None

    def __post_init__(self):
        if not (isinstance(self.probes, dict) and all(isinstance(k, str) and isinstance(p, Probe)
                                                      for k, p in self.probes.items())):
            raise invalid("save.probes", self.probes, "{name: Probe}, e.g. {'c5': chain.contact_probe(5)}")
        if not (is_real(self.sample_interval) and self.sample_interval > 0 and math.isfinite(self.sample_interval)):
            raise invalid("save.sample_interval", self.sample_interval, "must be > 0 s")
        if self.frame_interval is not None and not (is_real(self.frame_interval) and self.frame_interval > 0):
            raise invalid("save.frame_interval", self.frame_interval, "must be > 0 s or None")

    @property
    def names(self) -> tuple:
        return tuple(self.probes)

    def channels(self, offset: int) -> tuple:
        """(slots, weights): the probes in the kernels' slot numbering (contact k is slot
        k + offset, offset 1 with a striker), one row per probe, zero-weight padded."""
        width = max([len(p.contacts) for p in self.probes.values()] + [1])
        slots = np.zeros((len(self.probes), width), dtype=np.int64)
        weights = np.zeros((len(self.probes), width))
        for c, p in enumerate(self.probes.values()):
            for j, (k, w) in enumerate(zip(p.contacts, p.weights)):
                slots[c, j] = k + offset
                weights[c, j] = w
        return slots, weights
