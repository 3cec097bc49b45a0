"""Archives of layout 1 (written before the layout had a version): refused in one line that
says to run ``rig upgrade``; ``Archive.upgrade`` rewrites them in the current layout.

data/layout1.h5 was written by the archive code of layout 1 (commit b574fe9): two virtual
shots sharing a truth (names with dots, such as upper.average_force) and one real shot."""
import shutil
from pathlib import Path

import numpy as np
import pytest

from instruments.archive import Archive
from instruments.errors import InstrumentError

LAYOUT1 = Path(__file__).parent / "data" / "layout1.h5"


@pytest.fixture
def old(tmp_path):
    path = tmp_path / "old.h5"
    shutil.copyfile(LAYOUT1, path)
    return path


def test_an_old_layout_is_refused_with_the_command_that_converts_it(old):
    for call in (lambda a: a.ids(), lambda a: a.read(1), lambda a: a.summary()):
        with pytest.raises(InstrumentError,
                           match=r"archive layout 1, this version reads layouts 2, 3 and 4: run `rig upgrade"):
            call(Archive(old))
    assert "rig upgrade" in Archive(old).verify()["bad"][0]["reason"]


def test_upgrade_keeps_every_shot_and_value(old):
    a = Archive(old)
    assert a.upgrade() == 3 and a.upgrade() == 0  # the second call finds the current layout
    assert a.ids() == [1, 2, 3] and a.verify() == {"shots": 3, "ok": 3, "bad": []}
    one, two, real = (a.read(i) for i in (1, 2, 3))
    assert (one.seed, two.seed, one.scene, one.project_version) == (1, 2, "tiny", "0.9")
    assert one.start_time == "2026-01-01T00:00:00+00:00" and "layout 1" in one.start_time_source
    assert set(one.truth) == {"upper_average_force", "wall_force"}  # NeXus names now
    assert np.array_equal(one.truth["upper_average_force"], np.linspace(0, 1, 32))
    assert one.facts.gauges["upper"].bead == 3 and not real.simulated and real.truth is None
    codes = np.random.default_rng(1).integers(-100, 100, 64).astype(np.int8)
    assert np.array_equal(one.record["CH1"].codes, codes)  # the fixture's draws, bit for bit
    assert one.record["CH1"].preamble.point_format == "Y" and one.record["CH1"].preamble.trigger_index == 10
    assert Archive(old).append([two]) == [4]  # and the archive grows in the current layout
