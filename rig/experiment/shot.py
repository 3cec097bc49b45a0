"""The virtual shot: parts and instruments assembled around the solver.

``Rig.from_scene("ptfe52_magnetic").fire(seed=1)`` solves the chain once (the solution is
reused by later fires: instruments draw their randomness per shot, the chain does not),
records only the contacts of the gauge beads and the wall, runs every connected
instrument and the oscilloscope, and returns a ShotRecord. Same seed, same bits.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from instruments.archive import Entry
from instruments.gauges import GaugeDraw, GaugeSettings, PiezoGauge
from instruments.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger
from instruments.records import ScopeRecord

from rig import __version__
from rig.experiment import scene as scene_io
from rig.model.apparatus import Holder, RingMagnet
from rig.model.chain import Chain
from rig.solver.saveat import SaveAt
from rig.errors import RigError, invalid
from rig.model.materials import Material, material
from rig.model.parts import Bead, GaugeBead, MagneticBead, Striker, Wall
from rig.solver.solution import SolverStats
from rig.solver.solve import solve


@dataclass(frozen=True, eq=False)
class GaugeTruth:
    """Noise-free truth at one gauge bead (chain index ``bead``, 0 = top bead)."""

    bead: int
    channel: str
    position_m: float          # equilibrium centre, down from bead 0's centre
    average_force: np.ndarray  # N, what the rigid gauge bead's plate feels
    contact_above: np.ndarray | None  # N (None where only the average was recorded)
    contact_below: np.ndarray | None  # N
    static_above_N: float
    static_below_N: float


@dataclass(frozen=True, eq=False)
class Truth:
    """Ground truth on the solver's output grid t = n * sample_interval (s, 0 = impact)."""

    sample_interval: float
    gauges: dict
    wall_force: np.ndarray | None
    wave_speed_m_per_s: float | None


@dataclass(frozen=True, eq=False)
class ShotRecord:
    """One virtual shot: scope records, every part's settings, the seed and the truth."""

    scene: str
    scene_text: str
    overrides: tuple
    seed: int
    settings: dict
    scope: ScopeRecord
    truth: Truth
    solver: SolverStats
    draws: dict
    analysis_truth: dict | None = None  # the truth block of rig/measure.py, when computed

    def to_entry(self) -> Entry:
        """The archive's plain form of this shot (instruments never see rig objects)."""
        arrays, gauges = {}, {}
        for name, g in self.truth.gauges.items():
            arrays[f"{name}.average_force"] = g.average_force
            if g.contact_above is not None:
                arrays[f"{name}.contact_above"] = g.contact_above
                arrays[f"{name}.contact_below"] = g.contact_below
            gauges[name] = {"bead": g.bead, "channel": g.channel, "position_m": g.position_m,
                            "static_above_N": g.static_above_N, "static_below_N": g.static_below_N}
        if self.truth.wall_force is not None:
            arrays["wall_force"] = self.truth.wall_force
        facts = {"sample_interval_s": self.truth.sample_interval, "gauges": gauges,
                 "analysis": self.analysis_truth,
                 "wave_speed_m_per_s": self.truth.wave_speed_m_per_s, "draws": self.draws,
                 "trigger_time_after_impact_s": self.scope.trigger_time,
                 "solver": self.solver.as_dict(), "overrides": list(self.overrides)}
        key = hashlib.sha256((self.scene_text + "\n".join(self.overrides) + __version__).encode())
        return Entry(self.scope, True, self.seed, self.scene, self.scene_text,
                     {**self.settings, "overrides": list(self.overrides)}, arrays, facts,
                     key.hexdigest()[:16], project_version=__version__)


