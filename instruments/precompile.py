"""The instruments' kernels compiled in a side process while the rig compiles its solver.

numba compiles a kernel on its first call, one kernel after the other in one process: a
cold ``rig shot`` compiled the solver, then the gauges, the scope and the analysis. Those
are independent, so on a cold cache the command starts a side process that compiles the
instruments' kernels a task needs (their signatures below) into numba's on-disk cache while
the main process compiles the solver; the main process's first call of one of those
kernels waits until the cache holds it (instruments/dispatcher.py) and loads it from there. A signature that no longer matches what the task calls costs time only (the
main process then compiles that kernel itself); tests/instruments/test_precompile.py
keeps them in step.
"""
from __future__ import annotations

import subprocess
import sys

PACKAGE = "instruments._kernels"
F1, F2 = "float64[::1]", "float64[:, ::1]"
# the kernels a shot calls from Python: {(module of PACKAGE, kernel): its argument types}; the
# analysis first (most of the compile time: numba compiles what a kernel calls with it)
SHOT = {("pulses", "leading_pair"): f"({F1}, {F1}, {F1}, float64, float64, UniTuple(float64, 7), {F1})",
        ("acquisition", "scope_shot"): f"({F2}, float64, int64, float64, boolean, float64, int64, float64, {F1}, "
                                       f"{F1}, {F1}, {F1}, {F2}, float64, float64, int8[:, ::1], boolean[::1], "
                                       f"boolean[::1])",
        ("acquisition", "gauge_signal"): f"({F1}, float64, float64, float64, float64, float64, float64, float64, "
                                         f"{F1})",
        ("acquisition", "condition"): f"({F1}, float64, {F1}, {F1})",
        ("acquisition", "samples_before_input"): "(int64, float64, float64, float64)",
        ("pulses", "conditioned"): f"({F1}, int64, float64, float64, float64)",
        ("pulses", "noise_level"): f"({F1}, int64, float64)",
        ("pulses", "first_peak"): f"({F1},)"}
TASKS = {"shot": SHOT}


def needs_compiling(task: str) -> bool:
    """Whether numba's cache lacks the machine code of any kernel ``task`` calls."""
    from instruments.jit import has_machine_code

    return not all(has_machine_code(_kernel(module, name)) for module, name in TASKS[task])


def start(task: str) -> bool:
    """Start the side process that compiles ``task``'s kernels, when numba's cache lacks any;
    True when started (the caller may say so)."""
    from instruments.dispatcher import SIDE_COMPILES

    if not needs_compiling(task):
        return False
    side = subprocess.Popen([sys.executable, "-c", f"from instruments.precompile import compile_now; "
                                                   f"compile_now({task!r})"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for module, name in TASKS[task]:
        SIDE_COMPILES[f"{PACKAGE}.{module}.{name}"] = side
    return True


def compile_now(task: str) -> None:
    """Compile ``task``'s kernels in this process (numba caches each, with its callees)."""
    for (module, name), signature in TASKS[task].items():
        _kernel(module, name).compile(signature)


def _kernel(module: str, name: str):
    import importlib

    return getattr(importlib.import_module(f"{PACKAGE}.{module}"), name)
