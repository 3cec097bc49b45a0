"""Monte Carlo studies: inputs, seeds, executors, resume, report, Sobol."""
import dataclasses
import json
import sys

import h5py
import numpy as np
import pytest

from rig.cli import main
from rig.study.batch import refire, run_batch
from rig.study.distributions import parse_vary
from rig.study.executors import run_study
from rig.study.montecarlo import MonteCarloStudy
from rig.study.report import jcgm101
from rig.study.store import Store

VARY = ["striker.velocity=normal(0.89 m/s, 0.01 m/s)", "chain.bead_mass=normal(0.1226 g, 0.0008 g)",
        "gauges.upper.misalignment=normal(0 mm, 1 mm)", "gauges.lower.gain=normal(1, 0.05)"]


def _study(shots=48, **kw):
    return MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY)), shots, seed=kw.pop("seed", 3), batch=16, **kw)


def _outputs(folder):
    with h5py.File(folder / "study.h5") as f:
        return {k: f["outputs"][k][()] for k in f["outputs"]}


@pytest.mark.parametrize("spec,message", [
    ("striker.velocity=normal(0.89 m/s, -0.01 m/s)", "standard deviation must be > 0"),
    ("magnet.force=uniform(3 N, 2 N)", "LO < HI"),
    ("striker.colour=normal(1, 2)", "unknown key"),
    ("striker.speed=normal(1 m/s, 0.1 m/s)", "unknown key; known in striker: material, mass, velocity"),
    ("chain.bead_mas=normal(1 g, 0.1 g)", "magnetic_poisson_ratio, bead_mass\n"),  # and the study's own, once each
    ("striker.mass=normal(0.47 g, 0.3 g)", "outside the allowed range"),
    ("chain.bead_mass=normal(0.1226 g, 0.1 g)", "outside the allowed range (0, inf) kg (the values in SI units)"),
    ("gauges.middle.gain=normal(1, 0.05)", "no gauge 'middle'"),
    ("striker.velocity=normal(0.89, 0.01)", "unit is required"),
    ("gauges.upper.gain=normal(nan, 0.05)", "a finite number"),  # a nan gain had meant "the scene's own draw"
    ("gauges.upper.gain=uniform(0.5, inf)", "a finite number"),
    ("gauges.upper.gain=lognormal(1, 1e200)", "a lognormal needs SD < 1e100 MEAN"),  # had overflowed mid-run
    ("solver.accuracy=uniform(1e-6, 2e-6)", "the study's own solver settings"),  # had been drawn and ignored
    ("striker.velocity=normal(0.89 m/s,, 0.01 m/s)", "none of them empty"),
    ("chain.poisson_ratio=truncnormal(0.4, 0.05, 0.3, 0.5)", "range (-1, 0.5) (the values in SI units); keep LO"),
])
def test_bad_distributions_fail_before_any_shot(tmp_path, capsys, spec, message):
    out = tmp_path / "study"
    assert main(["mc", "ptfe52_magnetic", "--shots", "10", "--vary", spec, "--out", str(out), "--quiet"]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("extra,message", [
    (["--set", "striker.velocity=1"], "--set = 'striker.velocity': a key that --vary does not draw"),
    (["--scheduler", "tcp://nohost"], "--scheduler = 'tcp://nohost': allowed 'local' or a scheduler's address"),
])
def test_a_study_that_cannot_mean_what_it_says_is_refused_in_one_line(tmp_path, capsys, extra, message):
    if "--scheduler" in extra:
        pytest.importorskip("dask.distributed")
    argv = ["mc", "ptfe52_magnetic", "--shots", "4", "--vary", VARY[0], "--out", str(tmp_path / "s"), "--quiet"]
    assert main(argv + extra) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_the_python_api_refuses_what_no_study_has_in_one_line():
    from instruments.errors import InstrumentError
    from instruments.streams import spawned_draws
    from rig.errors import RigError
    from rig.study.batch import batch_inputs, shot_inputs

    study = MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY[:1])), 10, batch=4)
    for call, message in ((lambda: run_batch(study, 3), "batch = 3: a whole number from 0 to 2"),
                          (lambda: refire(study, 10), "shot = 10: a shot of the study, 0..9"),
                          (lambda: shot_inputs(study, 10, 52), "shots of the study, 0..9"),
                          (lambda: batch_inputs(study, 5, 3, 52), "shots of the study, 0..9"),
                          (lambda: MonteCarloStudy("ptfe52_magnetic", study.dists, 10, batch=2.5), "--batch = 2.5"),
                          (lambda: parse_vary(VARY[0]), "a list of KEY=DIST texts")):
        with pytest.raises(RigError, match=message):
            call()
    # a negative size had written past the rows' ends (the interpreter aborted)
    for args, message in (((["normal", "normal"], [5, -3]), "size = -3"),
                          ((["normal"], [1, 2]), "two sequences of one length"),
                          (("normal", [1]), "two sequences of one length")):
        with pytest.raises(InstrumentError, match=message):
            spawned_draws(1, 0, 2, *args)
    assert MonteCarloStudy("ptfe52_magnetic", study.dists, np.int64(10), batch=np.int64(4)).digest() == study.digest()


