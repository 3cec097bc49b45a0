"""What a movie of a shot costs before it is rendered (``rig animate``): its options
checked, and its estimate, the shot's solve with the rendering beside it. Needs nothing of
the rendering (pyvista, imageio)."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rig.errors import RigError, invalid

if TYPE_CHECKING:  # the solver (numba) is imported where a movie is estimated, after the options' checks
    from rig.solver.estimate import RunEstimate

GIF_BYTES_PER_FRAME = 4.5e6  # a .gif's writer holds every frame until it closes (measured: 40 -> 120 frames, +360 MB)
SECONDS_PER_FRAME = 0.16  # rendering and encoding a frame, one core (measured: 0.10 .mp4, 0.16 .gif)


def check_options(frames, exaggerate) -> None:
    """RigError in one line for --frames outside 2..10000 or an --exaggerate that is no
    factor > 0 (before anything is estimated or solved)."""
    if not isinstance(frames, int) or not 2 <= frames <= 10000:
        raise invalid("--frames", frames, "a whole number of frames from 2 to 10000")
    if exaggerate is not None and not (np.isfinite(exaggerate) and exaggerate > 0):
        raise invalid("--exaggerate", exaggerate, "a factor > 0")


def movie_estimate(solve: RunEstimate, frames: int, out) -> RunEstimate:
    """The estimate of a movie of ``frames`` frames to ``out``: the shot's ``solve`` and the
    rendering beside it (a .gif holds every frame until it is written, a .mp4 streams them
    to its encoder, a .png renders one). RigError in one line where a .gif's frames would
    not fit in this machine's memory, whatever --allow-large says."""
    from rig.solver.run import physical_memory

    kind = Path(out).suffix.lower()
    count = 1 if kind == ".png" else frames
    held = GIF_BYTES_PER_FRAME * count if kind == ".gif" else 0.0
    memory = physical_memory()
    if held > memory:
        raise RigError(f"--frames {frames}: a .gif holds every frame until it is written, about {held / 1e9:.3g} GB, "
                       f"beyond this machine's {memory / 1e9:.3g} GB; write a .mp4 (its frames are streamed) or "
                       f"fewer frames")
    return replace(solve, bytes=solve.bytes + held, seconds=solve.seconds + SECONDS_PER_FRAME * count)
