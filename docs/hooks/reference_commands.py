"""reference/commands.md: every command and flag of rig.cli.build_parser()."""
from __future__ import annotations

import argparse

from reference_text import cell, names


def _subcommands(parser: argparse.ArgumentParser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, sub in action.choices.items():
                yield name, helps.get(name), sub


def _command(lines: list, path: str, summary, parser: argparse.ArgumentParser):
    lines += [f"## `{path}`", ""]
    if summary or parser.description:
        lines += [cell(summary or parser.description), ""]
    lines += ["```text", parser.format_usage().strip(), "```", ""]
    rows = []
    for action in parser._actions:
        if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        name = ", ".join(f"`{o}`" for o in action.option_strings) or f"`{action.metavar or action.dest}`"
        choices = names(action.choices) if action.choices else ""
        default = "" if action.default in (None, False, argparse.SUPPRESS) or action.option_strings == [] \
            else f"`{action.default}`"
        rows.append(f"| {name} | {choices} | {default} | {cell(action.help or '')} |")
    if rows:
        lines += ["| argument | choices | default | what |", "|---|---|---|---|", *rows, ""]
    for name, help_text, sub in _subcommands(parser):
        _command(lines, f"{path} {name}", help_text, sub)


def commands() -> str:
    from rig.cli import build_parser

    parser = build_parser()
    lines = ["# Commands and flags (generated)", "",
             "Every `rig` command and its flags, written from the command line's parser "
             "(`rig.cli.build_parser`) when the site is built. `rig COMMAND --help` prints the same. "
             "A bad value is one line naming the flag, the value and what is allowed, with exit status 2.", ""]
    for name, help_text, sub in _subcommands(parser):
        _command(lines, f"rig {name}", help_text, sub)
    return "\n".join(lines)
