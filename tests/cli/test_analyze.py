"""`rig analyze`: a clear result or a clear refusal, with the reason, for every file; the
SNR of each channel; every flag checked; exit 0 with a speed, 1 without, 2 for a mistake."""
import json
from pathlib import Path

import numpy as np
import pytest

from instruments.analysis.report import FIGURES
from instruments.archive import Archive
from instruments.devices.frontend import rc_highpass
from instruments.devices.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger
from instruments.formats import read_record
from instruments.formats.isf import write_isf
from rig.cli import main
from rig.experiment.analyze import IN_VOLTS

H = 1e-7


@pytest.fixture(scope="module")
def gauge_files(tmp_path_factory):
    """An emulated 8-bit two-gauge record, one ISF file per channel: PTFE-like pulses of
    4 N (0.05 V/N) 200 us apart, gauge RC 1 ms, the scope's own noise floor."""
    t = np.arange(30000) * H
    def pulse(t0):
        return 4.0 / np.cosh((t - t0) / 3e-5) ** 2
    scope = Oscilloscope(channels={"CH1": ChannelSettings(0.05, -1.0), "CH2": ChannelSettings(0.05, -1.0)},
                         timebase=Timebase(2e-7, 10000), trigger=Trigger("CH1", 0.03, "rising", 0.1))
    volts = {ch: rc_highpass(0.05 * pulse(t0), H, 1e-3) for ch, t0 in (("CH1", 1e-3), ("CH2", 1.2e-3))}
    rec = scope.acquire(volts, H, np.random.default_rng(0))
    up, low = write_isf(rec.waveforms, tmp_path_factory.mktemp("gauges"), "shot")
    return str(up), str(low)


GAUGE = ["--gauge-distance", "40 mm", "--sensitivity", "0.05 V/N", "--tau", "1 ms"]


def run(capsys, *argv):
    code = main([*argv, "--json"])
    out = capsys.readouterr()
    return code, (json.loads(out.out) if out.out else None), out.err


def refused(result, text):
    assert result["speed_m_per_s"] is None
    figures = [f if f in result else IN_VOLTS[f] for f in FIGURES]  # a real record's in volts: _V keys
    assert {f for f in figures if result[f] is None} <= set(result["reasons"])
    assert any(text in why for why in result["reasons"].values()), result["reasons"]


def test_a_clean_pair_gives_its_speed_snr_and_exit_0(gauge_files, capsys):
    code, (r,), _ = run(capsys, "analyze", *gauge_files, *GAUGE)
    assert code == 0 and r["speed_m_per_s"] == pytest.approx(200.0, rel=5e-3)
    assert r["amplitude_N"] == pytest.approx(4.0, rel=0.02)  # 8-bit: a code is 1% of this pulse
    assert min(r["snr"]["CH1"], r["snr"]["CH2"]) > 50
    assert set(r["reasons"]) == {"theory_speed_m_per_s"}  # no --material


