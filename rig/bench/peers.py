"""Peer solvers for the solver benchmark: the same chain, the same probe, the same grid.

Every peer integrates the same ChainProblem (rig/solver/problem.py): bodies from the top
[striker] + beads + [wall, inverse mass 0], displacement u from static equilibrium (m) and
velocity v (m/s), contact slot i joining bodies i-1 and i with the dynamic force

    f[i] = A[i] max(d, 0)^(3/2) - load[i],  d = d0[i] + u[i-1] - u[i],  f[0] = 0,  f[nb] = -load[nb]

(N), body i accelerated by (f[i] - f[i+1]) invm[i] (m/s^2), conservative Hertz law only.
Each integrates from t = 0 to t_end and records only one probe, the whole contact force of
one slot s, F = A[s] max(d_s, 0)^(3/2) (N), on the grid t_j = j sample_interval,
j = 0 .. floor(t_end / sample_interval) (the grid of rig.solver.solve):

- ``scipy_dop853``: scipy.integrate.solve_ivp, method DOP853, vectorised numpy right-hand
  side, in this process.
- ``numba_dop853``: DOP853 compiled with numba (rig/bench/kernels/dop853.py), Hairer's
  step-size control, the probe from the method's own dense output.
- ``lammps_hertz``: LAMMPS (pair_style granular, Hertz normal force, no damping, no
  friction; fix nve/sphere, velocity Verlet at a fixed step) in a subprocess, when an
  ``lmp`` or ``lmp_serial`` executable is on the PATH.

Each returns a PeerRun; cpu_s is the CPU time of the integration only (time.process_time in
process, the child's user + system time for LAMMPS).
"""
from __future__ import annotations

import math
import os
import resource
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rig.errors import RigError, invalid
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt
from rig.solver.solve import time_grid

POSITION_SCALE = 1e-5  # m: the absolute tolerance of a displacement is rtol x this
VELOCITY_FLOOR = 1e-3  # m/s: ... of a velocity, rtol x max(largest initial speed, this)
LAMMPS_EXECUTABLES = ("lmp", "lmp_serial")


@dataclass(frozen=True)
class PeerRun:
    """One run of a peer: name and setting (e.g. "numba-DOP853", "rtol=1e-08"); force: the
    probe on the output grid (N); cpu_s, wall_s: CPU and wall time of the integration (s);
    rhs_evaluations: evaluations of the chain's forces (all bodies); steps: accepted steps;
    note: what the times include and anything else a reader of the numbers must know."""

    name: str
    setting: str
    force: np.ndarray
    cpu_s: float
    wall_s: float
    rhs_evaluations: int
    steps: int
    note: str


def probe_slot(problem: ChainProblem, save: SaveAt) -> int:
    """The contact slot of the recorded probe: save holds one probe, one whole contact force
    (Chain.contact_probe)."""
    slots, weights = save.channels(problem.offset)
    if slots.shape[0] != 1 or np.count_nonzero(weights) != 1 or weights[0, 0] != 1.0:
        raise invalid("save.probes", save.names, "a peer records one probe: one contact force "
                                                "(Chain.contact_probe)")
    return int(slots[0, 0])


def output_samples(t_end: float, sample_interval: float) -> int:
    """Number of points of the grid t_j = j sample_interval up to t_end (as solve records)."""
    return time_grid(t_end, t_end, sample_interval)[2]


def absolute_tolerances(problem: ChainProblem, rtol: float) -> np.ndarray:
    """atol per state component (m for u, m/s for v) of both DOP853 peers:
    rtol x POSITION_SCALE for each u, rtol x max(max v0, VELOCITY_FLOOR) for each v."""
    nb = problem.n_bodies
    speed = max(float(problem.v0.max()), VELOCITY_FLOOR)
    return rtol * np.concatenate((np.full(nb, POSITION_SCALE), np.full(nb, speed)))