@pytest.mark.slow
def test_identical_results_with_one_two_workers_and_dask(tmp_path):
    pytest.importorskip("dask.distributed")
    runs = {}
    for name, kw in (("one", {}), ("two", {"workers": 2}), ("dask", {"scheduler": "local", "workers": 2})):
        store = Store(tmp_path / name, _study()).open()
        run_study(_study(), store, **kw)
        runs[name] = store.collect()
    for name in ("two", "dask"):
        assert np.array_equal(runs[name].inputs, runs["one"].inputs)
        assert np.array_equal(runs[name].seeds, runs["one"].seeds)
        for k, v in runs["one"].outputs.items():
            assert np.array_equal(runs[name].outputs[k], v, equal_nan=True), k


def test_the_batch_size_changes_no_result():
    """Shot i's inputs, seed and outputs are its own, whatever batch it runs in."""
    a = run_batch(_study(shots=12), 0)  # shots 0..11 in one batch of 16
    b = [run_batch(dataclasses.replace(_study(shots=12), batch=5), k) for k in range(3)]
    assert np.array_equal(np.concatenate([r.index for r in b]), a.index)
    assert np.array_equal(np.concatenate([r.seeds for r in b]), a.seeds)
    assert np.array_equal(np.concatenate([r.inputs for r in b]), a.inputs)
    for k, v in a.outputs.items():
        assert np.array_equal(np.concatenate([r.outputs[k] for r in b]), v, equal_nan=True), k


def test_a_resumed_study_keeps_its_batch_size(tmp_path, capsys):
    """`rig mc` without --batch resumes a study in --out with the batch size it was started
    with (the default changed from 128 to 256: an older study must still resume)."""
    out = tmp_path / "s"
    args = ["mc", "ptfe52_magnetic", "--shots", "6", "--vary", VARY[0], "--out", str(out), "--quiet", "--json"]
    assert main([*args, "--batch", "3"]) == 0
    capsys.readouterr()
    assert main(args) == 0
    assert json.loads((out / "study.json").read_text())["batch"] == 3
    assert main([*args, "--batch", "4"]) == 2  # another batch size is another study
    assert "holds this study begun with --batch 3; run it with that batch size (or without --batch)" in \
        capsys.readouterr().err


def test_a_study_in_one_process_on_many_threads_takes_128_shots_per_thread_a_batch(tmp_path, monkeypatch, capsys):
    """`rig mc` without --batch, its batches run here on 16 numba threads: 2048 shots a batch
    (rig.study.mc_spec.default_batch), the solver's widest chunk per thread; admitted
    without --allow-large (the estimate of the memory a batch holds is under the limit)."""
    import numba

    # rig mc asks numba (so does the solver's chunk width, which changes no result); the ranges run on 2
    monkeypatch.setattr(numba, "get_num_threads", lambda: 16)
    out = tmp_path / "s"
    assert main(["mc", "ptfe52_magnetic", "--shots", "2100", "--vary", VARY[0], "--out", str(out), "--quiet",
                 "--json"]) == 0
    assert json.loads((out / "study.json").read_text())["batch"] == 2048
    assert json.loads(capsys.readouterr().out)["shots"] == 2100


def test_the_estimate_of_a_shot_held_in_a_batch_bounds_what_a_batch_holds():
    """The memory a batch of arrays holds at its peak (tracemalloc: numpy's arrays), per shot,
    over the scene's whole record (the longest window), is under the estimate that sizes rig
    mc's batches and admits a study (rig.study.mc_run.held_per_shot), and not far under it.
    Counted from what is traced before the batch, after a first batch has made the nominal
    shot, the pilot and the kernels."""
    import tracemalloc

    from rig.study.mc_run import held_per_shot

    study = MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY[:1])), 512, seed=2, batch=256, window="record")
    run_batch(dataclasses.replace(study, batch=4), 0)  # the nominal shot, the pilot, the kernels: before the count
    tracing = tracemalloc.is_tracing()
    if not tracing:
        tracemalloc.start()  # numpy's arrays are traced (the kernels' own scratch is not: a few per thread)
    try:
        tracemalloc.reset_peak()
        before = tracemalloc.get_traced_memory()[0]
        run_batch(study, 1)
        held = (tracemalloc.get_traced_memory()[1] - before) / 256
    finally:
        if not tracing:
            tracemalloc.stop()
    estimate = held_per_shot(study).bytes
    assert 0.25 * estimate < held <= estimate


