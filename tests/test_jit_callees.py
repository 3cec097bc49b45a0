"""A kernel called only from other kernels is optimised and emitted once, in its callers'
machine code (numerics/callees.py): its own copy has no machine code, no Python wrapper and
no cache entry, a call from Python compiles it as a kernel of its own, and its loops still
vectorise in the caller. Each case runs in a fresh process with an empty numba cache."""
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from numerics.callees import ACTIVE, TESTED
from numerics.jit import jit

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.skipif(not ACTIVE, reason=f"numba releases {TESTED} only: others compile as numba does")


@jit
def _roots(x, out):
    """out = sqrt(x) element by element (a loop LLVM vectorises)."""
    for i in range(x.shape[0]):
        out[i] = math.sqrt(x[i])


@jit
def _middle(x, out):
    _roots(x, out)
    return out[0] + out[-1]


@jit
def _outer(x, out):
    return 2.0 * _middle(x, out)


def _run(probe: str, cache: Path) -> list:
    head = "import numpy as np\nfrom tests.test_jit_callees import _middle, _outer, _roots\n"
    done = subprocess.run([sys.executable, "-c", head + probe], capture_output=True, text=True, cwd=ROOT,
                          env=dict(os.environ, NUMBA_CACHE_DIR=str(cache)))
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout.split()


def test_callees_have_no_copy_of_their_own_and_a_call_from_python_compiles_one(tmp_path):
    probe = """
from numerics.callees import CalleeLibrary
from numerics.dispatcher import has_machine_code
x = np.arange(64.0); out = np.empty(64)
print(_outer(x, out) == 2.0 * (0.0 + np.sqrt(63.0)), np.array_equal(out, np.sqrt(x)))
lib = lambda k: next(iter(k.overloads.values())).library
print(isinstance(lib(_middle), CalleeLibrary), isinstance(lib(_roots), CalleeLibrary), lib(_roots)._finalized)
print(has_machine_code(_outer), has_machine_code(_middle), has_machine_code(_roots))
y = np.empty(64)
_roots(x, y)  # from Python: compiled again, with machine code and a wrapper of its own
print(np.array_equal(y, np.sqrt(x)), isinstance(lib(_roots), CalleeLibrary), has_machine_code(_roots))
print(_middle(x, out) == np.sqrt(63.0), _outer(x, out) == 2.0 * np.sqrt(63.0))
"""
    assert _run(probe, tmp_path) == ["True", "True", "True", "True", "False", "True", "False", "False",
                                     "True", "False", "True", "True", "True"]
    # a later process loads the callers' machine code from the cache, the callees' inside it
    warm = ("x = np.arange(64.0); out = np.empty(64)\n"
            "print(_outer(x, out) == 2.0 * np.sqrt(63.0), len(_middle.overloads))")
    assert _run(warm, tmp_path) == ["True", "0"]


def test_a_callees_loop_vectorises_in_its_caller(tmp_path):
    probe = """
x = np.arange(64.0); out = np.empty(64)
_outer(x, out)
import re
ir = "\\n".join(_outer.inspect_llvm().values())
print(bool(re.search(r"llvm\\.sqrt\\.v\\d+f64", ir)))
"""
    assert _run(probe, tmp_path) == ["True"]


def test_the_kernels_agree_with_plain_python():
    x = np.linspace(0.0, 9.0, 33)
    out, ref = np.empty(33), np.empty(33)
    assert _outer(x, out) == _outer.py_func(x, ref) and np.array_equal(out, ref)