def check_conservative(problem: ChainProblem) -> None:
    """The peers integrate the conservative Hertz chain under constant loads only."""
    if problem.chain.law.dissipative:
        raise invalid("chain.contact_law", problem.chain.law.name, "the peers integrate the Hertz law only")
    if problem.sched_t.size:
        raise invalid("chain.top_force", "ForceSchedule", "the peers take a constant top force only")


def probe_history(problem: ChainProblem, slot: int, u_above: np.ndarray, u_below: np.ndarray) -> np.ndarray:
    """F = A[s] max(d0[s] + u[s-1] - u[s], 0)^(3/2) (N) from the two displacements (m)."""
    d = np.maximum(problem.d0[slot] + u_above - u_below, 0.0)
    return problem.A[slot] * d * np.sqrt(d)


# --- scipy's DOP853 -------------------------------------------------------------------------

def scipy_dop853(problem: ChainProblem, save: SaveAt, t_end: float, rtol: float) -> PeerRun:
    """scipy.integrate.solve_ivp(method DOP853) on y = [u, v] with t_eval = the output grid,
    atol from absolute_tolerances; the right-hand side is vectorised numpy (a fresh array
    per call, as solve_ivp keeps references to what it returns). solve_ivp computes the
    dense output only for steps holding an output point and interpolates every component
    there; the probe is taken from the two displacements it needs after the timing."""
    from scipy.integrate import DOP853, solve_ivp

    check_conservative(problem)
    slot = probe_slot(problem, save)
    nb = problem.n_bodies
    A_mid, d0_mid, load_mid = problem.A[1:], problem.d0[1:], problem.load[1:nb]
    invm = problem.invm
    f = np.zeros(nb + 1)
    f[nb] = -problem.load[nb]

    def rhs(t, y):
        u = y[:nb]
        d = np.maximum(d0_mid + u[:-1] - u[1:], 0.0)
        f[1:nb] = A_mid * d * np.sqrt(d) - load_mid
        dy = np.empty(2 * nb)
        dy[:nb] = y[nb:]
        np.subtract(f[:-1], f[1:], out=dy[nb:])
        dy[nb:] *= invm
        return dy

    counted = {"steps": 0, "dense": 0}

    class CountedDOP853(DOP853):
        """scipy's DOP853, counting its accepted steps and its dense outputs."""

        def step(self):
            message = super().step()
            counted["steps"] += self.status != "failed"
            return message

        def dense_output(self):
            counted["dense"] += 1
            return super().dense_output()

    t_eval = np.arange(output_samples(t_end, save.sample_interval)) * save.sample_interval
    t_eval[-1] = min(t_eval[-1], t_end)
    y0 = np.concatenate((problem.u0, problem.v0))
    cpu0, wall0 = time.process_time(), time.perf_counter()
    r = solve_ivp(rhs, (0.0, t_end), y0, method=CountedDOP853, t_eval=t_eval, rtol=rtol,
                  atol=absolute_tolerances(problem, rtol))
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    if not r.success:
        raise RigError(f"scipy DOP853 failed: {r.message}")
    attempts = (r.nfev - 2 - 3 * counted["dense"]) // 12  # 12 evaluations per attempted step
    force = probe_history(problem, slot, r.y[slot - 1], r.y[slot])
    return PeerRun("scipy-DOP853", f"rtol={rtol:g}", force, cpu, wall, int(r.nfev), counted["steps"],
                   f"solve_ivp in process; {attempts - counted['steps']} rejected steps, "
                   f"{counted['dense']} dense outputs of all {2 * nb} components; times include "
                   f"interpolating every component at each output point")


# --- DOP853 compiled ------------------------------------------------------------------------

