"""The dispatcher of every kernel (numerics.jit): numba's CPU dispatcher, but a call from
compiled code is typed by its arguments' plain types, never by a constant's literal type.

numba compiles a callee for the types its caller hands it, and a constant argument is of
a literal type (``Literal[int](0)``): each constant then costs one more copy of the callee
and of everything it calls (the analysis' ``_leading(..., 0, ...)`` and ``(..., 1, ...)``
were two, ``index_of`` fourteen), and a flag first typed ``False`` before its loop made it
``bool`` a copy that is never run. A callee's arithmetic is the same for a constant and a
variable (no fastmath: the same bits), so one copy per array layout does.
"""
import time

from numba.core.registry import CPUDispatcher
from numba.core.types import unliteral


class OneTypePerArgument(CPUDispatcher):
    """A CPU dispatcher that compiles a callee for its arguments' plain types."""

    def get_call_template(self, args, kws):
        return super().get_call_template(tuple(unliteral(a) for a in args),
                                         {k: unliteral(v) for k, v in kws.items()})

    def compile(self, sig):
        """Compile (or load from numba's cache) the copy for ``sig``, called from Python or
        from a kernel being compiled. If a side process compiles this kernel
        (instruments/precompile.py), first wait until the cache holds its machine code (or
        that process has ended)."""
        side = SIDE_COMPILES.get(f"{self.py_func.__module__}.{self.py_func.__qualname__}")
        while side is not None and side.poll() is None and not has_machine_code(self):
            time.sleep(POLL_S)
        return super().compile(sig)


SIDE_COMPILES: dict = {}  # {module.kernel: the side process (subprocess.Popen) compiling it}
POLL_S = 0.05  # how often a kernel waiting for a side process looks into numba's cache (s)


def has_machine_code(dispatcher) -> bool:
    """Whether numba's on-disk cache holds machine code of ``dispatcher`` (a ``jit``
    kernel) for this machine and its current source, for any signature. True where numba
    keeps no such cache (nothing to compile ahead then: a command compiles as it goes)."""
    load_index = getattr(getattr(getattr(dispatcher, "_cache", None), "_cache_file", None), "_load_index", None)
    return load_index is None or bool(load_index())
