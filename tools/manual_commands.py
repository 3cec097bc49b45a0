"""Write the command lists of the emulated scope's manuals (instruments/virtual_scope/manuals/).

Each personality's file holds the SCPI syntax lines of the command groups a waveform
program uses, as ``tm_devices.commands`` (Tektronix's Python package, whose command trees
are generated from the programmer manuals) gives them: one line ``group<TAB>syntax``.
Run with tm_devices installed (it is not a dependency of the project):

    python tools/manual_commands.py

The conformance test (tests/lab/test_manual_conformance.py) and the coverage table
(docs/reference/scpi-coverage.md) read these files. The TDS2000 has no tree there: its list,
manuals/tds2000.txt, is transcribed by hand from its programmer manual (071-1075-04), not
generated. This tool writes only the files of MODELS, so running it leaves that one as it is;
edit it against the manual.
"""
from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path

MODELS = {"mdo3000": "mdo3k_commands", "mso4": "mso4_commands"}  # not tds2000: transcribed, see above
GROUPS = {
    "waveform transfer": ("curve", "curvestream", "data", "wfmoutpre", "wavfrm"),
    "horizontal": ("horizontal",),
    "trigger": ("trigger",),
    "vertical": ("ch", "select"),
    "acquisition": ("acquire",),
    "measurement": ("measurement",),
    "save and recall set-up": ("set", "save_and_recall", "factory", "recall", "save"),
    "display": ("display",),
    "status and events": ("status_and_error", "allev", "busy", "dese", "event", "evmsg", "evqty"),
    "miscellaneous": ("miscellaneous", "header", "verbose", "id", "lock", "unlock", "rem"),
    "configuration": ("configuration",),
}
TRIGGER_KEPT = ("TRIGger", "TRIGger:A", "TRIGger:STATE", "TRIGger:A:EDGE", "TRIGger:A:LEVel", "TRIGger:A:MODe",
                "TRIGger:A:TYPe", "TRIGger:A:HOLDoff")
SYNTAX = re.compile(r"SCPI Syntax:\n\s*```\n(.*?)```", re.S)


def kept(group: str, header: str) -> bool:
    """Within the big trees, the parts a waveform program touches."""
    if group == "trigger":
        return any(header == k or header.startswith(k + ":") for k in TRIGGER_KEPT)
    if group == "save and recall set-up" and header.split(":")[0] in ("SAVe", "RECAll"):
        return header.upper().startswith(("SAVE:SETU", "RECALL:SETU"))
    return True


def lines_of(module_name: str) -> list:
    import tm_devices.commands as commands

    module = importlib.import_module(f"{commands.__name__}.{module_name}")
    source = inspect.getsource(module)
    out = []
    for package, sub in re.findall(r"from \.(gen_\w+)\.(\w+) import", source):
        group = next((g for g, subs in GROUPS.items() if sub in subs), None)
        if group is None:
            continue
        text = inspect.getsource(importlib.import_module(f"{commands.__name__}.{package}.{sub}"))
        for block in SYNTAX.findall(text):
            for line in block.splitlines():
                line = line.strip()
                if line.startswith("- ") and kept(group, line[2:].split(" ")[0].rstrip("?")):
                    out.append(f"{group}\t{line[2:]}")
    return sorted(set(out))


def main() -> None:
    import tm_devices

    folder = Path(__file__).resolve().parent.parent / "instruments" / "virtual_scope" / "manuals"
    for name, module in MODELS.items():
        lines = lines_of(module)
        head = (f"# {name}: SCPI syntax of the command groups a waveform program uses, from "
                f"tm_devices {tm_devices.__version__} ({module}), generated from Tektronix's programmer manual\n")
        (folder / f"{name}.txt").write_text(head + "\n".join(lines) + "\n", encoding="utf-8")
        print(f"{name}: {len(lines)} syntax lines")


if __name__ == "__main__":
    main()