def numba_dop853(problem: ChainProblem, save: SaveAt, t_end: float, rtol: float) -> PeerRun:
    """DOP853 compiled with numba (rig/bench/kernels/dop853.py: Hairer's error estimate and
    step-size control, his starting step with scipy's norms), same tolerances as
    scipy_dop853; the probe from the 7th-order dense output of u[s-1] and u[s] only, whose
    three extra stages are computed only for steps that hold an output point. The kernel
    is compiled (or loaded from numba's cache) before the timing."""
    from rig.bench.kernels import dop853

    check_conservative(problem)
    slot = probe_slot(problem, save)
    nb = problem.n_bodies
    atol = absolute_tolerances(problem, rtol)
    n_out = output_samples(t_end, save.sample_interval)

    def run(t):
        y = np.concatenate((problem.u0, problem.v0))
        out = np.zeros(n_out)
        counts = np.zeros(5, np.int64)
        dop853.integrate(y, t, rtol, atol, problem.A, problem.d0, problem.damping, problem.load,
                         problem.invm, slot, save.sample_interval, out,
                         np.zeros((dop853.N_STAGES_EXTENDED, 2 * nb)), np.zeros(2 * nb),
                         np.zeros((2, 2 * nb)), np.zeros(nb + 1), counts)
        return out, counts

    run(min(t_end, save.sample_interval))  # compile or load, outside the timing
    cpu0, wall0 = time.process_time(), time.perf_counter()
    force, counts = run(t_end)
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    if counts[dop853.STATUS] != dop853.SUCCESS:
        raise RigError(f"numba DOP853: step size too small (rtol={rtol:g})")
    return PeerRun("numba-DOP853", f"rtol={rtol:g}", force, cpu, wall, int(counts[dop853.EVALUATIONS]),
                   int(counts[dop853.ACCEPTED]),
                   f"compiled, in process; {counts[dop853.REJECTED]} rejected steps, "
                   f"{counts[dop853.DENSE_STEPS]} steps with output points (3 extra stages each)")


# --- LAMMPS ----------------------------------------------------------------------------------

def lammps_float(value) -> str:
    """A float as LAMMPS reads it back to the same double (17 significant digits)."""
    return f"{float(value):.17g}"


def lammps_executable() -> str | None:
    """The LAMMPS executable on the PATH (``lmp`` or ``lmp_serial``), or None."""
    return next((found for name in LAMMPS_EXECUTABLES if (found := shutil.which(name))), None)


