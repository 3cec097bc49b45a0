"""Served-scope benchmark (``rig bench serve``): what a lab script pays for the network.

A served scope (rig/lab/serve.py, raw socket and HiSLIP, in this process) and pyvisa with
pyvisa-py as the client, against ``Rig.fire`` of the same shot in process, in interleaved
rounds; CPU time of this process (server threads and client together), medians:

- arm to record ready: ``ACQuire:STATE ON`` then ``*OPC?`` answered, against one
  ``Rig.fire``: at the scene's settings (the solve reused, as a repeated shot reuses it) and
  with a new striker velocity per shot (each one solved);
- ``CURVe?`` of 10,000 points, 16-bit binary (an mso4's record);
- 100 acquire cycles (arm, wait, fetch CH1) against 100 shots in process;
- time to the first ``CURVe?`` answer (wall clock: what the client waits) after a new
  striker velocity, at records of 2,500 points (tds2000), 10,000, 1,000,000 and the longest
  the served scope's limits let through at the scene's span (5,000,000; 10,000,000 would
  hold about 3.4 GB, past the 2 GB limit, and is refused at HORizontal:RECOrdlength; mso4),
  each spanning the scene's own time (so the longer the record, the finer its samples and the solver's grid),
  against the same shot fired in process (``SceneShots.shot``); the longest once a round;
  and 10,000 points at 200 ns/div (0.2 ns a sample: the chain solved only until the record
  ends, rig/lab/shots.py).
"""
from __future__ import annotations

import statistics
import time

SCENE = "ptfe52_magnetic"
ROUNDS = 5
CYCLES = 100
CURVE_POINTS = 10_000
RECORDS = (("tds2000", 2_500, None), ("mso4", 10_000, None), ("mso4", 1_000_000, None), ("mso4", 5_000_000, None),
           ("mso4", 10_000, 2e-7))
"""(personality, points, s/div: None keeps the scene's span) of the time-to-first-CURVe? rows."""


def _client(rm, resource: str):
    inst = rm.open_resource(resource, timeout=120_000)
    if resource.endswith("SOCKET"):
        inst.read_termination = inst.write_termination = "\n"
    inst.write("*CLS;:HEADER OFF;:ACQUIRE:STOPAFTER SEQUENCE")
    return inst


def _arm(inst) -> None:
    inst.write("ACQUIRE:STATE ON")
    inst.query("*OPC?")


def _cpu(f) -> float:
    t0 = time.process_time()
    f()
    return time.process_time() - t0


def run(scene: str = SCENE, rounds: int = ROUNDS, cycles: int = CYCLES) -> dict:
    import numpy as np
    import pyvisa

    from rig.experiment.shot import Rig
    from rig.lab.serve import ScopeServer, ServeSettings

    server = ScopeServer(ServeSettings(scene=scene, port=0, hislip=0, personality="mso4", seed=1),
                         say=lambda line: None)
    rm = pyvisa.ResourceManager("@py")
    try:
        clients = {kind: _client(rm, next(r for r in server.resources if kind in r)) for kind in ("SOCKET", "hislip")}
        sock = clients["SOCKET"]
        sock.write(f"HORIZONTAL:RECORDLENGTH {CURVE_POINTS}")
        overrides = [o for o in sock.query("RIG:OVERRIDES?").strip().strip('"').split(",") if o]
        rig = Rig.from_scene(scene, overrides)
        rig.fire(seed=0)
        velocities = [f"{0.85 + 0.001 * k:.3f} m/s" for k in range(rounds)]
        rows: dict[str, list] = {f"arm to record ready ({kind})": [] for kind in clients} | {"new striker velocity": [],
                                                                             "CURVe? 10,000 points 16-bit": [],
                                                                             f"{cycles} acquire cycles": []}
        base: dict[str, list] = {"fire": [], "fire, new velocity": [], f"{cycles} fires": []}
        for k in range(rounds):
            for kind, inst in clients.items():
                rows[f"arm to record ready ({kind})"].append(_cpu(lambda inst=inst: _arm(inst)))
            base["fire"].append(_cpu(lambda k=k: rig.fire(seed=k)))
            sock.write(f"RIG:STRIKER:VELOCITY {velocities[k]}")
            rows["new striker velocity"].append(_cpu(lambda: _arm(sock)))
            fresh = [*overrides, f"striker.velocity={velocities[k]}"]
            base["fire, new velocity"].append(_cpu(lambda fresh=fresh, k=k: Rig.from_scene(scene, fresh).fire(seed=k)))
            sock.write("DATA:SOURCE CH1;:DATA:ENCDG SRIBINARY;:DATA:WIDTH 2;:DATA:START 1;"
                       f":DATA:STOP {CURVE_POINTS}")
            curve: list[np.ndarray] = []
            rows["CURVe? 10,000 points 16-bit"].append(_cpu(lambda curve=curve: curve.append(
                sock.query_binary_values("CURVE?", datatype="h", container=np.array))))
            if curve[0].size != CURVE_POINTS:
                raise RuntimeError(f"CURVe? gave {curve[0].size} points, not {CURVE_POINTS}")

            def cycle():
                for _ in range(cycles):
                    _arm(sock)
                    sock.query_binary_values("CURVE?", datatype="h", container=np.array)
            rows[f"{cycles} acquire cycles"].append(_cpu(cycle))
            base[f"{cycles} fires"].append(_cpu(lambda: [rig.fire(seed=j) for j in range(cycles)]))
        for inst in clients.values():
            inst.close()
    finally:
        rm.close()
        server.close()
    pairs = {f"arm to record ready ({kind})": "fire" for kind in clients} | {
        "new striker velocity": "fire, new velocity", "CURVe? 10,000 points 16-bit": None,
        f"{cycles} acquire cycles": f"{cycles} fires"}
    out = []
    for name, against in pairs.items():
        ms = statistics.median(rows[name]) * 1e3
        ref = statistics.median(base[against]) * 1e3 if against else None
        ratio = statistics.median(a / b for a, b in zip(rows[name], base[against])) if against else None
        out.append(dict(figure=name, served_ms=ms, in_process=against, in_process_ms=ref, ratio=ratio))
    return dict(scene=scene, rounds=rounds, personality="mso4", record_points=CURVE_POINTS, rows=out,
                first_curve=first_curve(scene, rounds),
                targets={"arm to record ready": "<= 1.5x Rig.fire", "CURVe? 10,000 points 16-bit": "<= 20 ms",
                         f"{cycles} acquire cycles": "<= 2x"})


