"""The one place that says how hot code is compiled and cached.

Every kernel uses the same flags so that a scene never triggers a second
compile, and the cache written by one run is reused by the next.
"""
import gc
import hashlib
from contextlib import contextmanager
from pathlib import Path

from numba import njit, types
from numba.core.errors import TypingError
from numba.core.typing import signature
from numba.core.typing.templates import make_concrete_template
from numba.core.registry import CPUDispatcher
from numba.extending import overload
from numba.np.numpy_support import as_dtype

from . import claims, typing_costs  # noqa: F401  (typing_costs: installed on import)
from .disk_cache import PackageCache
from .step_library import KernelCompiler, StepCache, StepCompiler

# fastmath without 'nnan' and 'ninf': those let LLVM assume no NaN/inf exists,
# which silently breaks `t_max = inf` and the NaN checks that drop bad samples.
# Nor 'reassoc' and 'contract' (fused multiply-add), which let the result of a
# sum depend on how the code around it was optimised: a step Numba compiles on
# its own (jit_step) is also linked into its caller and optimised again there,
# so the process that compiled a kernel ran one copy and every later process,
# loading it from the cache, ran the other -- the first render and the next
# gave different bits for the same seed (whole different paths in
# bouncing_spheres).  Without them both copies compute the same values
# (tests/test_cache.py); what they were worth: benchmarks/results/measurements.md.
FASTMATH = {"nsz", "arcp", "afn"}

# error_model='numpy': a division by zero gives inf or nan instead of raising,
# and no kernel pays for the zero checks.  Every function is compiled with it,
# steps included, whatever calls them.
# No function here is called from C through a pointer (a cfunc or a first-class
# function value): Python calls kernels, host functions and step entries
# through their wrappers for Python, so none gets the wrapper for C either
# (one more function per signature to build and optimise).
_NO_C = dict(no_cfunc_wrapper=True)
_OPTIONS = dict(fastmath=FASTMATH, error_model="numpy", **_NO_C)
# A step (jit_step): no reference counting (its callers hold the arrays), no
# wrappers for Python, compiled into IR for kernels only (step_library.py).
_STEP_OPTIONS = dict(_OPTIONS, _nrt=False, no_cpython_wrapper=True)


PACKAGE = Path(__file__).resolve().parent.parent


