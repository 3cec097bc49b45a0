"""An example bluesky plan on the rig's devices (rig/lab/bluesky.py; the ``bluesky`` extra):
the magnet's force scanned, N shots per force, every shot one event holding the force it
was fired with and the scope's waveforms.

It is built as bluesky's own plans are (``one_nd_step``): a checkpoint before each shot, so
that a pause (Ctrl-C once: a deferred pause) stops there, and an immediate one (Ctrl-C
twice, ``RunEngine.request_pause()``) rewinds there: ``RunEngine.resume()`` goes on from
that shot, which the scope fires again at its own seed if the pause caught it in flight
(rig/lab/bluesky.py). The run then holds one event per planned shot, seq_num 1, 2, ... and
the seeds N, N+1, ... once each (but for the two instants of an immediate pause that
``VirtualScope`` names). bluesky's ``count``, ``scan``, ``list_scan`` and ``grid_scan`` take
the same devices (``Magnet``, ``Striker`` as motors).

    from bluesky import RunEngine
    bench = InProcessBench("ptfe52_magnetic", seed=1)
    scope, magnet = VirtualScope(bench, name="scope"), Magnet(bench, name="magnet")
    docs = documents(RunEngine(), magnet_force_scan(scope, magnet, [2.0, 3.0], shots=3))
"""
from __future__ import annotations

from collections.abc import Iterable

import bluesky.plan_stubs as bps
import bluesky.preprocessors as bpp

from rig.errors import invalid


def magnet_force_scan(scope, magnet, forces: Iterable[float], shots: int = 1, md: dict | None = None):
    """A plan: for each force (N), move the magnet there, then ``shots`` times trigger the
    scope and read the magnet and the scope (one event per shot), a checkpoint before each
    shot (and before the move to its force, for a force's first shot). One run; its start
    document names the forces and the shots per force."""
    forces = [float(f) for f in forces]
    if not forces:
        raise invalid("forces", forces, "one force or more, in N")
    if isinstance(shots, bool) or not isinstance(shots, int) or shots < 1:
        raise invalid("shots", shots, "a whole number of shots per force >= 1")
    meta = {"plan_name": "magnet_force_scan", "forces_N": forces, "shots_per_force": shots,
            "detectors": [scope.name], "motors": [magnet.name], "num_points": len(forces) * shots,
            "hints": {"dimensions": [([f"{magnet.name}-force"], "primary")]}, **(md or {})}

    @bpp.stage_decorator([scope, magnet])
    @bpp.run_decorator(md=meta)
    def scan():
        for force in forces:
            for shot in range(shots):
                yield from bps.checkpoint()  # a pause stops here, and resume goes on from here
                if shot == 0:
                    yield from bps.mv(magnet, force)
                # the scope read last: its reading marks its shot delivered (bluesky.py), so
                # a pause between the mark and the event's save falls in one loop turn only
                yield from bps.trigger_and_read([magnet, scope])

    return (yield from scan())


def documents(run_engine, plan) -> list:
    """Run ``plan`` on ``run_engine``; the (name, document) pairs it emitted, in order. For a
    run that may be paused, subscribe a callback of your own instead: a pause ends this call
    (``RunEngineInterrupted``), and the rest of the documents come with ``resume()``."""
    out = []
    token = run_engine.subscribe(lambda name, doc: out.append((name, doc)))
    try:
        run_engine(plan)
    finally:
        run_engine.unsubscribe(token)
    return out


def tiled_writer(uri: str, api_key: str | None = None):
    """A RunEngine callback storing every document in the tiled catalog at ``uri``
    (``run_engine.subscribe(tiled_writer(uri))``). RigError of one line where tiled is not
    installed."""
    try:
        from bluesky.callbacks.tiled_writer import TiledWriter
        from tiled.client import from_uri
    except ImportError as exc:
        raise invalid("tiled_writer", uri, f"needs the tiled client (pip install 'tiled[client]'): {exc}") from None
    return TiledWriter(from_uri(uri, api_key=api_key))
