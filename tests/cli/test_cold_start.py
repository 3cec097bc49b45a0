"""A cold start: the first `rig shot` with an empty numba cache says in one line what it
compiles, compiles the instruments' kernels in a side process (instruments/precompile.py)
and gives the bits of a warm shot; the side process compiles exactly the signatures a shot
calls (else the main process would compile them again, and the side process be waste)."""
import json
import os
import subprocess
import sys

from numba.core.sigutils import normalize_signature

from instruments.precompile import PACKAGE, SHOT, compile_now
from rig.cli import main

SHOT_ARGS = ["shot", "ptfe52_magnetic", "--seed", "1", "--json"]


def _kernel(module, name):
    import importlib

    return getattr(importlib.import_module(f"{PACKAGE}.{module}"), name)


def test_the_side_process_compiles_the_signatures_a_shot_calls(capsys):
    compile_now("shot")
    assert main(SHOT_ARGS) in (0, None)
    for (module, name), signature in SHOT.items():
        assert _kernel(module, name).signatures == [normalize_signature(signature)[0]], (module, name)


def test_a_cold_shot_says_what_it_compiles_once_and_has_the_warm_bits(tmp_path):
    warm = subprocess.run([sys.executable, "-m", "rig.cli", *SHOT_ARGS], capture_output=True, text=True, check=True)
    assert "compiling" not in warm.stderr
    cold = subprocess.run([sys.executable, "-m", "rig.cli", *SHOT_ARGS], capture_output=True, text=True, check=True,
                          env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)))
    lines = cold.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rig shot: numba is compiling the chain solver and the "
                                                   "instruments (in a second process)"), cold.stderr
    assert _bits(json.loads(cold.stdout)) == _bits(json.loads(warm.stdout))


def _bits(out):
    """A shot's JSON less its timings (wall_s)."""
    if isinstance(out, dict):
        return {k: _bits(v) for k, v in out.items() if k != "wall_s"}
    return [_bits(v) for v in out] if isinstance(out, list) else out
