"""How a step (kernel/jit.py jit_step) is compiled: into LLVM IR that kernels
link in and inline, never into machine code of its own; and how a kernel is
optimised once they are in it (KernelLibrary, at the end).

Numba finalises every function it compiles as if it could be called: the
module optimised at O3 with its callees linked in, then turned into machine
code.  A step is only ever inlined into its callers, which optimise it again
there; so each level of a call chain optimised everything below it once more,
and the machine code was never run.  A step's library (StepLibrary) stops at
the per-function passes Numba runs as IR is added, and at linking its callees
in; the kernel that inlines it optimises the whole once, and only the kernel
becomes machine code.  In the cache a step is its IR (bitcode), which a
kernel compiled later links in.

Numba internals this leans on, each checked by tests/test_cache.py (the
same bits compiled and loaded, no step left as a call, a step called from
Python): CPUCodeLibrary's linking and serialisation, the compiler pipeline's
`state.library`, and CompileResult's rebuild through
codegen.unserialize_library.
"""
from llvmlite import binding as ll
from numba.core.codegen import JITCodeLibrary
from numba.core.compiler import Compiler
from numba.core.compiler_lock import require_global_compiler_lock

from . import disk_cache

# How a step's library is kept in the cache: bitcode for linking, no machine
# code (Numba's own kinds are 'object' and 'bitcode').
KIND = "rtweekend-step"


class StepLibrary(JITCodeLibrary):
    """A step's code: IR for linking only (above)."""

    def finalize(self):
        require_global_compiler_lock()
        self._raise_if_finalized()
        seen = set()
        for library in self._linking_libraries:
            if library not in seen:
                seen.add(library)
                self._reload_init.update(library._reload_init)
                self._final_module.link_in(library._get_module_for_linking(), preserve=True)
        self._finalize_dynamic_globals()
        self._finalized = True

    @property
    def codegen(self):
        """The codegen, whose set_env does nothing for a step: setting a
        function's environment needs its module in the JIT engine (machine
        code), and a step has no use for one (no Python objects, no NRT)."""
        return _NoEnvironment(self._codegen)

    def get_pointer_to_function(self, name):
        """No machine code, so no address (a step has no wrapper for Python
        anyway: Python calls it through an entry, jit.py)."""
        self._ensure_finalized()
        return 0

    def serialize_using_object_code(self):
        return (self.name, KIND, self._get_module_for_linking().as_bitcode())

    @classmethod
    def _unserialize(cls, codegen, state):
        name, kind, bitcode = state
        if kind != KIND:
            return JITCodeLibrary._unserialize(codegen, state)
        self = cls(codegen, name)
        self._final_module = ll.parse_bitcode(bitcode)
        self._finalized = True
        return self


class _NoEnvironment:
    """A codegen whose set_env does nothing (StepLibrary.codegen)."""

    def __init__(self, codegen):
        self._codegen = codegen

    def __getattr__(self, name):
        return getattr(self._codegen, name)

    def set_env(self, env_name, env):
        pass


class _IntoLibrary(Compiler):
    """Numba's pipeline, lowering a function into a library of class LIBRARY."""

    LIBRARY = None

    def compile_extra(self, func):
        if self.state.library is None:
            self.state.library = self.LIBRARY(self.state.targetctx.codegen(), func.__qualname__)
            self.state.library.enable_object_caching()
        return super().compile_extra(func)


class StepCompiler(_IntoLibrary):
    """Lowers a step into a StepLibrary."""

    LIBRARY = StepLibrary


class _StepCacheImpl(disk_cache.PackageCache._impl_class):
    def rebuild(self, target_context, payload):
        # Numba rebuilds a cached result through codegen.unserialize_library;
        # for the duration (under the compiler lock) that is StepLibrary's.
        codegen = target_context.codegen()
        codegen.unserialize_library = lambda state: StepLibrary._unserialize(codegen, state)
        try:
            return super().rebuild(target_context, payload)
        finally:
            del codegen.unserialize_library


class StepCache(disk_cache.PackageCache):
    """The package's cache, keeping a step as its IR."""

    _impl_class = _StepCacheImpl


class KernelLibrary(JITCodeLibrary):
    """A kernel's code (jit_kernel): its steps' IR inlined, then optimised once.

    Numba optimises a function's module at O3 after linking its callees in.
    A kernel's steps arrive optimised already, function by function at O3 (as
    Numba adds each one's IR); what is left once they are inlined is folding
    the kernel's constants and arguments through them, which O1 does: the
    kernels run as fast as at O3 with the same bits, and compile sooner
    (benchmarks/results/measurements.md)."""

    def _optimize_final_module(self):
        cheap, cheap_builder = self._codegen._module_pass_manager(
            loop_vectorize=self._codegen._loopvect, slp_vectorize=False,
            opt=self._codegen._opt_level, cost="cheap")
        cheap.run(self._final_module, cheap_builder)        # inlines the steps
        full, full_builder = self._codegen._module_pass_manager(opt=KERNEL_OPT)
        full.run(self._final_module, full_builder)


KERNEL_OPT = 1


class KernelCompiler(_IntoLibrary):
    """Lowers a kernel into a KernelLibrary."""

    LIBRARY = KernelLibrary
