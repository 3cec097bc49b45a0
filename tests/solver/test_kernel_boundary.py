"""The kernels' boundary by name: the bundles they take (rig/solver/kernels/bundles.py,
built by rig.solver.run.kernel_inputs) and the slots of the report they write
(rig/solver/kernels/report.py)."""
import re
from pathlib import Path

import numpy as np
from chains import ptfe_rig, record_contacts

from rig import ChainProblem
from rig.model.laws.thornton import STATE_ROWS
from rig.solver.kernels import report
from rig.solver.methods import method
from rig.solver.problem import CONTACT_ROWS
from rig.solver.run import kernel_inputs, stacked
from rig.solver.solution import KernelReport, Status
from rig.solver.stepsize import Stepping

SLOTS = ("ENERGY_ERROR", "MOMENTUM_ERROR", "WALL_IMPULSE", "STATUS", "STEPS", "END_TIME", "DISSIPATED",
         "BODIES_STEPPED")
ROOT = Path(__file__).resolve().parents[2]


def test_report_slots_fill_the_diagnostics_once_each():
    assert sorted(getattr(report, name) for name in SLOTS) == list(range(report.DIAGNOSTICS))


def test_kernel_report_reads_each_slot_by_its_name():
    diag = np.zeros(report.DIAGNOSTICS)
    values = {"ENERGY_ERROR": 3e-6, "MOMENTUM_ERROR": 2e-13, "WALL_IMPULSE": 1.5e-3, "STATUS": 1.0, "STEPS": 400.0,
              "END_TIME": 8e-4, "DISSIPATED": 2e-5, "BODIES_STEPPED": 400.0 * 37}
    for name, x in values.items():
        diag[getattr(report, name)] = x
    r = KernelReport.of(diag)
    assert (r.energy_error, r.momentum_error, r.wall_impulse_Ns, r.status, r.steps, r.end_time_s,
            r.dissipated_energy_J, r.bodies_stepped) == (3e-6, 2e-13, 1.5e-3, Status.UNSTABLE, 400, 8e-4, 2e-5, 37.0)


def test_no_diagnostics_slot_is_read_or_written_by_number():
    positional = re.compile(r"\bdiag(?:nostics)?\[\s*(?:[-\d]|:\s*,\s*\d)")
    hits = [f"{path.relative_to(ROOT)}:{n}: {line.strip()}" for path in sorted((ROOT / "rig").rglob("*.py"))
            for n, line in enumerate(path.read_text().splitlines(), 1) if positional.search(line)]
    assert hits == []


def test_bundles_carry_the_problem_arrays_of_their_names():
    chain = ptfe_rig(n=12)
    p = ChainProblem.from_chain(chain)
    save = record_contacts(chain, 3, 9)
    m = method("srkn6b")
    out, frames = np.zeros((2, 11)), np.zeros((0, p.n_bodies))
    def take(name):
        return getattr(p, name)

    k = kernel_inputs(p, take, stacked(take, 0), m, Stepping(1e-6), 1e-6, 10, save, out, frames, 1.0)
    for name, x in k.chain._asdict().items():
        assert x is getattr(p, name), name
    for rows, names in ((k.contacts.con, CONTACT_ROWS), (k.contacts.state, STATE_ROWS),
                        (k.holder.onsite, ("drag", "friction"))):
        assert rows.shape == (len(names), p.n_bodies)
        for row, name in zip(rows, names):
            assert np.array_equal(row, getattr(p, name)), name
    assert k.contacts.law == p.law and k.holder.slip == p.slip_speed
    assert (k.method.dt, k.method.n_steps, k.method.head) == (1e-6, 10, 0)
    assert list(k.method.a_coef) == list(m.drifts) and list(k.method.b_coef) == list(m.kicks)
    assert k.record.out is out and k.record.frames is frames and k.record.sample_dt == save.sample_interval
    assert (k.checks.e_ref, k.checks.p_ref, k.checks.wall_slot) == (p.energy_scale, p.momentum_scale, p.wall_slot)
    assert k.schedule.body == p.sched_body and k.schedule.t is p.sched_t
