"""The one place that says how hot code is compiled and cached.

Every kernel uses the same flags so that a scene never triggers a second
compile, and the cache written by one run is reused by the next.
"""
import gc
import hashlib
import os
from contextlib import contextmanager
from pathlib import Path

from numba import config, njit, types
from numba.extending import overload
from numba.np.numpy_support import as_dtype

# fastmath without 'nnan' and 'ninf': those let LLVM assume no NaN/inf exists,
# which silently breaks `t_max = inf` and the NaN checks that drop bad samples.
# Nor 'reassoc' and 'contract' (fused multiply-add), which let the result of a
# sum depend on how the code around it was optimised: a helper Numba compiles on
# its own (render_row, nee.py's) is also linked into its caller and optimised
# again there, so the process that compiled a kernel ran one copy and every
# later process, loading it from the cache, ran the other -- the first render
# and the next gave different bits for the same seed (whole different paths in
# bouncing_spheres).  Without them both copies compute the same values
# (tests/test_cache.py); they were worth about 6% of cornell_glass's speed
# (benchmarks/results/measurements.md).
FASTMATH = {"nsz", "arcp", "afn"}

# error_model='numpy': a division by zero gives inf or nan instead of raising,
# and no kernel pays for the zero checks.  A helper inlined at Numba's level
# (jit_inline) is compiled with its caller's model, so a test calling it from a
# plain @njit gets Python's; such helpers guard their own divisions.
_OPTIONS = dict(cache=True, fastmath=FASTMATH, error_model="numpy")
# A function compiled on its own and called from compiled code only: no
# reference counting (its callers hold the arrays), no wrappers for Python.
_ALONE = dict(_nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True, **_OPTIONS)


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


def jit(fn):
    """A small helper called from kernels; LLVM inlines what is worth it."""
    return njit(**_OPTIONS)(fn)


def jit_inline(fn):
    """A hot helper that takes arrays, inlined into its caller by Numba itself.

    Each call of a compiled function with array arguments increments and
    decrements every array's reference count (atomic operations); inlining at
    Numba's level removes them.  It costs compile time, so only for the
    helpers called per object or per bounce.
    """
    return njit(inline="always", **_OPTIONS)(fn)


def jit_leaf(fn):
    """A small helper that reads one array (a primitive's row, say), compiled on
    its own without reference counting, for LLVM to inline: no copy of its IR in
    every caller (Numba-level inlining costs compile time), and no atomic count
    updates on its array argument.  Called from compiled code only (no wrapper
    for Python is built)."""
    return njit(**_ALONE)(fn)


def jit_row(fn):
    """The per-row function a prange kernel calls, compiled without reference
    counting (Numba's NRT off).

    The hot helpers take NamedTuples of arrays and are inlined at Numba's level;
    binding such an argument copies the tuple, and with NRT each copy increments
    and decrements the count of every array in it (atomic operations, per object
    tested).  Nothing in a row allocates and the kernel holds every array for
    the whole call, so the counts are not needed: off, they cost nothing (a
    Numba option that is not public API; a function that allocates fails to
    compile, loudly).  Called from the kernel only: no wrapper for Python.
    """
    return njit(**_ALONE)(fn)


def jit_apart(fn):
    """A per-bounce helper that takes NamedTuples, compiled once on its own
    (reference counting off, as jit_row) and called, not inlined: for code whose
    inlined copy would carry another copy of the dispatch on every primitive kind
    (seconds of compile) and which runs rarely enough for a call to cost nothing
    measurable (path/nee.py)."""
    return njit(**_ALONE)(fn)


def jit_parallel(fn):
    """A kernel with a `prange` loop over rows (path/kernel.py, classic/kernel.py).

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
