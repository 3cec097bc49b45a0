"""The documentation matches the program: the site builds with warnings as errors, and the
code blocks of README.md and docs/**/*.md run.

- ```bash blocks: each ``rig ...`` command runs as the ``rig`` console script does
  (``rig.cli.main``, in this process: the command line's own process is tested by
  tests/cli/test_startup.py) in a fresh folder per page, blocks in page order, and must
  exit 0 (or the block's ``<!-- exit: N -->``); ``python docs/...`` scripts run as
  subprocesses. Installing, the test suite
  and building the site (SETUP) are listed as not run; any other command fails the test.
  A block marked ``<!-- slow: WHY -->`` or ``<!-- needs: WHAT -->`` is checked by the
  command line's parser only (the command and its flags exist). What is not run is listed
  with its reason in pytest's warnings summary.
- ```python blocks run in that folder, in one namespace per page (a ``needs:`` block is
  compiled only).
"""
from __future__ import annotations

import contextlib
import glob
import io
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
from doc_blocks import ROOT, blocks, pages

PAGES = [page for page in pages() if blocks(page)]
TIMEOUT = 120  # s per command: the first run of a command compiles numba kernels
SETUP = (("pip", "install"), ("python", "-m", "pytest"), ("coverage", "combine"), ("coverage", "report"),
         ("mkdocs", "build"), ("mkdocs", "serve"))
"""Commands a page may show without the test running them: installing, the test suite and its
coverage, the site."""


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    env.setdefault("MPLBACKEND", "Agg")
    env.setdefault("NO_MKDOCS_2_WARNING", "1")  # mkdocs-material's banner about its successor
    return env


def _expand(words: list, folder: Path) -> list:
    """Shell-style globs (``scope/*.isf``) expanded in ``folder``, as a shell would."""
    out = []
    for word in words:
        hits = sorted(glob.glob(word, root_dir=folder)) if any(c in word for c in "*?[") else []
        out.extend(hits or [word])
    return out


def _parse_only(argv: list, where: str):
    """The command and every flag exist and take these values (the parser, nothing run)."""
    from rig.cli import build_parser

    try:
        build_parser().parse_args(argv)
    except SystemExit as exc:
        pytest.fail(f"{where}: rig {' '.join(argv)}: the parser refuses it (exit {exc.code})")


def _run(argv: list, folder: Path, where: str, expected: int) -> str:
    done = subprocess.run([sys.executable, *argv], cwd=folder, env=_env(), capture_output=True, text=True,
                          timeout=TIMEOUT, check=False)
    assert done.returncode == expected, (
        f"{where}: {' '.join(argv)} exited {done.returncode}, the page says {expected}\n"
        f"stdout: {done.stdout[-2000:]}\nstderr: {done.stderr[-2000:]}")
    return done.stdout


def _rig(argv: list, folder: Path, where: str, expected: int, monkeypatch) -> str:
    """``rig`` + ``argv`` run in ``folder``; its stdout."""
    from rig.cli import main

    monkeypatch.chdir(folder)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:  # the parser's own exit (--help, a refused flag)
            code = exc.code
    assert code == expected, (
        f"{where}: rig {' '.join(argv)} exited {code}, the page says {expected}\n"
        f"stdout: {out.getvalue()[-2000:]}\nstderr: {err.getvalue()[-2000:]}")
    return out.getvalue()


def _bash(block, folder: Path, report: list, monkeypatch):
    expected = int(block.marker("exit") or 0)
    last_json = None
    for words in block.commands():
        line = " ".join(words)
        if words[0] == "rig":
            if block.not_run:
                _parse_only(words[1:], block.where)
                report.append(f"{block.where}: parsed only ({block.not_run}): {line[:100]}")
                continue
            last_json = _rig(_expand(words[1:], folder), folder, block.where, expected, monkeypatch)
        elif words[0] == "python" and len(words) > 1 and words[1].startswith("docs/"):
            _run([str(ROOT / words[1]), *words[2:]], folder, block.where, 0)
        else:
            assert any(tuple(words[:len(s)]) == s for s in SETUP), (
                f"{block.where}: {line}: neither a rig command nor python docs/...; the test cannot check it")
            report.append(f"{block.where}: not run (installs, tests or builds the site): {line[:100]}")
    keys = block.marker("json-keys")
    if keys:
        assert last_json is not None, f"{block.where}: json-keys on a block that runs no rig command"
        printed = json.loads(last_json)
        assert sorted(printed) == sorted(keys.split()), (
            f"{block.where}: the page lists {sorted(keys.split())}, the command prints {sorted(printed)}")


