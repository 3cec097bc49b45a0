"""Kernels compiled in a side process while the command compiles the others.

numba compiles a kernel on its first call, one kernel after the other in one process: a
cold ``rig shot`` compiled the solver, then the gauges, the scope and the analysis. Much of
that is independent, so on a cold cache a command starts a side process that compiles the
instruments' kernels it needs (below) into numba's on-disk cache while the main process
compiles the chain solver. When the main
process needs one of those kernels, called from Python or from a kernel it compiles, it
waits until the cache holds it (numerics/dispatcher.py) and loads it from there. A
signature that no longer matches what the command calls costs time only (the main process
then compiles that kernel itself); tests/cli/test_cold_start.py keeps them in step.
"""
from __future__ import annotations

import atexit
import importlib
import subprocess
import sys

ANALYSIS, DEVICES = "instruments.analysis._kernels", "instruments.devices._kernels"  # the wings' kernel packages
F1, F2 = "float64[::1]", "float64[:, ::1]"
# the instruments' kernels a shot compiles aside: {module.kernel: its argument types}; its analysis (about
# 6.4 s CPU on one core here: numba compiles what a kernel calls with it), and the pulse train's candidates
# (0.7 s: inlined in the leading pair's, so compiled on their own for the train's call from Python; a study
# compiles those itself, while it waits for its batches' kernels)
LEADING = {f"{ANALYSIS}.pulses.leading_pair": f"({F1}, {F1}, {F1}, float64, float64, UniTuple(float64, 7), {F1})"}
SHOT = {**LEADING, f"{ANALYSIS}.pulses.candidates": f"({F1}, float64, float64, int64, float64)"}
# the others a shot calls from Python, small (about 2.3 s in all), compiled aside after the analysis: the
# solver's compile (about 11 s) outlasts both
SHOT_SMALL = {f"{DEVICES}.acquisition.scope_shot": f"({F2}, float64, int64, float64, boolean, float64, float64, int64, "
                                                   f"float64, "
                                                   f"{F1}, {F1}, {F1}, {F1}, {F2}, float64, float64, int8[:, ::1], "
                                                   f"boolean[::1], boolean[::1])",
              f"{DEVICES}.acquisition.gauge_signal": f"({F1}, float64, float64, float64, float64, float64, float64, "
                                                     f"float64, {F1})",
              f"{DEVICES}.acquisition.condition": f"({F1}, float64, {F1}, {F1})",
              f"{DEVICES}.acquisition.samples_before_input": "(int64, float64, float64, float64)",
              f"{ANALYSIS}.baseline.conditioned": f"({F1}, int64, float64, float64, float64)",
              f"{ANALYSIS}.baseline.noise_level": f"({F1}, int64, float64)",
              f"{ANALYSIS}.pulses.first_peaks": "(int64, int64, float64[:, :, ::1], int64[::1], int64[:, ::1])"}
B1, I1, I8 = "boolean[::1]", "int64[::1]", "int8[:, :, ::1]"
F3 = "float64[:, :, ::1]"
# and those a study's batches call (its nominal shot calls SHOT's): the acquisition and the analysis of many shots
STUDY = {f"{DEVICES}.acquisition.shots": f"(int64, int64, {I1}, {F3}, float64, {F1}, {F3}, "
                                         f"Tuple(({F1}, {F1}, {B1}, {F1}, {B1}, {F2}, {F1})), "
                                         f"Tuple(({I1}, {F1}, {F2}, {F2}, int64, float64, boolean, int64, float64, "
                                         f"{F1}, {F1}, {F1}, {F1}, float64, float64, boolean, boolean)), {B1}, int64, "
                                         f"{I1}, {I8}, boolean[:, ::1], {I1}, {F2}, {F3})",
         f"{ANALYSIS}.batch_analysis.analyse_range": f"(int64, int64, {I8}, {I1}, {F2}, float64, int64, {F1}, {F1}, "
                                                   f"{F1}, {I1}, {I1}, "
                                                   f"{F1}, {F1}, UniTuple(float64, 7), {F2}, {F2}, {B1}, "
                                                   f"boolean[:, ::1])"}
# and the shots' drawn values, small: a study draws them first thing, so it compiles them itself (aside, it
# would wait for them behind the solver's and the analysis' kernels)
STUDY_SMALL = {"instruments._kernels.pcg64.spawned_draws": f"(uint64[::1], int64, {B1}, {I1}, {F2}, uint64[::1])"}


def needs_compiling(kernels: dict) -> bool:
    """Whether numba's cache lacks the machine code of any of ``kernels`` (module.kernel names)."""
    from numerics.dispatcher import has_machine_code

    return not all(has_machine_code(kernel(name)) for name in kernels)


def start(kernels: dict, then: dict | None = None) -> bool:
    """Start a side process compiling ``kernels`` ({module.kernel: argument types}, in this
    order) when numba's cache lacks any; True when started (the caller may say so). The
    command waits for these when it needs them; ``then``, compiled after them, it does not
    (it compiles them itself where it gets there first): kernels that it calls soon, small,
    which a later command needs (a study's leaves the cache holding all a shot needs)."""
    from numerics.dispatcher import SIDE_COMPILES

    if not needs_compiling(kernels):
        return False
    side = subprocess.Popen([sys.executable, "-c", "import sys; from instruments.precompile import compile_now; "
                                                   "compile_now(dict(zip(sys.argv[1::2], sys.argv[2::2])))",
                             *[x for item in {**kernels, **(then or {})}.items() for x in item]],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for name in kernels:
        SIDE_COMPILES[name] = side
    atexit.register(finish, side)
    return True


def stop() -> None:
    """Stop every side process ``start`` started (the command refused its input: nothing
    will wait for their kernels); numba's cache stays whole (``finish``)."""
    from numerics.dispatcher import SIDE_COMPILES

    for side in set(SIDE_COMPILES.values()):
        side.kill()
        side.wait()
    SIDE_COMPILES.clear()


def finish(side: subprocess.Popen, wait_s: float = 30.0) -> None:
    """At the command's exit: let the side process end its compiles (``then``'s may outlast
    the command) for up to ``wait_s`` seconds, then stop it, so none outlives the command (a
    stopped compile leaves numba's cache whole: each of its files is replaced whole, and
    has_machine_code counts an entry once its data is there)."""
    try:
        side.wait(timeout=wait_s)
    except subprocess.TimeoutExpired:
        side.kill()
        side.wait()


def compile_now(kernels: dict) -> None:
    """Compile ``kernels`` in this process, in their order (numba caches each, with its callees),
    each for the tuple of its argument types: numba's cache keys a copy on what ``compile``
    was given, and the main process looks it up by that tuple."""
    from numba.core.sigutils import normalize_signature

    for name, signature in kernels.items():
        kernel(name).compile(normalize_signature(signature)[0])


def kernel(name: str):
    """The kernel (a jit dispatcher) of qualified name ``module.kernel``."""
    module, _, function = name.rpartition(".")
    return getattr(importlib.import_module(module), function)
