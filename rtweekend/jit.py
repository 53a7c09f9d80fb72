"""The one place that says how hot code is compiled and cached.

Every kernel uses the same flags so that a scene never triggers a second
compile, and the cache written by one run is reused by the next.
"""
import gc
import hashlib
import os
from contextlib import contextmanager
from pathlib import Path

from numba import config, njit

# fastmath without 'nnan' and 'ninf': those let LLVM assume no NaN/inf exists,
# which silently breaks `t_max = inf` and the NaN checks that drop bad samples.
FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}

# error_model='numpy': a division by zero gives inf instead of raising, so
# ray-plane tests need no branch for parallel rays.
_OPTIONS = dict(cache=True, fastmath=FASTMATH, error_model="numpy")


def _source_digest():
    """A hash of the package's sources.

    Numba checks a cached kernel against the timestamp of its own file only,
    not of the files its callees live in: edit pdf.py and render_pass would
    still load the old code.  Keying the cache folder by every source file
    makes any edit (or upgrade) compile afresh.
    """
    h = hashlib.sha256()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


# The sources this process imported (workers of a distributed render compare it).
SOURCE_DIGEST = _source_digest()


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


def jit_parallel(fn):
    """A kernel with a `prange` loop over pixels (only render.py and classic.py)."""
    return njit(parallel=True, **_OPTIONS)(fn)


@contextmanager
def collector_paused():
    """Python's cyclic garbage collector off for a compile, back on after.

    Numba's compiler makes millions of short-lived IR objects (inlining
    deep-copies them), and each collection walks every live object of the
    process: off, a cold compile is 10-15% faster, more in a process holding
    many objects (a Dask worker).
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