def first_curve(scene: str = SCENE, rounds: int = ROUNDS) -> list:
    """Rows of the time to the first CURVe? answer per record length (module doc)."""
    import numpy as np
    import pyvisa

    from rig.lab.serve import ScopeServer, ServeSettings
    from rig.lab.shots import SceneShots

    rows = []
    rm = pyvisa.ResourceManager("@py")
    try:
        for personality in dict.fromkeys(r[0] for r in RECORDS):
            server = ScopeServer(ServeSettings(scene=scene, port=0, personality=personality, seed=1),
                                 say=lambda line: None)
            try:
                inst = _client(rm, server.resources[0])
                in_process = SceneShots(scene)
                for name, points, per_div in RECORDS:
                    if name != personality:
                        continue
                    if personality != "tds2000":  # the record spans the scene's time: HOR:SCA kept
                        inst.write(f"HORIZONTAL:RECORDLENGTH {points}")
                    if per_div is not None:
                        inst.write(f"HORIZONTAL:SCALE {per_div:.6E}")
                    inst.write(f"DATA:SOURCE CH1;:DATA:ENCDG RIBINARY;:DATA:WIDTH 1;:DATA:START 1;:DATA:STOP {points}")
                    served, fired = [], []
                    for k in range(1 if points > 1_000_000 else rounds):
                        inst.write(f"RIG:STRIKER:VELOCITY {0.80 + 0.01 * k + 1e-6 * points:.6f} m/s")
                        t0 = time.perf_counter()
                        _arm(inst)
                        codes = inst.query_binary_values("CURVE?", datatype="b", container=np.array)
                        served.append(time.perf_counter() - t0)
                        if codes.size != points:
                            raise RuntimeError(f"CURVe? gave {codes.size} points, not {points}")
                        last = server.shots.last
                        if last is None:
                            raise RuntimeError("the served shot was not kept")
                        overrides = {k: v for k, v in (o.split("=", 1) for o in last.overrides)}
                        t0 = time.perf_counter()
                        in_process.shot(overrides, last.seed)
                        fired.append(time.perf_counter() - t0)
                    rows.append(dict(personality=personality, points=points, rounds=len(served),
                                     s_per_div=float(inst.query("HORIZONTAL:SCALE?")),
                                     served_s=statistics.median(served), in_process_s=statistics.median(fired),
                                     ratio=statistics.median(a / b for a, b in zip(served, fired))))
                inst.close()
            finally:
                server.close()
    finally:
        rm.close()
    return rows


def table(r: dict) -> str:
    lines = [f"served scope ({r['personality']}, {r['record_points']} points) of {r['scene']} through pyvisa-py, "
             f"CPU medians of {r['rounds']} interleaved rounds",
             f"  {'figure':34s} {'served ms':>10s}  {'in process':22s} {'ms':>9s} {'ratio':>6s}"]
    for row in r["rows"]:
        ref = f"{row['in_process_ms']:9.2f} {row['ratio']:6.2f}" if row["in_process"] else f"{'':9s} {'':6s}"
        lines.append(f"  {row['figure']:34s} {row['served_ms']:10.2f}  {row['in_process'] or '':22s} {ref}")
    lines.append("  targets: " + "; ".join(f"{k} {v}" for k, v in r["targets"].items()))
    lines.append("time to the first CURVe? answer after a new striker velocity (wall-clock medians), the record "
                 "spanning the scene's time but at 200 ns/div")
    lines.append(f"  {'model':8s} {'points':>11s} {'s/div':>9s} {'rounds':>6s} {'served s':>9s} {'in process s':>13s} "
                 f"{'ratio':>6s}")
    for row in r["first_curve"]:
        lines.append(f"  {row['personality']:8s} {row['points']:11,d} {row['s_per_div']:9.3g} {row['rounds']:6d} "
                     f"{row['served_s']:9.3f} "
                     f"{row['in_process_s']:13.3f} {row['ratio']:6.2f}")
    return "\n".join(lines)
