"""The rig on the bench: parts and instruments assembled from a scene, with the wiring
checked (every gauge and the wall sensor on a channel of the scope, no channel taken
twice, a trigger on a connected channel)."""
from __future__ import annotations

import contextlib
import math
from typing import TypeGuard

from instruments.devices.gauges import GaugeSettings
from instruments.devices.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger
from instruments.errors import InstrumentError
from rig.errors import RigError, invalid
from rig.experiment.scene import Scene
from rig.experiment.settings import GaugeWiring, SolverSettings, WallWiring
from rig.model.apparatus import Holder, RingMagnet
from rig.model.chain import Chain
from rig.model.laws import PARAMETERS as LAW_PARAMETERS
from rig.model.materials import Material, material
from rig.model.parts import Bead, GaugeBead, MagneticBead, Striker, Wall

REQUIRED_TABLES = ("chain", "striker", "holder", "wall", "scope", "solver")
MAX_PREVIOUS_SHOTS = 100  # chain.previous_shots: each is a solve of the chain before this shot
MAX_BEADS = 10_000_000  # a list of 1e9 beads is 8 GB before the tube's length could refuse it


SCENE_NAMES = {"E": "youngs_modulus", "nu": "poisson_ratio"}
"""A part's own name of a field where the scene's key differs (a material's E and nu)."""


@contextlib.contextmanager
def scene_key(table: str, prefix: str = ""):
    """Name the scene's key in a part's refusal: a part knows its field as 'bead.diameter',
    'material' or 'material[ptfe].E', the scene as 'chain.diameter', 'chain.material',
    'chain.youngs_modulus' (``prefix``: 'magnetic_' for the magnetic bead's keys)."""
    try:
        yield
    except (RigError, InstrumentError) as exc:
        field, sep, rest = str(exc).partition(" = ")
        if not sep or " " in field or field.startswith(f"{table}."):  # not that form, or named already
            raise
        name = field.split(".")[-1].split("[")[0]
        key = table if name == table.split(".")[-1] else f"{table}.{prefix}{SCENE_NAMES.get(name, name)}"
        raise type(exc)(f"{key} = {rest}") from None


