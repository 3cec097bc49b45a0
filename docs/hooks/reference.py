"""mkdocs hook: the Reference pages written from the code at each build.

- reference/scene-keys.md: every key of rig.experiment.scene.SCHEMA, its unit or type, the
  contact laws' bounds, defaults and meanings (rig.model.laws LawParameter), the other
  keys' defaults (the keyword defaults of the classes the assembly builds from each table),
  the names a key takes (materials, laws, methods), and each key's value in a published scene;
- reference/commands.md: every command and flag of rig.cli.build_parser();
- reference/api.md: mkdocstrings pages for the names rig/__init__.py's facade exports and
  every public module of the instruments package;
- reference/archive.md: the archive layout, from instruments.archive's LAYOUT and the
  docstrings of the archive's modules.

A scene key without a meaning fails the build, so a new key is documented or the site does
not build. Each page is written by a module beside this one (``reference_scene_keys``,
``reference_commands``, ``reference_api``, ``reference_archive``), which mkdocs finds here
while it loads the hook.
"""
from __future__ import annotations

from mkdocs.structure.files import File
from reference_api import api
from reference_archive import archive
from reference_commands import commands
from reference_scene_keys import scene_keys
from reference_text import ROOT

__all__ = ["PAGES", "on_files"]

PAGES = {"reference/scene-keys.md": scene_keys, "reference/commands.md": commands,
         "reference/api.md": api, "reference/archive.md": archive}


def on_files(files, config):
    """Add the generated pages to the site."""
    import sys

    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    for path, write in PAGES.items():
        files.append(File.generated(config, path, content=write()))
    return files
