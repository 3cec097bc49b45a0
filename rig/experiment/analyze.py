"""`rig analyze`: the measurement pipeline on scope files and archives.

Virtual shots in an archive carry what the analysis needs (gauge channels and nominal
positions, sensitivities, RC time constants, beta and F_0 from their numerics). Real files
need it from the command line: --gauge-distance, and optionally --sensitivity, --tau,
--beta, --f0, --diameter; --material adds the long-wave Eq (1) speed beside each result.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

from instruments.analysis import PeakRules
from instruments.archive import Archive
from instruments.formats import read_record
from instruments.pipeline import GaugeSetup, Setup, analyze_record
from instruments.records import ScopeRecord
from rig.errors import RigError
from rig.model.materials import material
from rig.theory.longwave import solitary_wave_speed, sonic_vacuum_speed

THEORY_FACTOR = 2.0  # a measured speed within 1/2 to 2 x Eq (1) at its amplitude is plausible


@dataclass(frozen=True)
class AnalyzeOptions:
    """What `rig analyze` is told. files: scope files and/or archives (.h5); shot: one shot
    of an archive (None: all). For real files: gauge_distance (m) between the two gauges,
    channels "UPPER,LOWER[,WALL]" (None: file order), wall (the third channel is the wall
    sensor), sensitivity (V/N), tau (s, the gauge RC to invert; None: none), beta
    (F_d / F_m,e), f0 (N, precompression), diameter (m), material (adds the Eq (1) speed)."""

    files: tuple
    shot: int | None = None
    gauge_distance: float | None = None
    channels: str | None = None
    wall: bool = False
    sensitivity: float = 1.0
    tau: float | None = None
    beta: float = 1.0
    f0: float = 0.0
    diameter: float = 4.76e-3
    material: str | None = None


def analyze_paths(options: AnalyzeOptions) -> list:
    """One result per archive shot and one for the scope files together (JSON-ready dicts)."""
    paths = [Path(p) for p in options.files]
    archives = [p for p in paths if p.suffix.lower() in (".h5", ".hdf5", ".nxs")]
    files = [p for p in paths if p not in archives]
    results = []
    for a in archives:
        archive = Archive(a)
        ids = [options.shot] if options.shot is not None else archive.ids()
        for i in ids:
            entry = archive.read(i, with_truth=False)
            setup = _setup_from_entry(entry, options) if entry.simulated else _setup_from_flags(options, entry.record)
            results.append(_result(f"{a}#{i}", entry.record, setup, options, entry))
    if files:
        record = read_record(files)
        results.append(_result(", ".join(map(str, files)), record, _setup_from_flags(options, record), options))
    return results


def _real_file_flags(options: AnalyzeOptions) -> list:
    """The flags given that describe a real set-up (a virtual shot carries its own)."""
    given = {"--gauge-distance": options.gauge_distance is not None, "--channels": options.channels is not None,
             "--wall": options.wall, "--sensitivity": options.sensitivity != 1.0, "--tau": options.tau is not None,
             "--beta": options.beta != 1.0, "--f0": options.f0 != 0.0, "--diameter": options.diameter != 4.76e-3}
    return [flag for flag, on in given.items() if on]


def _setup_from_entry(entry, options: AnalyzeOptions) -> Setup:
    flags = _real_file_flags(options)
    if flags:
        raise RigError(f"{', '.join(flags)}: for real scope files only; shot {entry.shot_id} is a virtual shot "
                       f"and carries its own gauge positions, sensitivities and beta")
    facts, settings = entry.facts, entry.settings
    if facts is None:
        raise RigError(f"shot {entry.shot_id}: a virtual shot without its facts (gauge positions) cannot be analysed")
    gauges = sorted(facts.gauges.items(), key=lambda kv: kv[1].position_m)
    roles = []
    for name, g in gauges[:2]:
        s = settings["gauges"][name]
        roles.append(GaugeSetup(g.channel, g.position_m, s.get("sensitivity", 0.05), s.get("tau", 1e-3)))
    wall = None
    if "wall_sensor" in settings:
        ws = settings["wall_sensor"]
        wall = GaugeSetup(ws["channel"], math.inf, ws.get("sensitivity", 0.05), ws.get("tau", 1e-3))
    truth = facts.analysis or {}
    return Setup(roles[0], roles[1], wall, settings["chain"]["diameter"], truth.get("beta") or 1.0,
                 truth.get("static_force_N") or 0.0, PeakRules())


def _setup_from_flags(options: AnalyzeOptions, record: ScopeRecord) -> Setup:
    if options.gauge_distance is None:
        raise RigError("--gauge-distance is required for real scope files (e.g. --gauge-distance '43.1 mm')")
    names = options.channels.split(",") if options.channels else list(record.waveforms)[:3 if options.wall else 2]
    if len(names) < 2:
        raise RigError(f"two gauge channels are needed; the files hold {', '.join(record.waveforms) or 'none'}")
    for n in names:
        if n not in record.waveforms:
            raise RigError(f"--channels: {n!r} is not in the files (channels: {', '.join(record.waveforms)})")
    g = lambda ch, x: GaugeSetup(ch, x, options.sensitivity, options.tau)  # noqa: E731
    wall = g(names[2], math.inf) if len(names) > 2 else None
    return Setup(g(names[0], 0.0), g(names[1], options.gauge_distance), wall, options.diameter,
                 options.beta, options.f0, PeakRules())


def _result(source, record, setup: Setup, options: AnalyzeOptions, entry=None) -> dict:
    """The pipeline's report as a JSON-ready dict, with the Eq (1) speed where the material
    is known. With a material, a speed above its bar speed sqrt(E/rho) is implausible (the
    pipeline refuses it), and so is one off Eq (1) at the measured amplitude by more than
    THEORY_FACTOR: V ~ F^(1/6), so even a tenfold error in the gauge sensitivity moves Eq
    (1) by only 1.5x."""
    mat = options.material or (entry.settings["chain"]["material"] if entry is not None and entry.simulated else None)
    m = material(mat) if mat else None
    if m is not None:
        setup = replace(setup, max_speed_m_per_s=math.sqrt(m.E / m.rho))
    rep = analyze_record(record, setup)
    out = {"source": source, "channels": [setup.upper.channel, setup.lower.channel], **rep.as_dict()}
    out.pop("leading", None)
    out["theory_speed_m_per_s"] = None
    if m is None:
        out["reasons"].setdefault("theory_speed_m_per_s", "no bead material given (--material)")
    elif not rep.amplitude_N or rep.amplitude_N <= 0:
        out["reasons"].setdefault("theory_speed_m_per_s", out["reasons"].get("amplitude_N", "no amplitude"))
    else:
        F0 = setup.static_force_N
        Fm = rep.amplitude_N + F0
        v = float(solitary_wave_speed(m.E, m.nu, m.rho, setup.bead_diameter_m, F0, Fm) if F0 > 0
                  else sonic_vacuum_speed(m.E, m.nu, m.rho, setup.bead_diameter_m, Fm))
        out["theory_speed_m_per_s"] = v
        ratio = rep.speed_m_per_s / v
        if not 1 / THEORY_FACTOR <= ratio <= THEORY_FACTOR:
            why = (f"implausible: {rep.speed_m_per_s:.4g} m/s is {ratio:.3g} x the Eq (1) speed of {mat} at the "
                   f"measured amplitude ({v:.4g} m/s; allowed 1/{THEORY_FACTOR:g} to {THEORY_FACTOR:g} x): check "
                   f"--gauge-distance, --material, --sensitivity")
            for key in ("speed_m_per_s", "speed_xcorr_m_per_s", "width_diameters"):
                out[key] = None
                out["reasons"][key] = why
    return out
