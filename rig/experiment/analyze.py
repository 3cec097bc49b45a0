"""`rig analyze`: the measurement pipeline on scope files and archives.

Virtual shots in an archive carry what the analysis needs (gauge channels and nominal
positions, sensitivities, RC time constants, beta and F_0 from their numerics). Real files
need it from the command line: --gauge-distance, and optionally --sensitivity, --tau,
--beta, --f0, --diameter; --material adds the long-wave Eq (1) speed beside each result.
--f0 and --material work in newtons: they need --sensitivity (check_force_flags).

Plausibility: the speed must be below the bar speed sqrt(E / rho) of the bead material
(with --material; else of the fastest material in the table), and, with a material known
(--material or the virtual shot's scene), within a factor THEORY_FACTOR of Eq (1) at the
measured amplitude; otherwise it is None and its reason quotes it. Every None figure has
its reason in "reasons" (figure -> why), and "snr" gives each gauge channel's SNR.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from pathlib import Path

from instruments.analysis import GaugeSetup, PeakRules, Setup, analyze_record
from instruments.analysis.plausibility import Limits
from instruments.analysis.report import SPEED_FIGURES, Report
from instruments.archive import Archive, Entry
from instruments.errors import InstrumentError
from instruments.formats import read_record
from instruments.formats.checks import vertical_unit
from instruments.records import ScopeRecord
from rig.errors import RigError, invalid, lookup
from rig.model.materials import MATERIALS, Material, material
from rig.theory.longwave import solitary_wave_speed, sonic_vacuum_speed


@dataclass(frozen=True)
class AnalyzeOptions:
    """What `rig analyze` is told. files: scope files and/or archives (.h5); shot: one shot
    of an archive (None: all). For real files: gauge_distance (m) between the two gauges,
    channels "UPPER,LOWER[,WALL]" (None: file order), wall (the third channel is the wall
    sensor), sensitivity (V/N; None: 1 V/N, the forces are the gauges' volts), tau (s, the
    gauge RC to invert; None: none), beta (F_d / F_m,e), f0 (N, precompression), diameter
    (m), material (adds the Eq (1) speed). A virtual shot carries its own set-up: these
    flags are refused where only virtual shots are analysed, and apply to the real ones
    where both are."""

    files: tuple
    shot: int | None = None
    gauge_distance: float | None = None
    channels: str | None = None
    wall: bool = False
    sensitivity: float | None = None
    tau: float | None = None
    beta: float = 1.0
    f0: float = 0.0
    diameter: float = 4.76e-3
    material: str | None = None

    def __post_init__(self):
        if self.shot is not None and (isinstance(self.shot, bool) or not isinstance(self.shot, int) or self.shot < 0):
            raise invalid("--shot", self.shot, "a shot number is a whole number >= 0")
        for flag, value, zero_ok, unit in (("--gauge-distance", self.gauge_distance, False, "m"),
                                           ("--sensitivity", self.sensitivity, False, "V/N"),
                                           ("--tau", self.tau, False, "s"), ("--beta", self.beta, False, ""),
                                           ("--f0", self.f0, True, "N"), ("--diameter", self.diameter, False, "m")):
            if value is not None and not (math.isfinite(value) and (value >= 0 if zero_ok else value > 0)):
                raise invalid(flag, value,
                              f"a finite number {'>= 0' if zero_ok else '> 0'}{' ' + unit if unit else ''}")
        if self.material is not None:
            lookup(MATERIALS, self.material, "--material", Material)  # an unknown name: one line naming the known


THEORY_FACTOR = 2.0  # measured / Eq (1) beyond this (or below its inverse): not a solitary wave
# (published speeds agree with Eq (1) to about 10%; an amplitude off by 30% moves Eq (1) by 5%;
# a factor 2 in speed is a factor 64 in force)


def analyze_paths(options: AnalyzeOptions) -> list:
    """One result per archive shot and one for the scope files together (JSON-ready dicts)."""
    paths = [Path(p) for p in options.files]
    archives = [p for p in paths if p.suffix.lower() in (".h5", ".hdf5", ".nxs")]
    files = [p for p in paths if p not in archives]
    if options.shot is not None and not archives:
        raise invalid("--shot", options.shot, "picks a shot of an archive (.h5); scope files are one shot together")
    shots: list[tuple[str, Entry | None]] = []
    unread = {}
    for a in archives:
        archive = Archive(a)
        ids = [options.shot] if options.shot is not None else archive.ids()
        for i in ids:
            try:
                shots.append((f"{a}#{i}", archive.read(i, with_truth=False)))
            except InstrumentError as exc:  # a damaged shot of several: a row with its reason, the others go on
                if options.shot is not None:
                    raise
                shots.append((f"{a}#{i}", None))
                unread[f"{a}#{i}"] = str(exc).removeprefix(f"{a}: ")
    real = bool(files) or not all(entry.simulated for _, entry in shots if entry is not None)
    if real:
        check_force_flags(options)
    results = []
    for source, entry in shots:
        if entry is None:
            results.append(_refused(source, unread[source]))
            continue
        try:
            setup = (_setup_from_entry(entry, options, real) if entry.simulated
                     else _setup_from_flags(options, entry.record))
            results.append(_result(source, entry.record, setup, options, entry))
        except (RigError, InstrumentError) as exc:
            if len(shots) + bool(files) == 1 or (entry.simulated and not real):
                raise
            results.append(_refused(source, f"shot {entry.shot_id}: {exc}", entry.simulated))
    if files:
        record = read_record(files)
        results.append(_result(", ".join(map(str, files)), record, _setup_from_flags(options, record), options))
    return results


REAL_FILE_FLAGS = ("gauge_distance", "channels", "wall", "sensitivity", "tau", "beta", "f0", "diameter", "material")


def check_force_flags(options: AnalyzeOptions):
    """Refuse the flags that work in newtons (--f0 is added to the measured force, --material
    puts the measured amplitude into Eq (1) and judges the speed by it) where a real record's
    forces are its gauges' volts (no --sensitivity): volts taken as newtons."""
    if options.sensitivity is not None:
        return
    given = [flag for flag, on in (("--f0", options.f0 > 0), ("--material", options.material is not None)) if on]
    if given:
        raise RigError(f"{' and '.join(given)} without --sensitivity: {'they need' if len(given) > 1 else 'it needs'} "
                       f"the real record's forces in newtons, and without --sensitivity they are its gauges' volts; "
                       f"give the gauges' --sensitivity, e.g. '0.05 V/N'")


