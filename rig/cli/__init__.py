"""The ``rig`` command line: the parser. The commands themselves live in rig/cli/ (one module
per group), and import what they need inside each command, so that the parser, ``--help``
and ``--version`` load no numba, scipy, pint, h5py or matplotlib (tests/cli/test_startup.py).
Every user mistake ends in one clear line (exit 2), never a traceback."""
from __future__ import annotations

import argparse
import json
import os
import sys

from instruments.errors import InstrumentError
from rig import __version__
from rig.cli import data, fitting, lab, shots, study, sweeps, tools
from rig.cli.common import (
    OneLineParser,
    allow_large,
    count_arg,
    fraction_arg,
    os_error_line,
    plain,
    positive_seconds,
    quantity_type,
    rounds_arg,
    seed_arg,
)
from rig.errors import Interrupted, RigError


def _command(sub, name: str, help_text: str, func):
    """A subcommand with its --json flag, run by ``func(args)``."""
    parser = sub.add_parser(name, help=help_text)
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.set_defaults(func=func)
    return parser


def build_parser() -> argparse.ArgumentParser:
    ap = OneLineParser(prog="rig", description="Virtual rig for strongly nonlinear granular chains.")
    ap.add_argument("--version", action="version", version=f"rig {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)

    th = _command(sub, "theory", "long-wave and exact discrete solitary wave speeds", tools.cmd_theory)
    th.add_argument("--material", default="ptfe", help="ptfe | steel316 | ... (default ptfe)")
    th.add_argument("--diameter", default="4.76 mm", help="bead diameter, e.g. 4.76mm (plain number: m)")
    th.add_argument("--f0", required=True, help="precompression F0 (plain number: N)")
    th.add_argument("--fm", help="maximum contact force Fm of the wave (plain number: N)")

    sh = _command(sub, "shot", "fire one virtual shot of a scene", shots.cmd_shot)
    sh.add_argument("scene", help="a scene file, or a published scene's name (e.g. ptfe52_magnetic)")
    sh.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="override a scene key, e.g. striker.velocity=1.2 (plain numbers in SI)")
    sh.add_argument("--seed", type=seed_arg, help="seed of every random draw (default: a fresh one, printed)")
    sh.add_argument("--export", metavar="DIR", help="write the scope records to DIR")
    sh.add_argument("--format", choices=["isf", "csv"], help="with --export: scope file format (default isf)")
    sh.add_argument("--out", metavar="ARCHIVE.h5", help="append the shot to an HDF5 archive")
    allow_large(sh)

    ve = _command(sub, "verify", "check every shot of an archive (exit 1 if any is bad)", data.cmd_verify)
    ve.add_argument("archive")

    up = _command(sub, "upgrade", "rewrite an archive of an older layout in the current one", data.cmd_upgrade)
    up.add_argument("archive")

    im = _command(sub, "import", "import real scope files into an archive", data.cmd_import)
    im.add_argument("files", nargs="+", metavar="FILE")
    im.add_argument("--into", required=True, metavar="ARCHIVE.h5")
    im.add_argument("--together", action="store_true", help="the files are the channels of one shot")

    sw = _command(sub, "sweep", "one shot per value of a scene key", sweeps.cmd_sweep)
    sw.add_argument("scene")
    sw.add_argument("--vary", required=True, action="append", metavar="KEY=START:STOP:COUNT",
                    help="the one key to sweep, e.g. striker.velocity=0.3:1.5:7 (plain numbers in the key's SI unit)")
    sw.add_argument("--set", action="append", metavar="KEY=VALUE", help="other overrides")
    sw.add_argument("--seed", type=seed_arg, default=0, help="the sweep's seed (default 0)")
    sw.add_argument("--out", metavar="ARCHIVE.h5", help="append every shot to an archive")
    sw.add_argument("--quiet", action="store_true", help="no progress bar")
    allow_large(sw)

    an = _command(sub, "animate", "render a virtual shot to a movie or still, off-screen", shots.cmd_animate)
    an.add_argument("scene")
    an.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene key")
    an.add_argument("--seed", type=seed_arg, help="seed of the instruments' draws (default: a fresh one, printed)")
    an.add_argument("--out", required=True, metavar="FILE", help="FILE.mp4, FILE.gif or FILE.png (one still)")
    an.add_argument("--frames", type=plain(int), default=100,
                    help="frames over the scene's duration (default 100); for a .png still, the instants "
                         "it is picked from (the one nearest the leading pulse at the last gauge)")
    an.add_argument("--exaggerate", type=plain(float),
                    help="displacement factor (default: the largest displacement shown as 1/3 diameter)")
    an.add_argument("--quiet", action="store_true", help="no progress bar")
    allow_large(an)

    rp = _command(sub, "reproduce", "re-run a published study (daraio2006)", sweeps.cmd_reproduce)
    rp.add_argument("study", choices=["daraio2006"], help="the published study to re-run")
    rp.add_argument("--out", required=True, metavar="DIR", help="folder for tables and figures")
    rp.add_argument("--fitted", action="store_true",
                    help="also fit the PTFE model to the published experiment (Table 1) and compare its shots")
    rp.add_argument("--family", action="append", metavar="NAME",
                    help="with --fitted: fit only this model family (repeat for more; default: every one)")
    rp.add_argument("--identifiability", action="store_true",
                    help="instead: fit each new contact parameter to noisy virtual Fig. 3 observations (20 data "
                         "sets each) and count the 95%% intervals that hold the truth (identifiability.json, .md)")
    rp.add_argument("--sensitivity", action="store_true",
                    help="instead: each Fig. 3 figure's d ln(figure)/d ln(p) and each key's window meeting every "
                         "Fig. 3 target, at the Fig. 3 parameter set or --set (sensitivity.json, .md)")
    rp.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="with --identifiability or --sensitivity: overrides of the Fig. 3 parameter set")
    rp.add_argument("--param", action="append", metavar="KEY=LO:HI",
                    help="with --identifiability: a key to find again (with --truth), instead of the five new ones")
    rp.add_argument("--truth", action="append", metavar="VALUE",
                    help="with --param: its truth, a quantity in the key's unit (one per --param, in order)")
    rp.add_argument("--draws", type=count_arg, default=20,
                    help="with --identifiability: data sets per key (default 20)")
    rp.add_argument("--seed", type=seed_arg, default=0, help="with --identifiability: the noise's seed (default 0)")
    rp.add_argument("--quiet", action="store_true", help="no progress bar")

    fi = _command(sub, "fit", "fit scene keys to measured points, scope records or observations", fitting.cmd_fit)
    fi.add_argument("scene", help="the model: a scene file, or a published scene's name")
    fi.add_argument("--param", action="append", metavar="KEY=LO:HI",
                    help="a scene key to fit with its bounds in units, e.g. 'chain.youngs_modulus=0.4 GPa:2 GPa' "
                         "(a dimensionless key: plain numbers, e.g. chain.contact_exponent=1.2:2.4)")
    fi.add_argument("--records", nargs="+", metavar="FILE", help="one shot's scope files (ISF, CSV, WFM)")
    fi.add_argument("--archive", metavar="A.h5", help="an archive: every shot (or --shot N)")
    fi.add_argument("--shot", type=count_arg, help="with --archive: one shot")
    fi.add_argument("--points", metavar="TABLE.csv",
                    help="measured points: columns 'F_d [N]', 'F_d_sd [N]', 'V_s [m/s]', 'V_s_sd [m/s]' "
                         "and scene keys per row, e.g. 'magnet.force [N]'")
    fi.add_argument("--observations", metavar="FILE.toml",
                    help="observed figures of shots ([[observation]] kind, value, sd, scene, set, gauge: a speed, "
                         "a gauge reading's peak, fwhm, duration, pulses, wall_peak, tail, ratio)")
    fi.add_argument("--set", action="append", metavar="KEY=VALUE", help="fixed overrides of the scene")
    fi.add_argument("--out", required=True, metavar="DIR",
                    help="folder for fit.json, residuals.csv, fit.png, fitted.toml; its evaluations/ resume a fit")
    fi.add_argument("--max-evaluations", type=count_arg, default=400, help="the fit's budget (default 400)")
    fi.add_argument("--posterior", type=count_arg, default=0, metavar="STEPS",
                    help="then sample the posterior by MCMC for STEPS steps (needs the extra: "
                         "pip install 'sonic-rig[posterior]'); resumes in DIR/posterior.h5")
    fi.add_argument("--walkers", type=count_arg, help="with --posterior: walkers (default 4 per parameter, at least 8)")
    fi.add_argument("--seed", type=seed_arg, help="with --posterior: the walkers' seed (default 0)")
    fi.add_argument("--quiet", action="store_true", help="no progress lines")

    mc = _command(sub, "mc", "Monte Carlo study over many virtual shots", study.cmd_mc)
    mc.add_argument("scene")
    mc.add_argument("--shots", type=count_arg, required=True, help="number of shots (>= 1)")
    mc.add_argument("--vary", action="append", metavar="KEY=DIST",
                    help='e.g. striker.velocity="normal(0.89 m/s, 0.01 m/s)"; also chain.bead_mass, '
                         'gauges.NAME.gain, gauges.NAME.misalignment')
    mc.add_argument("--set", action="append", metavar="KEY=VALUE", help="fixed overrides")
    mc.add_argument("--seed", type=seed_arg, default=0, help="the study's seed (default 0)")
    mc.add_argument("--batch", type=count_arg, help="shots per batch (default 256; resuming a study in --out: "
                                                    "its own)")
    mc.add_argument("--accuracy", type=plain(float), help="solver accuracy (default: the scene's)")
    mc.add_argument("--workers", type=count_arg,
                    help="local worker processes, or with --scheduler local the cluster's (default 1)")
    mc.add_argument("--scheduler", help="Dask scheduler: tcp://HOST:PORT, or 'local' for a LocalCluster")
    mc.add_argument("--sobol", action="store_true", help="Sobol design and indices (needs SALib)")
    mc.add_argument("--truth", action="store_true", help="also analyse each shot's noise-free truth (slower)")
    mc.add_argument("--window", choices=["leading", "record"], default="leading",
                    help="simulate until the leading pulse has passed the last gauge (default), "
                         "or the scene's whole record")
    mc.add_argument("--traces", action="store_true",
                    help="also archive every shot's scope record and truth in DIR/traces/ (one archive per batch)")
    mc.add_argument("--out", required=True, metavar="DIR")
    mc.add_argument("--quiet", action="store_true", help="no progress bar")
    mc.add_argument("--max-failed", type=fraction_arg, default=0.05, metavar="PERCENT",
                    help="fail the study (exit 1) when more shots than this fail (default 5%%)")
    mc.add_argument("--worker-timeout", type=positive_seconds, metavar="SECONDS",
                    help="with --scheduler: stop when no Dask worker is alive for this long (default 300)")
    allow_large(mc)

    an = _command(sub, "analyze", "speeds and amplitudes from scope files or an archive, each channel's SNR, "
                                  "and why any figure is missing (exit 1 when no source gives a speed)",
                  data.cmd_analyze)
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

    ls = _command(sub, "ls", "list the shots of an archive", data.cmd_ls)
    ls.add_argument("archive")

    lab.add_parsers(sub, _command)

    be = _command(sub, "bench", "benchmarks", tools.cmd_bench)
    be.add_argument("what", choices=["solver", "accuracy", "models", "fit", "shot", "archive", "pipeline", "mc",
                                     "animate", "startup", "serve"],
                    help="what to benchmark")
    be.add_argument("--quick", action="store_true", help="solver, accuracy, models, fit: fewer settings, one repeat")
    be.add_argument("--peers", action="store_true",
                    help="solver: also scipy's DOP853, a numba-compiled DOP853 and LAMMPS (when installed)")
    be.add_argument("--cold", action="store_true",
                    help="startup: the first rig shot and rig mc with an empty numba cache (everything compiled), "
                         "beside the warm ones")
    be.add_argument("--baseline", metavar="REV",
                    help="solver, mc, startup --cold: measure git revision REV of this checkout too, in turns with the current code")
    be.add_argument("--rounds", type=rounds_arg, metavar="N",
                    help="solver, mc, startup --cold: rounds, 1 to 100, of the figures that run in turns with --baseline "
                         "(solver: its kernel figure only, default 3, 1 with --quick; mc: every figure, default 3; "
                         "startup --cold: default 1); more "
                         "rounds steady the ratios on a machine whose speed swings")
    return ap