def _python(block, folder: Path, namespace: dict, report: list, monkeypatch):
    code = compile(block.text, block.where, "exec")
    if block.not_run:
        report.append(f"{block.where}: python compiled only ({block.not_run})")
        return
    monkeypatch.chdir(folder)
    exec(code, namespace)  # noqa: S102 - the documentation's own example


@pytest.mark.parametrize("page", PAGES)
def test_code_blocks_run(page, tmp_path, monkeypatch):
    report, namespace = [], {"__name__": "__docs__"}
    for block in blocks(page):
        if block.language == "bash":
            _bash(block, tmp_path, report, monkeypatch)
        else:
            _python(block, tmp_path, namespace, report, monkeypatch)
    if report:
        # a plain UserWarning, which pytest-xdist's controller can unpickle (a class of this
        # module it could not import): the warnings summary lists every block not run, with why
        warnings.warn(UserWarning("\n  ".join([f"{page}: checked, not run:", *report])), stacklevel=1)


def test_site_builds_strict(tmp_path):
    """mkdocs build --strict: a broken link, a page missing from the navigation, a docstring
    mkdocstrings cannot read or a scene key without a meaning fails; the generated reference
    names every command, flag and scene key of the program."""
    site = tmp_path / "site"
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                           str(ROOT / "mkdocs.yml"), "--site-dir", str(site)], cwd=ROOT, env=_env(),
                          capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, f"mkdocs build --strict failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"

    import argparse

    from rig.cli import build_parser
    from rig.experiment.scene import SCHEMA

    commands = (site / "reference" / "commands" / "index.html").read_text()
    for action in build_parser()._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                assert f"rig {name}" in commands, name
                for flag in (o for a in sub._actions for o in a.option_strings):
                    assert flag in commands, f"rig {name} {flag}"
    keys = (site / "reference" / "scene-keys" / "index.html").read_text()
    for table, entries in SCHEMA.items():
        for key in entries:
            if key != "*":
                assert f"{table}.{key}" in keys, f"{table}.{key}"


def test_block_reading(tmp_path, monkeypatch):
    """A page's markers, continuation lines, comments and ``&&`` are read as the test runs
    them; a slow block's unknown flag fails the parser check."""
    import doc_blocks

    page = tmp_path / "page.md"
    page.write_text('Text.\n\n<!-- slow: a long one -->\n<!-- exit: 1 -->\n```bash\n'
                    'pip install -e . && rig shot ptfe52_magnetic \\\n    --seed 1   # a comment\n```\n\n'
                    '```python\nx = 1\n```\n')
    monkeypatch.setattr(doc_blocks, "ROOT", tmp_path)
    bash, python = doc_blocks.blocks("page.md")
    assert (bash.language, python.language) == ("bash", "python")
    assert bash.not_run == "a long one" and bash.marker("exit") == "1" and python.not_run is None
    assert bash.commands() == [["pip", "install", "-e", "."], ["rig", "shot", "ptfe52_magnetic", "--seed", "1"]]
    with pytest.raises(pytest.fail.Exception, match="the parser refuses it"):
        _parse_only(["shot", "ptfe52_magnetic", "--no-such-flag"], "page.md:5")


def test_readme_links_resolve():
    """The README is not a page of the site, so mkdocs does not check its links: every
    relative link and picture names a file of the repository."""
    import re

    readme = (ROOT / "README.md").read_text()
    targets = re.findall(r"\]\(([^)#\s]+)[^)]*\)", readme)
    local = [t for t in targets if "://" not in t]
    assert len(local) >= 10, local  # the picture and the links to the pages
    missing = [t for t in local if not (ROOT / t).exists()]
    assert not missing, f"README.md links to files that do not exist: {missing}"
    assert len(readme.splitlines()) <= 200, "the README is at most 200 lines; the rest goes to docs/"
