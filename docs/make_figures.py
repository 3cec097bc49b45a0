"""Make the README's picture: the scope traces of one virtual shot.

    python docs/make_figures.py [OUT.png]    (default docs/figures/shot_traces.png)

Fires ``ptfe52_magnetic`` at seed 1 (the quick start's shot, bit-identical to
``rig shot ptfe52_magnetic --seed 1``) and draws each scope channel (its gauge or the wall sensor) in volts against
the time from the trigger in microseconds, through the public API only.
"""
from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from rig.experiment.shot import Rig

SCENE, SEED = "ptfe52_magnetic", 1
DEFAULT_OUT = Path(__file__).resolve().parent / "figures" / "shot_traces.png"


def draw(out: Path) -> Path:
    """Fire the shot and write its traces (PNG, 110 dpi) to ``out``; returns ``out``."""
    shot = Rig.from_scene(SCENE).fire(seed=SEED)
    labels = {g["channel"]: f"{g['channel']}: gauge in bead {g['bead']}" for g in shot.settings["gauges"].values()}
    labels[shot.settings["wall_sensor"]["channel"]] = f"{shot.settings['wall_sensor']['channel']}: wall sensor"
    fig, ax = plt.subplots(figsize=(7.5, 3.6), dpi=110)
    for channel, waveform in sorted(shot.scope.waveforms.items()):
        ax.plot(waveform.time() * 1e6, waveform.volts(), lw=0.8, label=labels.get(channel, channel))
    ax.set_xlabel("time from the trigger (us)")
    ax.set_ylabel("scope input (V)")
    ax.set_title(f"rig shot {SCENE} --seed {SEED}: the virtual scope's channels", fontsize=10)
    ax.legend(frameon=False)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    plt.close(fig)
    return out


if __name__ == "__main__":
    print(f"wrote {draw(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_OUT)}")
