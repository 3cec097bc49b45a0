"""The code blocks of the documentation (README.md and docs/**/*.md), as the docs test runs them.

A fenced ```bash or ```python block may be preceded, on the lines right above it, by
HTML comments that say how to check it:

- ``<!-- slow: WHY -->``: too long for the suite (a full reproduction, a big study, a
  server); its ``rig`` commands are only parsed by the command line's parser, and the test
  lists them with WHY;
- ``<!-- needs: WHAT -->``: needs what the suite does not have (the reader's own scope
  files); checked as a slow block is (a python block is compiled, not run);
- ``<!-- exit: N -->``: its ``rig`` commands exit with N (default 0);
- ``<!-- json-keys: K1 K2 ... -->``: its last ``rig`` command prints JSON with exactly
  these top-level keys.
"""
from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FENCE = re.compile(r"^```(\w+)[^\n]*\n(.*?)^```[ \t]*$", re.M | re.S)
COMMENT_LINE = re.compile(r"^\s*<!--.*-->\s*$")
MARKER = re.compile(r"<!--\s*(slow|needs|exit|json-keys):\s*(.*?)\s*-->")


@dataclass(frozen=True)
class Block:
    """One fenced block: its page (relative to the repository), first line, language, text
    and the markers above it ({name: value})."""

    page: str
    line: int
    language: str
    text: str
    markers: tuple

    @property
    def where(self) -> str:
        return f"{self.page}:{self.line}"

    def marker(self, name: str) -> str | None:
        return dict(self.markers).get(name)

    @property
    def not_run(self) -> str | None:
        """Why the block is only checked, not run (its slow: or needs: marker), or None."""
        return self.marker("slow") or self.marker("needs")

    def commands(self) -> list:
        """The block's shell commands as argument lists: continuation lines joined, comments
        dropped, ``a && b`` split into its commands."""
        joined = re.sub(r"\\\n", " ", self.text)
        commands = []
        for line in joined.splitlines():
            words = shlex.split(line, comments=True)
            current = []
            for word in words + ["&&"]:
                if word == "&&":
                    if current:
                        commands.append(current)
                    current = []
                else:
                    current.append(word)
        return commands


def pages() -> list:
    """README.md and every Markdown page under docs/, relative to the repository."""
    return ["README.md"] + sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").rglob("*.md"))


def blocks(page: str) -> list:
    """The bash and python blocks of one page, in order."""
    text = (ROOT / page).read_text()
    found = []
    for match in FENCE.finditer(text):
        language = match.group(1)
        if language not in ("bash", "python"):
            continue
        above = []  # the comment lines right above the fence
        for line in reversed(text[:match.start()].splitlines()):
            if not COMMENT_LINE.match(line):
                break
            above.insert(0, line)
        markers = tuple((name, value) for name, value in MARKER.findall("\n".join(above)))
        found.append(Block(page, text.count("\n", 0, match.start()) + 1, language, match.group(2), markers))
    return found
