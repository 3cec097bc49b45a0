"""A virtual shot in the archive's plain form (instruments never see rig objects)."""
from __future__ import annotations

import hashlib

from instruments.archive import Entry
from instruments.archive.facts import GaugeFact, ShotFacts
from rig import __version__
from rig.experiment.shot import ShotRecord


def shot_entry(shot: ShotRecord) -> Entry:
    """The archive Entry of a shot: scope record, scene, settings, truth arrays and facts.
    The truth key (one truth stored per scene text, overrides and version) lets shots of
    the same scene share their noise-free truth. Truth names are NeXus names:
    ``upper_average_force``, ``upper_contact_above``, ..., ``wall_force``."""
    arrays, gauges = {}, {}
    for name, g in shot.truth.gauges.items():
        arrays[f"{name}_average_force"] = g.average_force
        if g.contact_above is not None:
            arrays[f"{name}_contact_above"] = g.contact_above
            arrays[f"{name}_contact_below"] = g.contact_below
        gauges[name] = GaugeFact(g.bead, g.channel, g.position_m, g.static_above_N, g.static_below_N)
    if shot.truth.wall_force is not None:
        arrays["wall_force"] = shot.truth.wall_force
    facts = ShotFacts(shot.truth.sample_interval, gauges, shot.analysis_truth, shot.truth.wave_speed_m_per_s,
                      shot.draws, shot.scope.trigger_time, shot.solver.as_dict(), tuple(shot.overrides))
    key = hashlib.sha256((shot.scene_text + "\n".join(shot.overrides) + __version__).encode())
    return Entry(shot.scope, True, shot.seed, shot.scene, shot.scene_text,
                 {**shot.settings, "overrides": list(shot.overrides)}, arrays, facts,
                 key.hexdigest()[:16], project_version=__version__)
