"""rig analyze on every real scope file (none is an impact record): a clear result that passes
the plausibility rules, or a clear refusal with its reason; never a confident speed on a sine
or a noise record, never a traceback."""
import json

from rig.cli import main


def _real(realdata):
    return sorted(p for p in realdata.iterdir() if p.is_file() and not p.name.endswith((".source.txt", ".md")))


def _run(capsys, argv):
    code = main(argv)
    out = capsys.readouterr()
    return code, out


def test_every_real_file_alone_and_twice_gives_a_reason_not_a_speed(capsys, realdata):
    runs = 0
    for path in _real(realdata):
        for files in ([str(path)], [str(path), str(path)]):
            code, out = _run(capsys, ["analyze", *files, "--gauge-distance", "43.1 mm", "--json"])
            runs += 1
            assert "Traceback" not in out.err
            if code == 2:  # refused: another maker's format, a single channel, ...
                assert len(out.err.strip().splitlines()) == 1
                assert str(path) in out.err or "channel" in out.err
                continue
            assert code == 1, (path.name, out.out)
            for r in json.loads(out.out):
                assert r["speed_m_per_s"] is None and r["reasons"]["speed_m_per_s"], r
    assert runs == 2 * len(_real(realdata))


def test_the_envelope_file_is_refused_as_an_envelope(capsys, realdata):
    f = str(realdata / "jeremitu_data1.isf")
    code, out = _run(capsys, ["analyze", f, f, "--gauge-distance", "43.1 mm"])
    assert code == 1 and "MATH is an envelope (peak-detect) record" in out.out


def test_a_two_channel_sine_record_says_why_it_has_no_speed(capsys, realdata):
    code, out = _run(capsys, ["analyze", str(realdata / "bee331_MSO3012_tek0000.csv"), "--gauge-distance", "43.1 mm"])
    assert code == 1 and "baseline noise" in out.out and "no result" in out.out


def test_a_virtual_shot_still_analyses_and_states_its_snr(capsys, tmp_path):
    archive = str(tmp_path / "a.h5")
    assert main(["shot", "ptfe52_magnetic", "--seed", "1", "--out", archive]) == 0
    capsys.readouterr()
    code, out = _run(capsys, ["analyze", archive, "--json"])
    (r,) = json.loads(out.out)
    assert code == 0 and 200 < r["speed_m_per_s"] < 250 and min(r["snr"].values()) > 100
    assert set(r["reasons"]) <= {"pulses"} or not r["reasons"]
    code, out = _run(capsys, ["analyze", archive, "--material", "steel316"])  # the wrong material: 0.39 x Eq (1)
    assert code == 1 and "x the Eq (1) speed of steel316" in out.out
