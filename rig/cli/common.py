"""Helpers shared by the commands."""
from __future__ import annotations

import argparse
import contextlib
import math
import sys

from rig.units import MAX_SEED


class OneLineParser(argparse.ArgumentParser):
    """argparse with the project's error policy: a mistake is one line, exit 2."""

    def error(self, message):
        if message.endswith("expected one argument"):  # argparse reads a value starting with '-' as a flag
            flag = message.split()[1].rstrip(":")
            message += f" (a value that starts with '-' is written {flag}=VALUE)"
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        sys.exit(2)


def command(sub, name: str, help_text: str, func):
    """A subcommand with its --json flag, run by ``func(args)``."""
    parser = sub.add_parser(name, help=help_text)
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.set_defaults(func=func)
    return parser


def whole_number(text: str, low: int, high: float, allowed: str) -> int:
    """The command-line whole number ``text`` in [low, high]; else argparse's refusal
    ``'TEXT': allowed``."""
    from rig.errors import RigError
    from rig.units import whole

    try:
        value = whole(text, "value", allowed)
    except RigError as exc:
        raise refusal(exc, "value") from None
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(f"{text!r}: {allowed}")
    return value


def refusal(exc, field: str, text: str | None = None) -> argparse.ArgumentTypeError:
    """argparse's refusal of an option's value from a RigError ``field = value: why``: the
    option's name is argparse's to print; ``text`` (if given) is the value as typed."""
    why = str(exc).removeprefix(f"{field} = ")
    return argparse.ArgumentTypeError(why if text is None else f"{text!r}: {why.split(': ', 1)[-1]}")


def seed_arg(text: str) -> int:
    """A seed: a whole number from 0 to 2^63 - 1."""
    return whole_number(text, 0, MAX_SEED, f"a whole number from 0 to {MAX_SEED}")


def quantity_type(unit: str, field: str):
    """An argparse type for a quantity in ``unit`` (a plain number is taken in ``unit``);
    a mistake is reported as the field, the value and what is allowed."""
    def parse(text: str) -> float:
        from rig.errors import RigError
        from rig.units import typed_quantity

        try:
            return typed_quantity(text, unit, field)
        except RigError as exc:
            raise refusal(exc, field) from None

    parse.__name__ = f"quantity in {unit}"
    return parse


def folder_shown(path) -> str:
    """A folder as printed: normalised, with one trailing separator ("fit1//" -> "fit1/")."""
    import os

    return os.path.join(os.path.normpath(path), "")


def check_export_folder(path, flag: str):
    """Refuse ``path`` as the folder ``flag`` writes into where it is an existing file (before
    any work; mkdir would say only "File exists")."""
    from pathlib import Path

    from rig.errors import invalid

    if Path(path).exists() and not Path(path).is_dir():
        raise invalid(flag, str(path), "is a file, not a folder: name a folder (it is made if missing)")


def check_archive_out(path, flag: str):
    """Refuse ``path`` as the archive ``flag`` appends to where it is a directory, before any
    work, naming the flag."""
    from instruments.archive import check_archive_path
    from instruments.errors import InstrumentError
    from rig.errors import RigError

    try:
        check_archive_path(path)
    except InstrumentError as exc:
        raise RigError(f"{flag} {exc}") from None


def scene_overrides(args, given_elsewhere: dict | None = None) -> tuple:
    """The command's --set items, each key set once: a key set twice (where the last would
    win silently), or a key that another option already gives (``given_elsewhere``: {key:
    that option's words}, e.g. a swept or fitted key), is refused naming both."""
    from rig.errors import invalid

    items = tuple(args.set or ())
    first: dict[str, str] = {}
    for item in items:
        key = item.split("=", 1)[0].strip()
        if key in first:
            raise invalid("--set", key, f"set twice ({first[key]!r} and {item!r}); set each key once")
        if given_elsewhere and key in given_elsewhere:
            raise invalid("--set", item, f"{given_elsewhere[key]} already gives {key}; give it once")
        first[key] = item
    return items


@contextlib.contextmanager
def progress_bar(quiet: bool = False, **kw):
    """A tqdm bar on stderr that shows itself only after a second (a mistake found at once
    leaves nothing but its one error line) and clears its line when the command fails."""
    from tqdm import tqdm

    bar = tqdm(file=sys.stderr, disable=quiet, delay=1.0, **kw)
    try:
        yield bar
    except BaseException:
        bar.leave = False
        bar.close()
        raise
    bar.close()


def os_error_line(exc: OSError) -> str:
    """An I/O failure as one line: the path(s) and the cause (e.g. 'No space left on device')."""
    cause = exc.strerror or str(exc) or type(exc).__name__
    paths = [str(p) for p in (exc.filename, exc.filename2) if p is not None]
    return f"{' -> '.join(paths)}: {cause}" if paths else cause


def allow_large(parser):
    """The flag that confirms a run beyond the size limits of rig/solver/estimate.py."""
    parser.add_argument("--allow-large", action="store_true",
                        help="run even when the estimate passes 2 GB of memory or 2 minutes of solving")


def fraction_arg(text: str) -> float:
    """A share: '5%' or 0.05, from 0 to 1 (100%)."""
    from rig.errors import RigError
    from rig.units import number

    allowed = "a share from 0% to 100%, e.g. 5% or 0.05"
    try:
        value = number(text[:-1], "value", allowed) / 100 if text.endswith("%") else number(text, "value", allowed)
    except RigError as exc:
        raise refusal(exc, "value", text) from None
    if not 0 <= value <= 1:
        raise argparse.ArgumentTypeError(f"{text!r}: {allowed}")
    return value


