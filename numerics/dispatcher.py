"""The dispatcher of every kernel (numerics.jit): numba's CPU dispatcher, but a call from
compiled code is typed by its arguments' plain types, never by a constant's literal type,
except for the parameters compiled per value (``PER_VALUE``).

numba compiles a callee for the types its caller hands it, and a constant argument is of
a literal type (``Literal[int](0)``): each constant then costs one more copy of the callee
and of everything it calls (the analysis' ``_leading(..., 0, ...)`` and ``(..., 1, ...)``
were two, ``index_of`` fourteen), and a flag first typed ``False`` before its loop made it
``bool`` a copy that is never run. A callee's arithmetic is the same for a constant and a
variable (no fastmath: the same bits), so one copy per array layout does.

A parameter named in ``PER_VALUE`` (the contacts' law code of the chain's kernels) is the
opposite: a ``Constant`` handed to a kernel from Python, alone or as a field of a named
tuple, is typed by its value, each kernel it reaches is compiled for that value, and the
compiler takes it as the constant it is (``ConstantArguments``): the branches of the other
values are dropped before numba types them, so the kernels they call are never compiled (a
Hertz chain compiles no Thornton code). One copy per value used, the same operations on
the branch taken (the same bits).
"""
import logging
import os
import time
from dataclasses import dataclass

from numba.core import ir, sigutils, types
from numba.core.caching import FunctionCache
from numba.core.compiler import CompilerBase, DefaultPassBuilder
from numba.core.compiler_machinery import FunctionPass, register_pass
from numba.core.ir_utils import get_definition, guard
from numba.core.registry import CPUDispatcher
from numba.core.typed_passes import NopythonTypeInference
from numba.core.types import unliteral
from numba.core.untyped_passes import IRProcessing
from numba.extending import typeof_impl

from numerics.callees import DEPTH, KernelLibraries, is_callee

PER_VALUE = frozenset({"law", "flows", "multirate"})  # the parameters compiled per value (module doc)


@dataclass(frozen=True, eq=False)
class Constant:
    """An integer that the kernels it is handed to are compiled for (numba types it as its
    literal value; a parameter named in PER_VALUE keeps that type in every callee). In
    Python it is its value: equal to it, hashed as it."""

    value: int

    def __index__(self):
        return int(self.value)

    def __eq__(self, other):
        return int(self.value) == (int(other.value) if isinstance(other, Constant) else other)

    def __hash__(self):
        return hash(int(self.value))


@typeof_impl.register(Constant)
def _typeof_constant(val, c):
    return types.IntegerLiteral(int(val.value))


@register_pass(mutates_CFG=True, analysis_only=False)
class ConstantArguments(FunctionPass):
    """Replace each read of an argument of integer literal type, and of such a field of a
    tuple argument (``law, con, state = contacts``), with the constant it is, so that
    numba's dead-branch pruning, which follows, drops the branches of the other values."""

    _name = "constant_arguments"

    def __init__(self):
        FunctionPass.__init__(self)

    def run_pass(self, state):
        func_ir, changed = state.func_ir, False
        arguments = {stmt.target.name: state.args[stmt.value.index]  # {variable: the type of the argument it holds}
                     for block in func_ir.blocks.values() for stmt in block.body
                     if isinstance(stmt, ir.Assign) and isinstance(stmt.value, ir.Arg)}
        for block in func_ir.blocks.values():
            for stmt in block.body:
                if isinstance(stmt, ir.Assign):
                    ty = _read_type(func_ir, stmt.value, state.args, arguments)
                    if isinstance(ty, types.IntegerLiteral):
                        stmt.value = ir.Const(ty.literal_value, stmt.loc)
                        changed = True
        return changed


def _read_type(func_ir, expr, args, arguments):
    """The type of the argument, or of the tuple argument's field, that ``expr`` reads; None
    for any other expression."""
    if isinstance(expr, ir.Arg):
        return args[expr.index]
    if not (isinstance(expr, ir.Expr) and expr.op == "static_getitem" and isinstance(expr.index, int)):
        return None
    source = guard(get_definition, func_ir, expr.value)  # None where the variable is defined more than once
    whole = source.value if isinstance(source, ir.Expr) and source.op == "exhaust_iter" else expr.value
    ty = arguments.get(getattr(whole, "name", None))
    fields = getattr(ty, "types", ()) if isinstance(ty, types.BaseTuple) else ()  # every numba tuple type's fields
    return fields[expr.index] if expr.index < len(fields) else None