def test_text_output_states_snr_and_reasons(gauge_files, capsys):
    assert main(["analyze", *gauge_files, *GAUGE, "--gauge-distance", "19 km"]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[2].startswith("  SNR (leading pulse / pre-trigger noise): CH1 ")
    assert any(line.startswith("  no speed_m_per_s, speed_xcorr_m_per_s, pulses, width_diameters: implausible speed:")
               for line in out), out


def test_text_output_says_when_its_forces_are_volts(gauge_files, capsys):
    """Without --sensitivity the force columns hold the gauges' volts (1 V/N): the table
    says so above its header, and not when the sensitivity is given."""
    volts = ["--gauge-distance", "40 mm", "--tau", "1 ms"]
    assert main(["analyze", *gauge_files, *volts]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("note: without --sensitivity a real scope file's forces are its gauges' volts")
    assert out[3].startswith("  SNR (leading pulse / pre-trigger noise): CH1 ") and out[3].count(" V)") == 2
    assert main(["analyze", *gauge_files, *GAUGE]) == 0
    out = capsys.readouterr().out
    assert not out.startswith("note:") and out.splitlines()[2].count(" N)") == 2
    # the JSON says the unit of the forces and the noise; the noise scales with the sensitivity
    (_, (v,), _), (_, (n,), _) = run(capsys, "analyze", *gauge_files, *volts), run(capsys, "analyze", *gauge_files,
                                                                                    *GAUGE)
    assert (v["force_unit"], n["force_unit"], v["simulated"]) == ("V", "N", False)
    assert v["noise"]["CH1"] == pytest.approx(0.05 * n["noise"]["CH1"], rel=1e-12)


def _keys(node, path=""):
    """Every key of a JSON document, with where it stands."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield f"{path}.{k}", k
            yield from _keys(v, f"{path}.{k}")
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _keys(v, f"{path}[{i}]")


def test_a_figure_in_volts_is_never_under_a_newton_key(gauge_files, realdata, capsys):
    """Without --sensitivity a real record's forces are its gauges' volts: every force
    figure goes under a _V key, the _N keys appear only where a sensitivity makes newtons,
    and the volts are the newtons times the sensitivity; no _N key at all in a row in volts
    (static_force_N, F_0, needs --sensitivity too). Every JSON row rig analyze writes for a
    real record: the gauge pair, and each real file that gives a row."""
    _, (v,), _ = run(capsys, "analyze", *gauge_files, "--gauge-distance", "40 mm", "--tau", "1 ms")
    _, (n,), _ = run(capsys, "analyze", *gauge_files, *GAUGE)
    assert (v["force_unit"], n["force_unit"]) == ("V", "N")
    for name, key in IN_VOLTS.items():
        assert name not in v and name not in v["reasons"] and key in v and key not in n
    assert v["amplitude_V"] == pytest.approx(0.05 * n["amplitude_N"], rel=1e-9)
    assert v["averaged_amplitude_V"] == pytest.approx(0.05 * n["averaged_amplitude_N"], rel=1e-9)
    assert v["total_force_V"] == pytest.approx(0.05 * n["total_force_N"], rel=1e-9)  # F_0 = 0: --f0 needs N
    rows = [v]
    for path in sorted(p for p in realdata.iterdir() if p.suffix.lower() in (".csv", ".isf", ".wfm")):
        code, out, _ = run(capsys, "analyze", str(path), str(path), "--gauge-distance", "43 mm")
        rows += out if code != 2 else []
    assert len(rows) > 5
    for row in rows:
        newton_keys = [where for where, key in _keys(row) if key.endswith("_N")]
        assert newton_keys == [], newton_keys  # F_0 too: --f0 (N) needs --sensitivity


def test_19_km_between_the_gauges_is_refused(gauge_files, capsys):
    code, (r,), _ = run(capsys, "analyze", *gauge_files, *GAUGE, "--gauge-distance", "19 km")
    assert code == 1
    refused(r, "even at 1.033e+04 m/s a pulse needs 1.84 s between them, but the record spans 0.002 s")
    assert r["amplitude_N"] == pytest.approx(4.0, rel=0.02)  # the pulses themselves were measured


def test_swapped_files(gauge_files, capsys):
    code, (r,), _ = run(capsys, "analyze", *reversed(gauge_files), *GAUGE)
    assert code == 1
    refused(r, "channels swapped?")


def test_the_same_file_twice(gauge_files, capsys):
    code, (r,), _ = run(capsys, "analyze", gauge_files[0], gauge_files[0], *GAUGE)
    assert code == 1
    refused(r, "hold the same record (the same file twice?)")


def test_the_speed_is_checked_against_eq1_for_the_material(gauge_files, capsys):
    code, (ptfe,), _ = run(capsys, "analyze", *gauge_files, *GAUGE, "--material", "ptfe")
    assert code == 0 and 0.5 < ptfe["speed_m_per_s"] / ptfe["theory_speed_m_per_s"] < 2
    code, (steel,), _ = run(capsys, "analyze", *gauge_files, *GAUGE, "--material", "steel316")
    assert code == 1 and steel["theory_speed_m_per_s"] > 400  # 200 m/s is no 4 N wave in steel
    refused(steel, "is off Eq (1)'s")


@pytest.mark.parametrize("flag,value,message", [
    ("--beta", "nan", "--beta = nan: a finite number > 0"),
    ("--beta", "inf", "--beta = inf: a finite number > 0"),
    ("--beta", "-1", "--beta = -1.0: a finite number > 0"),
    ("--shot", "-1", "--shot = -1: a shot number is a whole number >= 0"),
    ("--shot", "one", "argument --shot: invalid int value: 'one'"),
    ("--gauge-distance", "0 m", "--gauge-distance = 0.0: a finite number > 0 m"),
    ("--gauge-distance", "nan", "argument --gauge-distance: 'nan': a finite number"),
    ("--gauge-distance", "-43 mm", "--gauge-distance = -0.043: a finite number > 0 m"),
    ("--sensitivity", "0", "--sensitivity = 0.0: a finite number > 0 V/N"),
    ("--tau", "-1 ms", "--tau = -0.001: a finite number > 0 s"),
    ("--f0", "-1 N", "--f0 = -1.0: a finite number >= 0 N"),
    ("--f0", "inf", "argument --f0: 'inf': a finite number"),
    ("--diameter", "0 mm", "--diameter = 0.0: a finite number > 0 m"),
    ("--channels", "CH9,CH1", "--channels = 'CH9,CH1': 'CH9' is not in the files (channels: CH1, CH2)"),
    ("--channels", "CH1,CH1", "--channels = 'CH1,CH1': a channel named twice"),
    ("--channels", "CH1", "--channels = 'CH1': UPPER,LOWER[,WALL]: two or three of CH1, CH2"),
    ("--material", "unobtainium", "material = 'unobtainium': known materials:"),
    ("--shot", "1", "--shot = 1: picks a shot of an archive (.h5); scope files are one shot together"),
    ("--wall", None, "--wall reads the third channel as the wall sensor; the record holds CH1, CH2"),
])
def test_bad_flags_are_one_line_and_exit_2(gauge_files, capsys, flag, value, message):
    try:
        code = main(["analyze", *gauge_files, *GAUGE, flag, *([] if value is None else [value])])
    except SystemExit as exc:  # argparse's own checks
        code = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0], err


def test_beta_one_is_the_default(gauge_files, capsys):
    with_beta = run(capsys, "analyze", *gauge_files, *GAUGE, "--beta", "1")[1]
    assert with_beta == run(capsys, "analyze", *gauge_files, *GAUGE)[1]


def test_every_real_file_is_a_clear_refusal(realdata, capsys):
    # none of them is an impact record: each must end in a refusal with its reasons (exit 1)
    # or a one-line error (exit 2), never a speed; one-channel files are paired with themselves
    seen = {}
    for path in sorted(p for p in realdata.iterdir() if p.is_file() and not p.name.endswith((".source.txt", ".md"))):
        try:
            files = [str(path)] * (1 if len(read_record([path]).waveforms) > 1 else 2)
        except ValueError:  # a file the readers refuse is the readers' business (tests/instruments)
            files = [str(path)]
        for material in ([], ["--material", "ptfe", "--sensitivity", "0.05 V/N"]):
            code, out, err = run(capsys, "analyze", *files, "--gauge-distance", "43.1 mm", *material)
            assert code in (1, 2), (path.name, out)
            if code == 2:
                assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
                continue
            (r,) = out
            refused(r, "")
            seen[path.name] = r
    # the expected refusals of the files this project knows
    if "bee331_MSO3012_tek0000.csv" in seen:  # two channels of a sine: the baseline is the sine itself
        r = seen["bee331_MSO3012_tek0000.csv"]
        refused(r, "CH1: no pulse stands 8 times above the pre-trigger noise")
        assert max(r["snr"].values()) < 2
    if "jeremitu_data1.isf" in seen:
        refused(seen["jeremitu_data1.isf"], "an envelope (peak-detect) record holds min/max pairs, not samples")
    if "tek_8bit_two_records.isf" in seen:
        refused(seen["tek_8bit_two_records.isf"], "CH1#2: an envelope (peak-detect) record")
    for name in ("tek_16bit_dpo.isf", "accel_TEK00000.CSV", "pchem_TDS2001C_F0000CH1.CSV"):
        if name in seen:
            refused(seen[name], "the same file twice?")
    assert len(seen) >= 5, sorted(seen)


def test_a_virtual_archive_analyses_as_the_shot_measured_it(tmp_path, capsys):
    path = str(tmp_path / "a.h5")
    assert main(["shot", "ptfe52_magnetic", "--seed", "3", "--out", path, "--json"]) == 0
    measured = json.loads(capsys.readouterr().out)["measured"]
    code, (r,), _ = run(capsys, "analyze", path)
    assert code == 0 and r["reasons"] == {}
    assert r["speed_m_per_s"] == pytest.approx(measured["speed_m_per_s"], rel=1e-9)
    assert r["amplitude_N"] == pytest.approx(measured["amplitude_N"], rel=1e-9)
    assert r["pulses"] == measured["pulses"]
    assert 0.8 < r["speed_m_per_s"] / r["theory_speed_m_per_s"] < 1.25
    assert min(r["snr"].values()) > 100


def test_real_records_and_virtual_shots_in_one_call(gauge_files, tmp_path, capsys):
    """The real-file flags describe the real records: refused where only virtual shots are
    analysed, applied to the real ones beside a virtual shot, which keeps its own set-up
    (the same figures as alone), in one archive or as files beside it."""
    path = str(tmp_path / "mixed.h5")
    assert main(["shot", "ptfe52_magnetic", "--seed", "3", "--out", path]) == 0
    capsys.readouterr()
    _, (alone,), _ = run(capsys, "analyze", path)
    assert (alone["simulated"], alone["force_unit"]) == (True, "N")
    code, out, err = run(capsys, "analyze", path, *GAUGE)
    assert code == 2 and out is None
    assert "--gauge-distance, --sensitivity, --tau: for real scope files only; shot 1 is a virtual shot" in err
    code, (virtual, real), _ = run(capsys, "analyze", path, *gauge_files, *GAUGE)
    assert code == 0 and virtual == alone and real["speed_m_per_s"] == pytest.approx(200.0, rel=5e-3)
    assert main(["import", *gauge_files, "--together", "--into", path]) == 0
    capsys.readouterr()
    assert main(["analyze", path, *GAUGE]) == 0
    text = capsys.readouterr().out.splitlines()
    assert text[0] == ("note: --gauge-distance, --sensitivity, --tau describe the real records; "
                       "the virtual shots use their own set-up")
    code, (virtual, real), _ = run(capsys, "analyze", path, *GAUGE)
    assert virtual == alone and real["source"].endswith("#2") and real["speed_m_per_s"] == pytest.approx(200, rel=5e-3)


def test_a_reader_that_closes_the_output_early_ends_the_command_quietly(tmp_path):
    # `rig ... | head`: the output's reader is gone before the command writes; exit 141
    # (as cat's), no traceback and no 'Exception ignored' warning
    import os
    import subprocess
    import sys

    for argv in (["theory", "--f0", "1 N", "--fm", "5 N"], ["theory", "--f0", "1 N", "--json"]):
        r, w = os.pipe()
        os.close(r)
        try:
            done = subprocess.run([sys.executable, "-m", "rig.cli", *argv], stdout=w, stderr=subprocess.PIPE,
                                  text=True, timeout=120)
        finally:
            os.close(w)
        assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr, done.stderr
        assert done.returncode == 141 and not done.stderr, (argv, done.returncode, done.stderr)
    # --help: argparse drops its own failed write; nothing to say either
    r, w = os.pipe()
    os.close(r)
    done = subprocess.run([sys.executable, "-m", "rig.cli", "--help"], stdout=w, stderr=subprocess.PIPE, text=True,
                          timeout=120)
    os.close(w)
    assert not done.stderr


def test_a_train_counted_without_the_wall_channel_says_so(gauge_files, capsys):
    assert main(["analyze", *gauge_files, *GAUGE]) == 0
    out = capsys.readouterr().out.splitlines()
    assert "  pulses: counted to the record's end; without --wall (the wall sensor's channel) the wall's " \
           "reflection may be among them" in out


def test_the_bead_material_of_a_virtual_shot_is_its_own(gauge_files, tmp_path, capsys):
    # --material describes the real records, as the other real-file flags: refused where
    # only virtual shots are analysed, and beside real records the virtual shot keeps its
    # scene's PTFE (the same Eq (1) speed as alone) while the real pair is judged as steel
    path = str(tmp_path / "v.h5")
    assert main(["shot", "ptfe52_magnetic", "--seed", "3", "--out", path]) == 0
    capsys.readouterr()
    _, (alone,), _ = run(capsys, "analyze", path)
    code, out, err = run(capsys, "analyze", path, "--material", "steel316")
    assert code == 2 and "--material: for real scope files only; shot 1 is a virtual shot" in err
    code, (virtual, real), _ = run(capsys, "analyze", path, *gauge_files, *GAUGE, "--material", "steel316")
    assert virtual == alone and virtual["speed_m_per_s"] is not None
    assert "for steel316" in real["reasons"]["speed_m_per_s"]  # 200 m/s is far below steel's Eq (1)


def test_a_bad_shot_of_an_archive_is_a_row_with_its_reason(gauge_files, tmp_path, capsys, realdata):
    # one damaged shot and one real record that holds a single channel do not stop the
    # other shots: each is a row whose every figure is missing for its reason (exit 0: a
    # speed was measured); alone, the same shot is a one-line refusal (exit 2)
    import h5py

    path = str(tmp_path / "three.h5")
    for seed in ("3", "4"):
        assert main(["shot", "ptfe52_magnetic", "--seed", seed, "--out", path]) == 0
    assert main(["import", str(realdata / "tek_16bit_dpo.isf"), "--into", path]) == 0
    capsys.readouterr()
    with h5py.File(path, "r+") as f:
        f["shot_000002/data/CH1"][100] += 3
    code, rows, _ = run(capsys, "analyze", path, "--gauge-distance", "43 mm")
    assert code == 0 and [r["source"] for r in rows] == [f"{path}#{i}" for i in (1, 2, 3)]
    assert rows[0]["speed_m_per_s"] is not None and set(rows[1]) == set(rows[0])
    assert rows[1]["reasons"]["speed_m_per_s"] == "shot 2: data/CH1: damaged (SHA-256 differs)"
    assert rows[2]["reasons"]["amplitude_N"].startswith("shot 3: two gauge channels are needed; the record holds")
    assert all(rows[k][f] is None for k in (1, 2) for f in FIGURES)
    code, _, err = run(capsys, "analyze", path, "--shot", "2")
    assert code == 2 and "shot 2: data/CH1: damaged" in err


def test_a_noise_refusal_states_the_noise_in_the_forces_unit(realdata, capsys):
    # a sine record (no pulse): the SNR refusal gives its noise in V without --sensitivity,
    # in N with it (the noise in N is the volts over the sensitivity)
    f = str(realdata / "bee331_MSO3012_tek0000.csv")
    _, (v,), _ = run(capsys, "analyze", f, "--gauge-distance", "43 mm")
    _, (n,), _ = run(capsys, "analyze", f, "--gauge-distance", "43 mm", "--sensitivity", "0.5 V/N")
    why_v, why_n = v["reasons"]["speed_m_per_s"], n["reasons"]["speed_m_per_s"]
    sigma = v["noise"]["CH1"]
    assert f"pre-trigger noise ({sigma:.3g} V)" in why_v and f"pre-trigger noise ({sigma / 0.5:.3g} N)" in why_n


def test_the_force_columns_are_headed_with_their_unit(gauge_files, capsys):
    for flags, unit in ((["--gauge-distance", "40 mm", "--tau", "1 ms"], "V"), (GAUGE, "N")):
        assert main(["analyze", *gauge_files, *flags]) == 0
        header = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("source"))
        assert f"F_d {unit}" in header and f"F_m,e {unit}" in header


@pytest.mark.parametrize("flags,named", [(["--f0", "1 N"], "--f0 without --sensitivity"),
                                         (["--material", "ptfe"], "--material without --sensitivity"),
                                         (["--f0", "1", "--material", "ptfe"], "--f0 and --material without")])
def test_flags_in_newtons_need_the_sensitivity_of_a_real_record(gauge_files, tmp_path, capsys, flags, named):
    """Without --sensitivity a real record's forces are volts: --f0 had been added to them
    (0.22 V + 1 N) and --material had put volts into Eq (1) and rejected a right speed; a
    virtual shot beside them is no excuse, alone it refuses these flags as its own."""
    code, _, err = run(capsys, "analyze", *gauge_files, "--gauge-distance", "40 mm", *flags)
    assert code == 2 and len(err.strip().splitlines()) == 1 and named in err and "--sensitivity" in err, err
    path = str(tmp_path / "v.h5")
    assert main(["shot", "ptfe52_magnetic", "--seed", "3", "--out", path]) == 0
    capsys.readouterr()
    code, _, err = run(capsys, "analyze", path, *gauge_files, "--gauge-distance", "40 mm", *flags)
    assert code == 2 and named in err, err
    code, _, err = run(capsys, "analyze", path, *flags)
    assert code == 2 and "for real scope files only" in err, err
    code, rows, _ = run(capsys, "analyze", path, *gauge_files, "--gauge-distance", "40 mm", "--sensitivity",
                        "0.05 V/N", *flags)
    assert code == 0 and rows[1]["force_unit"] == "N"


def test_eq1_without_f0_says_it_assumes_no_precompression(gauge_files, capsys):
    assert main(["analyze", *gauge_files, *GAUGE, "--material", "ptfe"]) in (0, 1)
    assert "  Eq1: with F_0 = 0 (no --f0): the speed of a chain without precompression" in capsys.readouterr().out
    assert main(["analyze", *gauge_files, *GAUGE, "--material", "ptfe", "--f0", "2.4 N"]) in (0, 1)
    assert "Eq1: with F_0 = 0" not in capsys.readouterr().out


@pytest.fixture(scope="module")
def three_channels(tmp_path_factory):
    """gauge_files' record with a third channel, CH3, a later pulse (the wall sensor's place)."""
    t = np.arange(30000) * H
    def pulse(t0):
        return 4.0 / np.cosh((t - t0) / 3e-5) ** 2
    chans = {ch: ChannelSettings(0.05, -1.0) for ch in ("CH1", "CH2", "CH3")}
    scope = Oscilloscope(channels=chans, timebase=Timebase(2e-7, 10000), trigger=Trigger("CH1", 0.03, "rising", 0.1))
    volts = {ch: rc_highpass(0.05 * pulse(t0), H, 1e-3) for ch, t0 in (("CH1", 1e-3), ("CH2", 1.2e-3),
                                                                        ("CH3", 1.6e-3))}
    rec = scope.acquire(volts, H, np.random.default_rng(0))
    return [str(p) for p in write_isf(rec.waveforms, tmp_path_factory.mktemp("three"), "s")]


def test_a_channel_the_analysis_does_not_read_is_named(three_channels, capsys):
    """Three channels without --wall or --channels: the first two are the gauges, and the
    third is named as not read (it had been dropped without a word)."""
    files = three_channels
    code, rows, _ = run(capsys, "analyze", *files, *GAUGE)
    assert code == 0 and rows[0]["unread_channels"] == ["CH3"] and rows[0]["channels"] == ["CH1", "CH2"]
    assert main(["analyze", *files, *GAUGE]) == 0
    assert ("  not read: CH3 (the gauges are CH1, CH2; --channels UPPER,LOWER[,WALL] names them, --wall reads a "
            "third channel as the wall sensor)") in capsys.readouterr().out.splitlines()
    code, rows, _ = run(capsys, "analyze", *files, *GAUGE, "--wall")
    assert code == 0 and rows[0]["unread_channels"] == []


def test_wall_flags_that_disagree_are_refused_and_a_named_wall_needs_no_note(three_channels, capsys):
    files = three_channels
    assert main(["analyze", *files, *GAUGE, "--wall", "--channels", "CH1,CH2"]) == 2
    assert "with --wall, name the wall sensor's channel third" in capsys.readouterr().err
    assert main(["analyze", *files, *GAUGE, "--channels", "CH1,CH2,CH3"]) == 0
    out = capsys.readouterr().out
    assert "without --wall" not in out and "not read" not in out
    assert main(["analyze", *files, *GAUGE, "--channels", "CH1,CH2"]) == 0
    assert "  not read: CH3" in capsys.readouterr().out.splitlines()  # named, without a hint to pass --channels


def test_an_archive_keeps_its_files_channel_order_and_nothing_of_this_machine(gauge_files, tmp_path, capsys):
    """rig import keeps the channels in the order of the files, so that an archive and the
    files it came from analyse alike by default (the first channel the upper gauge); and it
    stores each file's name, not where it lay on the importing machine (unless asked)."""
    lower_first = list(reversed(gauge_files))  # CH2 first: the gauges as the user ordered them
    archive = tmp_path / "order.h5"
    assert main(["import", *lower_first, "--together", "--into", str(archive)]) == 0
    capsys.readouterr()
    _, (files,), _ = run(capsys, "analyze", *lower_first, *GAUGE)
    _, (stored,), _ = run(capsys, "analyze", str(archive), *GAUGE)
    assert files["channels"] == stored["channels"] == ["CH2", "CH1"]
    assert files["reasons"] == stored["reasons"]
    entry = Archive(archive).read(1)
    assert list(entry.record.waveforms) == ["CH2", "CH1"]
    assert main(["ls", str(archive), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)[0]["channels"] == ["CH2", "CH1"]  # rig ls had listed them sorted
    import h5py
    with h5py.File(archive, "r") as f:  # the NeXus plot's signal is the record's first channel
        assert f["shot_000001/data"].attrs["signal"] == "CH2"
    assert {w.preamble.extra["source"] for w in entry.record.waveforms.values()} == {"shot_CH1.isf", "shot_CH2.isf"}
    folder = str(Path(gauge_files[0]).parent).encode()
    stored_bytes = b"".join(p.read_bytes() for p in tmp_path.rglob("*")
                            if p.is_file() and str(p.relative_to(tmp_path)).startswith("order"))
    assert folder not in stored_bytes
    kept = tmp_path / "kept.h5"
    assert main(["import", *lower_first, "--together", "--keep-paths", "--into", str(kept)]) == 0
    assert Archive(kept).read(1).record["CH1"].preamble.extra["source"] == gauge_files[0]


def test_a_record_in_amperes_is_not_analysed_as_gauge_volts(gauge_files, tmp_path, capsys):
    """YUNIT "A" (a current probe) had been read as volts; "Volts", as TDS scopes write it,
    is volts."""
    amps, volts = tmp_path / "amps_CH1.isf", tmp_path / "volts_CH1.isf"
    data = Path(gauge_files[0]).read_bytes()
    assert b'YUNIT "V"' in data
    amps.write_bytes(data.replace(b'YUNIT "V"', b'YUNIT "A"'))
    volts.write_bytes(data.replace(b'YUNIT "V"', b'YUNIT "Volts"'))
    code, _, err = run(capsys, "analyze", str(amps), gauge_files[1], *GAUGE)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert f"{amps}: channel CH1 is in A (its vertical unit), not V" in err
    code, (r,), _ = run(capsys, "analyze", str(volts), gauge_files[1], *GAUGE)
    assert code == 0 and r["speed_m_per_s"] == pytest.approx(200.0, rel=5e-3)


def test_an_archive_imported_with_volts_spelled_out_still_analyses(gauge_files, tmp_path, capsys):
    """Archives imported before the readers named volts V hold YUNIT as the scope wrote it
    ("Volts", as TDS scopes do): analysed as volts, not refused as another unit."""
    from dataclasses import replace

    from instruments.archive import Entry
    from instruments.records import ScopeRecord

    record = read_record(gauge_files)
    old = ScopeRecord({ch: replace(w, preamble=replace(w.preamble, y_unit="Volts"))
                       for ch, w in record.waveforms.items()}, True)
    archive = Archive(tmp_path / "old.h5")
    archive.append([Entry(old, False, scene="", settings={"source_files": ["shot_CH1.isf", "shot_CH2.isf"]})])
    code, (r,), _ = run(capsys, "analyze", str(archive.path), *GAUGE)
    assert code == 0 and r["speed_m_per_s"] == pytest.approx(200.0, rel=5e-3)


def test_a_table_mixing_newtons_and_volts_says_each_rows_unit(gauge_files, tmp_path, capsys):
    """A virtual shot (N) beside a real record without --sensitivity (V): the header says
    N|V and each force figure carries its row's unit (it had been left to guess)."""
    archive = str(tmp_path / "mixed.h5")
    assert main(["shot", "ptfe52_magnetic", "--seed", "1", "--out", archive]) == 0
    assert main(["import", *gauge_files, "--together", "--into", archive]) == 0
    capsys.readouterr()
    main(["analyze", archive, "--gauge-distance", "40 mm", "--tau", "1 ms"])
    out = capsys.readouterr().out.splitlines()
    header = next(line for line in out if line.startswith("source"))
    rows = [line for line in out if line.startswith(("mixed.h5#1", "mixed.h5#2"))]
    assert "F_d N|V" in header and len(rows) == 2, out
    assert " N " in rows[0] and " V " in rows[1], rows
