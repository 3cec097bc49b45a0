"""Virtual shots and real files in the archive, through the rig's commands."""
import json
from pathlib import Path

import numpy as np
import pytest

from instruments.archive import Archive
from rig.cli import main
from rig.experiment.entry import shot_entry
from rig.experiment.shot import Rig


def test_virtual_shots_in_four_transactions_round_trip_bit_identical(tmp_path):
    """40 shots in four appends (was 1,000, then 200: each fired shot has a time base of its
    own, so nothing a part holds depends on more than a few shots per transaction; the
    ten-thousand-shot test in tests/instruments/test_archive_scale.py holds the scale): the
    first append writes the scene's shared group, the later ones link to it in another part;
    every id, draw, code and preamble back as fired."""
    rig = Rig.from_scene("ptfe52_magnetic")
    shots = [rig.fire(seed=s) for s in range(40)]
    archive = Archive(tmp_path / "mc.h5")
    ids = []
    for k in range(0, 40, 10):  # four transactions
        ids += archive.append([shot_entry(s) for s in shots[k:k + 10]])
    assert ids == list(range(1, 41))
    assert archive.verify() == {"shots": 40, "ok": 40, "bad": []}
    for i, s in zip(ids, shots):
        back = archive.read(i)
        assert back.seed == s.seed and back.simulated and back.scene == "ptfe52_magnetic"
        assert back.scene_text == s.scene_text and back.facts.draws == s.draws
        for ch, w in s.scope.waveforms.items():
            assert np.array_equal(back.record[ch].codes, w.codes)
            assert back.record[ch].preamble == w.preamble
    first = archive.read(1)
    assert np.array_equal(first.truth["upper_average_force"], shots[0].truth.gauges["upper"].average_force)