@dataclass(frozen=True)
class LammpsChain:
    """The chain as LAMMPS spheres on the x axis (SI): one atom per body (id = body + 1),
    x the centres at static equilibrium (m, bead 0 at 0, down is +x), radius (m), mass (kg),
    atom_type (1-based: one per kind of bead, one for the striker, one for the wall),
    stiffness {(type, type): k_n} (N/m^2) of LAMMPS's Hertz law F = k_n sqrt(R delta) delta,
    R = r_a r_b / (r_a + r_b), so k_n = A / sqrt(R); mobile: the atoms that move."""

    x: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    atom_type: np.ndarray
    stiffness: dict
    mobile: np.ndarray

    @classmethod
    def of(cls, problem: ChainProblem) -> LammpsChain:
        """The striker, a flat-faced cylinder, is a sphere of its own diameter placed with
        its surface at the striker's face (gap above bead 0); the wall is a fixed sphere of
        the last bead's radius touching at the wall's surface. A sphere of any radius
        carries the problem's constant A: k_n is set per pair of types."""
        check_conservative(problem)
        chain, off = problem.chain, problem.offset
        x_beads = chain.equilibrium_positions()
        r_beads = np.array([b.radius for b in chain.beads])
        x, radius, kinds = list(x_beads), list(r_beads), [(b.material.name, b.diameter) for b in chain.beads]
        if off:
            r_s = 0.5 * chain.striker.diameter
            x.insert(0, x_beads[0] - r_beads[0] - chain.striker.gap - r_s)
            radius.insert(0, r_s)
            kinds.insert(0, "striker")
        if problem.wall_slot:
            x.append(chain.wall_position() + r_beads[-1])
            radius.append(r_beads[-1])
            kinds.append("wall")
        types = {kind: n + 1 for n, kind in enumerate(dict.fromkeys(kinds))}
        atom_type = np.array([types[k] for k in kinds])
        radius = np.array(radius)
        stiffness = {}
        for i in range(1, problem.n_bodies):
            pair = tuple(sorted((int(atom_type[i - 1]), int(atom_type[i]))))
            reduced = radius[i - 1] * radius[i] / (radius[i - 1] + radius[i])
            k_n = problem.A[i] / math.sqrt(reduced)
            if not math.isclose(stiffness.setdefault(pair, k_n), k_n, rel_tol=1e-12):
                raise invalid("chain", f"types {pair}", "one pair of atom types with two Hertz constants")
        mobile = problem.invm > 0
        return cls(np.array(x), radius, problem.mass.copy(), atom_type, stiffness, mobile)

    def data_file(self, shift: np.ndarray) -> str:
        """A LAMMPS data file (atom_style sphere: id type diameter density x y z), the
        centres moved by ``shift`` (m); the wall's mass is a bead's (it never moves)."""
        span = 4.0 * self.radius.max()
        x = self.x + shift
        mass = np.where(self.mobile, self.mass, self.mass.max())
        density = mass / (math.pi / 6.0 * (2.0 * self.radius) ** 3)
        num = lammps_float
        lines = ["LAMMPS data file: a Hertz chain (rig.bench.peers)", "",
                 f"{len(x)} atoms", f"{self.atom_type.max()} atom types",
                 f"{num(x.min() - span)} {num(x.max() + span)} xlo xhi",
                 f"{num(-span)} {num(span)} ylo yhi", f"{num(-span)} {num(span)} zlo zhi", "",
                 "Atoms # sphere", ""]
        lines += [f"{i + 1} {self.atom_type[i]} {num(2.0 * self.radius[i])} {num(density[i])} {num(x[i])} 0 0"
                  for i in range(len(x))]
        return "\n".join(lines) + "\n"

    def input_script(self, problem: ChainProblem) -> str:
        """Everything but the run: the atoms, a Hertz pair law without damping or friction
        per pair of types, the constant loads (fix gravity, fix addforce on bead 0), the
        striker's speed, fix nve/sphere on the mobile atoms."""
        chain, off = problem.chain, problem.offset
        law = "0.0 tangential linear_nohistory 0.0 0.0"  # no damping; no tangential force (mu = 0)
        lines = ["units si", "atom_style sphere", "dimension 3", "boundary m m m",
                 "atom_modify map array", "comm_modify vel yes", "read_data chain.data",
                 "pair_style granular", f"pair_coeff * * hertz {lammps_float(max(self.stiffness.values()))} {law}"]
        lines += [f"pair_coeff {a} {b} hertz {lammps_float(k)} {law}" for (a, b), k in sorted(self.stiffness.items())]
        moving = np.flatnonzero(self.mobile) + 1
        lines += [f"neighbor {lammps_float(0.5 * self.radius.min())} bin", "neigh_modify delay 0 every 1 check yes",
                  f"group mobile id {moving.min()}:{moving.max()}", "fix move mobile nve/sphere"]
        if chain.gravity:
            lines.append(f"fix weight mobile gravity {lammps_float(chain.gravity)} vector 1 0 0")
        if chain.initial_top_force:
            lines += [f"group top id {off + 1}",
                      f"fix pull top addforce {lammps_float(chain.initial_top_force)} 0.0 0.0"]
        moving_now = np.flatnonzero(problem.v0) + 1
        lines += [f"set atom {i} vx {lammps_float(problem.v0[i - 1])}" for i in moving_now]
        return "\n".join(lines) + "\n"