def real_file_flags(options: AnalyzeOptions) -> list:
    """The flags given (other than their defaults) that describe a real set-up: a virtual
    shot carries its own."""
    defaults = {f.name: f.default for f in fields(AnalyzeOptions)}
    return [f"--{name.replace('_', '-')}" for name in REAL_FILE_FLAGS if getattr(options, name) != defaults[name]]


def _setup_from_entry(entry, options: AnalyzeOptions, real: bool) -> Setup:
    """A virtual shot's own set-up; ``real``: real records are analysed beside it, for which
    the real-file flags are given."""
    flags = real_file_flags(options)
    if flags and not real:
        raise RigError(f"{', '.join(flags)}: for real scope files only; shot {entry.shot_id} is a virtual shot "
                       f"and carries its own gauge positions, sensitivities, beta and bead material")
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
    calibration = facts.analysis or {}  # the truth's analysis, or a study's calibration (ShotFacts)
    return Setup(roles[0], roles[1], wall, settings["chain"]["diameter"], calibration.get("beta") or 1.0,
                 calibration.get("static_force_N") or 0.0, PeakRules())


def _setup_from_flags(options: AnalyzeOptions, record: ScopeRecord) -> Setup:
    if options.gauge_distance is None:
        raise RigError("--gauge-distance is required for real scope files (e.g. --gauge-distance '43.1 mm')")
    held = ", ".join(record.waveforms) or "none"
    names = [n.strip() for n in options.channels.split(",")] if options.channels else \
        list(record.waveforms)[:3 if options.wall else 2]
    if options.channels and not 2 <= len(names) <= 3:
        raise invalid("--channels", options.channels, f"UPPER,LOWER[,WALL]: two or three of {held}")
    if len(names) < 2:
        raise RigError(f"two gauge channels are needed; the record holds {held}")
    if options.wall and not options.channels and len(names) < 3:
        raise RigError(f"--wall reads the third channel as the wall sensor; the record holds {held}")
    if options.wall and options.channels and len(names) < 3:
        raise invalid("--channels", options.channels, "with --wall, name the wall sensor's channel third: "
                                                      "UPPER,LOWER,WALL")
    for n in names:
        if n not in record.waveforms:
            raise invalid("--channels", options.channels, f"{n!r} is not in the files (channels: {held})")
        unit = record.waveforms[n].preamble.y_unit
        if vertical_unit(unit) != "V":  # an archive imported before the readers named volts V holds "Volts"
            source = record.waveforms[n].preamble.extra.get("source", "the record")
            raise RigError(f"{source}: channel {n} is in {unit} (its vertical unit), not V: the analysis reads the "
                           f"gauges' voltages (a current probe's or a math channel's record is no gauge's)")
    if len(set(names)) < len(names):
        raise invalid("--channels", options.channels, "a channel named twice (each gauge has its own channel)")
    volts_per_newton = 1.0 if options.sensitivity is None else options.sensitivity
    def g(ch, x):
        return GaugeSetup(ch, x, volts_per_newton, options.tau)
    wall = g(names[2], math.inf) if len(names) > 2 else None
    return Setup(g(names[0], 0.0), g(names[1], options.gauge_distance), wall, options.diameter,
                 options.beta, options.f0, PeakRules(), force_unit="V" if options.sensitivity is None else "N")


