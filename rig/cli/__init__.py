"""The ``rig`` command line: the parser. The commands themselves live in rig/cli/ (one module
per group), each making its commands' subparsers (``add_*``), and import what they need
inside each command, so that the parser, ``--help``
and ``--version`` load no numba, scipy, pint, h5py or matplotlib (tests/cli/test_startup.py).
Every user mistake ends in one clear line (exit 2), never a traceback."""
from __future__ import annotations

import argparse
import json
import os
import sys
import warnings

from rig import __version__
from rig.cli import data, fitting, lab, shots, study, sweeps, tools
from rig.cli.common import OneLineParser, command, os_error_line
from rig.errors import Interrupted, RigError


def _own_instruments() -> None:
    """Exit with one line (2) where the import name ``instruments`` is another
    distribution's (InstrumentKit installs a package of that name): the rig's own
    instruments package cannot load beside it, and every command would fail with a
    ModuleNotFoundError deep in an import."""
    import importlib.util

    try:
        ours = importlib.util.find_spec("instruments.rails") is not None
    except ImportError:  # the other package's own imports failed
        ours = False
    if ours:
        return
    from importlib.metadata import packages_distributions

    spec = importlib.util.find_spec("instruments")
    where = [] if spec is None else [str(w) for w in spec.submodule_search_locations or ()] or [str(spec.origin)]
    others = [d for d in packages_distributions().get("instruments", []) if d.lower() != "sonic-rig"]
    print(f"rig: error: the import name 'instruments' is {' and '.join(others) or 'another package'}'s here "
          f"({', '.join(where) or 'not found'}): the rig's own 'instruments' package cannot load beside "
          f"it; give the rig a virtual environment of its own", file=sys.stderr)
    raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    """The ``rig`` parser: each command's subparser is made by its own module (rig/cli/),
    in the order ``rig --help`` lists them."""
    ap = OneLineParser(prog="rig", description="Virtual rig for strongly nonlinear granular chains.")
    ap.add_argument("--version", action="version", version=f"rig {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)

    tools.add_theory(sub)
    shots.add_shot(sub)
    data.add_verify(sub)
    data.add_upgrade(sub)
    data.add_import_(sub)
    sweeps.add_sweep(sub)
    shots.add_animate(sub)
    sweeps.add_reproduce(sub)
    fitting.add_fit(sub)
    study.add_mc(sub)
    data.add_analyze(sub)
    data.add_ls(sub)
    lab.add_parsers(sub, command)
    tools.add_bench(sub)
    return ap


PATH_FLAGS = ("out", "export", "into", "log", "observations", "points", "archive")  # flags that name a path
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


def _note(message, category, filename, lineno, file=None, line=None) -> None:
    """warnings.showwarning for the command line: a RigNote as one line ``note: ...``."""
    from rig.errors import RigNote

    if issubclass(category, RigNote):
        print(f"note: {message}", file=sys.stderr)
    else:
        _show_warning(message, category, filename, lineno, file, line)


_show_warning = warnings.showwarning


def _run(argv) -> int:
    _own_instruments()  # before any command imports the rig's instruments
    warnings.showwarning = _note
    from instruments.errors import InstrumentError

    args, extra = build_parser().parse_known_args(argv)
    command = f"{args.command} {args.what}" if args.command == "serve" else args.command  # as argparse names it
    if extra:  # named by the command's parser, not the top one's ("rig: error:")
        return _fail(command, f"unrecognized arguments: {' '.join(extra)} (see rig {command} --help)")
    for name in PATH_FLAGS:  # '' had meant the current folder (rig mc) or nothing at all (rig shot, exit 0)
        value = getattr(args, name, None)
        if isinstance(value, str) and not value.strip():
            return _fail(command, f"--{name.replace('_', '-')} = {value!r}: an empty path; give the path it names "
                                  f"(rig {command} --help)")
    for value in getattr(args, "files", None) or ():  # '' had been read as the current folder, '.'
        if isinstance(value, str) and not value.strip():
            return _fail(command, f"FILE = {value!r}: an empty path; give a scope file or an archive")
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
