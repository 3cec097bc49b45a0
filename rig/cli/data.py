"""`rig verify`, `rig upgrade`, `rig import`, `rig analyze` and `rig ls`."""
from __future__ import annotations

from rig.cli.common import command, missing_lines, plain, quantity_type
from rig.errors import RigError


def cmd_verify(args) -> dict:
    """Every shot's checksums; a bad row names the shot (or the shots of a shared group) and
    the dataset or attribute, or the path of an object added or deleted. Exit 1 if any is bad."""
    from pathlib import Path

    from instruments.archive import Archive

    path = Path(args.archive)  # a path that holds no file is a mistake (exit 2), a damaged file a finding (1)
    if not path.exists():
        raise RigError(f"{path}: no such archive")
    if path.is_dir():
        raise RigError(f"{path}: a folder, not an archive file")
    report = Archive(path).verify()
    if not args.json:
        n = len(report["bad"])
        print(f"{args.archive}: {report['shots']} shots, {report['ok']} ok, {report['shots'] - report['ok']} bad "
              f"({n} problem{'' if n == 1 else 's'})")
        for b in report["bad"]:
            who = f"shot {b['shot']}" if b["shot"] is not None else \
                f"shots {', '.join(map(str, b['shots']))}" if b["shots"] else "archive"
            parts = 3 if b["where"].startswith("/shared/") else 2 if b["where"].startswith("/shot_") else 1
            item = b["where"].split("/", parts)[-1]  # the dataset or attribute within its group
            what = b["reason"]
            if what.startswith(("added: ", "missing: ")):  # the reason names the path
                print(f"  {who}: {what}")
                continue
            for head in (f"{item}: ", f"attribute {item}: "):
                what = what.removeprefix(head)  # the path names it already
            print(f"  {who}: {b['where']}: {what}")
    args.exit_code = 1 if report["bad"] else 0
    return report


def cmd_upgrade(args) -> dict:
    """Rewrite an archive of an older layout (1 or 2) in the current one, layout 3 (one
    transaction); "members_recorded": the root's member lists are recorded now and were not."""
    from instruments.archive import Archive

    archive = Archive(args.archive)
    listed = archive.lists_members()
    n = archive.upgrade()
    members = n > 0 and not listed
    if not args.json:
        print(f"{args.archive}: {n} shots rewritten in the current layout" if n else
              f"{args.archive}: already in the current layout")
    return {"archive": args.archive, "upgraded": n, "members_recorded": members}


def cmd_import(args) -> dict:
    """Real scope files into an archive, in the same layout as virtual shots (simulated = false).
    A file whose raw data (SHA-256) an archived shot already holds is imported with a warning;
    an archive that is not a rig archive (or of an older layout) is refused in one line."""
    import sys
    from datetime import datetime, timezone
    from pathlib import Path

    from instruments.archive import Archive, Entry, raw_digest
    from instruments.formats import check_one_time_base, read_record, read_waveforms

    if args.together and len(args.files) < 2:
        raise RigError(f"--together: the channels of one shot in two or more files; {args.files[0]} is one")
    groups = [args.files] if args.together else [[f] for f in args.files]
    entries = []
    for files in groups:
        # scope files hold no acquisition time: the start time is the oldest file's
        # modification time, stored as what it is
        mtime = datetime.fromtimestamp(min(Path(f).stat().st_mtime for f in files), timezone.utc).isoformat()
        record = read_record(files)
        if any("@" in ch for ch in record.waveforms):  # a channel name met in two files: name them
            seen: dict[str, str] = {}
            for f in files:
                for w in read_waveforms(f):
                    if w.channel in seen:
                        raise RigError(f"--together: {seen[w.channel]} and {f} both hold {w.channel}: the channels "
                                       f"of one shot have different names; import these files as separate shots "
                                       f"(without --together)")
                    seen[w.channel] = f
        if args.together:
            check_one_time_base(record)  # the analysis of one shot needs one time base: refuse now, not then
        if not args.keep_paths:
            record = _names_only(record)
        entries.append(Entry(record, False, scene="",
                             settings={"source_files": [str(Path(f).resolve().name) for f in files]},
                             start_time=mtime, file_modification_time=mtime,
                             start_time_source="file modification time (the file holds no acquisition time)"))
    archive = Archive(args.into)
    stored: dict[str, int] = {}  # raw-data digest -> the first shot that holds it
    for i, d in sorted(archive.digests().items() if Path(args.into).exists() else []):
        stored.setdefault(d, i)
    duplicates, this_import = [], set()
    for files, e in zip(groups, entries):
        digest = raw_digest(e.record)
        if digest in stored or digest in this_import:
            same = stored.get(digest)
            duplicates.append({"files": [str(f) for f in files], "same_as": same})
            print(f"rig import: warning: {', '.join(map(str, files))}: the same raw data as "
                  f"{f'shot {same}' if same else 'another file of this import'} (imported again)", file=sys.stderr)
        this_import.add(digest)
    ids = archive.append(entries)
    out = {"archive": args.into, "shots": ids, "duplicates": duplicates}
    if not args.json:
        print(f"imported {len(args.files)} file(s) into {args.into} as shot(s) {', '.join(map(str, ids))}")
    return out


