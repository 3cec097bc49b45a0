"""The suite's fixtures and its order: the kernels compiled once before the workers start,
the longest files dealt out first."""
import pytest
from chains import steel_sonic_vacuum


@pytest.fixture
def sonic_vacuum():
    return steel_sonic_vacuum


@pytest.fixture(scope="session")
def realdata():
    """The folder of real scope files (provenance in *.source.txt): $RIG_REALDATA, else
    ../shared/realdata beside the checkout. CI (CI=true) must have them: missing there,
    the test fails; elsewhere it is skipped, saying how to provide them."""
    import os
    from pathlib import Path

    env = os.environ.get("RIG_REALDATA")
    base = Path(env) if env else Path(__file__).resolve().parents[2] / "shared" / "realdata"
    used = ("tek_16bit_dpo.isf", "tek_8bit_two_records.isf")  # what the tests read
    if base.is_dir() and (any(base.glob("*.source.txt")) or all((base / f).is_file() for f in used)):
        return base
    how = (f"real scope files not found in {base}: set RIG_REALDATA=/path/to/realdata "
           f"or place them at ../shared/realdata beside the checkout")
    if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
        pytest.fail(how + " (CI must run the real-data tests)")
    pytest.skip(how)


@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session):
    """Before pytest-xdist starts its workers on a cold numba cache, compile the kernels
    most test files need once, in as many processes as there will be workers
    (tests/compile_once.py), rather than once in every worker; not where RIG_KERNELS_COMPILED
    says it was done before (.ci/run does it while pip installs the test extras)."""
    import os

    config = session.config
    workers = getattr(config.option, "numprocesses", None)
    if hasattr(config, "workerinput") or not isinstance(workers, int) or workers < 2:
        return
    if os.environ.get("RIG_KERNELS_COMPILED"):
        COMPILED.append(os.environ["RIG_KERNELS_COMPILED"])
        return
    from compile_once import compile_all, said

    wall, failed = compile_all(workers)
    COMPILED.append(said(wall, workers, failed, "before the workers started"))


COMPILED: list = []  # what pytest_sessionstart compiled, said in the summary

# The test files that take longest, seconds summed over their tests (fresh clone, 2 cores):
# dealt out to the workers first. pytest-xdist hands out whole files (--dist loadfile), by
# default the files with the most tests first, which left the few long single tests (the
# 10,000-shot archive, the cold shot, mypy) for the end, one worker running them while the
# other idled (about 12 s of a run's wall time).
LONGEST_FIRST = {"tests/solver/test_models.py": 38, "tests/cli/test_full_disk_studies.py": 34,
                 "tests/study/test_fig3_studies.py": 32, "tests/instruments/test_archive_scale.py": 30,
                 "tests/instruments/test_archive_flips.py": 28, "tests/cli/test_full_disk.py": 26,
                 "tests/fit/test_fit.py": 22, "tests/bench/test_models_bench.py": 21,
                 "tests/cli/test_cold_start.py": 21, "tests/test_typing.py": 20, "tests/cli/test_small_disk.py": 19,
                 "tests/study/test_mc.py": 16, "tests/cli/test_bad_input_corpus.py": 15,
                 "tests/lab/test_clients.py": 12, "tests/solver/test_vectorised.py": 12, "tests/docs/test_docs.py": 12,
                 "tests/bench/test_modules_import.py": 11, "tests/cli/test_analyze.py": 10}


def pytest_configure(config):
    """The controller deals the files out in the order the workers collected them
    (pytest_collection_modifyitems), not reordered by their number of tests."""
    if hasattr(config.option, "loadscopereorder"):
        config.option.loadscopereorder = False


def pytest_collection_modifyitems(items):
    """The files of LONGEST_FIRST first, longest first; then the others, those with the
    most tests first (pytest-xdist's own order); the tests of a file in their order."""
    from collections import Counter

    counts = Counter(item.nodeid.split("::")[0] for item in items)
    order = {f: k for k, f in enumerate(sorted(counts, key=lambda f: (-LONGEST_FIRST.get(f, 0), -counts[f])))}
    items.sort(key=lambda item: order[item.nodeid.split("::")[0]])


def pytest_terminal_summary(terminalreporter):
    for line in COMPILED:
        terminalreporter.write_line(line)