class Assembly:
    """Parts (holder, striker, chain, ring magnet), instruments (gauges, wall sensor,
    oscilloscope) and solver settings of one scene (see rig/experiment/scene.py).

    scene: a validated Scene. bead_masses (kg): one mass per plain bead, top to bottom, for
    studies of the bead-to-bead scatter. like: an assembly whose parts and instruments are
    taken over where this scene's table is the very same object as its own (a study's
    shots share all but the tables their draws change).
    """

    holder: Holder
    gauges: tuple[GaugeWiring, ...]
    striker: Striker
    magnet: RingMagnet | None
    chain: Chain
    wall_sensor: WallWiring | None
    scope: Oscilloscope
    solver: SolverSettings

    def __init__(self, scene: Scene, bead_masses=None, like: Assembly | None = None):
        if not isinstance(scene, Scene):
            raise invalid("scene", scene, "a Scene (rig.experiment.scene.load); Rig.from_scene takes a name or path")
        self.scene = scene
        self.bead_masses = None if bead_masses is None else [float(m) for m in bead_masses]
        self._build(like)

    @property
    def name(self) -> str:
        return self.scene.name

    @property
    def values(self) -> dict:
        return self.scene.values

    def _build(self, like: Assembly | None):
        """The parts and instruments, each refusal naming the scene's key (scene_key)."""
        v = self.values
        for table in REQUIRED_TABLES:
            if table not in v:
                raise invalid(f"scene [{table}]", None, "this table is required")

        def shared(like: Assembly | None, *tables: str) -> TypeGuard[Assembly]:
            """Built from the very same tables as ``like``'s: take like's."""
            return like is not None and all(v.get(t) is like.values.get(t) for t in tables)

        with scene_key("holder"):
            self.holder = like.holder if shared(like, "holder") else Holder(**v["holder"])
        beads, first = self._beads(v["chain"])
        if shared(like, "gauges", "chain"):
            self.gauges = like.gauges
        else:
            self.gauges = tuple(self._gauge(name, dict(g), first, len(beads))
                                for name, g in sorted(v.get("gauges", {}).items()))
            on: dict[int, str] = {}
            for g in self.gauges:  # one gauge per bead: a bead holds one piezo plate
                if g.bead in on:
                    raise RigError(f"gauges.{on[g.bead]} and gauges.{g.name} are both on bead {g.bead - first + 1} "
                                   f"(from the top): each gauge needs a bead of its own")
                on[g.bead] = g.name
            named = {g.name: g for g in self.gauges}
            if "upper" in named and "lower" in named and named["upper"].bead > named["lower"].bead:
                raise RigError(f"gauges.upper is on bead {named['upper'].bead - first + 1} and gauges.lower on bead "
                               f"{named['lower'].bead - first + 1} (from the top): the upper gauge is the one the "
                               "pulse reaches first; swap their beads")
        for g in self.gauges:
            with scene_key(f"gauges.{g.name}"):
                beads[g.bead] = GaugeBead.like(beads[g.bead], mass=g.mass)
        with scene_key("striker"):
            self.striker = like.striker if shared(like, "striker") else Striker(**v["striker"])
        self.holder.check(beads, self.striker)
        if shared(like, "magnet"):
            self.magnet = like.magnet
        else:
            with scene_key("magnet"):
                self.magnet = RingMagnet(**v["magnet"]) if "magnet" in v else None
        if self.magnet is not None and not first:
            raise invalid("magnet", "set", "a ring magnet needs chain.magnetic_bead = true")
        with scene_key("wall"):
            wall = like.chain.wall if shared(like, "wall") else Wall(**v["wall"])
        c, h = v["chain"], self.holder
        self.chain = Chain(beads, striker=self.striker, wall=wall, gravity=h.gravity,
                           top_force=self.magnet.top_force() if self.magnet else 0.0,
                           contact_law=c.get("contact_law", "hertz"),
                           **{key: c[key] for key in LAW_PARAMETERS if key in c},
                           drag=h.drag, friction=h.friction, slip_speed=h.slip_speed,
                           hold=self.magnet.held if self.magnet else 0.0)
        if shared(like, "wall_sensor"):
            self.wall_sensor = like.wall_sensor
        elif "wall_sensor" in v:
            ws = dict(v["wall_sensor"])
            with scene_key("wall_sensor"):
                self.wall_sensor = WallWiring(ws.pop("channel", None), GaugeSettings(misalignment_sd=0.0, **ws))
        else:
            self.wall_sensor = None
        self.scope = like.scope if shared(like, "scope") else self._scope(v["scope"])
        if not shared(like, "gauges", "chain", "wall_sensor", "scope"):
            self._check_connections()
        with scene_key("solver"):
            self.solver = like.solver if shared(like, "solver") else SolverSettings.from_table(v["solver"])
        self.previous_shots = v["chain"].get("previous_shots", 0)
        if not 0 <= self.previous_shots <= MAX_PREVIOUS_SHOTS:
            raise invalid("chain.previous_shots", self.previous_shots,
                          f"a whole number of shots from 0 to {MAX_PREVIOUS_SHOTS}")

    def _beads(self, table: dict) -> tuple:
        """(the chain's beads, 1 if the top one is the magnetic bead else 0)."""
        c = dict(table)
        n = c.pop("beads", None)
        if not isinstance(n, int) or not 1 <= n <= MAX_BEADS:
            raise invalid("chain.beads", n, f"a whole number of beads from 1 to {MAX_BEADS:,}")
        first = 1 if c.pop("magnetic_bead", False) else 0
        with scene_key("chain"):
            mat = material(c.get("material"))
            if "youngs_modulus" in c or "poisson_ratio" in c:
                mat = Material(mat.name, c.get("youngs_modulus", mat.E), c.get("poisson_ratio", mat.nu), mat.rho,
                               mat.source + "; elastic constants set by the scene")
            # a missing diameter (None) is refused by Bead, naming the key
            plain = Bead(mat, c.get("diameter"), c.get("mass"))  # type: ignore[arg-type]
        magnetic = MagneticBead()
        if "magnetic_youngs_modulus" in c or "magnetic_poisson_ratio" in c:
            m = material(magnetic.material)
            with scene_key("chain", "magnetic_"):
                magnetic = MagneticBead(Material(m.name, c.get("magnetic_youngs_modulus", m.E),
                                                 c.get("magnetic_poisson_ratio", m.nu), m.rho,
                                                 m.source + "; elastic constants set by the scene"))
        if self.bead_masses is None:
            plain_beads = [plain] * n
        else:
            if len(self.bead_masses) != n:
                raise invalid("bead_masses", len(self.bead_masses), f"one mass per plain bead ({n})")
            plain_beads = [plain.with_mass(m) for m in self.bead_masses]
        return ([magnetic] if first else []) + plain_beads, first

    @staticmethod
    def _gauge(name: str, g: dict, first: int, total: int) -> GaugeWiring:
        field = f"gauges.{name}"
        bead, from_wall = g.pop("bead", None), g.pop("from_wall", None)
        if bead is None and from_wall is None:
            raise invalid(field, None, "give exactly one of bead (from the top) or from_wall")
        if bead is not None and from_wall is not None:
            raise invalid(f"{field}.from_wall", from_wall, f"give exactly one of bead (from the top, here {bead}) "
                                                          "or from_wall")
        plain = total - first
        count = bead if bead is not None else from_wall
        if not 1 <= count <= plain:
            key = "bead" if bead is not None else "from_wall"
            raise invalid(f"{field}.{key}", count, f"the chain has beads 1..{plain} (magnetic bead not counted)")
        index = first + bead - 1 if bead is not None else total - from_wall
        mass = g.pop("mass", None)
        with scene_key(field):
            return GaugeWiring(name, index, g.pop("channel", None), GaugeSettings(**g), mass)

    @staticmethod
    def _scope(s: dict) -> Oscilloscope:
        s = dict(s)
        channels = {}
        for ch, cs in s.pop("channels", {}).items():
            with scene_key(f"scope.channels.{ch}"):
                channels[ch] = ChannelSettings(**cs)
        trigger = Trigger(**s.pop("trigger", {}))
        timebase = Timebase(s.pop("sample_interval", 1e-7), s.pop("record_length", 20000))
        with scene_key("scope"):
            return Oscilloscope(channels=channels, timebase=timebase, trigger=trigger, **s)

    def _check_connections(self):
        used: dict[str, str] = {}  # {channel: the key that took it}
        wiring = [(f"gauges.{g.name}.channel", g.channel) for g in self.gauges]
        if self.wall_sensor is not None:
            wiring.append(("wall_sensor.channel", self.wall_sensor.channel))
        for field, ch in wiring:
            if ch not in self.scope.channels:
                raise invalid(field, ch, f"not set up on the scope (channels: {', '.join(self.scope.channels)})")
            if ch in used:
                raise invalid(field, ch, f"already taken by {used[ch]}")
            used[ch] = field
        src = self.scope.trigger.source
        if src not in used:
            raise invalid("scope.trigger.source", src,
                          f"triggers on an unconnected channel (connected: {', '.join(used) or 'none'})")

    def check_record(self, trigger: bool = True):
        """Refuse scope settings that can give no record of this rig's solve (RigError naming
        them), before it runs: a shot fires only after this (a fit's windowed solves, which
        read no scope, do not ask). ``trigger``: a trigger that never fires too
        (``trigger_never_fires``)."""
        tb, tr, s = self.scope.timebase, self.scope.trigger, self.solver
        span = tb.record_length * tb.sample_interval
        after = (1 - tr.pre_trigger) * span
        settings = (f"scope.record_length = {tb.record_length} x scope.sample_interval = {tb.sample_interval:g} s, "
                    f"{1 - tr.pre_trigger:.0%} after the trigger")
        if after > s.duration:
            raise RigError(f"the scope records {after:.4g} s after its trigger ({settings}), longer than the "
                           f"simulated solver.duration = {s.duration:g} s: lengthen solver.duration or shorten "
                           "the record")
        if span < 2 * s.sample_interval:
            raise RigError(f"the scope record spans {span:.4g} s ({settings}), less than two samples of its input "
                           f"(solver.sample_interval = {s.sample_interval:g} s): a longer scope.sample_interval")
        if s.sample_interval > tb.sample_interval * (1 + 1e-9):  # the scope would make up its samples
            raise RigError(f"solver.sample_interval = {s.sample_interval:g} s is coarser than scope.sample_interval "
                           f"= {tb.sample_interval:g} s: the scope would read straight lines drawn between the "
                           "solver's recorded forces (samples it never had, a pulse's peak cut); a "
                           f"solver.sample_interval of at most {tb.sample_interval:g} s")
        st, g = self.striker, self.holder.gravity
        if st.gap >= st.velocity * s.duration + 0.5 * g * s.duration**2:  # no impact within the solve
            reach = st.gap / st.velocity if g == 0 else (math.sqrt(st.velocity**2 + 2 * g * st.gap) - st.velocity) / g
            raise RigError(f"striker.gap = {st.gap:g} m at striker.velocity = {st.velocity:g} m/s: the striker "
                           f"reaches the top bead after {reach:.4g} s, not within solver.duration = {s.duration:g} s")
        never = self.trigger_never_fires() if trigger else None
        if never is not None:
            raise never

    def trigger_never_fires(self) -> RigError | None:
        """The refusal of a trigger that cannot fire on this rig's gauges, or None: in NORMal
        mode (in AUTO a record comes all the same), a rising edge at or below the gauges' rest
        at 0 V. ``check_record`` raises it; a served scope waits for the trigger instead (a
        real scope armed in NORMal waits for a valid trigger event: rig/lab/shots.py)."""
        tr = self.scope.trigger
        if tr.slope == "rising" and tr.level <= 0 and tr.mode == "normal":
            return invalid("scope.trigger.level", f"{tr.level:g} V", "a rising trigger needs a level above the "
                                                                    "gauges' rest at 0 V, e.g. '30 mV'")
        return None

    def wiring(self) -> dict:
        """{scope channel: what is connected to it ("gauges.NAME" or "wall_sensor")}."""
        out = {g.channel: f"gauges.{g.name}" for g in self.gauges}
        if self.wall_sensor is not None:
            out[self.wall_sensor.channel] = "wall_sensor"
        return out
