"""A chain's shot history (chain.previous_shots, rig/experiment/history.py): the contacts
keep their flattening from shot to shot, rest on their new elastic curves under the static
load, and the next shot meets stiffer contacts: it loses less and runs faster (the Fig. 3
set, gravity only: 128.7, 133.9, 137.2 m/s for shots 1, 2, 3, where an outside study had
measured 128 -> 134 -> 137); a chain that never yields is the same chain; the history is
the same bits however the shot is fired."""
import numpy as np
import pytest

from rig import RigError
from rig.experiment.shot import Rig
from rig.model.laws.thornton import STATE_ROWS
from rig.study import fig3

QUICK = ("solver.duration=2 ms",)  # the pulse passes both gauges by 1.2 ms


def rig(shots: int, extra=()) -> Rig:
    return Rig.from_scene(fig3.GRAVITY, fig3.PARAMETER_SET + QUICK + (f"chain.previous_shots={shots}",) + extra)


@pytest.fixture(scope="module")
def history():
    """The rigs of shots 1, 2, 3 on one chain, solved."""
    rigs = [rig(k) for k in range(3)]
    for r in rigs:
        r.solution()
    return rigs


def test_each_shot_meets_the_contacts_the_last_one_flattened(history):
    first, second, third = history
    dp = STATE_ROWS.index("permanent_overlap")
    assert np.all(first.chain.rest_state()[dp] == 0)  # no hold, no yield under gravity: as new
    flattened = second.chain.rest_state()[dp] > 0
    assert flattened.sum() > 40  # the pulse flattened nearly every contact it passed
    # at rest each flattened contact carries its static force on its new elastic curve
    ap = second.chain.rest_state()[STATE_ROWS.index("unloading_constant")]
    d0, F = second.chain.static_overlaps(), second.chain.static_forces()
    rest = ap[flattened] * (d0[flattened] - second.chain.rest_state()[dp][flattened]) ** 1.5
    assert rest == pytest.approx(F[flattened], rel=1e-10)
    # it loses less and runs faster, shot after shot
    lost = [r.solution().stats.dissipated_energy_J for r in history]
    speed = [r.truth_analysis().as_dict()["speed_m_per_s"] for r in history]
    assert lost[0] > lost[1] > lost[2] > 0
    assert speed[0] < speed[1] < speed[2]
    assert speed[2] / speed[0] - 1 > 0.03  # a drift a study must name its shot for (6.6% here)


def test_a_chain_that_never_yields_is_the_same_chain_and_the_history_is_deterministic(history):
    a, b = (Rig.from_scene(fig3.GRAVITY, QUICK + (f"chain.previous_shots={k}",)) for k in (0, 1))  # Hertz
    assert np.array_equal(a.chain.static_overlaps(), b.chain.static_overlaps())
    for name, f in a.solution().forces.items():
        assert np.array_equal(f, b.solution().forces[name])
    again = rig(1)
    for name, f in again.solution().forces.items():
        assert np.array_equal(f, history[1].solution().forces[name])


@pytest.mark.parametrize("value", ["-1", "101", "1.5"])
def test_a_history_out_of_range_is_refused_by_name(value):
    with pytest.raises(RigError, match="chain.previous_shots"):
        rig(0, (f"chain.previous_shots={value}",))


def test_rig_shot_repeat_fires_shots_on_one_chain_each_reproducible_from_its_items(history, capsys, tmp_path):
    """rig shot --repeat 3: the drift of the shots above, and each archived shot the bits of
    the scene with its own items (chain.previous_shots and its seed) fired alone."""
    import json

    from instruments.archive import Archive
    from rig.cli import main

    items = [a for o in fig3.PARAMETER_SET + QUICK + ("scope.record_length=2500",) for a in ("--set", o)]
    archive = tmp_path / "shots.h5"
    assert main(["shot", fig3.GRAVITY, *items, "--seed", "7", "--repeat", "3", "--out", str(archive), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    rows = out["repeat"]
    assert [r["shot"] for r in rows] == [1, 2, 3] and [r["seed"] for r in rows] == [7, 8, 9]
    assert [r["speed_m_per_s"] for r in rows] == [r.truth_analysis().as_dict()["speed_m_per_s"] for r in history]
    assert out["drift"]["speed_m_per_s"]["relative"] > 0.03
    last = Archive(archive).read(3)
    alone = Rig.from_scene(fig3.GRAVITY, tuple(rows[2]["overrides"])).fire(seed=9)
    assert "chain.previous_shots=2" in rows[2]["overrides"]
    for ch, w in alone.scope.waveforms.items():
        assert np.array_equal(w.codes, last.record[ch].codes)