class Rig:
    """Parts and instruments of one scene (see rig/scene.py for the file format)."""

    def __init__(self, values: dict, scene_text: str = "", overrides: tuple = (), bead_masses=None,
                 like: Rig | None = None):
        """values: a validated scene in SI (rig.scene.load); bead_masses (kg): one mass per
        plain bead, top to bottom, for studies of the bead-to-bead scatter. like: a rig whose
        parts and instruments are taken over where this rig's scene table is the very same
        object as its own (a study's shots share all but the tables their draws change)."""
        self.values = values
        self.scene_text = scene_text
        self.overrides = tuple(overrides)
        self.bead_masses = None if bead_masses is None else [float(m) for m in bead_masses]
        self.name = values.get("scene", {}).get("name", "scene")
        self._build(like)
        self._solution = None

    @classmethod
    def from_scene(cls, name_or_path, overrides=()) -> "Rig":
        values, text = scene_io.load(name_or_path, overrides)
        return cls(values, text, tuple(overrides))

    # --- assembly -------------------------------------------------------------------
    def _build(self, like: Rig | None = None):
        v = self.values
        for table in ("chain", "striker", "holder", "wall", "scope", "solver"):
            if table not in v:
                raise invalid(f"scene [{table}]", None, "this table is required")

        def shared(*tables):  # built from the very same tables as like's: take like's
            return like is not None and all(v.get(t) is like.values.get(t) for t in tables)

        self.holder = like.holder if shared("holder") else Holder(**v["holder"])
        c = dict(v["chain"])
        n = c.pop("beads", None)
        if not isinstance(n, int) or n < 1:
            raise invalid("chain.beads", n, "a whole number of beads >= 1")
        magnetic = c.pop("magnetic_bead", False)
        law = c.pop("contact_law", "hertz")
        damping = c.pop("damping_time", 0.0)
        mat = material(c.get("material"))
        if "youngs_modulus" in c or "poisson_ratio" in c:
            mat = Material(mat.name, c.get("youngs_modulus", mat.E), c.get("poisson_ratio", mat.nu), mat.rho,
                           mat.source + "; elastic constants set by the scene")
        plain = Bead(mat, c.get("diameter"), c.get("mass"))
        first = 1 if magnetic else 0
        if self.bead_masses is None:
            plain_beads = [plain] * n
        else:
            if len(self.bead_masses) != n:
                raise invalid("bead_masses", len(self.bead_masses), f"one mass per plain bead ({n})")
            plain_beads = [plain.with_mass(m) for m in self.bead_masses]
        beads = ([MagneticBead()] if magnetic else []) + plain_beads
        if shared("gauges", "chain"):
            self.gauges = like.gauges
        else:
            self.gauges = {}
            for name, g in sorted(v.get("gauges", {}).items()):
                g = dict(g)
                index = self._gauge_index(name, g.pop("bead", None), g.pop("from_wall", None), first, len(beads))
                self.gauges[name] = (index, g.pop("channel", None), GaugeSettings(**g))
        for index, _, _ in self.gauges.values():
            beads[index] = GaugeBead.like(beads[index])
        self.striker = like.striker if shared("striker") else Striker(**v["striker"])
        self.holder.check(beads, self.striker)
        if shared("magnet"):
            self.magnet = like.magnet
        else:
            self.magnet = RingMagnet(**v["magnet"]) if "magnet" in v else None
        if self.magnet is not None and not magnetic:
            raise invalid("magnet", "set", "a ring magnet needs chain.magnetic_bead = true")
        wall = like.chain.wall if shared("wall") else Wall(**v["wall"])
        self.chain = Chain(beads, striker=self.striker, wall=wall, gravity=self.holder.gravity,
                           top_force=self.magnet.top_force() if self.magnet else 0.0,
                           contact_law=law, damping_time=damping)
        if shared("wall_sensor"):
            self.wall_channel, self.wall_sensor = like.wall_channel, like.wall_sensor
        else:
            ws = dict(v.get("wall_sensor", {}))
            self.wall_channel = ws.pop("channel", None)
            self.wall_sensor = GaugeSettings(misalignment_sd=0.0, **ws) if "wall_sensor" in v else None
        self.scope = like.scope if shared("scope") else self._scope(v["scope"])
        if not shared("gauges", "chain", "wall_sensor", "scope"):
            self._check_connections()
        s = v["solver"]
        self.solver = {"method": s.get("method", "srkn6b"), "accuracy": s.get("accuracy"),
                       "duration": s.get("duration"), "sample_interval": s.get("sample_interval", 1e-7)}
        if not self.solver["duration"] or self.solver["duration"] <= 0:
            raise invalid("solver.duration", self.solver["duration"], "simulated time > 0 s, e.g. '4 ms'")

    @staticmethod
    def _gauge_index(name, bead, from_wall, first, total):
        field = f"gauges.{name}"
        if (bead is None) == (from_wall is None):
            raise invalid(field, None, "give exactly one of bead (from the top) or from_wall")
        plain = total - first
        count = bead if bead is not None else from_wall
        if not 1 <= count <= plain:
            key = "bead" if bead is not None else "from_wall"
            raise invalid(f"{field}.{key}", count, f"the chain has beads 1..{plain} (magnetic bead not counted)")
        return first + bead - 1 if bead is not None else total - from_wall

    @staticmethod
    def _scope(s: dict) -> Oscilloscope:
        s = dict(s)
        channels = {ch: ChannelSettings(**cs) for ch, cs in s.pop("channels", {}).items()}
        trigger = Trigger(**s.pop("trigger", {}))
        timebase = Timebase(s.pop("sample_interval", 1e-7), s.pop("record_length", 20000))
        return Oscilloscope(channels=channels, timebase=timebase, trigger=trigger, **s)

    def _check_connections(self):
        used = {}
        wiring = [(f"gauges.{n}.channel", ch) for n, (_, ch, _) in self.gauges.items()]
        if self.wall_sensor is not None:
            wiring.append(("wall_sensor.channel", self.wall_channel))
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

    # --- the shot ---------------------------------------------------------------------
    def save_at(self, contacts: bool = True, averages: bool = False) -> SaveAt:
        """Only what the instruments need: each gauge bead's two contacts (``contacts``)
        and/or its plate's average of them as one probe (``averages``: studies that need
        no contact apart record 2 channels fewer), and the wall's contact."""
        if not (contacts or averages):
            raise invalid("save_at", "nothing", "the contacts, the averages or both")
        probes = {}
        for name, (index, _, _) in self.gauges.items():
            if contacts:
                for k in (index, index + 1):
                    probes[f"contact{k}"] = self.chain.contact_probe(k)
            if averages:
                probes[f"gauge_{name}"] = self.chain.gauge_probe(index)
        if self.wall_sensor is not None:
            probes["wall"] = self.chain.wall_probe()
        return SaveAt(probes, sample_interval=self.solver["sample_interval"])

    def solution(self):
        if self._solution is None:
            self._solution = solve(self.chain, self.solver["duration"], save=self.save_at(),
                                   method=self.solver["method"], accuracy=self.solver["accuracy"])
        return self._solution

    def truth(self) -> Truth:
        sol = self.solution()
        x = self.chain.equilibrium_positions()
        F0 = self.chain.static_forces()
        gauges = {}
        for name, (j, ch, _) in self.gauges.items():
            above, below = sol.forces.get(f"contact{j}"), sol.forces.get(f"contact{j + 1}")
            average = sol.forces.get(f"gauge_{name}")
            gauges[name] = GaugeTruth(j, ch, float(x[j]), 0.5 * (above + below) if average is None else average,
                                      above, below, float(F0[j]), float(F0[j + 1]))
        return Truth(sol.sample_interval, gauges, sol.forces.get("wall"), _wave_speed(gauges, sol.sample_interval))

    def truth_analysis(self):
        """The pipeline on the noise-free truth (computed once per rig; see rig/measure.py)."""
        if getattr(self, "_truth_report", None) is None:
            from rig.experiment.measure import truth_report

            self._truth_report = truth_report(self, self.truth())
        return self._truth_report

    def use_solution(self, solution):
        """Take the chain's solution from elsewhere (a batched solve of many shots)."""
        self._solution = solution
        self._truth_report = None

    def fire(self, seed: int | None = None, fixed: dict | None = None, truth: bool = True) -> ShotRecord:
        """One shot. ``seed`` (int) fixes every random draw; None draws a fresh one (recorded).
        fixed: {gauge name: {"gain": g, "misalignment": m}} replaces those draws (studies);
        truth=False skips the analysis of the noise-free truth (studies that do not need it)."""
        if seed is None:  # fresh, 63 bits so that it fits a signed 64-bit integer anywhere
            seed = int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(1))
        if not isinstance(seed, (int, np.integer)) or seed < 0:
            raise invalid("seed", seed, "a whole number >= 0")
        rng = np.random.default_rng(int(seed))
        forces = self.truth()
        h = forces.sample_interval
        inputs, draws = {}, {}
        for name, (_, ch, settings) in self.gauges.items():
            draw = GaugeDraw.draw(settings, rng)
            if fixed and name in fixed:
                draw = GaugeDraw(fixed[name].get("gain", draw.gain), fixed[name].get("misalignment", draw.misalignment))
            draws[name] = {"gain": draw.gain, "misalignment_m": draw.misalignment}
            inputs[ch] = PiezoGauge(settings).read(forces.gauges[name].average_force, h, draw, rng,
                                                   forces.wave_speed_m_per_s)
        if self.wall_sensor is not None:
            draw = GaugeDraw.draw(self.wall_sensor, rng)
            draws["wall_sensor"] = {"gain": draw.gain}
            inputs[self.wall_channel] = PiezoGauge(self.wall_sensor).read(forces.wall_force, h, draw, rng)
        try:
            record = self.scope.acquire(inputs, h, rng)
        except ValueError as exc:
            raise RigError(f"{exc} (solver.duration = {self.solver['duration']:g} s)") from None
        truth_analysis = self.truth_analysis().as_dict() if truth and len(self.gauges) >= 2 else None
        return ShotRecord(self.name, self.scene_text, self.overrides, int(seed), self.values, record,
                          forces, self.solution().stats, draws, truth_analysis)


def _wave_speed(gauges: dict, h: float) -> float | None:
    """Leading-pulse speed (m/s) between the outermost gauges, from the truth's peaks."""
    if len(gauges) < 2:
        return None
    g = sorted(gauges.values(), key=lambda t: t.position_m)
    t_top, t_bottom = _first_peak_time(g[0].average_force, h), _first_peak_time(g[-1].average_force, h)
    if t_top is None or t_bottom is None or t_bottom <= t_top:
        return None
    return (g[-1].position_m - g[0].position_m) / (t_bottom - t_top)


def _first_peak_time(f: np.ndarray, h: float) -> float | None:
    """Time (s) of the first local maximum of the dynamic force above half its peak."""
    dyn = f - f[0]
    if dyn.max() <= 0:
        return None
    i = int(np.argmax(dyn > 0.5 * dyn.max()))
    falls = np.flatnonzero(dyn[i + 1:] < dyn[i:-1])  # climb from i to the first sample that falls
    return (i + int(falls[0]) if falls.size else dyn.size - 1) * h
