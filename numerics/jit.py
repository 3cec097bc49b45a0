"""The one numba decorator of the project and the guard that keeps numba's on-disk cache
of a kernel package consistent with its sources.

Every compiled kernel (the chain integrators in rig/solver/kernels/, the instruments'
and the analysis' loops in the instruments' kernel packages) is declared with ``@jit`` (or
``@jit(parallel=True)``): numba's ``njit`` with ``cache=True`` (compiled once per machine,
kept on disk), ``fastmath=False`` (IEEE arithmetic: results bit-identical to numpy's) and
no C-callable wrapper (``no_cfunc_wrapper``: numba builds one for every function by
default, for a function passed as a value, which no kernel does; 4% of the solver's
compile time). A kernel compiled as another kernel's callee is optimised and turned into
machine code once, in its callers' (numerics/callees.py), not in a library of its own too.
A loop that divides and must vectorise takes ``error_model="numpy"`` (a division by zero
gives inf, as in numpy; numba's default checks every divisor, a branch per element).
A kernel package calls ``drop_stale_cache(__name__)`` in its ``__init__``.

OpenMP's threads sleep when a parallel loop ends (OMP_WAIT_POLICY=PASSIVE, unless the
environment says otherwise): by default they spin on the cores for a while, and the
Python threads that come next (a batch's random draws, instruments/devices/batch.acquire) ran 1.8x
slower beside them.
"""
from __future__ import annotations

import functools
import hashlib
import importlib
import inspect
import os
import pkgutil
import types
from pathlib import Path

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # before numba loads its OpenMP layer

OPTIONS = {"cache": True, "fastmath": False}


def jit(function=None, **options):
    """numba's njit with the project's options; ``@jit`` or ``@jit(parallel=True)``. numba
    is loaded here, by the first module that declares a kernel.

    A call from another kernel is typed by its arguments' plain types (one compiled copy
    per array layout, not one per constant argument), but for a ``Constant`` handed to a
    parameter compiled per value (the contacts' law): one copy per value, the other values'
    branches never compiled (numerics/dispatcher.py)."""
    if function is None:
        return lambda f: _declare(f, options)
    return _declare(function, {})


def _declare(function, options: dict):
    """``function`` as a cached ``OneTypePerArgument`` dispatcher with njit's target
    options and ``options``."""
    from numerics.dispatcher import ConstantPipeline, OneTypePerArgument

    targetoptions = {"nopython": True, "boundscheck": None, "fastmath": OPTIONS["fastmath"], "no_cfunc_wrapper": True,
                     **options}
    dispatcher = OneTypePerArgument(py_func=function, locals={}, targetoptions=targetoptions,
                                    pipeline_class=ConstantPipeline)
    if OPTIONS["cache"]:
        dispatcher.enable_caching()
    return dispatcher


@functools.cache
def interpreted(kernel):
    """``kernel`` (a ``jit`` function) run by the Python interpreter, the kernels it calls
    interpreted too: the same float64 operations in the same order as its machine code
    (IEEE arithmetic, no fastmath, libm's pow and sqrt), so the same bits, and nothing to
    compile; for a call too small to pay for a compile (rig.solver.problem.balance_at_rest
    of one short chain: 0.7 s of a cold shot's compile, milliseconds interpreted)."""
    from numba.core.dispatcher import Dispatcher

    f = kernel.py_func
    names = dict(f.__globals__)
    for name in f.__code__.co_names:
        if isinstance(names.get(name), Dispatcher):
            names[name] = interpreted(names[name])
    return types.FunctionType(f.__code__, names, f.__name__, f.__defaults__, f.__closure__)


def kernel(function=None, **options):
    """Mark a function of a module that must stay light to import (a contact law's,
    rig.model.laws, which every scene check reads) as a kernel: plain Python until
    ``compile_kernels`` of its module makes it a ``jit`` one with ``options``, as a kernel
    package does before its own kernels are compiled (they then call it, or inline it)."""
    def mark(f):
        f.jit_options = options
        return f
    return mark if function is None else mark(function)


def compile_kernels(module) -> None:
    """Replace every function of ``module`` marked by ``kernel`` with its jit form (once:
    a jit function is left as it is). numba reads a kernel's globals when it compiles it, so
    the marked functions call each other's jit forms."""
    for name, obj in list(vars(module).items()):
        options = getattr(obj, "jit_options", None)
        if options is not None and not hasattr(obj, "py_func"):
            setattr(module, name, jit(**options)(obj))


def drop_stale_cache(package: str, constants: tuple = ()) -> None:
    """Drop the cached machine code of every kernel of ``package`` when any of its sources
    changed since that code was written.

    numba's cache=True keys each compiled function on its own source file only, but a
    kernel inlines the kernels it calls from the package's other files: after a change to
    a callee alone, its callers' cached code would still hold the old callee. Keying the
    whole package on a digest of all its sources closes that gap (numba then compiles
    afresh, once). ``constants``: modules outside the package whose globals the kernels
    read as compile-time constants (e.g. the contact-law codes); their sources join the
    digest.
    """
    from numba.core.dispatcher import Dispatcher

    root = importlib.import_module(package)
    folder = Path(inspect.getfile(root)).parent
    digest = hashlib.sha256()
    sources = sorted(folder.glob("*.py")) + [Path(inspect.getfile(importlib.import_module(m))) for m in constants]
    for path in sources:
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    modules = [importlib.import_module(f"{package}.{m.name}") for m in pkgutil.iter_modules([str(folder)])]
    caches: dict[str, list] = {}
    for module in modules:
        for obj in vars(module).values():
            cache = getattr(obj, "_cache", None) if isinstance(obj, Dispatcher) else None
            if cache is not None and getattr(cache, "cache_path", None) and hasattr(cache, "flush"):  # None: not cached
                caches.setdefault(cache.cache_path, []).append(cache)
    for cache_dir, members in caches.items():
        stamp = Path(cache_dir) / f"{package}.sources"
        try:
            if stamp.is_file() and stamp.read_text() == digest.hexdigest():
                continue
            for cache in members:
                cache.flush()
            stamp.parent.mkdir(parents=True, exist_ok=True)
            stamp.write_text(digest.hexdigest())
        except OSError:  # a cache folder we cannot write: numba cannot cache there either
            continue