SIGPIPE_EXIT = 141  # 128 + SIGPIPE: what a shell reports for a command whose reader went away


def main(argv=None) -> int:
    """Run one command. A user mistake or an I/O failure (a missing file, a folder, no
    permission, a full disk, ...) is one line on stderr and exit 2; never a traceback. A
    reader that closes the output early (``rig analyze ... --json | head``) ends the command
    quietly, as it ends cat or grep (exit 141)."""
    try:
        try:
            return _run(argv)
        finally:  # here, not at the interpreter's exit, where a closed pipe prints a warning (--help too)
            sys.stdout.flush()
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # Python's last flush goes nowhere
        return SIGPIPE_EXIT


def _run(argv) -> int:
    args, extra = build_parser().parse_known_args(argv)
    command = f"{args.command} {args.what}" if args.command == "serve" else args.command  # as argparse names it
    if extra:  # named by the command's parser, not the top one's ("rig: error:")
        return _fail(command, f"unrecognized arguments: {' '.join(extra)} (see rig {command} --help)")
    try:
        out = args.func(args)
    except BrokenPipeError:
        raise
    except Interrupted as exc:  # Ctrl-C, with what the run kept
        _fail(command, str(exc))
        return 130
    except (RigError, InstrumentError) as exc:
        return _fail(command, str(exc))
    except OSError as exc:
        return _fail(command, os_error_line(exc))
    except MemoryError:
        return _fail(command, "out of memory: choose a shorter duration, fewer beads or fewer points")
    except KeyboardInterrupt:
        _fail(command, "interrupted")
        return 130
    if args.json:
        print(json.dumps(out, indent=2))
    return getattr(args, "exit_code", 0)


def _fail(command: str, message: str) -> int:
    print(f"rig {command}: error: {' '.join(message.split())}", file=sys.stderr)
    return 2
