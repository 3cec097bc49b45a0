"""An example bluesky plan on the rig's devices (rig/lab/bluesky.py; the ``bluesky`` extra):
the magnet's force scanned, N shots per force, every shot one event holding the force it
was fired with and the scope's waveforms.

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
    scope and read it with the magnet (one event per shot). One run; its start document
    names the forces and the shots per force."""
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
            yield from bps.mv(magnet, force)
            for _ in range(shots):
                yield from bps.trigger_and_read([scope, magnet])

    return (yield from scan())


def documents(run_engine, plan) -> list:
    """Run ``plan`` on ``run_engine``; the (name, document) pairs it emitted, in order."""
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