def test_interrupted_study_keeps_finished_shots_and_resumes(tmp_path):
    study = _study(shots=96)  # 6 batches
    store = Store(tmp_path / "s", study).open()
    seen = []

    def interrupt(n):
        seen.append(n)
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_study(study, store, progress=interrupt)
    # the two batches progress was told of are on disk; the writer stores batches that came
    # while it was busy as one group, so the interrupt may find one or two more stored with them
    kept = store.done()
    assert {0, 1} <= kept and kept == set(range(len(kept))), kept
    assert run_study(study, store) == 6 - len(kept)  # the re-run does only what is missing
    whole = Store(tmp_path / "w", study).open()
    run_study(study, whole)
    for k, v in whole.collect().outputs.items():
        assert np.array_equal(store.collect().outputs[k], v, equal_nan=True)


def test_study_json_appears_whole_or_not_at_all(tmp_path, monkeypatch):
    # a full disk (or a kill) while study.json is written leaves no study.json behind, so
    # running the same command again starts the study instead of stopping at a broken file
    import errno
    from pathlib import Path

    real = Path.write_text

    def disk_full(self, *args, **kw):
        real(self, '{"dig')
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Path, "write_text", disk_full)
    with pytest.raises(OSError):
        Store(tmp_path / "s", _study()).open()
    monkeypatch.undo()
    assert sorted(p.name for p in (tmp_path / "s").iterdir()) == ["batches"]
    Store(tmp_path / "s", _study()).open()
    assert json.loads((tmp_path / "s" / "study.json").read_text())["digest"] == _study().digest()


def test_any_shot_refires_alone_with_the_same_result():
    study = _study(shots=32)
    batch = run_batch(study, 1)
    again = refire(study, 21)
    for k, v in again.items():
        assert v == batch.outputs[k][5] or (np.isnan(v) and np.isnan(batch.outputs[k][5]))


def test_study_inputs_follow_their_distributions():
    study = _study(shots=64)
    x = np.concatenate([run_batch(study, b).inputs for b in range(4)])
    v = x[:, 0]
    assert abs(np.mean(v) - 0.89) < 4 * 0.01 / 8 and 0.006 < np.std(v) < 0.014


def test_jcgm101_summary():
    y = np.random.default_rng(1).normal(10.0, 2.0, 200_000)
    r = jcgm101(y)
    assert r["estimate"] == pytest.approx(10.0, abs=0.02) and r["std"] == pytest.approx(2.0, rel=0.01)
    assert r["ci95"] == pytest.approx([10 - 1.96 * 2, 10 + 1.96 * 2], abs=0.05)
    assert r["trials"] == 200_000 and r["converged"]
    assert not jcgm101(y[:200])["converged"]  # too few trials for two significant digits


