"""Every hand-written choices list of the parser is its registry's: the lists stay literal
so that ``rig --help`` loads neither numba nor the instruments (tests/test_layers.py), and
these tests hold each one to the registry it restates (as tests/lab/test_serve.py holds
--personality to the scope's PERSONALITIES)."""
import argparse
import ast
import importlib.util
from pathlib import Path

import pytest

from rig.cli import build_parser


def _subparser(*names):
    parser = build_parser()
    for name in names:
        (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        parser = sub.choices[name]
    return parser


def _choices(command, dest):
    (action,) = [a for a in _subparser(*command)._actions if a.dest == dest]
    return list(action.choices)


def test_the_export_formats_are_the_scope_writers():
    from instruments.formats import WRITERS

    assert sorted(_choices(["shot"], "format")) == sorted(WRITERS)


def test_the_study_windows_are_the_monte_carlo_study_s():
    from rig.study.mc_spec import WINDOWS

    assert _choices(["mc"], "window") == list(WINDOWS)


def test_the_published_studies_are_the_ones_reproduce_knows():
    from rig.study.reproduce import STUDIES

    assert _choices(["reproduce"], "study") == list(STUDIES)


def _defines_run_and_table(module: str) -> bool:
    tree = ast.parse(Path(importlib.util.find_spec(module).origin).read_text())
    return {"run", "table"} <= {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}


# modules with run() and table() that are parts of another benchmark, not choices of their own
PARTS = {"cold_start": "rig bench startup --cold", "mc_scaling": "rig bench mc's scaling table"}


def test_every_benchmark_choice_is_a_benchmark_module_and_every_module_a_choice():
    choices = _choices(["bench"], "what")
    for what in choices:
        assert importlib.util.find_spec(f"rig.bench.{what}") is not None, what
        assert _defines_run_and_table(f"rig.bench.{what}"), f"rig.bench.{what} has no run() and table()"
    folder = Path(importlib.util.find_spec("rig.bench").origin).parent
    modules = {p.stem for p in folder.glob("*.py") if _defines_run_and_table(f"rig.bench.{p.stem}")}
    assert modules - set(PARTS) == set(choices)


@pytest.mark.parametrize("argv", [["shot", "x", "--format", "wfm"], ["mc", "x", "--window", "all"],
                                  ["reproduce", "other"], ["bench", "nothing"]])
def test_a_value_outside_the_registry_is_refused_in_one_line(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "invalid choice" in err[0]
