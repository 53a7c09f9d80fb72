"""The one place that says how hot code is compiled and cached.

Every kernel uses the same flags so that a scene never triggers a second
compile, and the cache written by one run is reused by the next.
"""
import gc
import hashlib
import os
from contextlib import contextmanager
from pathlib import Path

from llvmlite import binding as ll
from numba import config, njit, types
from numba.core.caching import CompileResultCacheImpl, FunctionCache
from numba.core.codegen import JITCodeLibrary
from numba.core.compiler import Compiler
from numba.core.compiler_lock import require_global_compiler_lock
from numba.core.errors import TypingError
from numba.core.registry import CPUDispatcher
from numba.extending import overload
from numba.np.numpy_support import as_dtype

# fastmath without 'nnan' and 'ninf': those let LLVM assume no NaN/inf exists,
# which silently breaks `t_max = inf` and the NaN checks that drop bad samples.
# Nor 'reassoc' and 'contract' (fused multiply-add), which let the result of a
# sum depend on how the code around it was optimised: a step Numba compiles on
# its own (jit_step) is also linked into its caller and optimised again there,
# so the process that compiled a kernel ran one copy and every later process,
# loading it from the cache, ran the other -- the first render and the next
# gave different bits for the same seed (whole different paths in
# bouncing_spheres).  Without them both copies compute the same values
# (tests/test_cache.py); they were worth about 6% of cornell_glass's speed
# (benchmarks/results/measurements.md).
FASTMATH = {"nsz", "arcp", "afn"}

# error_model='numpy': a division by zero gives inf or nan instead of raising,
# and no kernel pays for the zero checks.  Every function is compiled with it,
# steps included, whatever calls them.
_OPTIONS = dict(cache=True, fastmath=FASTMATH, error_model="numpy")
# A step (jit_step): no reference counting (its callers hold the arrays), no
# wrappers for Python; caching is switched on by the dispatcher.
_STEP_OPTIONS = dict(_nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True,
                     fastmath=FASTMATH, error_model="numpy")


PACKAGE = Path(__file__).resolve().parent.parent


def source_digest(root=PACKAGE):
    """A hash of every .py file under `root` (the whole package, subpackages too).

    Numba checks a cached kernel against the timestamp of its own file only,
    not of the files its callees live in: edit path/pdf.py and the render
    kernel would still load the old code.  Keying the cache folder by every
    source file makes any edit (or upgrade) compile afresh.
    """
    h = hashlib.sha256()
    for path in sorted(Path(root).rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


# The sources this process imported (workers of a distributed render compare it).
SOURCE_DIGEST = source_digest()


def _cache_dir():
    """$NUMBA_CACHE_DIR, else the user's cache folder; a subfolder per source hash.

    A user cache folder also works for a read-only installed package.
    """
    base = config.CACHE_DIR or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "rtweekend")
    path = os.path.join(base, f"numba-{SOURCE_DIGEST}")
    try:
        os.makedirs(path, exist_ok=True)
    except OSError:
        return config.CACHE_DIR     # unwritable: Numba's own fallbacks
    return path


# Must be set before the first @njit(cache=True) below creates its cache.
config.CACHE_DIR = _cache_dir()


# How a step's library is kept in the cache: LLVM bitcode for linking, no
# machine code (Numba's own kinds are 'object' and 'bitcode').
STEP_KIND = "rtweekend-step"


class StepLibrary(JITCodeLibrary):
    """A step's code: IR that kernels link in and inline, never run on its own.

    Numba finalises every function it compiles as if it could be called: the
    module optimised at O3 with its callees linked in, then turned into machine
    code.  A step is only ever inlined into its callers, which optimise it
    again there, so each level of a call chain optimised everything below it
    once more, and its machine code was never run.  A step's library stops at
    the per-function passes (run as its IR is added) and the linking of its
    callees; the kernel that inlines it optimises the whole once, and only the
    kernel becomes machine code.
    """

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
        """The codegen, except that a step's environment pointer is not set:
        that needs its module in the engine (its machine code), and a step
        has no use for it (no Python objects, no NRT)."""
        return _NoEnvironment(self._codegen)

    def get_pointer_to_function(self, name):
        """No machine code: no function to point to (a step has no wrapper for
        Python anyway; Python calls it through an entry, jit_step's __call__)."""
        self._ensure_finalized()
        return 0

    def serialize_using_object_code(self):
        return (self.name, STEP_KIND, self._get_module_for_linking().as_bitcode())

    @classmethod
    def _unserialize(cls, codegen, state):
        name, kind, bitcode = state
        if kind != STEP_KIND:
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


class _StepCompiler(Compiler):
    """Numba's pipeline, lowering a step into a StepLibrary."""

    def compile_extra(self, func):
        if self.state.library is None:
            self.state.library = StepLibrary(self.state.targetctx.codegen(), func.__qualname__)
            self.state.library.enable_object_caching()
        return super().compile_extra(func)