class ConstantPipeline(CompilerBase):
    """numba's nopython pipeline with ConstantArguments before its dead-branch pruning, and
    the kernels' libraries (numerics/callees.py) before lowering."""

    def define_pipelines(self):
        passes = DefaultPassBuilder.define_nopython_pipeline(self.state)
        passes.add_pass_after(ConstantArguments, IRProcessing)
        passes.add_pass_after(KernelLibraries, NopythonTypeInference)
        passes.finalize()
        return [passes]


class OneTypePerArgument(CPUDispatcher):
    """A CPU dispatcher that compiles a callee for its arguments' plain types (a PER_VALUE
    parameter's literal kept)."""

    def get_call_template(self, args, kws):
        names = self.py_func.__code__.co_varnames[:self.py_func.__code__.co_argcount]
        return super().get_call_template(tuple(_plain(a, n) for a, n in zip(args, names)) + args[len(names):],
                                         {k: _plain(v, k) for k, v in kws.items()})

    def typeof_pyval(self, val):
        """numba's type of ``val``, a named tuple's Constant fields by their value (numba's
        own typeof makes a named tuple's fields plain)."""
        if isinstance(val, tuple) and hasattr(val, "_fields") and any(isinstance(x, Constant) for x in val):
            return types.NamedTuple([self.typeof_pyval(x) for x in val], type(val))
        return super().typeof_pyval(val)

    def compile(self, sig):
        """Compile (or load from numba's cache) the copy for ``sig``, called from Python or
        from a kernel being compiled (then a callee's copy, numerics/callees.py; called from
        Python, a kernel compiled as a callee only is compiled again, as a kernel of its
        own). If a side process compiles this kernel (instruments/precompile.py), first
        wait until the cache holds its machine code (or that process has ended)."""
        side = SIDE_COMPILES.get(f"{self.py_func.__module__}.{self.py_func.__qualname__}")
        while side is not None and side.poll() is None and not has_machine_code(self):
            time.sleep(POLL_S)
        args, _ = sigutils.normalize_signature(sig)
        if DEPTH[0] == 0 and is_callee(self.overloads.get(tuple(args))):
            del self.overloads[tuple(args)]
        DEPTH[0] += 1
        try:
            return super().compile(sig)
        finally:
            DEPTH[0] -= 1

    def add_overload(self, cres):
        """numba's, but a callee's copy is not entered in the table of calls from Python."""
        if is_callee(cres):
            self.overloads[tuple(cres.signature.args)] = cres
        else:
            super().add_overload(cres)

    def enable_caching(self):
        self._cache = SavedIfRoom(self.py_func)


class SavedIfRoom(FunctionCache):
    """numba's on-disk cache of a kernel, whose machine code is saved where the disk takes it:
    a save that fails (a full disk, a file-size limit, a read-only cache folder) leaves the
    compiled kernel running and the command going on, as if the cache were off (numba lets
    the OSError end the command; its temporary file is removed either way). The next
    command compiles that kernel again; the failure is logged (numerics.dispatcher, INFO).
    A callee's copy is not kept (it has no machine code of its own: its callers' holds it)."""

    def save_overload(self, sig, data):
        if is_callee(data):
            return
        try:
            super().save_overload(sig, data)
        except OSError as e:
            LOG.info("numba's cache kept no machine code of %s%s: %s", self._name, sig, e)


LOG = logging.getLogger(__name__)


def _plain(ty, name):
    """``ty`` as a callee's parameter ``name`` is compiled for: its plain type, unless a
    PER_VALUE parameter's integer literal."""
    return ty if name in PER_VALUE and isinstance(ty, types.IntegerLiteral) else unliteral(ty)


SIDE_COMPILES: dict = {}  # {module.kernel: the side process (subprocess.Popen) compiling it}
POLL_S = 0.05  # how often a kernel waiting for a side process looks into numba's cache (s)


def has_machine_code(dispatcher) -> bool:
    """Whether numba's on-disk cache holds machine code of ``dispatcher`` (a ``jit``
    kernel) for this machine and its current source, for any signature. True where numba
    keeps no such cache (nothing to compile ahead then: a command compiles as it goes).
    numba writes a new entry's index before its data file (each replaced whole), so an
    entry counts once its data file is there too: a kernel that another process is saving
    is not loaded (a miss, compiled again) in between."""
    cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
    if cache_file is None:
        return True
    return any(os.path.exists(cache_file._data_path(name)) for name in cache_file._load_index().values())
