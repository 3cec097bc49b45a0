"""The code is lint-clean: ruff, with the rules pyproject.toml selects ([tool.ruff.lint]:
pycodestyle E and W, pyflakes F, isort I, bugbear B, pyupgrade UP, simplify SIM; each rule
kept off there says why), finds nothing in rig/, instruments/, numerics/, tests/ and docs/.
A line that breaks a rule for a reason carries ``# noqa: CODE`` and the reason.

ruff runs here, in the suite, as mypy does (tests/test_typing.py); it checks the whole tree
in about a second."""
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CHECKED = ("rig", "instruments", "numerics", "tests", "docs")
SELECTED = {"E", "F", "W", "I", "B", "UP", "SIM"}

pytestmark = pytest.mark.skipif(importlib.util.find_spec("ruff") is None,
                                reason="ruff is not installed (pip install -e .[test])")


def ruff(*args: str, text: str | None = None) -> subprocess.CompletedProcess:
    """``python -m ruff check`` in the project's root (its pyproject.toml configures it)."""
    return subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", *args], input=text,
                          check=False, capture_output=True, text=True, cwd=ROOT, timeout=120)


def test_ruff_finds_nothing_in_the_project():
    out = ruff(*CHECKED)
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]


def test_the_project_configuration_selects_the_rules_and_is_the_one_applied():
    """The rules are those selected, and a file that breaks them is reported: the clean run
    above checked something, under this configuration (line length 120)."""
    if sys.version_info >= (3, 11):
        import tomllib
    else:
        import tomli as tomllib
    lint = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["ruff"]["lint"]
    assert set(lint["select"]) == SELECTED
    bad = ("import os\nimport sys\n\n\ndef f(x):\n    return x\n\n\n"
           f"y = {'1 + ' * 30}1\n"  # 125 characters
           "g = lambda: sys\n")
    out = ruff("--output-format", "concise", "--stdin-filename", "rig/lint_probe.py", "-", text=bad)
    assert out.returncode == 1, out.stdout + out.stderr
    found = set(re.findall(r"^rig/lint_probe\.py:\d+:\d+: ([A-Z]+\d+) ", out.stdout, re.MULTILINE))
    assert {"F401", "E501", "E731"} <= found, out.stdout
