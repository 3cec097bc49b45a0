"""A kernel called only from other kernels is optimised and turned into machine code once,
in its caller's module, not in a library of its own as well (numerics/dispatcher.py).

numba compiles a callee to machine code in a library of its own (LLVM's full optimisation
of its module, then code emission, and a Python wrapper), then links that module into each
caller's and optimises and emits it again there: each level of calls compiles its whole
subtree once more, and a callee's own machine code is never run (its callers run their
copies). A kernel compiled while another kernel is being compiled (a callee: the kernels'
dispatcher counts the depth, ``DEPTH``) gets a ``CalleeLibrary`` instead: its functions are
lowered and given LLVM's per-function optimisation as before, but its module is handed to
its callers as it is, and only a caller called from Python (a ``KernelLibrary``, with every
callee beneath it linked in) runs the module optimisation and emits machine code. The
same operations in the same order reach LLVM (no fastmath: the same bits).

A callee's copy has no Python wrapper and no machine code of its own, so it is neither
called from Python (a call from Python compiles the kernel afresh, as a kernel of its own)
nor kept in numba's on-disk cache (its callers' cached machine code holds it).
"""
import llvmlite.binding as ll
import numba
from numba.core.codegen import JITCodeLibrary
from numba.core.compiler_machinery import FunctionPass, register_pass

DEPTH = [0]  # kernels being compiled, nested (the dispatcher's compile counts them)
TESTED = ((0, 68), (0, 69))
"""numba releases (from, before) whose code libraries this module was tested with: it uses
their private parts (the modules linked, the final module); on another release numba
compiles each callee in a library of its own, as numba does (the same machine code, a
slower compile)."""
ACTIVE = TESTED[0] <= tuple(int(x) for x in numba.__version__.split(".")[:2]) < TESTED[1]


class KernelLibrary(JITCodeLibrary):
    """numba's JIT library, which links a callee's ``CalleeLibrary`` as it is (unoptimised,
    no machine code of its own) and, once it has emitted its own machine code, points the
    callees' environment globals at their environments."""

    def add_linking_library(self, library):
        if isinstance(library, CalleeLibrary) and not library._finalized:
            self._reload_init.update(library._reload_init)
            self._linking_libraries.append(library)
        else:
            super().add_linking_library(library)

    def finalize(self):
        super().finalize()
        codegen = self._codegen
        for library in _callees(self):
            for name, env in library.environments:
                if codegen._engine.get_global_value_address(name):  # 0: dropped by the optimiser
                    codegen.set_env(name, env)  # type: ignore[attr-defined]  # the JIT codegen's


class CalleeLibrary(KernelLibrary):
    """The library of a kernel compiled as a callee: its module is linked into its callers'
    unfinalised (``_get_module_for_linking``); finalised only where a caller outside the
    kernels' compiles (one of numba's own) links it."""

    def __init__(self, codegen, name):
        super().__init__(codegen, name)
        self.environments = []  # (global's name, numba Environment): set once a module defining it is emitted

    @property
    def codegen(self):
        return self._codegen if self._finalized else _Deferred(self)

    def get_pointer_to_function(self, name):
        """0 for a function this library does not define (its Python wrapper, which it has
        none of: numba asks for it once, after lowering), without emitting any code."""
        if not self._finalized:
            try:
                self._final_module.get_function(name)
            except NameError:
                return 0
        return super().get_pointer_to_function(name)

    def _get_module_for_linking(self):
        if self._finalized:
            return super()._get_module_for_linking()
        if self._shared_module is None:
            module = self._final_module.clone()
            for library in dict.fromkeys(self._linking_libraries):
                module.link_in(library._get_module_for_linking(), preserve=True)
            for function in module.functions:
                if not function.is_declaration and function.linkage == ll.Linkage.external:
                    function.linkage = "linkonce_odr"  # as numba's: defined in every caller, merged
            self._shared_module = module
        return self._shared_module


class _Deferred:
    """A callee library's codegen as numba's lowering sees it: an environment is kept for the
    caller to set (the global is not emitted yet); anything else is the codegen's."""

    def __init__(self, library):
        self._library = library

    def set_env(self, name, env):
        self._library.environments.append((name, env))

    def __getattr__(self, name):
        return getattr(self._library._codegen, name)


def _callees(library, seen=None) -> list:
    """``library`` and every CalleeLibrary linked beneath it."""
    seen = {} if seen is None else seen
    if id(library) not in seen:
        seen[id(library)] = library
        for linked in library._linking_libraries:
            if isinstance(linked, CalleeLibrary):
                _callees(linked, seen)
    return [x for x in seen.values() if isinstance(x, CalleeLibrary)]


def is_callee(compile_result) -> bool:
    """Whether a compile result is a callee's copy (no wrapper, no machine code of its own)."""
    return isinstance(getattr(compile_result, "library", None), CalleeLibrary)


@register_pass(mutates_CFG=False, analysis_only=False)
class KernelLibraries(FunctionPass):
    """Before lowering: the library a kernel is lowered into, a CalleeLibrary (and no Python
    wrapper) where it is compiled as a callee of another kernel, else a KernelLibrary."""

    _name = "kernel_libraries"

    def __init__(self):
        FunctionPass.__init__(self)

    def run_pass(self, state):
        if state.library is None and ACTIVE:
            callee = DEPTH[0] > 1
            kind = CalleeLibrary if callee else KernelLibrary
            state.library = kind(state.targetctx.codegen(), state.func_id.func_qualname)
            state.library.enable_object_caching()
            if callee:
                state.flags.no_cpython_wrapper = True
        return True