def plain(convert):
    """An argparse type: ``convert`` (int or float) of a text that is one plain number as
    ``rig.units.is_number`` reads it (Python's int and float read "1_000" and "١"), or nan or
    inf, which Python reads right; the range is the library's to check, which names the
    option."""
    def parse(text: str):
        from rig.errors import RigError
        from rig.units import check_digits, is_non_finite, is_number

        try:
            check_digits(text, "value")
        except RigError as exc:
            raise refusal(exc, "value") from None
        if not (is_number(text) or is_non_finite(text)):
            raise ValueError(text)  # argparse: "invalid float value: '2*0.5'"
        return convert(text)

    parse.__name__ = convert.__name__  # argparse's "invalid float value: 'x'"
    return parse


def positive_seconds(text: str) -> float:
    """A time in seconds > 0 (a plain number)."""
    from rig.errors import RigError
    from rig.units import number

    try:
        value = number(text, "value", "a number of seconds > 0")
    except RigError as exc:
        raise refusal(exc, "value") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: a number of seconds > 0")
    return value


def check_size(estimate, args, what: str):
    """Refuse a run beyond the size limits unless --allow-large; say what a large one costs."""
    from rig.solver.estimate import NOTICE_SECONDS

    estimate.refuse_unless(args.allow_large, what)
    if estimate.large or estimate.seconds > NOTICE_SECONDS:
        print(f"{what} needs {estimate.describe()}", file=sys.stderr, flush=True)


MAX_ROUNDS = 100  # rounds of rig bench's figures measured in turns with a baseline


def rounds_arg(text: str) -> int:
    """rig bench --rounds: a whole number from 1 to MAX_ROUNDS."""
    return whole_number(text, 1, MAX_ROUNDS, f"a whole number of rounds from 1 to {MAX_ROUNDS}")


def count_arg(text: str) -> int:
    """A whole number >= 1."""
    return whole_number(text, 1, math.inf, "a whole number >= 1")


@contextlib.contextmanager
def writing_to(path):
    """Name ``path`` in an I/O failure that names no file (a write on a full disk)."""
    try:
        yield
    except OSError as exc:
        if exc.filename is None:
            raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
        raise


def missing_lines(reasons: dict) -> list:
    """One line per reason of a Report's missing figures ({figure: reason}): "no F1, F2:
    reason", or "no result: reason" where every figure is missing for it."""
    from instruments.analysis.report import FIGURES

    why: dict[str, list] = {}
    for figure, reason in reasons.items():
        why.setdefault(reason, []).append(figure)
    return [f"no {'result' if set(FIGURES) <= set(figures) else ', '.join(figures)}: {reason}"
            for reason, figures in why.items()]


def flag_lines(flags: dict) -> list:
    """One line per reason of a block's flagged figures ({figure: why they cannot be
    trusted as they are}): "flagged F1, F2: reason"."""
    why: dict[str, list] = {}
    for figure, reason in flags.items():
        why.setdefault(reason, []).append(figure)
    return [f"flagged {', '.join(figures)}: {reason}" for reason, figures in why.items()]


def compile_cold(command: str, task: str, quiet: bool = False) -> None:
    """On a cold numba cache (a new install, a changed kernel): start compiling the
    instruments' kernels of ``task`` ("shot" or "study") in a side process while this one
    compiles the chain solver, and say so in one line on stderr unless ``quiet``, a
    terminal or not (a log or a pipe had sat silent for the whole compile, tens of
    seconds). Nothing on a warm cache."""
    with compiling_cold(command, task, quiet):
        pass


@contextlib.contextmanager
def compiling_cold(command: str, task: str, quiet: bool = False):
    """compile_cold with the side process started before the block and the line said after
    it: the block's own compiles (a chain's statics, about 0.7 s of a cold shot) run while the
    side process compiles, and a refusal in the block stops the side process and is the
    command's one line (no word of a compile that will not happen)."""
    from instruments.precompile import LEADING, SHOT, SHOT_SMALL, STUDY, start, stop
    from numerics.dispatcher import has_machine_code
    from rig.solver.kernels.ensemble import integrate_chunks
    from rig.solver.kernels.integrators import integrate

    # this process: the chain solver (a shot's single-shot kernel, a study's batched one; about 11 s CPU on one
    # core here); the side process: the analysis (7 s), then a shot's small kernels (2.3 s), or a study's
    # leading pair (6.4 s), its batches' acquisition and analysis (9 s), then (not waited for) a shot's small
    # kernels
    kernels = {**LEADING, **STUDY} if task == "study" else {**SHOT, **SHOT_SMALL}
    cold_solver = not (has_machine_code(integrate) and (task == "shot" or has_machine_code(integrate_chunks)))
    aside = start(kernels, then=SHOT_SMALL if task == "study" else None)  # so a shot after it compiles nothing
    try:
        yield
    except BaseException:
        stop()
        raise
    parts = (["the chain solver"] if cold_solver else []) + (["the instruments"] if aside else [])
    if parts and not quiet:
        print(f"rig {command}: numba is compiling {' and '.join(parts)}{' (in two processes)' if aside else ''}, "
              f"once: later runs load the machine code from its cache", file=sys.stderr, flush=True)
