"""The virtual shot: the assembled rig solved, its instruments read, the scope triggered.

``Rig.from_scene("ptfe52_magnetic").fire(seed=1)`` solves the chain once (the solution is
reused by later fires: instruments draw their randomness per shot, the chain does not),
records only the contacts of the gauge beads and the wall, runs every connected
instrument and the oscilloscope, and returns a ShotRecord. Same seed, same bits.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from instruments.analysis.report import Report
from instruments.devices.gauges import GaugeDraw, PiezoGauge
from instruments.records import ScopeRecord
from rig.errors import RigError, RigNote, invalid
from rig.experiment import scene as scene_io
from rig.experiment.assembly import Assembly
from rig.experiment.history import after_shots
from rig.experiment.truth import Truth, truth_of
from rig.solver.estimate import RunEstimate, estimate_solve
from rig.solver.problem import ChainProblem
from rig.solver.run import Unstable
from rig.solver.saveat import SaveAt
from rig.solver.solution import Solution, SolverStats
from rig.solver.solve import solve


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
    analysis_truth: dict | None = None  # the truth block of rig/experiment/measure.py, when computed


FAR = 20  # an overlap of more than radius / FAR is far outside the contact law's range


def overlap_doubt(chain) -> str:
    """Why a chain's solve may blow up at every step, or "": a static load that presses a
    contact more than 1/FAR of its bead's radius together (Chain.static_overlaps), or a
    striker whose energy could press it that far into the top bead (Chain.impact_overlap);
    the solver stops as unstable at half a radius."""
    radii = np.array([b.radius for b in chain.beads])
    static = chain.static_overlaps()[:radii.size] / radii  # contact k: above bead k
    k = int(np.argmax(static))
    if static[k] > 1 / FAR:
        return (f": the static load, {chain.static_forces()[k]:.4g} N at contact {k} (magnet.force and the chain's "
                f"weight), presses it {static[k]:.3g} times a bead's {radii[k] * 1e3:.3g} mm radius together; the "
                f"contact law holds for overlaps far below the radius")
    if chain.striker is None:
        return ""
    overlap, radius = chain.impact_overlap(), radii[0]
    if not overlap > radius / FAR:
        return ""
    st, n = chain.striker, float(chain.contact_exponents()[0])
    v_far = st.velocity * (radius / FAR / overlap) ** ((n + 1) / 2)  # the overlap grows as v^(2 / (n + 1))
    return (f": striker.velocity = {st.velocity:g} m/s with striker.mass = {st.mass:g} kg could press the striker "
            f"{overlap:.3g} m into the top bead, {overlap / radius:.3g} times its {radius * 1e3:.3g} mm radius; the "
            f"contact law holds for overlaps far below the radius (1/{FAR} of it up to {v_far:.3g} m/s here)")


def fresh_seed() -> int:
    """A fresh seed of 63 bits, so that it fits a signed 64-bit integer anywhere."""
    return int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(1))


class Rig(Assembly):
    """An assembled scene that fires shots (see Assembly for the parts and instruments).
    ``after``: the rig of the shot before on the same chain (its scene the same but for
    chain.previous_shots, one less): this rig's chain is the one that shot left, as
    chain.previous_shots would solve it again (the same solve, the same bits)."""

    def __init__(self, scene, bead_masses=None, like: Assembly | None = None, after: Rig | None = None):
        super().__init__(scene, bead_masses, like)
        self._solution: Solution | None = None
        self._truth_report: Report | None = None
        if after is not None:  # the next shot on ``after``'s chain: its history is after's and after's shot
            if self.previous_shots != after.previous_shots + 1:
                raise invalid("chain.previous_shots", self.previous_shots,
                              f"the shot after one with chain.previous_shots = {after.previous_shots} is "
                              f"{after.previous_shots + 1}")
            self.chain = after.chain.after_shot(after.solution())
        elif self.previous_shots and not self.chain.law.yielding:  # the same chain: nothing to solve
            warnings.warn(f"chain.previous_shots = {self.previous_shots} changes nothing here: the contact law "
                          f"{self.chain.law.name!r} keeps no memory of a shot (chain.contact_law = thornton does)",
                          RigNote, stacklevel=2)
        elif self.previous_shots:  # the chain as its earlier shots left it (rig/experiment/history.py)
            self.chain = after_shots(self.chain, self.previous_shots, self.solver, self.save_at())

    @classmethod
    def from_scene(cls, name_or_path, overrides=()) -> Rig:
        return cls(scene_io.load(name_or_path, overrides))

    def save_at(self, contacts: bool = True, averages: bool = False) -> SaveAt:
        """Only what the instruments need: each gauge bead's two contacts (``contacts``)
        and/or its plate's average of them as one probe (``averages``: studies that need
        no contact apart record 2 channels fewer), and the wall's contact."""
        if not (contacts or averages):
            raise invalid("save_at", "nothing", "the contacts, the averages or both")
        probes = {}
        for g in self.gauges:
            if contacts:
                for k in (g.bead, g.bead + 1):
                    probes[f"contact{k}"] = self.chain.contact_probe(k)
            if averages:
                probes[f"gauge_{g.name}"] = self.chain.gauge_probe(g.bead)
        if self.wall_sensor is not None:
            probes["wall"] = self.chain.wall_probe()
        return SaveAt(probes, sample_interval=self.solver.sample_interval)

    def estimate(self, controlled: bool = True) -> RunEstimate:
        """How big and how long this rig's solve will be (before it runs); ``controlled``:
        with the accuracy control's tries (False: one solve at its step, as a study's shots)."""
        s = self.solver
        return estimate_solve(ChainProblem.from_chain(self.chain), s.duration, len(self.save_at().names),
                              s.sample_interval, s.method, s.accuracy, controlled)

    def solution(self) -> Solution:
        if self._solution is None:
            s = self.solver
            try:
                self._solution = solve(self.chain, s.duration, save=self.save_at(), method=s.method,
                                       accuracy=s.accuracy)
            except Unstable as exc:
                raise Unstable(f"{exc}{overlap_doubt(self.chain)}", exc.stepping) from None
        return self._solution

    def truth(self) -> Truth:
        return truth_of(self, self.solution())

    def truth_analysis(self):
        """The pipeline on the noise-free truth (computed once per rig; see measure.py)."""
        if self._truth_report is None:
            from rig.experiment.measure import truth_report

            self._truth_report = truth_report(self, self.truth())
        return self._truth_report

    def use_solution(self, solution: Solution):
        """Take the chain's solution from elsewhere (a batched solve of many shots)."""
        self._solution = solution
        self._truth_report = None

    def fire(self, seed: int | None = None, fixed: dict | None = None, truth: bool = True) -> ShotRecord:
        """One shot. ``seed`` (int) fixes every random draw; None draws a fresh one (recorded).
        fixed: {gauge name: {"gain": g, "misalignment": m}} replaces those draws (studies);
        truth=False skips the analysis of the noise-free truth (studies that do not need it)."""
        if seed is None:
            seed = fresh_seed()
        if not isinstance(seed, (int, np.integer)) or seed < 0:
            raise invalid("seed", seed, "a whole number >= 0")
        self.check_record()
        rng = np.random.default_rng(int(seed))
        forces = self.truth()
        h = forces.sample_interval
        inputs, draws, rest = {}, {}, {}
        for g in self.gauges:
            draw = GaugeDraw.draw(g.settings, rng)
            if fixed and g.name in fixed:
                f = fixed[g.name]
                draw = GaugeDraw(f.get("gain", draw.gain), f.get("misalignment", draw.misalignment))
            draws[g.name] = {"gain": draw.gain, "misalignment_m": draw.misalignment}
            inputs[g.channel] = PiezoGauge(g.settings).read(forces.gauges[g.name].average_force, h, draw, rng,
                                                            forces.wave_speed_m_per_s)
            rest[g.channel] = g.settings.noise
        if self.wall_sensor is not None and forces.wall_force is not None:  # a wall sensor's truth has it
            draw = GaugeDraw.draw(self.wall_sensor.settings, rng)
            draws["wall_sensor"] = {"gain": draw.gain}
            inputs[self.wall_sensor.channel] = PiezoGauge(self.wall_sensor.settings).read(forces.wall_force, h,
                                                                                          draw, rng)
            rest[self.wall_sensor.channel] = self.wall_sensor.settings.noise
        try:
            record = self.scope.acquire(inputs, h, rng, rest)
        except ValueError as exc:  # the record would run past the simulated input: a late trigger
            tr = self.scope.trigger
            raise RigError(f"the scope triggered late, on {tr.source} ({self.wiring().get(tr.source)}, "
                           f"scope.trigger.level = {tr.level:g} V): {exc}; lengthen solver.duration = "
                           f"{self.solver.duration:g} s, or trigger on a gauge the pulse reaches sooner") from None
        truth_analysis = self.truth_analysis().as_dict() if truth and len(self.gauges) >= 2 else None
        return ShotRecord(self.name, self.scene.text, self.scene.overrides, int(seed), self.values, record,
                          forces, self.solution().stats, draws, truth_analysis)
