"""Compile the kernels most test files need once, before the test workers start.

With numba's on-disk cache cold (a fresh clone, a changed kernel), every pytest-xdist
worker compiled the chain solver for each contact law, the batched solver and the
instruments on its own: the same machine code two times or more, tens of seconds each.
tests/conftest.py runs ``compile_all`` in the controller before it starts the workers: the
jobs below, shared out over as many processes as there will be workers, fill the cache,
and the workers load from it. Nothing here is asserted; a job that fails is reported in one
line and its kernels are compiled by the tests that need them (which then show the real
error).

``python tests/compile_once.py`` runs ``compile_all`` on every core and says what it did
in one line; it needs only the rig's own dependencies (no pytest), so .ci/run starts it
while pip is still installing the test extras, and the tests then find the kernels
compiled (RIG_KERNELS_COMPILED set: conftest.py compiles nothing before the workers).
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
    from chains import PTFE

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


def said(wall: float, processes: int, failed: list[str], when: str) -> str:
    """The one line that says what compile_all did, and ``when``."""
    return (f"compiled the shared kernels once in {wall:.0f} s ({processes} processes) {when}"
            + "".join(f"; failed: {f}" for f in failed))


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).parent))  # the chains' parts (tests/chains.py)
    if len(sys.argv) == 1:  # every job, on every core (.ci/run, while the test extras install)
        import os

        processes = os.cpu_count() or 1
        wall, failed = compile_all(processes)
        print(said(wall, processes, failed, "while pip installed the test extras"))
    for job in sys.argv[1:]:
        try:
            run_job(job)
        except Exception as exc:  # reported by compile_all; the tests compile it again and fail there
            print(f"FAILED {job}: {type(exc).__name__}: {exc}", file=sys.stderr)
