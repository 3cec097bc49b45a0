"""A leading pulse resolved by too few solver samples: flagged in the truth and measured
blocks, naming solver.sample_interval and the pulse's width; a solver.sample_interval
coarser than the scope's refused before anything is solved."""
import json
import math

import numpy as np
import pytest

from rig.cli import main
from rig.experiment.measure import SAMPLES_PER_WIDTH, peak_loss

S = "ptfe52_magnetic"


@pytest.mark.parametrize("per_width", [1, 2, 3, 5, 10, 20])
def test_peak_loss_is_the_worst_sampled_peak_of_a_sech2_pulse(per_width):
    tau = 1.0
    fwhm = 2 * tau * math.acosh(math.sqrt(2))
    h = fwhm / per_width
    worst = min(np.max(np.cosh((np.arange(-60, 61) + phase) * h / tau) ** -2.0)
                for phase in np.linspace(0, 1, 401))
    assert peak_loss(per_width) == pytest.approx(1 - worst, rel=1e-3, abs=1e-6)
    assert (peak_loss(per_width) < 0.01) == (per_width >= SAMPLES_PER_WIDTH)  # the rule: under 1 % at 10 samples


def _blocks(capsys, *sets):
    argv = ["shot", S, "--seed", "1", "--json"]
    for s in sets:
        argv += ["--set", s]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    return out["truth"], out["measured"]


def test_a_pulse_resolved_by_few_solver_samples_is_flagged_naming_the_interval_and_the_width(capsys):
    # 20 us samples across a ~62 us pulse (3 per width): F_d comes out several % low
    coarse = ("solver.sample_interval=20 us", "scope.sample_interval=20 us", "scope.record_length=140")
    truth, measured = _blocks(capsys, *coarse)
    assert isinstance(truth["reasons"], dict) and isinstance(measured["reasons"], dict)
    assert truth["amplitude_N"] is not None and set(truth["flags"]) >= {"amplitude_N", "speed_m_per_s", "beta"}
    why = truth["flags"]["amplitude_N"]
    assert why.startswith("solver.sample_interval = 2e-05 s gives 3.") and "width (FWHM" in why, why
    width = float(why.split("leading pulse's ")[1].split(" s width")[0])
    assert 40e-6 < width < 90e-6  # the pulse's FWHM, not a made-up figure
    assert all(measured["flags"][k] == why for k in measured["flags"])
    fine, _ = _blocks(capsys, "scope.sample_interval=20 us", "scope.record_length=140")  # solver at 0.1 us
    assert fine["flags"] == {} and truth["amplitude_N"] < (1 - 0.01) * fine["amplitude_N"]  # the peak cut (1.8 %)