def _names_only(record):
    """``record`` with each channel's source file named by its name alone (the readers keep
    the path they were given, which an archive would carry to every machine it goes to)."""
    from dataclasses import replace
    from pathlib import Path

    def named(w):
        extra = w.preamble.extra
        if "source" not in extra:
            return w
        return replace(w, preamble=replace(w.preamble, extra={**extra, "source": Path(str(extra["source"])).name}))
    return replace(record, waveforms={ch: named(w) for ch, w in record.waveforms.items()})


def cmd_analyze(args) -> list:
    """The analysis table, each channel's SNR and, under each source, why any figure is
    missing. Exit 0 when at least one source gave a speed, 1 when none did (as `rig verify`
    with bad shots); a mistake in the flags or files is exit 2 (main)."""
    from pathlib import Path

    from rig.experiment.analyze import AnalyzeOptions, analyze_paths, real_file_flags

    options = AnalyzeOptions(files=tuple(args.files), shot=args.shot, gauge_distance=args.gauge_distance,
                             channels=args.channels, wall=args.wall, sensitivity=args.sensitivity, tau=args.tau,
                             beta=args.beta, f0=args.f0, diameter=args.diameter, material=args.material)
    results = analyze_paths(options)
    args.exit_code = 0 if any(r["speed_m_per_s"] is not None for r in results) else 1
    if not args.json:
        def fmt(v, spec=".2f"):
            return "-" if v is None else format(v, spec)
        if any(r["force_unit"] == "V" for r in results):
            print("note: without --sensitivity a real scope file's forces are its gauges' volts (1 V/N): its "
                  "F_d and F_m,e and noise are in V; give e.g. --sensitivity '0.05 V/N' for newtons")
        flags = real_file_flags(options)
        if flags and any(r["simulated"] for r in results):
            print(f"note: {', '.join(flags)} {'describe' if len(flags) > 1 else 'describes'} the real records; "
                  f"the virtual shots use their own set-up")
        wall_read = args.wall or (args.channels is not None and len(args.channels.split(",")) == 3)
        units = {r["force_unit"] for r in results} - {None}
        unit = units.pop() if len(units) == 1 else "N|V"  # mixed: each row's figures carry their unit

        def force(r, figure):
            """A force figure as the table prints it: with its row's unit where the rows mix N and V."""
            value = _force(r, figure)
            return fmt(value, ".3f") + (f" {r['force_unit']}" if unit == "N|V" and value is not None else "")
        print(f"{'source':40s} {'V_s m/s':>8s} {'xcorr':>8s} {'F_d ' + unit:>8s} {'F_m,e ' + unit:>8s} "
              f"{'pulses':>6s} {'FWHM us':>8s} {'Eq1 m/s':>8s}")
        for r in results:
            fwhm = None if r["duration_s"] is None else r["duration_s"] * 1e6
            src = ", ".join(Path(part).name for part in r["source"].split(", "))  # the files' names (JSON: paths)
            src = src if len(src) <= 40 else src[:37] + "..."
            print(f"{src:40s} {fmt(r['speed_m_per_s'], '.1f'):>8s} "
                  f"{fmt(r['speed_xcorr_m_per_s'], '.1f'):>8s} {force(r, 'amplitude'):>8s} "
                  f"{force(r, 'averaged_amplitude'):>8s} {fmt(r['pulses'], '.0f'):>6s} "
                  f"{fmt(fwhm, '.1f'):>8s} {fmt(r['theory_speed_m_per_s'], '.1f'):>8s}")
            if r["snr"]:
                noise = r["noise"]
                print("  SNR (leading pulse / pre-trigger noise): " + ", ".join(
                    f"{ch} {fmt(v, '.3g')}" + (f" (noise {noise[ch]:.3g} {r['force_unit']})" if ch in noise else "")
                    for ch, v in r["snr"].items()))
            if r["theory_speed_m_per_s"] is not None and not r["simulated"] and not args.f0:
                print("  Eq1: with F_0 = 0 (no --f0): the speed of a chain without precompression")
            if r.get("unread_channels"):
                hint = "" if args.channels else (f" (the gauges are {', '.join(r['channels'])}; --channels "
                                                 f"UPPER,LOWER[,WALL] names them, --wall reads a third channel as "
                                                 f"the wall sensor)")
                print(f"  not read: {', '.join(r['unread_channels'])}{hint}")
            if r["pulses"] is not None and not r["simulated"] and not wall_read:
                print("  pulses: counted to the record's end; without --wall (the wall sensor's channel) the wall's "
                      "reflection may be among them")
            for line in missing_lines(r["reasons"]):
                print(f"  {line}")
    return results


