"""The rest of the rig over SCPI, the ``RIG:`` subsystem: ``RIG:FIRE`` (a shot now, an impact in the trigger's mode),
``RIG:STRiker:VELocity``, ``RIG:MAGnet:FORCe``, ``RIG:MAGnet:POSition`` (scene keys
striker.velocity, magnet.force, magnet.position; values as in scene files, a number and
its unit: ``RIG:STR:VEL 0.9 m/s``, or a quoted string; the query answers the text set, or
"scene" while the scene's own value holds), ``RIG:SEED`` (the next shot's seed),
``RIG:SCENe?`` (the scene's name) and ``RIG:OVERrides?`` (what the next shot is fired with,
``"key=value,..."``). A value goes to the injected ``validate(key, text)``; its refusal
is a -224 event with the rig's own words. Its own table, so a server can put it on the
scope's port and on a port of its own."""
from __future__ import annotations

from ..scpi.engine import Call
from ..scpi.status import ScpiError

RIG_KEYS = {"STRiker:VELocity": "striker.velocity", "MAGnet:FORCe": "magnet.force",
            "MAGnet:POSition": "magnet.position"}


def register(tree, scope) -> None:
    """Add the RIG: commands of ``scope`` (a VirtualScope) to a command tree."""

    def setter(key: str):
        def write(c: Call):
            c.only(1)
            text = c.arg().text.strip()
            refusal = scope.validate(key, text)
            if refusal is not None:
                raise ScpiError(-224, refusal)
            scope.rig_values[key] = text
        return write

    def reader(key: str):
        return lambda c: _quoted(scope.rig_values.get(key, scope.rig_scene.get(key, "not set in the scene")))

    def set_seed(c: Call):
        seed = c.number()
        if seed != int(seed) or not 0 <= seed < 2 ** 63:
            raise ScpiError(-222, f"{c.header} {c.arg().text}: a whole number from 0 to 2^63 - 1")
        scope.acq.next_seed = int(seed)

    for pattern, key in RIG_KEYS.items():
        tree.add(f"RIG:{pattern}", write=setter(key), read=reader(key))
    tree.add("RIG:FIRE", write=lambda c: c.only(0) or scope.acq.fire())
    tree.add("RIG:SEED", write=set_seed, read=lambda c: str(scope.acq.next_seed))
    tree.add("RIG:SCENe", read=lambda c: _quoted(scope.scene_name))
    tree.add("RIG:OVERrides", read=lambda c: _quoted(",".join(f"{k}={v}" for k, v in scope.overrides_locked().items())))


def _quoted(text: str) -> str:
    return '"' + text.replace('"', '""') + '"'
