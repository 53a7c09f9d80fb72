"""Image rows and the threads that render them.

A path-tracing kernel renders a list of rows (jit_kernel: it releases the
GIL); on_threads hands each of `threads` threads a contiguous part of the list,
and each row is written by one thread only, so the image is the same whatever
the number of threads.  Threads of our own rather than a Numba `prange`: the
parallel compile of a prange kernel cost a second and a half of every cold
compile (benchmarks/results/measurements.md), and a thread here runs the very
code a prange thread would.
"""
import math
import threading
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

_POOL = None
_POOL_LOCK = threading.Lock()


def interleaved_rows(height):
    """A permutation of the rows such that any contiguous chunk of it (what a
    thread gets) samples the whole image, so threads get equal work: in the
    Cornell box the rows through the boxes cost more, in the classic demo the
    floor's reflections make the bottom rows dearest
    (benchmarks/results/measurements.md)."""
    step = max(1, int(height * 0.6180339887))
    while math.gcd(step, height) != 1:
        step += 1
    return (np.arange(height, dtype=np.int64) * step) % height


def _pool():
    """The helper threads, started once: as many as Numba may use, less this one."""
    global _POOL
    with _POOL_LOCK:
        if _POOL is None:
            _POOL = ThreadPoolExecutor(max(1, numba.config.NUMBA_NUM_THREADS - 1),
                                       thread_name_prefix="rtweekend-rows")
    return _POOL


def on_threads(work, rows, threads):
    """work(part) for `threads` contiguous parts of `rows` at once, this thread
    taking the first; returns when all are done (an error in any is raised)."""
    parts = [part for part in np.array_split(rows, max(1, threads)) if len(part)]
    if len(parts) <= 1:
        work(rows)
        return
    others = [_pool().submit(work, part) for part in parts[1:]]
    try:
        work(parts[0])
    finally:
        for future in others:
            future.result()
