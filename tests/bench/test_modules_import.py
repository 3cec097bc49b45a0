"""Every benchmark module imports (a module no other test touches, such as rig/bench/mc.py,
would otherwise reach `rig bench` with a syntax error), each with its docstring."""
import importlib
import pkgutil

import pytest

import rig.bench


@pytest.mark.parametrize("name", sorted(m.name for m in pkgutil.iter_modules(rig.bench.__path__) if not m.ispkg))
def test_the_bench_module_imports(name):
    module = importlib.import_module(f"rig.bench.{name}")
    assert module.__doc__


def test_the_mc_snippet_runs_this_batch_size():
    from rig.bench import mc
    from rig.study.mc_spec import DEFAULT_BATCH

    compile(mc.SNIPPET, "snippet", "exec")
    assert f"mc.BATCH = {DEFAULT_BATCH}" in mc.SNIPPET


def test_the_mc_benchmarks_stages_run_on_a_small_study(monkeypatch):
    # the parts of `rig bench mc` that no other test runs, at batches of 8: each figure a
    # positive rate or time (its stage timing once drew shots past its study's end)
    from rig.bench import mc
    from rig.study.distributions import parse_vary
    from rig.study.montecarlo import MonteCarloStudy

    monkeypatch.setattr(mc, "BATCH", 8)
    monkeypatch.setattr(mc, "WARM_UP", 1)
    study = MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(mc.VARY)), 16, batch=8)
    figures = {**mc._solver(study, 16), **mc._stages(study, batches=2),
               **mc._one_process(MonteCarloStudy("ptfe52_magnetic", study.dists, 56, batch=8))}
    for key in ("solver_kernel_shots_per_s", "solver_shots_per_s", "pipeline_shots_per_s",
                *(f"stage_{k}_us_per_shot" for k in mc.STAGES)):
        assert figures[key] > 0, key


@pytest.mark.parametrize("what,argv,expected", [
    ("mc", [], {}),
    ("mc", ["--rounds", "7"], {"rounds": 7}),
    ("mc", ["--rounds", "2", "--baseline", "HEAD"], {"rounds": 2, "baseline": "HEAD"}),
    ("solver", ["--rounds", "5", "--quick"], {"kernel_rounds": 5, "quick": True}),
    ("solver", [], {"kernel_rounds": None}),
])
def test_rounds_reach_the_benchmark(monkeypatch, what, argv, expected):
    """rig bench's --rounds is passed to the benchmark it names (the run itself replaced)."""
    from rig.cli import main

    module = importlib.import_module(f"rig.bench.{what}")
    seen = {}
    monkeypatch.setattr(module, "run", lambda **kw: seen.update(kw) or {})
    assert main(["bench", what, *argv, "--json"]) == 0
    for key, value in expected.items():
        assert seen[key] == value, key
    if what == "mc" and "--rounds" not in argv:
        assert "rounds" not in seen  # mc.run's own default


def test_the_mc_scaling_table_runs_at_one_and_two_workers(monkeypatch):
    # rig bench mc's scaling table on a small study (batches of 8, 2 per worker): a positive
    # steady rate for every way of running at each N, the efficiencies computed from them,
    # and the table shows each mode's rates
    from rig.bench import mc, mc_scaling

    monkeypatch.setattr(mc_scaling, "PER_WORKER", 3)
    monkeypatch.setattr(mc_scaling, "WARM_UP", 1)
    monkeypatch.setattr(mc_scaling, "THREAD_BATCHES", 1)
    monkeypatch.setattr(mc_scaling, "DEFAULT_BATCH", 8)  # rig mc's batch in one process on N threads beside it
    r = mc_scaling.run(mc.VARY, 8, [2, 1])
    assert r["counts"] == [1, 2] and r["batch"] == 8 and 60 < r["result_bytes_per_shot"] < 200
    assert {n: row["batch"] for n, row in r["modes"]["threads_batch"].items()} == {1: 256, 2: 256}
    for mode, by_n in r["modes"].items():
        one, two = by_n[1], by_n[2]
        assert one["shots_per_s"] > 0 and two["shots_per_s"] > 0, mode
        assert two["efficiency_vs_2"] == 1 and one["efficiency_vs_2"] is None
        assert two["efficiency_vs_1"] == two["shots_per_s"] / (2 * one["shots_per_s"])
    pool = r["modes"]["workers"]
    assert pool[2]["parent_cpu_ms_per_batch"] > 0 and pool[2]["worker_cpu_ms_per_batch"] > 0
    assert set(r["store_ms_per_batch"]) == {1, mc_scaling.STORE_GROUP} and min(r["store_ms_per_batch"].values()) > 0
    for row in r["modes"]["threads"].values():  # a batch's time outside its compiled ranges, measured
        assert 0 < row["outside_ranges_ms_per_batch"] < row["batch_ms"]
    assert mc_scaling.amdahl_efficiency(0.0, 16) == 1 and mc_scaling.amdahl_efficiency(1.0, 16) == 2 / 16
    assert abs(mc_scaling.amdahl_efficiency(0.1, 16) - (0.55 / 0.15625) / 8) < 1e-12
    text = mc_scaling.table(r)
    assert "outside the compiled ranges" in text and "at N = 16" in text
    for mode, label in mc_scaling.MODES.items():
        if mode in r["modes"]:
            assert label in text and f"{r['modes'][mode][2]['shots_per_s']:7.0f} (100%)" in text


def test_startup_cold_takes_rounds_and_a_baseline(monkeypatch):
    """rig bench startup --cold runs the cold benchmark (rig/bench/cold_start.py) with the
    rounds and the baseline given (the run itself replaced)."""
    from rig.bench import cold_start
    from rig.cli import main

    seen = {}
    monkeypatch.setattr(cold_start, "run", lambda **kw: seen.update(kw) or {})
    assert main(["bench", "startup", "--cold", "--rounds", "2", "--baseline", "HEAD", "--json"]) == 0
    assert seen == {"rounds": 2, "baseline": "HEAD"}
