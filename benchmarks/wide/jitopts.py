"""Compile flags of the prototype, and a cycle counter usable in nopython code.

The flags are rtweekend's (kernel/jit.py): fastmath without nnan/ninf (the
kernels compare with inf and test for NaN), numpy's error model (a division by
zero gives inf, no zero test in the loops, which would stop vectorisation),
no bounds checks.

Cached, in a folder of its own keyed by a hash of rtweekend's sources AND of
this folder's (the kernels inline rtweekend's helpers and call each other, and
Numba alone only notices edits to a kernel's own file): the benchmark starts
many fresh processes.  WIDE_NO_CACHE=1 compiles afresh (for cold compile
times); WIDE_FASTMATH=0 compiles without fastmath (asm.py: what vectorises).
"""
import os
from pathlib import Path

from llvmlite import ir
from numba import config, njit, types
from numba.extending import intrinsic

import rtweekend  # noqa: F401  (every rtweekend kernel created with its own cache folder)
from rtweekend.kernel.jit import SOURCE_DIGEST, source_digest

FASTMATH = {"nsz", "arcp", "contract", "afn", "reassoc"}
if os.environ.get("WIDE_FASTMATH") == "0":
    FASTMATH = set()
CACHE = os.environ.get("WIDE_NO_CACHE") != "1"
_OPTS = dict(fastmath=FASTMATH, error_model="numpy", boundscheck=False, cache=CACHE)

# Numba's locator reads config.CACHE_DIR when a kernel is decorated: the folder
# set here applies to this folder's kernels only (rtweekend's exist already).
if CACHE and config.CACHE_DIR:
    _tag = f"{SOURCE_DIGEST}-{source_digest(Path(__file__).resolve().parent)}"
    config.CACHE_DIR = os.path.join(os.path.dirname(config.CACHE_DIR), f"wide-{_tag}")
    os.makedirs(config.CACHE_DIR, exist_ok=True)


def kernel(fn):
    """A loop kernel called from the wave loop: compiled on its own, without
    reference counting or a Python wrapper (like rtweekend's jit_leaf), so the
    assembly of each loop can be inspected by name and nothing allocates."""
    return njit(_nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True, **_OPTS)(fn)


def inline(fn):
    """A helper copied into its caller by Numba."""
    return njit(inline="always", **_OPTS)(fn)


def plain(fn):
    return njit(**_OPTS)(fn)


def parallel(fn):
    return njit(parallel=True, **_OPTS)(fn)


@intrinsic
def cycles(typingctx):
    """The CPU's time-stamp counter (llvm.readcyclecounter: rdtsc on x86).

    The TSC ticks at a constant rate (constant_tsc), so differences of it
    divide a tile's time between phases without leaving nopython code."""
    sig = types.int64()

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(64), [])
        fn = builder.module.declare_intrinsic("llvm.readcyclecounter", fnty=fnty)
        return builder.call(fn, [])
    return sig, codegen
