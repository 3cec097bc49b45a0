"""An archive of 10,000 shots: appended in batches, verified, its first and last shot read
back, one more appended; an append writes its own part and a master of links, so its cost
does not grow with what the archive holds. The shots are the smallest real ones (one
channel of 16 int8 codes, no truth): what is measured is the archive's cost per shot."""
import numpy as np
import pytest

from instruments.archive import Archive
from rig.bench.archive_large import small_shot as small

SHOTS, BATCH = 10_000, 2_000


@pytest.mark.slow
def test_ten_thousand_shots_append_verify_read_and_take_one_more(tmp_path):
    a = Archive(tmp_path / "big.h5")
    for start in range(0, SHOTS, BATCH):
        assert a.append([small(s) for s in range(start, start + BATCH)]) == list(range(start + 1, start + BATCH + 1))
    report = a.verify()
    assert report == {"shots": SHOTS, "ok": SHOTS, "bad": []}
    first, last = a.read(1), a.read(SHOTS)
    assert np.array_equal(first.record["CH1"].codes, small(0).record["CH1"].codes)
    assert np.array_equal(last.record["CH1"].codes, small(SHOTS - 1).record["CH1"].codes)
    parts = {p.name: (p.stat().st_ino, p.stat().st_mtime_ns, p.stat().st_size) for p in tmp_path.glob("big.h5.d/*.h5")}
    assert a.append([small(SHOTS)]) == [SHOTS + 1]
    assert a.read(SHOTS + 1).settings == {"source_files": [f"s{SHOTS}.isf"]}
    assert len(list(tmp_path.glob("big.h5.d/*.h5"))) == SHOTS // BATCH + 1  # a part per transaction
    # what the append wrote is its own part and the master: every part already stored is the same file, untouched
    # (its cost is what rig bench archive's one-shot rows at 10, 10,000 and 100,000 shots measure)
    assert {p.name: (p.stat().st_ino, p.stat().st_mtime_ns, p.stat().st_size)
            for p in tmp_path.glob("big.h5.d/*.h5") if p.name in parts} == parts
