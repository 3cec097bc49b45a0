"""The solver benchmark's two problems, which ``rig bench solver`` and ``rig bench
accuracy`` both solve: a chain of N_BEADS steel beads (316, 4.76 mm, 0.4501 g) struck by
one bead mass at 0.44 m/s, no gravity, in two scenarios (sonic vacuum: no precompression;
precompressed: 2.38 N from the top, a wall at the bottom), the probe the force of contact
PROBE."""
from __future__ import annotations

from rig.model.chain import Chain
from rig.model.parts import Bead, Striker, Wall

N_BEADS = 1000
PROBE = 500
STEEL = dict(material="steel316", diameter="4.76 mm", mass="0.4501 g")
SCENARIOS = {  # name: (top force N, t_end s) -- t_end lets the pulse pass contact 500
    "sonic-vacuum": (0.0, 5.0e-3),
    "precompressed": (2.38, 4.6e-3),
}


def chain(top_force: float, n: int = N_BEADS) -> Chain:
    """The benchmark chain of ``n`` beads, with the top force (N) and a wall where it is not 0."""
    striker = Striker("steel316", "0.4501 g", "0.44 m/s")
    if top_force:
        return Chain([Bead(**STEEL)] * n, striker=striker, wall=Wall(), gravity=0, top_force=top_force)
    return Chain([Bead(**STEEL)] * n, striker=striker, gravity=0)