class _StepCacheImpl(CompileResultCacheImpl):
    def rebuild(self, target_context, payload):
        # Numba rebuilds a cached result through codegen.unserialize_library;
        # for the duration (under the compiler lock) that is StepLibrary's.
        codegen = target_context.codegen()
        codegen.unserialize_library = lambda state: StepLibrary._unserialize(codegen, state)
        try:
            return super().rebuild(target_context, payload)
        finally:
            del codegen.unserialize_library


class _StepCache(FunctionCache):
    _impl_class = _StepCacheImpl


class _InlinedDispatcher(CPUDispatcher):
    """Numba's dispatcher, but LLVM must inline every function it compiles
    (the LLVM attribute alwaysinline) into whatever calls it."""

    def add_overload(self, cres):
        # Freshly compiled, the function is in the library's module; loaded from
        # the cache, in the bitcode kept for linking (both are what callers link).
        library = cres.library
        for module in (library._final_module, library._shared_module):
            if module is None:
                continue
            try:
                function = module.get_function(cres.fndesc.llvm_func_name)
            except NameError:
                continue
            function.add_function_attribute("alwaysinline")
        super().add_overload(cres)

    def get_call_template(self, args, kws):
        """Typing a call from compiled code: compile for the arguments' types
        without their literal values.  Numba would compile a step once per
        constant it is called with (col(v, 0), col(v, 3), ...); LLVM folds
        the constants once the step is inlined, so those copies cost compile
        time and bought nothing.  A step that needs a constant to type (an
        index into a tuple of mixed types, say) keeps it."""
        plain = tuple(types.unliteral(a) for a in args)
        if plain != tuple(args) and not kws:
            try:
                return super().get_call_template(plain, kws)
            except TypingError:
                pass
        return super().get_call_template(args, kws)

    def __call__(self, *args):
        """From Python (tests, benchmarks): through a small compiled function that
        calls it, made on first use (a step has no wrapper for Python of its own:
        building one for every step cost a tenth of a cold compile)."""
        entries = self.__dict__.setdefault("_entries", {})
        if len(args) not in entries:
            names = ", ".join(f"a{i}" for i in range(len(args)))
            space = {"step": self}
            exec(f"def entry({names}):\n    return step({names})\n", space)
            entries[len(args)] = njit(fastmath=FASTMATH, error_model="numpy")(space["entry"])
        return entries[len(args)](*args)


def jit_step(fn):
    """A step of a kernel (a bounce, a shape's distance, a material's sample):
    compiled once for each signature on its own, then inlined by LLVM into every
    caller.

    Every compiled helper of the kernels is one, down to vec3's dot.  Why not
    the alternatives: Numba's own inlining (inline="always") copies the
    callee's IR into each caller and types it again there, and typing is most of
    a compile (about 1 ms per statement): the path loop written that way took
    8 s to compile.  A plain call passes every array of a NamedTuple argument,
    and returns a tuple, through memory: on the per-bounce helpers that cost
    5-25% of the speed.  Compiled apart and always inlined, each step is typed
    once and runs as if written in place.

    No reference counting (Numba's NRT off, an option that is not public API):
    a step takes the kernel's arrays, which the kernel holds for the whole call,
    and allocates nothing (one that did would fail to compile, loudly).  Called
    from Python, it goes through a compiled entry (__call__ above).  The
    attribute is set on the function after Numba compiles it and before any
    caller links it in (a Numba internal: tests/test_cache.py checks that
    kernels hold no call to a step).
    """
    dispatcher = _InlinedDispatcher(py_func=fn, locals={}, targetoptions=_STEP_OPTIONS,
                                    pipeline_class=_StepCompiler)
    dispatcher._cache = _StepCache(fn)
    return dispatcher


def jit_kernel(fn):
    """An estimator's kernel over a list of image rows, called by the drivers
    from several threads at once (kernel/rows.py).

    nogil: it releases the GIL, so threads render rows side by side, and the
    main thread stays awake to Ctrl-C while it runs (kernel/calls.py)."""
    return njit(nogil=True, **_OPTIONS)(fn)


def jit_parallel(fn):
    """A kernel with a `prange` loop over rows (classic/kernel.py).

    nogil: the drivers call it from a worker thread while the main thread
    waits awake to Ctrl-C (kernel/calls.py); it releases the GIL, or the main
    thread could not run the signal handler until the kernel returned."""
    return njit(parallel=True, nogil=True, **_OPTIONS)(fn)


def like(x, value):
    """value in x's floating-point type: a constant that keeps float32 code float32
    (a float64 literal such as inf would promote what it meets).  The nearest-hit
    search uses it, so benchmarks/precision.py can run it in either precision."""
    return type(x)(value)


@overload(like, inline="always")
def _like(x, value):
    if isinstance(x, types.Float):
        cast = as_dtype(x).type
        return lambda x, value: cast(value)


@contextmanager
def collector_paused():
    """Python's cyclic garbage collector off for a compile, back on after.

    Numba's compiler makes millions of short-lived IR objects (inlining
    deep-copies them), and each collection walks every live object of the
    process: off, a cold compile is faster, more so in a process holding many
    objects (a Dask worker; benchmarks/results/measurements.md).
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