def _force(row: dict, figure: str):
    """A row's force figure in its own unit: FIGURE_N (newtons) or FIGURE_V (a real record's
    gauge volts without --sensitivity)."""
    return row.get(f"{figure}_N", row.get(f"{figure}_V"))


def cmd_ls(args) -> list:
    from instruments.archive import Archive

    rows = Archive(args.archive).summary()
    if not args.json:
        print(f"{'shot':>5s}  {'start (UTC)':20s}  {'kind':7s}  {'scene':22s}  {'seed':>20s}  channels")
        for r in rows:
            if "damaged" in r:
                print(f"{r['shot']:5d}  DAMAGED: {r['damaged']}; run `rig verify {args.archive}`")
                continue
            mark = "~" if r["start_time_source"].startswith("file modification") else " "
            s = r["settings"]
            extra = f"  v={s['velocity']:g} m/s" if "velocity" in s else ""
            what = r["scene"] or ",".join(r["sources"]) or "-"
            print(f"{r['shot']:5d}  {r['start_time'][:19]:19s}{mark}  {'virtual' if r['simulated'] else 'real':7s}  "
                  f"{what:22s}  {'' if r['seed'] is None else r['seed']:>20}  "
                  f"{','.join(r['channels'])}{'' if r['triggered'] else '  NO TRIGGER'}{extra}")
        if any(r.get("start_time_source", "").startswith("file modification") for r in rows):
            print("~ the file's modification time (the file holds no acquisition time)")
    args.exit_code = 1 if any("damaged" in r for r in rows) else 0  # a finding, as rig verify's
    return rows


def add_verify(sub) -> None:
    """The parser of ``rig verify``."""
    ve = command(sub, "verify", "check every shot of an archive (exit 1 if any is bad)", cmd_verify)
    ve.add_argument("archive")


def add_upgrade(sub) -> None:
    """The parser of ``rig upgrade``."""
    up = command(sub, "upgrade", "rewrite an archive of an older layout in the current one", cmd_upgrade)
    up.add_argument("archive")


def add_import_(sub) -> None:
    """The parser of ``rig import``."""
    im = command(sub, "import", "import real scope files into an archive", cmd_import)
    im.add_argument("files", nargs="+", metavar="FILE")
    im.add_argument("--into", required=True, metavar="ARCHIVE.h5")
    im.add_argument("--together", action="store_true", help="the files are the channels of one shot")
    im.add_argument("--keep-paths", action="store_true",
                    help="keep each file's full path in the archive (default: its name and the data's digest only, "
                         "nothing of this machine)")


def add_analyze(sub) -> None:
    """The parser of ``rig analyze``."""
    an = command(sub, "analyze", "speeds and amplitudes from scope files or an archive, each channel's SNR, "
                                  "and why any figure is missing (exit 1 when no source gives a speed)",
                  cmd_analyze)
    an.add_argument("files", nargs="+", metavar="FILE", help=".isf, .csv, .wfm (Tektronix) or .h5 (an archive)")
    an.add_argument("--shot", type=plain(int),
                    help="one shot of an archive, by its number (shots are numbered from 1; default: every shot)")
    an.add_argument("--gauge-distance", type=quantity_type("m", "--gauge-distance"),
                    help="distance between the two gauges (plain number: m), for real files")
    an.add_argument("--channels", help="UPPER,LOWER[,WALL] channel names (default: file order)")
    an.add_argument("--wall", action="store_true", help="the third channel is the wall sensor")
    an.add_argument("--sensitivity", type=quantity_type("V/N", "--sensitivity"),
                    help="gauge sensitivity, e.g. '0.05 V/N' (plain number: V/N; default 1: volts)")
    an.add_argument("--tau", type=quantity_type("s", "--tau"), help="gauge RC time constant to invert (s)")
    an.add_argument("--beta", type=plain(float), default=1.0,
                    help="beta = F_d / F_m,e, dimensionless, > 0 (default 1)")
    an.add_argument("--f0", type=quantity_type("N", "--f0"), default=0.0, help="precompression F_0 (N)")
    an.add_argument("--diameter", type=quantity_type("m", "--diameter"), default=4.76e-3,
                    help="bead diameter (plain number: m; default 4.76 mm)")
    an.add_argument("--material", help="bead material: adds the Eq (1) speed and checks the measured one "
                                       "against it and the material's bar speed")


def add_ls(sub) -> None:
    """The parser of ``rig ls``."""
    ls = command(sub, "ls", "list the shots of an archive", cmd_ls)
    ls.add_argument("archive")
