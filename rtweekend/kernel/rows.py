"""Image rows and the threads that render them.

A path-tracing kernel renders the rows of a queue (jit_kernel: it releases
the GIL): share_rows runs it on `threads` threads at once, and each thread
claims the queue's next row whenever it is free, until none is left.  A row
is rendered whole by the thread that claimed it, so the image is the same
whatever the number of threads or which thread took which row.  Claimed one
at a time rather than cut into a part per thread beforehand: a part's time
moves from pass to pass on a shared machine (two parts of equal work ended 9%
of a pass apart on the 2-core VM, the pass waiting for the later), and rows
differ in cost; a free thread takes more rows instead of waiting
(benchmarks/results/measurements.md).  Threads of our own rather than a
Numba `prange`: the parallel compile of a prange kernel cost a second and a
half of every cold compile, and a thread here runs the very code a prange
thread would.  on_threads splits other work (the BVH's subtrees, the photon
maps) in fixed parts.
"""
import math
import threading
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np

from .atomic import atomic_add
from .jit import jit_step

_POOL = None
_POOL_LOCK = threading.Lock()


def interleaved_rows(height):
    """A permutation of the rows such that any contiguous chunk of it (a part
    of on_threads, a band of rows rendered ahead of the rest) samples the whole
    image, so parts get equal work: in the Cornell box the rows through the
    boxes cost more, in the classic demo the floor's reflections make the
    bottom rows dearest (benchmarks/results/measurements.md).  A pass's
    threads claim rows in this order, so the last rows claimed, on which the
    pass waits, are no dearer than the rest."""
    step = max(1, int(height * 0.6180339887))
    while math.gcd(step, height) != 1:
        step += 1
    return (np.arange(height, dtype=np.int64) * step) % height


def row_queue(rows):
    """The queue of a pass over `rows`: int64 [1 + len(rows)], the count of rows
    claimed so far (none yet), then the rows in the order they are handed out."""
    queue = np.empty(len(rows) + 1, dtype=np.int64)
    queue[0] = 0
    queue[1:] = rows
    return queue


@jit_step
def claim(queue):
    """The queue's next row for this thread, or -1 when every row is claimed.
    Each call adds one to the count atomically and takes the row at the count
    it found: no two threads get the same row, and none is skipped."""
    i = atomic_add(queue, (0,), 1)
    if i < queue.shape[0] - 1:
        return queue[i + 1]
    return -1


def _pool():
    """The helper threads, started once: as many as Numba may use, less this one."""
    global _POOL
    with _POOL_LOCK:
        if _POOL is None:
            _POOL = ThreadPoolExecutor(max(1, numba.config.NUMBA_NUM_THREADS - 1),
                                       thread_name_prefix="rtweekend-rows")
    return _POOL


def _at_once(work, args):
    """work(a) for each a of args on threads at once, this thread taking the
    first (the pool the others); returns when all are done (an error in any is
    raised)."""
    others = [_pool().submit(work, a) for a in args[1:]]
    try:
        work(args[0])
    finally:
        for future in others:
            future.result()


def share_rows(work, rows, threads):
    """work(queue) on `threads` threads at once (no more than there are rows,
    one at least), this thread one of them, all claiming the rows of one
    queue."""
    queue = row_queue(rows)
    _at_once(work, [queue] * max(1, min(threads, len(rows))))


def on_threads(work, rows, threads):
    """work(part) for `threads` contiguous parts of `rows` at once, this thread
    taking the first."""
    parts = [part for part in np.array_split(rows, max(1, threads)) if len(part)]
    _at_once(work, parts or [rows])           # no rows: one call, with none
