"""``rig serve scope`` with --fire on-command, the RIG: commands on a port of their own,
--out and --log: an armed scope waits for RIG:FIRE, a setting made on the rig port is the
next shot's, and every served shot (the warm-up shot first) is archived with its seed and settings and logged."""
import json
import time

import pytest

from lab.served import Served, open_scope
from lab.test_serve import SCENE
from rig.cli import main

pyvisa = pytest.importorskip("pyvisa")

SEED = 40


def test_on_command_the_rig_port_fires_and_every_shot_is_archived_and_logged(rm, tmp_path, capsys):
    archive, log = tmp_path / "served.h5", tmp_path / "served.log"
    s = Served(SCENE, "--port", "0", "--rig-port", "0", "--fire", "on-command", "--seed", str(SEED),
               "--out", str(archive), "--log", str(log))
    try:
        scope_port, rig_port = s.resources[0], s.resource("RIG: commands").split(" ")[0]
        scope, bench = open_scope(rm, scope_port), open_scope(rm, rig_port)
        try:
            bench.write("RIG:STRIKER:VELOCITY 0.92 m/s")
            assert bench.query("RIG:STRIKER:VELOCITY?").strip() == '"0.92 m/s"'
            scope.write("ACQUIRE:STOPAFTER SEQUENCE;:ACQUIRE:STATE ON")
            armed = time.monotonic()
            bench.timeout = 1000
            with pytest.raises(pyvisa.errors.VisaIOError):  # the rig's port answers no scope command
                bench.query("CURVE?")
            # a reply to CURVE? however late would come before this one (one message at a time)
            assert bench.query("ALLEV?").startswith('113,"Undefined header')  # Tek's unsigned code
            assert time.monotonic() - armed >= 1.0  # the query's timeout: the armed scope has waited
            assert scope.query("ACQUIRE:STATE?").strip() == "1"  # armed, waiting for the command
            assert scope.query("ACQUIRE:NUMACQ?").strip() == "1"  # the warm-up shot only
            bench.write("RIG:FIRE")
            assert scope.query("*OPC?").strip() == "1"
            assert scope.query("ACQUIRE:NUMACQ?").strip() == "2"
        finally:
            scope.close()
            bench.close()
    finally:
        code, rest = s.stop()
    assert code == 0, rest
    capsys.readouterr()
    assert main(["ls", str(archive), "--json"]) == 0  # the archive the served process wrote, read here
    rows = json.loads(capsys.readouterr().out)
    assert [r["seed"] for r in rows] == [SEED, SEED + 1]  # the warm-up shot, at the scene's settings, then ours
    assert all(r["simulated"] and r["scene"] == SCENE for r in rows)
    assert rows[0]["settings"]["velocity"] == pytest.approx(0.89)
    assert rows[1]["settings"]["velocity"] == pytest.approx(0.92)
    text = log.read_text()
    assert "raw socket on 127.0.0.1" in text and f"shot: seed {SEED + 1}" in text
    assert "striker.velocity=0.92 m/s" in text
