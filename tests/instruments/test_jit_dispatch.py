"""A kernel called from another kernel with constant arguments is compiled once, for the
arguments' plain types (numerics/dispatcher.py): numba would compile one copy per
constant (each copy with everything it calls), which was most of a cold start's waste. A
contact law's code handed as a Constant is the one exception: each kernel compiled for that
law alone, the other laws' code never compiled."""
import os
import subprocess
import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np
from numba.core import types

from numerics.jit import jit

ROOT = Path(__file__).resolve().parents[2]


@jit
def _slot(role, field):
    return 1 + 7 * role + field


@jit
def _fill(out):
    for role in (0, 1):  # a constant per call below, and a loop variable
        out[_slot(role, 2)] = role
    out[_slot(0, 3)] = 10.0
    out[_slot(1, 3)] = 11.0
    flag = False
    for x in out:
        flag = flag or x > 10.5
    return _slot(int(flag), 0)


def test_constant_arguments_share_one_compiled_copy_with_the_same_result(tmp_path):
    out = np.zeros(16)
    got = _fill(out)
    assert got == 8 and out[3] == 0.0 and out[10] == 1.0 and out[4] == 10.0 and out[11] == 11.0
    assert _fill.py_func(np.zeros(16)) == got  # plain Python agrees
    # the copies compiled, seen in a fresh process with an empty cache (a cached _fill compiles no _slot)
    probe = ("import numpy as np\nfrom tests.instruments.test_jit_dispatch import _fill, _slot\n"
             "_fill(np.zeros(16))\nprint(repr(_slot.signatures))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT,
                          env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)))
    assert done.stdout.strip() == repr([(types.int64, types.int64)]), done.stdout


class _Contacts(NamedTuple):
    law: int
    scale: float


@jit
def _elastic(x):
    return x * x


@jit
def _yielding(x):
    return -x


@jit
def _force(x, law):
    if law == 3:
        return _yielding(x)
    return _elastic(x)


@jit
def _entry(x, contacts):
    law, scale = contacts
    total = scale * _force(x, law)
    if law == 3:
        total += _yielding(1.0)
    return total


def test_a_law_handed_as_a_constant_compiles_only_its_own_branches_in_every_kernel(tmp_path):
    # each kernel compiled for the law's value; the other law's kernel never compiled (fresh
    # process, empty cache); the results those of plain Python
    probe = ("from numerics.dispatcher import Constant\n"
             "from tests.instruments.test_jit_dispatch import _Contacts, _entry, _force, _yielding\n"
             "print(_entry(3.0, _Contacts(Constant(0), 2.0)), repr(_yielding.signatures), repr(_force.signatures))\n"
             "print(_entry(3.0, _Contacts(Constant(3), 2.0)), repr(_yielding.signatures))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True, cwd=ROOT,
                          env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)))
    hertz, thornton = done.stdout.strip().splitlines()
    assert hertz == f"{_entry.py_func(3.0, _Contacts(0, 2.0))} [] {[(types.float64, types.IntegerLiteral(0))]!r}"
    assert thornton == f"{_entry.py_func(3.0, _Contacts(3, 2.0))} {[(types.float64,)]!r}"
    assert _force(3.0, 3) == -3.0 and _force(3.0, 0) == 9.0  # a plain integer from Python: every branch, typed int64