def _refused(source: str, why: str, simulated: bool | None = None) -> dict:
    """The result row of an archive shot that cannot be analysed (damaged, or a set-up that
    does not fit its record), beside the shots that can: every figure None, with ``why``."""
    out = {"source": source, "channels": [], **Report().refuse(why).as_dict()}
    out.pop("leading", None)
    out.update(simulated=simulated, force_unit=None, theory_speed_m_per_s=None, unread_channels=[])
    out["reasons"]["theory_speed_m_per_s"] = why
    return out


IN_VOLTS = {"amplitude_N": "amplitude_V", "averaged_amplitude_N": "averaged_amplitude_V",
            "total_force_N": "total_force_V"}
"""The force figures of a real record analysed without --sensitivity, which the gauges'
volts give: each under a key that names its unit (a key's unit is in its name)."""


def _in_volts(out: dict) -> dict:
    """``out`` with its force figures, and their reasons, under the _V keys of IN_VOLTS,
    and no static_force_N (F_0 in N: --f0 needs --sensitivity, so there is none to add)."""
    out = {IN_VOLTS.get(k, k): v for k, v in out.items() if k != "static_force_N"}
    out["reasons"] = {IN_VOLTS.get(k, k): v for k, v in out["reasons"].items()}
    return out


def _limits(name: str | None) -> Limits:
    """The speed bound: the bar speed sqrt(E / rho) of the bead material, or of the
    fastest material in the table when it is not known."""
    mats = [material(name)] if name else list(MATERIALS.values())
    return Limits(max_speed_m_per_s=max(math.sqrt(m.E / m.rho) for m in mats))


def _result(source, record, setup: Setup, options: AnalyzeOptions, entry=None) -> dict:
    """One source's row: the figures, their reasons and the theory beside them; a real
    record's forces without --sensitivity under _V keys (IN_VOLTS)."""
    out = _figures(source, record, setup, options, entry)
    return _in_volts(out) if setup.force_unit == "V" else out


def _figures(source, record, setup: Setup, options: AnalyzeOptions, entry=None) -> dict:
    virtual = entry is not None and entry.simulated
    mat = entry.settings["chain"]["material"] if virtual else options.material
    setup = replace(setup, limits=_limits(mat))
    rep = analyze_record(record, setup)
    if virtual and not (entry.facts.analysis or {}).get("beta"):
        rep.refuse("this virtual shot was stored without its calibration (beta, F_0): only F_m,e is measured",
                   ("amplitude_N", "total_force_N"))
    out = {"source": source, "channels": [setup.upper.channel, setup.lower.channel], **rep.as_dict()}
    out.pop("leading", None)
    out["simulated"] = virtual
    out["force_unit"] = setup.force_unit  # of the forces and the noise
    read = {setup.upper.channel, setup.lower.channel} | ({setup.wall.channel} if setup.wall else set())
    out["unread_channels"] = [] if virtual else [ch for ch in record.waveforms if ch not in read]
    out["theory_speed_m_per_s"] = None
    if not mat:
        out["reasons"]["theory_speed_m_per_s"] = "no bead material given (--material)"
        return out
    if rep.amplitude_N is None or rep.amplitude_N + setup.static_force_N <= 0:
        out["reasons"]["theory_speed_m_per_s"] = "no amplitude measured"
        return out
    m = material(mat)
    F0, Fm = setup.static_force_N, rep.amplitude_N + setup.static_force_N
    theory = float(solitary_wave_speed(m.E, m.nu, m.rho, setup.bead_diameter_m, F0, Fm) if F0 > 0
                   else sonic_vacuum_speed(m.E, m.nu, m.rho, setup.bead_diameter_m, Fm))
    out["theory_speed_m_per_s"] = theory
    v = out["speed_m_per_s"]
    if v is not None and not 1 / THEORY_FACTOR <= v / theory <= THEORY_FACTOR:
        check = "is the leading pulse the one found?" if virtual else "are --material, --sensitivity, --f0 right?"
        why = (f"implausible speed: {v:.4g} m/s is off Eq (1)'s {theory:.4g} m/s for {m.name} at the measured "
               f"amplitude by more than a factor {THEORY_FACTOR:g} ({check})")
        for k in SPEED_FIGURES:
            out[k] = None
            out["reasons"].setdefault(k, why)
    return out