def test_rig_shot_out_then_ls_and_verify(tmp_path, capsys):
    path = str(tmp_path / "a.h5")
    assert main(["shot", "steel21_magnetic", "--seed", "4", "--out", path, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["archived"] == {"archive": path, "shot": 1}
    assert main(["shot", "ptfe52_gravity", "--seed", "5", "--out", path]) == 0
    capsys.readouterr()
    assert main(["ls", path, "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [(r["shot"], r["scene"], r["seed"]) for r in rows] == [(1, "steel21_magnetic", 4), (2, "ptfe52_gravity", 5)]
    assert main(["verify", path, "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == {"shots": 2, "ok": 2, "bad": []}



def test_verify_names_an_added_and_a_deleted_object(tmp_path, capsys):
    import h5py

    path = tmp_path / "a.h5"
    Archive(path).append([shot_entry(Rig.from_scene("steel21_gravity").fire(seed=s)) for s in (1, 2, 3)])
    with h5py.File(path, "a") as f:
        f.create_dataset("foo", data=1.0)  # once passed verify: the root's member list was not digested
        del f["shot_000002"]  # once passed too
        del f["shot_000003/data/CH2"]  # once named only through data/time@REFERENCE_LIST
    assert main(["verify", str(path)]) == 1
    out = capsys.readouterr().out.splitlines()
    # layout 3 attaches no dimension scales: no reference list that the deletion changes
    assert out[0] == f"{path}: 3 shots, 1 ok, 2 bad (3 problems)", out
    assert out[1:] == ["  archive: added: /foo", "  shot 2: missing: /shot_000002",
                       "  shot 3: missing: /shot_000003/data/CH2"], out

def test_real_files_import_into_the_same_layout(tmp_path, capsys, realdata):
    path = str(tmp_path / "real.h5")
    files = [str(realdata / "tek_16bit_dpo.isf"), str(realdata / "tek_8bit_two_records.isf")]
    assert main(["import", *files, "--into", path]) == 0
    a = Archive(path)
    dpo, eight = a.read(1), a.read(2)
    assert not dpo.simulated and dpo.seed is None
    v = dpo.record["CH2"].volts()
    assert (v.min(), v.max()) == (pytest.approx(-7.3), pytest.approx(17.1))
    assert set(eight.record.waveforms) == {"CH1", "CH1#2"}  # the second record is kept
    v1 = eight.record["CH1"].volts()
    assert (v1.min(), v1.max(), v1[0]) == (pytest.approx(0.3), pytest.approx(4.9), pytest.approx(0.9))


@pytest.mark.parametrize("make", ["truncated", "junk", "missing"])
def test_bad_archives_are_one_line_errors(tmp_path, capsys, make):
    path = tmp_path / "bad.h5"
    if make != "missing":
        Archive(path).append([shot_entry(Rig.from_scene("steel21_gravity").fire(seed=1))])
        data = path.read_bytes()
        path.write_bytes(data[: len(data) // 3] if make == "truncated" else b"hello")
    assert main(["ls", str(path)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "Traceback" not in err
    # a damaged file is a finding of verify (exit 1), naming the file once; a path with no
    # file is a mistake (exit 2)
    assert main(["verify", str(path)]) == (2 if make == "missing" else 1)
    out = capsys.readouterr().out
    why = "cannot be opened as HDF5" if make == "truncated" else "not an HDF5 file"
    assert make == "missing" or out.splitlines()[1].startswith(f"  archive: {path}: {why}")
    assert out.count(str(path)) == (0 if make == "missing" else 2)  # the summary line and the bad row


def test_every_readable_real_csv_imports_and_reads_back_exactly(tmp_path, capsys, realdata):
    # CSV files hold volts, not codes: the archive keeps the volts (float64) and reads them
    # back equal, and verify checks their SHA-256 like codes
    from instruments.errors import InstrumentError
    from instruments.formats import read_record

    imported = 0
    for path in sorted(p for p in realdata.iterdir() if p.suffix.lower() == ".csv"):
        try:
            record = read_record([path])
        except InstrumentError:
            continue  # another maker's layout: refused in one line (tested elsewhere)
        archive = tmp_path / f"{path.stem}.h5"
        assert main(["import", str(path), "--into", str(archive)]) == 0
        assert main(["verify", str(archive)]) == 0
        back = Archive(archive).read(1).record
        for ch, w in record.waveforms.items():
            assert np.array_equal(back[ch].volts(), w.volts()) and np.array_equal(back[ch].time(), w.time())
        imported += 1
    capsys.readouterr()
    assert imported >= 3


def test_importing_the_same_raw_data_again_warns(tmp_path, capsys, realdata):
    archive, isf = str(tmp_path / "a.h5"), str(realdata / "tek_16bit_dpo.isf")
    assert main(["import", isf, "--into", archive, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["duplicates"] == []
    assert main(["import", isf, "--into", archive, "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["duplicates"] == [{"files": [isf], "same_as": 1}]
    assert "the same raw data as shot 1" in captured.err


def test_every_readable_real_file_imports_and_reads_back_exactly(tmp_path, capsys, realdata):
    # every format (ISF, CSV, WFM): channel names, point format (envelopes stay envelopes),
    # volts and times as read from the file
    from instruments.errors import InstrumentError
    from instruments.formats import read_record

    imported = 0
    for path in sorted(p for p in realdata.iterdir() if not p.name.endswith((".source.txt", ".md"))):
        try:
            record = read_record([path])
        except InstrumentError:
            continue  # another maker's format: refused in one line (tests/instruments/test_realdata.py)
        archive = tmp_path / f"{path.name}.h5"
        assert main(["import", str(path), "--into", str(archive)]) == 0, path.name
        assert main(["verify", str(archive)]) == 0, path.name
        back = Archive(archive).read(1).record
        assert list(back.waveforms) == sorted(record.waveforms)
        for ch, w in record.waveforms.items():
            assert back[ch].preamble.point_format == w.preamble.point_format
            assert np.array_equal(back[ch].volts(), w.volts()) and np.array_equal(back[ch].time(), w.time())
        imported += 1
    capsys.readouterr()
    assert imported >= 6


def _flip(path, offset):
    with open(path, "r+b") as fh:
        fh.seek(offset)
        b = fh.read(1)
        fh.seek(offset)
        fh.write(bytes([b[0] ^ 0x5A]))


def test_verify_names_the_shot_and_the_dataset_of_a_flip(tmp_path, capsys):
    import h5py

    rig = Rig.from_scene("steel21_gravity")
    path = tmp_path / "f.h5"
    Archive(path).append([shot_entry(rig.fire(seed=s)) for s in (1, 2)])
    with h5py.File(path, "r") as f:  # layout 3: the chunks lie in the part file the links lead to
        time = f["shot_000002/data/time"]
        time_chunk, part = time.id.get_chunk_info(0).byte_offset, time.file.filename
        shared = f["shot_000001/truth/forces/upper_average_force"]
        forces_chunk, forces_name = shared.id.get_chunk_info(0).byte_offset, shared.name
        key = next(k for k in f["shared"] if f["shared"][k]["forces"] == f["shot_000001/truth/forces"])
        del time, shared  # an object of a part file keeps that file open (and its chunks cached) after the master
    part = Path(part)  # the file flipped; verify is given the archive (its master)
    pristine = part.read_bytes()
    _flip(part, time_chunk + 40)  # the time axis: once unprotected, now fletcher32 and SHA-256
    assert main(["verify", str(path)]) == 1
    out = capsys.readouterr().out
    assert "2 shots, 1 ok, 1 bad" in out and "shot 2: /shot_000002/data/time:" in out
    part.write_bytes(pristine)
    _flip(part, forces_chunk + 40)  # the shared truth: named once, with the shots that use it
    assert main(["verify", str(path), "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["ok"] == 0 and len(report["bad"]) == 1, report
    assert report["bad"][0]["where"] == f"/shared/{key}/forces/upper_average_force"
    assert report["bad"][0]["shots"] == [1, 2] and forces_name.endswith("upper_average_force")
    # the text counts the shots the problem touches (2 bad, 1 problem) and names the
    # dataset once per row
    assert main(["verify", str(path)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"{path}: 2 shots, 0 ok, 2 bad (1 problem)"
    assert out[1].startswith(f"  shots 1, 2: /shared/{key}/forces/upper_average_force: damaged (")
    assert out[1].endswith("(shared by shots 1, 2)") and out[1].count("upper_average_force") == 1


def test_a_full_disk_is_one_line_and_loses_nothing(tmp_path, capsys, monkeypatch):
    import errno
    import shutil

    import instruments.archive as archive

    path = tmp_path / "a.h5"
    assert main(["shot", "steel21_gravity", "--seed", "1", "--out", str(path)]) == 0
    before = path.read_bytes()

    def full(src, dst):
        shutil.copyfileobj(open(src, "rb"), open(dst, "wb"), length=1000)  # noqa: SIM115 - part of it
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(archive.shutil, "copyfile", lambda src, dst: full(src, dst))
    capsys.readouterr()
    assert main(["shot", "steel21_gravity", "--seed", "2", "--out", str(path)]) == 2
    err = capsys.readouterr().err
    assert err == f"rig shot: error: {path}: cannot append: No space left on device\n"
    assert path.read_bytes() == before and not list(tmp_path.glob(".a.h5.*.tmp"))


def test_import_refuses_a_foreign_or_old_archive_and_upgrade_converts(tmp_path, capsys, realdata):
    import shutil

    import h5py

    isf = str(realdata / "tek_16bit_dpo.isf")
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = [1, 2, 3]
    assert main(["import", isf, "--into", str(foreign)]) == 2
    assert "not a rig archive" in capsys.readouterr().err
    assert main(["verify", str(foreign)]) == 1
    assert "not a rig archive" in capsys.readouterr().out
    old = tmp_path / "old.h5"
    shutil.copyfile(Path(__file__).parents[1] / "instruments" / "data" / "layout1.h5", old)
    for argv in (["import", isf, "--into", str(old)], ["ls", str(old)], ["analyze", str(old)]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"run `rig upgrade {old}`" in err, err
    assert main(["upgrade", str(old)]) == 0
    assert "3 shots rewritten" in capsys.readouterr().out
    assert main(["import", isf, "--into", str(old), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["shots"] == [4]
    assert main(["ls", str(old), "--json"]) == 0
    row = json.loads(capsys.readouterr().out)[3]
    assert row["title"] == "tek_16bit_dpo.isf" and row["start_time_source"].startswith("file modification time")


def test_ls_lists_the_good_shots_beside_a_damaged_one(tmp_path, capsys):
    """A shot that cannot be read is a row saying so (exit 1, as verify's findings); the
    other shots are still listed."""
    import h5py

    path = tmp_path / "a.h5"
    rig = Rig.from_scene("steel21_gravity")
    Archive(path).append([shot_entry(rig.fire(seed=s)) for s in (1, 2, 3)])
    with h5py.File(path, "a") as f:
        f["shot_000002"].attrs["metadata"] = "{damaged"  # layout 4: the preambles are in the metadata
    assert main(["ls", str(path)]) == 1
    out = capsys.readouterr().out
    assert "    2  DAMAGED: unreadable (" in out and f"run `rig verify {path}`" in out
    assert main(["ls", str(path), "--json"]) == 1
    rows = json.loads(capsys.readouterr().out)
    assert [r["shot"] for r in rows] == [1, 2, 3] and "damaged" in rows[1]
    assert rows[0]["seed"] == 1 and rows[2]["seed"] == 3


def test_one_shot_of_files_that_hold_the_same_channel_is_refused(tmp_path, capsys, realdata):
    # --together makes the files the channels of one shot: two files that both hold the
    # same channel are named, and nothing is written
    f = str(realdata / "tek_16bit_dpo.isf")
    into = tmp_path / "a.h5"
    assert main(["import", f, f, "--together", "--into", str(into)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"rig import: error: --together: {f} and {f} both hold ") and err.count("\n") == 0
    assert "import these files as separate shots (without --together)" in err and not into.exists()


def test_a_sweep_point_that_gives_no_record_is_a_row_with_its_reason_and_the_sweep_goes_on(tmp_path, capsys):
    # the last two points are far outside the contact law: each is a row with the solver's
    # reason, the first point's shot is archived, and the sweep exits 0 (one point measured)
    out = tmp_path / "sw.h5"
    assert main(["sweep", "ptfe52_magnetic", "--vary", "striker.velocity=50:300:3", "--out", str(out),
                 "--quiet", "--json"]) == 0
    points = json.loads(capsys.readouterr().out)["points"]
    assert [p["value"] for p in points] == [50.0, 175.0, 300.0]
    assert points[0]["reason"] is None and points[0]["truth"] is not None
    for p in points[1:]:
        assert p["reason"].startswith("unstable at every step") and p["truth"] is None and p["measured"] is None
        assert p["overrides"][-1] == f"striker.velocity={p['value']!r} m/s" and isinstance(p["seed"], int)
    assert Archive(out).ids() == [1]


def test_a_sweep_where_no_point_gives_a_record_fails_with_one_line(tmp_path, capsys):
    out = tmp_path / "sw.h5"
    assert main(["sweep", "ptfe52_magnetic", "--vary", "striker.velocity=200:300:2", "--out", str(out),
                 "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rig sweep: error: no point of the sweep gave a record; point 1 of 2 "
                          "(striker.velocity = 200): unstable at every step") and "\n" not in err
    assert not out.exists()


def test_a_two_channel_tds_csv_imports_lists_and_analyses_both_channels(tmp_path, capsys, realdata):
    # TDS2000C/TBS1000B: CH1 and CH2 as two six-column blocks side by side in one file
    f, archive = str(realdata / "acruz_TDS2000C_2ch_ROD_PIEZO_1.csv"), str(tmp_path / "a.h5")
    assert main(["import", f, "--into", archive, "--json"]) == 0
    capsys.readouterr()
    assert main(["ls", archive, "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["channels"] == ["CH1", "CH2"]
    back = Archive(archive).read(1).record
    table = np.loadtxt(f, delimiter=",", usecols=(4, 10))
    assert np.array_equal(back["CH1"].volts(), table[:, 0]) and np.array_equal(back["CH2"].volts(), table[:, 1])
    main(["analyze", f, "--gauge-distance", "43.1 mm", "--json"])
    (result,) = json.loads(capsys.readouterr().out)
    # both channels analysed, not "the record holds CH1"; CH1 sits at 3.46 V, 6.9 divisions up at 0.5 V/div,
    # for its last 1121 samples without the one-code flicker of its baseline: the ADC's rail
    assert result["reasons"]["amplitude_V"].startswith("CH1: clipped: 1124 samples at the ADC's top")
    assert "CH2" not in result["reasons"]["amplitude_V"]
    assert not back["CH2"].overrange and back["CH1"].overrange


def test_import_together_refuses_files_of_different_time_bases(tmp_path, capsys, realdata):
    a, b = str(realdata / "pchem_TDS2001C_F0000CH1.CSV"), str(realdata / "accel_TEK00000.CSV")
    b_copy = tmp_path / "accel_CH2.csv"  # its channel renamed, so that only the time bases differ
    b_copy.write_text(Path(b).read_text().replace("TIME,CH1", "TIME,CH2"))
    assert main(["import", "--together", a, str(b_copy), "--into", str(tmp_path / "a.h5")]) == 2
    (err,) = capsys.readouterr().err.strip().splitlines()
    assert a in err and str(b_copy) in err and "different time bases" in err
    assert "2500 points at 1e-09 s" in err and "2000 points at 0.0008 s" in err
    assert not (tmp_path / "a.h5").exists()


def test_a_wfm_whose_name_has_a_hyphen_and_a_space_imports(tmp_path, capsys, realdata):
    f = tmp_path / "Tek000-ch1 copy.wfm"
    f.write_bytes((realdata / "tekpce_sample_1.wfm").read_bytes())
    assert main(["import", str(f), "--into", str(tmp_path / "a.h5"), "--json"]) == 0
    capsys.readouterr()
    assert main(["ls", str(tmp_path / "a.h5"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)[0]["channels"] == ["Tek000_ch1_copy"]
