"""Compile the kernels most test files need once, before the test workers start.

With numba's on-disk cache cold (a fresh clone, a changed kernel), every pytest-xdist
worker compiled the chain solver for each contact law, the batched solver and the
instruments on its own: the same machine code two times or more, tens of seconds each.
tests/conftest.py runs ``compile_all`` in the controller before it starts the workers: the
jobs below, shared out over as many processes as there will be workers, fill the cache,
and the workers load from it. Nothing here is asserted; a job that fails is reported in one
line and its kernels are compiled by the tests that need them (which then show the real
error).
"""
from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# {job: the contact-law keywords of its chain}; "instruments" takes none
LAWS = {"hertz": {}, "power": {"contact_exponent": 1.75},
        "kuwabara-kono": {"contact_law": "kuwabara-kono", "damping_time": 2e-6},
        "thornton": {"contact_law": "thornton", "yield_force": 0.5},
        "hertz, drag": {"drag": 0.05}}  # a Hertz chain with a dissipative flow: another copy (bundles.Holder.flows)
# the jobs, the costliest first (they are dealt out in this order); a job compiles the
# single-shot and the batched solver of its law, "instruments" a shot's and a study's
# acquisition and analysis
JOBS = ["instruments", "hertz", "thornton", "power", "kuwabara-kono", "hertz, drag"]


def run_job(name: str) -> None:
    """Compile what job ``name`` stands for (module doc), in this process."""
    if name == "instruments":
        from instruments.precompile import SHOT, SHOT_SMALL, STUDY, STUDY_SMALL, compile_now

        compile_now({**SHOT, **SHOT_SMALL, **STUDY, **STUDY_SMALL})
        return
    from conftest import PTFE

    from rig import Bead, Chain, ChainProblem, MagneticBead, SaveAt, Striker, Wall, solve
    from rig.solver.ensemble import solve_ensemble
    from rig.solver.stepsize import contact_time_scale, stepping_at

    chain = Chain([MagneticBead()] + [Bead(**PTFE)] * 6, striker=Striker("alumina", "0.47 g", "0.89 m/s"),
                  wall=Wall(), top_force=2.38, **LAWS[name])
    p = ChainProblem.from_chain(chain)
    step = stepping_at(p, contact_time_scale(p) / 8)
    save = SaveAt({"c3": chain.contact_probe(3)})
    solve(p, 2e-5, save=save, dt=step, estimate=False)
    solve_ensemble([p, p], 2e-5, save=save, dt=step)


def compile_all(processes: int) -> tuple[float, list[str]]:
    """Run JOBS in ``processes`` child processes (dealt out round robin, each child's jobs
    one after the other); (wall s, the jobs that failed)."""
    t0 = time.perf_counter()
    shares = [JOBS[k::processes] for k in range(processes)]
    children = [subprocess.Popen([sys.executable, __file__, *share], cwd=ROOT, stdin=subprocess.DEVNULL,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                for share in shares if share]
    failed = []
    for child in children:
        _, err = child.communicate()
        failed += [line.split(" ", 1)[1] for line in err.splitlines() if line.startswith("FAILED ")]
    return time.perf_counter() - t0, failed


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).parent))  # conftest's chain parts
    for job in sys.argv[1:]:
        try:
            run_job(job)
        except Exception as exc:  # reported by compile_all; the tests compile it again and fail there
            print(f"FAILED {job}: {type(exc).__name__}: {exc}", file=sys.stderr)