def run_lammps(executable: str, folder: Path, data: str, script: str) -> tuple:
    """Run LAMMPS on ``script`` with ``data`` as chain.data in ``folder``, one thread;
    returns (child CPU s, wall s). Raises RigError with the log's tail when it fails."""
    (folder / "chain.data").write_text(data)
    (folder / "in.chain").write_text(script)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall0 = time.perf_counter()
    done = subprocess.run([executable, "-in", "in.chain", "-log", "log.lammps", "-screen", "none", "-nocite"],
                          cwd=folder, env=env, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - wall0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        log = folder / "log.lammps"
        tail = log.read_text()[-2000:] if log.is_file() else done.stderr[-2000:]
        raise RigError(f"LAMMPS failed (exit {done.returncode}):\n{tail}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall


def read_dump(path: Path, column: int) -> np.ndarray:
    """A LAMMPS text dump (sorted by id) as (snapshots, atoms) of one ATOMS column."""
    lines = path.read_text().splitlines()
    rows = []
    for i, line in enumerate(lines):
        if line.startswith("ITEM: NUMBER OF ATOMS"):
            count = int(lines[i + 1])
        elif line.startswith("ITEM: ATOMS"):
            rows.append([float(row.split()[column]) for row in lines[i + 1:i + 1 + count]])
    return np.array(rows)


def lammps_forces(problem: ChainProblem, u: np.ndarray) -> np.ndarray | None:
    """The x force on each body (N) that LAMMPS computes with the chain displaced by u (m)
    from static equilibrium: contacts plus constant loads (for the wall, its contact alone);
    None without LAMMPS. For checking the set-up against (f[i] - f[i+1])."""
    executable = lammps_executable()
    if executable is None:
        return None
    layout = LammpsChain.of(problem)
    script = layout.input_script(problem) + (
        "dump forces all custom 1 forces.txt id fx\ndump_modify forces sort id format float %.17g\nrun 0\n")
    with tempfile.TemporaryDirectory() as tmp:
        run_lammps(executable, Path(tmp), layout.data_file(u), script)
        return read_dump(Path(tmp) / "forces.txt", 1)[0]


def lammps_hertz(problem: ChainProblem, save: SaveAt, t_end: float, dt: float) -> PeerRun | None:
    """LAMMPS on the same chain (LammpsChain: spheres at static equilibrium, a Hertz law per
    pair of atom types with the problem's A, no damping, no friction, the constant loads as
    fixes) with fix nve/sphere (velocity Verlet) at a fixed step dt' = sample_interval / k,
    k = ceil(sample_interval / dt) (so dt' <= dt and the grid falls on steps); the positions of
    the probe's two atoms are dumped every k steps and F = A[s] max(r_a + r_b - (x_b - x_a), 0)^(3/2)
    (N) is taken from them. None when LAMMPS is not installed."""
    executable = lammps_executable()
    if executable is None:
        return None
    slot = probe_slot(problem, save)
    layout = LammpsChain.of(problem)
    every = max(1, math.ceil(save.sample_interval / dt * (1 - 1e-12)))
    step = save.sample_interval / every
    n_out = output_samples(t_end, save.sample_interval)
    n_steps = (n_out - 1) * every
    script = layout.input_script(problem) + "\n".join((
        f"group probe id {slot} {slot + 1}", f"timestep {lammps_float(step)}",
        f"dump probe probe custom {every} probe.txt id x",
        "dump_modify probe sort id format float %.17g", f"run {n_steps}")) + "\n"
    with tempfile.TemporaryDirectory() as tmp:
        cpu, wall = run_lammps(executable, Path(tmp), layout.data_file(np.zeros(problem.n_bodies)), script)
        x = read_dump(Path(tmp) / "probe.txt", 1)
    gap = x[:, 1] - x[:, 0] - layout.radius[slot - 1] - layout.radius[slot]
    d = np.maximum(-gap, 0.0)
    force = problem.A[slot] * d * np.sqrt(d)
    return PeerRun("LAMMPS", f"dt={step:.4g} s", force, cpu, wall, n_steps + 1, n_steps,
                   f"{Path(executable).name} subprocess, one thread; CPU and wall times include "
                   f"start-up, reading the input, neighbour lists and writing the probe atoms' "
                   f"positions every {every} steps (the force is taken from them)")
