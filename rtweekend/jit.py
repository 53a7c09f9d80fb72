"""The one place that says how hot code is compiled.

Every kernel uses the same flags so that a scene never triggers a second
compile, and the cache written by one run is reused by the next.
"""
from numba import njit

# fastmath without 'nnan' and 'ninf': those let LLVM assume no NaN/inf exists,
# which silently breaks `t_max = inf` and the NaN checks that drop bad samples.
FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}

# error_model='numpy': a division by zero gives inf instead of raising, so
# ray-plane tests need no branch for parallel rays.
_OPTIONS = dict(cache=True, fastmath=FASTMATH, error_model="numpy")


def jit(fn):
    """A small helper called from kernels; LLVM inlines what is worth it."""
    return njit(**_OPTIONS)(fn)


def jit_parallel(fn):
    """A kernel with a `prange` loop over pixels (only render.py and classic.py)."""
    return njit(parallel=True, **_OPTIONS)(fn)
