"""LAMMPS as a peer of the solver benchmark: the same chain, the same probe, the same grid
(rig/bench/peers.py tells the conventions). LAMMPS (pair_style granular, Hertz normal force,
no damping, no friction; fix nve/sphere, velocity Verlet at a fixed step) runs in a
subprocess, when an ``lmp`` or ``lmp_serial`` executable is on the PATH (Debian: apt-get
install lammps)."""
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

from rig.bench.peers import PeerRun, check_conservative, output_samples, probe_slot
from rig.errors import RigError, invalid
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt

EXECUTABLES = ("lmp", "lmp_serial")


def lammps_float(value) -> str:
    """A float as LAMMPS reads it back to the same double (17 significant digits)."""
    return f"{float(value):.17g}"


def executable() -> str | None:
    """The LAMMPS executable on the PATH (``lmp`` or ``lmp_serial``), or None."""
    return next((found for name in EXECUTABLES if (found := shutil.which(name))), None)


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
        chain = problem.chain
        x_beads = chain.equilibrium_positions()
        r_beads = np.array([b.radius for b in chain.beads])
        x, radius = list(x_beads), list(r_beads)
        kinds: list = [(b.material.name, b.diameter) for b in chain.beads]  # and "striker", "wall"
        if chain.striker is not None:
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
        radii = np.array(radius)
        stiffness: dict[tuple, float] = {}
        for i in range(1, problem.n_bodies):
            pair = tuple(sorted((int(atom_type[i - 1]), int(atom_type[i]))))
            reduced = radii[i - 1] * radii[i] / (radii[i - 1] + radii[i])
            k_n = problem.A[i] / math.sqrt(reduced)
            if not math.isclose(stiffness.setdefault(pair, k_n), k_n, rel_tol=1e-12):
                raise invalid("chain", f"types {pair}", "one pair of atom types with two Hertz constants")
        mobile = problem.invm > 0
        return cls(np.array(x), radii, problem.mass.copy(), atom_type, stiffness, mobile)

    def data_file(self, shift: np.ndarray) -> str:
        """A LAMMPS data file (atom_style sphere: id type diameter density x y z), the
        centres moved by ``shift`` (m); the wall's mass is a bead's (it never moves)."""
        span = 4.0 * self.radius.max()
        x = self.x + shift
        mass = np.where(self.mobile, self.mass, self.mass.max())
        density = mass / (math.pi / 6.0 * (2.0 * self.radius) ** 3)
        num = lammps_float
        lines = ["LAMMPS data file: a Hertz chain (rig.bench.lammps)", "",
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
    exe = executable()
    if exe is None:
        return None
    layout = LammpsChain.of(problem)
    script = layout.input_script(problem) + (
        "dump forces all custom 1 forces.txt id fx\ndump_modify forces sort id format float %.17g\nrun 0\n")
    with tempfile.TemporaryDirectory() as tmp:
        run_lammps(exe, Path(tmp), layout.data_file(u), script)
        return read_dump(Path(tmp) / "forces.txt", 1)[0]


def lammps_hertz(problem: ChainProblem, save: SaveAt, t_end: float, dt: float) -> PeerRun | None:
    """LAMMPS on the same chain (LammpsChain: spheres at static equilibrium, a Hertz law per
    pair of atom types with the problem's A, no damping, no friction, the constant loads as
    fixes) with fix nve/sphere (velocity Verlet) at a fixed step dt' = sample_interval / k,
    k = ceil(sample_interval / dt) (so dt' <= dt and the grid falls on steps); the positions of
    the probe's two atoms are dumped every k steps and F = A[s] max(r_a + r_b - (x_b - x_a), 0)^(3/2)
    (N) is taken from them. None when LAMMPS is not installed."""
    exe = executable()
    if exe is None:
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
        cpu, wall = run_lammps(exe, Path(tmp), layout.data_file(np.zeros(problem.n_bodies)), script)
        x = read_dump(Path(tmp) / "probe.txt", 1)
    gap = x[:, 1] - x[:, 0] - layout.radius[slot - 1] - layout.radius[slot]
    d = np.maximum(-gap, 0.0)
    force = problem.A[slot] * d * np.sqrt(d)
    return PeerRun("LAMMPS", f"dt={step:.4g} s", force, cpu, wall, n_steps + 1, n_steps,
                   f"{Path(exe).name} subprocess, one thread; CPU and wall times include "
                   f"start-up, reading the input, neighbour lists and writing the probe atoms' "
                   f"positions every {every} steps (the force is taken from them)")