def test_mc_command_json_and_sobol(tmp_path, capsys):
    pytest.importorskip("SALib")
    out = tmp_path / "sobol"
    assert main(["mc", "ptfe52_magnetic", "--shots", "256", "--batch", "64", "--sobol",
                 "--vary", "gauges.lower.misalignment=normal(0 mm, 1 mm)",
                 "--vary", "gauges.upper.gain=normal(1, 0.1)", "--out", str(out), "--json", "--quiet"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["shots"] == 256 and r["shots_per_s"] > 0
    assert set(r["speed_m_per_s"]) >= {"estimate", "std", "ci95"} and len(r["amplitude_N"]["ci95"]) == 2
    assert r["sobol"]["speed_m_per_s"]["dominant"] == "gauges.lower.misalignment"
    assert r["sobol"]["amplitude_N"]["dominant"] == "gauges.upper.gain"
    for name in ("study.h5", "report.json", "histograms.png", "speed_vs_amplitude.png"):
        assert (out / name).stat().st_size > 0


def test_leading_window_measures_what_the_whole_record_measures():
    # with noise-free instruments the short study window (simulated until the leading pulse
    # has passed the last gauge, the scope's pre-trigger samples kept) gives the same speed
    # and amplitude as the scene's whole record, for a fraction of the simulated time
    from rig.study.nominal import nominal

    quiet = ("gauges.upper.noise=0 V", "gauges.lower.noise=0 V", "gauges.upper.calibration_error=0",
             "gauges.lower.calibration_error=0", "wall_sensor.noise=0 V", "wall_sensor.calibration_error=0",
             "scope.noise_floor=0 V")
    w = nominal("ptfe52_magnetic", quiet).leading_window
    duration, length, pre = w.duration, w.record_length, w.pre_trigger
    assert duration < 0.4 * 3e-3 and length < 12500 and round(pre * length) == 1250
    # each window calibrates its own step: at 1e-8 both solves are exact to far below the tolerance
    a, b = (run_batch(_study(8, overrides=quiet, window=w, accuracy=1e-8), 0).outputs for w in ("leading", "record"))
    for key in ("speed_m_per_s", "amplitude_N"):
        assert np.all(np.isfinite(a[key]))
        np.testing.assert_allclose(a[key], b[key], rtol=1e-6)


def test_traces_are_archived_only_when_asked_and_analyse_to_the_stored_outputs(tmp_path):
    # --traces: each batch's shots go to a shot archive of their own (scope codes and truth),
    # and the pipeline run on an archived record gives the speed the study stored
    from instruments.analysis import analyze_record
    from instruments.archive import Archive
    from rig.experiment.measure import setup_for
    from rig.study.nominal import nominal

    plain = Store(tmp_path / "plain", _study(32)).open()
    run_study(_study(32), plain)
    assert not (tmp_path / "plain" / "traces").exists()
    study = _study(32, traces=True)
    store = Store(tmp_path / "t", study).open()
    run_study(study, store)
    archives = sorted((tmp_path / "t" / "traces").glob("batch_*.h5"))
    assert [p.name for p in archives] == ["batch_000000.h5", "batch_000001.h5"]
    entries = [Archive(archives[1]).read(i) for i in Archive(archives[1]).ids()]
    assert len(entries) == 16
    e = entries[3]
    assert e.facts.study_shot == 19 and e.facts.study == study.digest() and e.truth is not None
    nom = nominal(study.scene, ())
    beta, F0 = nom.calibration
    # the analysis is told what an experimenter knows: the nominal rig's gauge positions
    speed = analyze_record(e.record, setup_for(nom.template(study.window), beta, F0), train=False).speed_m_per_s
    assert speed == store.collect().outputs["speed_m_per_s"][19]
    # the traces do not change the results
    for k, v in plain.collect().outputs.items():
        assert np.array_equal(store.collect().outputs[k], v, equal_nan=True)
    # each archived shot carries the calibration the study applied: rig analyze gives the
    # amplitude the study stored (beta and F_0 of the nominal shot, not 1 and 0)
    assert e.facts.analysis == {"beta": beta, "static_force_N": F0, "basis": "the study's nominal shot"}
    from rig.experiment.analyze import AnalyzeOptions, analyze_paths

    (r,) = analyze_paths(AnalyzeOptions(files=(str(archives[1]),), shot=4))
    assert (r["beta"], r["static_force_N"]) == (beta, F0)
    assert r["amplitude_N"] == pytest.approx(store.collect().outputs["amplitude_N"][19], rel=1e-12)


def test_a_study_records_the_gauge_averages_and_contacts_only_when_needed():
    # the gauges read their plates' average: a study records it as one probe per gauge
    # (3 channels with the wall, not 5); the truth analysis and the traces add the contacts
    from rig.study.batch import shot_inputs, shot_rig, study_save

    for kw, names in (({}, {"gauge_lower", "gauge_upper", "wall"}),
                      ({"truth": True}, {"gauge_lower", "gauge_upper", "wall", "contact20", "contact21",
                                         "contact29", "contact30"})):
        study = _study(16, **kw)
        rig = shot_rig(study, *shot_inputs(study, 0, 52)[:2])[0]
        assert set(study_save(study, rig).probes) == names
    plain = run_batch(_study(16), 0).outputs
    with_truth = run_batch(_study(16, truth=True), 0).outputs
    for k in ("speed_m_per_s", "amplitude_N"):
        assert np.array_equal(plain[k], with_truth[k])
    assert np.all(np.isfinite(with_truth["truth_speed_m_per_s"]))


@pytest.mark.parametrize("overrides", [(), ("chain.contact_law=thornton", "chain.yield_force=0.8 N",
                                              "chain.static_yield_ratio=0.6")])
def test_a_batch_shot_has_the_bits_of_the_shot_fired_alone(overrides):
    # no rig is built per shot in a batch (arrays all the way); the same shot built as a rig,
    # solved alone at the study's step, fired with its seed and draws and analysed as one
    # record gives the very same numbers; with a yielding law too, whose contacts the
    # magnet's static hold flattened before the shot (the beads rest lower, which moves
    # the gauges and so their misalignment's delay)
    from instruments.analysis import analyze_record
    from rig.experiment.measure import setup_for
    from rig.solver.problem import ChainProblem
    from rig.solver.solve import solve
    from rig.solver.stepsize import stepping_at
    from rig.study.batch import shot_inputs, shot_rig
    from rig.study.nominal import nominal

    study = _study(16, overrides=overrides)
    outputs = run_batch(study, 0).outputs
    nom = nominal(study.scene, overrides)
    template = nom.template(study.window)
    save = template.save_at(contacts=False, averages=True)
    pilot = nom.pilot(study.window, save, study.accuracy)
    beta, F0 = nom.calibration
    for i in (0, 5, 11):
        x, masses, seed = shot_inputs(study, i, 52)
        rig, draws = shot_rig(study, x, masses)
        p = ChainProblem.from_chain(rig.chain)
        rig.use_solution(solve(p, template.solver.duration, save=save, dt=stepping_at(p, pilot.stats.dt_s),
                               estimate=False))
        shot = rig.fire(seed=seed, fixed=draws, truth=False)
        m = analyze_record(shot.scope, setup_for(template, beta, F0), train=False)
        for key in ("speed_m_per_s", "speed_xcorr_m_per_s", "amplitude_N", "averaged_amplitude_N"):
            assert getattr(m, key) == outputs[key][i], (i, key)


def test_a_study_folder_that_cannot_be_checked_is_refused(tmp_path, capsys):
    """Batches without their study.json (whose batch size and inputs are unknown) are not
    taken as finished shots; a study.json that is not an object is one line, exit 2."""
    out = tmp_path / "s"
    args = ["mc", "ptfe52_magnetic", "--shots", "6", "--vary", VARY[0], "--out", str(out), "--quiet", "--json"]
    assert main([*args, "--batch", "3"]) == 0
    (out / "study.json").unlink()
    capsys.readouterr()
    assert main(args) == 2
    assert "holds finished batches but no study.json" in capsys.readouterr().err
    (out / "study.json").write_text("[1, 2]")
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "not a study file (a JSON list, not an object)" in err and "Traceback" not in err


def test_a_small_study_is_sized_by_its_shots_not_its_batch(tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["mc", "ptfe52_magnetic", "--shots", "4", "--vary", VARY[0], "--out", str(out), "--quiet",
                 "--json", "--batch", "99999"]) == 0


HOLD = """
import sys, time
from rig.study.store import Store
from rig.study.montecarlo import MonteCarloStudy
from rig.study.distributions import parse_vary
study = MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary([sys.argv[2]])), 4, seed=3, batch=2)
with Store(sys.argv[1], study).held():
    print("held", flush=True)
    time.sleep(600)
"""


def test_a_second_run_into_a_held_folder_is_refused_and_a_killed_holder_blocks_nothing(tmp_path, capsys):
    # two `rig mc` into one --out once both ran, the second redoing the first's shots
    import os
    import signal
    import socket
    import subprocess

    out = tmp_path / "s"
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(out), VARY[0]], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        argv = ["mc", "ptfe52_magnetic", "--shots", "4", "--batch", "2", "--vary", VARY[0], "--out", str(out),
                "--quiet"]
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"rig mc: error: {out}: in use by another run (pid {holder.pid} "
                                                       f"on {socket.gethostname()} since "), err
        assert err.rstrip().endswith("wait for it to end, or give another --out")
        assert not (out / "batches").exists() or not list((out / "batches").iterdir())  # it fired nothing
        # a study large enough to announce its cost, on a Sobol design: the hold is taken
        # before anything is printed, so the refusal is the only line
        assert main([*argv, "--shots", "100000", "--sobol", "--allow-large"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"rig mc: error: {out}: in use by another run"), err
    finally:
        os.kill(holder.pid, signal.SIGKILL)  # a killed run: its lock file stays, naming a dead pid
        holder.wait()
    assert f"pid {holder.pid} " in (out / "study.lock").read_text()
    assert main(argv) == 0
    assert capsys.readouterr().out.startswith("4 shots (4 run now, ")