def source_digest(root=PACKAGE):
    """A hash of every .py file under `root` (the whole package, subpackages
    too): the workers of a distributed render must run the same sources
    (distributed/worker.py).  The cache keys each kernel by the sources it is
    built from (disk_cache.py)."""
    h = hashlib.sha256()
    for path in sorted(Path(root).rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


# The sources this process imported (workers of a distributed render compare it).
SOURCE_DIGEST = source_digest()


def _cached(dispatcher):
    """The dispatcher, with its compiled code kept in the package's cache."""
    dispatcher._cache = PackageCache(dispatcher.py_func)
    return dispatcher


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
            function.add_function_attribute(self.__dict__.get("_inline", "alwaysinline"))
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
                return self._call_template(plain, kws)
            except TypingError:
                pass
        return self._call_template(args, kws)

    def _call_template(self, args, kws):
        """Numba's, except in a compile shared with a helper process
        (kernel/claims.py): a step the helper has claimed is only typed here,
        and its code taken from the cache when a caller is lowered
        (get_overload)."""
        session = claims.current()
        if session is not None and not kws:
            pysig, args = self._compiler.fold_argument_types(args, kws)
            args = tuple(args)
            if args not in self.overloads:
                key = session.key(self, args)
                if not session.claim(key) and not session.is_done(key):
                    typed = self.__dict__.setdefault("_typed", {})
                    if args not in typed:
                        typed[args] = claims.return_type(self, args)
                    template = make_concrete_template(
                        f"CallTemplate({self.py_func.__name__})", key=self.py_func.__name__,
                        signatures=[signature(typed[args], *args)])
                    return template, pysig, args, {}
        return super().get_call_template(args, kws)

    def compile(self, sig):
        """Numba's, marking a claimed step done (in the cache) for the other
        process, or waiting for it to be where the other process claimed it."""
        session = claims.current()
        if session is None:
            return super().compile(sig)
        args = claims.normalized(sig)
        if args in self.overloads:
            return super().compile(sig)
        key = session.key(self, args)
        if session.claim(key):
            try:
                return super().compile(sig)
            finally:
                session.done(key)
        session.wait(key)
        return super().compile(sig)       # from the cache (or here, if it failed there)

    def get_overload(self, sig):
        """A step only typed here (its code is the helper's): wait for it in
        the cache, and load it, when a caller is lowered."""
        args = claims.normalized(sig)
        if args not in self.overloads and args in self.__dict__.get("_typed", {}):
            self.compile(args)
        return super().get_overload(sig)

    def __call__(self, *args):
        """From Python (tests, benchmarks): through a small compiled function that
        calls it, made on first use (a step has no wrapper for Python of its own:
        building one for every step cost a tenth of a cold compile)."""
        entries = self.__dict__.setdefault("_entries", {})
        if len(args) not in entries:
            names = ", ".join(f"a{i}" for i in range(len(args)))
            space = {"step": self}
            exec(f"def entry({names}):\n    return step({names})\n", space)
            entries[len(args)] = njit(**_OPTIONS)(space["entry"])
        return entries[len(args)](*args)


def jit_step(fn=None, *, inline=True, exact=False):
    """A step of a kernel (a bounce, a shape's distance, a material's sample):
    compiled once for each signature on its own, then inlined by LLVM into every
    caller.

    Every compiled helper of the kernels is one, down to vec3's dot.  Why not
    the alternatives: Numba's own inlining (inline="always") copies the
    callee's IR into each caller and types it again there, and typing is most of
    a compile.  A plain call passes every array of a NamedTuple argument, and
    returns a tuple, through memory, which the per-bounce helpers feel.
    Compiled apart and always inlined, each step is typed once and runs as if
    written in place (benchmarks/results/measurements.md has the figures).

    No reference counting (Numba's NRT off, an option that is not public API):
    a step takes the kernel's arrays, which the kernel holds for the whole call,
    and allocates nothing (one that did would fail to compile, loudly).  Called
    from Python, it goes through a compiled entry (__call__ above).  The
    attribute is set on the function after Numba compiles it and before any
    caller links it in (a Numba internal: tests/test_cache.py checks that
    kernels hold no call to a step).

    exact=True: without the fastmath flags, for a step of code that must
    compute as NumPy does (the BVH builder's, bvh_build.py).

    inline=False: the step is called, not inlined -- one copy of it in a
    kernel that calls it from several places.  For a large step whose call
    costs nothing next to its work (bdpt's visibility test, its subpaths'
    walk): each inlined copy is seconds of compile.
    """
    if fn is None:
        return lambda fn: jit_step(fn, inline=inline, exact=exact)
    options = dict(_STEP_OPTIONS, fastmath=False) if exact else _STEP_OPTIONS
    dispatcher = _InlinedDispatcher(py_func=fn, locals={}, targetoptions=options,
                                    pipeline_class=StepCompiler)
    dispatcher._cache = StepCache(fn)
    dispatcher._inline = "alwaysinline" if inline else "noinline"
    return dispatcher


def jit_kernel(fn):
    """An estimator's kernel over a list of image rows, called by the drivers
    from several threads at once (kernel/rows.py).

    nogil: it releases the GIL, so threads render rows side by side, and the
    main thread stays awake to Ctrl-C while it runs (kernel/calls.py)."""
    return _cached(njit(nogil=True, pipeline_class=KernelCompiler, **_OPTIONS)(fn))


def jit_parallel(fn):
    """A kernel with a `prange` loop over rows (classic/kernel.py).

    nogil: the drivers call it from a worker thread while the main thread
    waits awake to Ctrl-C (kernel/calls.py); it releases the GIL, or the main
    thread could not run the signal handler until the kernel returned."""
    return _cached(njit(parallel=True, nogil=True, **_OPTIONS)(fn))


def jit_host(fn=None, *, nogil=False):
    """A compiled function called from Python that is no render kernel: the
    scene's packing, the BVH build, the OBJ reader.  Numba's defaults (no
    fastmath: nothing here is in the image's hot path), the package's cache;
    nogil for one that threads of ours run side by side (kernel/rows.py)."""
    if fn is None:
        return lambda fn: jit_host(fn, nogil=nogil)
    return _cached(njit(nogil=nogil, **_NO_C)(fn))


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
