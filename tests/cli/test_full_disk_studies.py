"""The study commands of tests/cli/test_full_disk.py under a full disk (the same checks;
kept apart so the suite's workers share these, the longest runs)."""
import pytest
from test_full_disk import STUDIES, check_full_disk


@pytest.mark.parametrize("case", STUDIES)
def test_a_full_disk_is_one_line_leaves_nothing_broken_and_a_second_run_succeeds(tmp_path, realdata, case,
                                                                                    monkeypatch, capsys):
    check_full_disk(tmp_path, realdata, case, monkeypatch, capsys)
