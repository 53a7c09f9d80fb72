"""The rows of a pass and the threads that claim them (kernel/rows.py)."""
import threading

import numpy as np
from numba import njit

from rtweekend.kernel.atomic import atomic_add
from rtweekend.kernel.rows import claim, interleaved_rows, row_queue, share_rows


@njit(nogil=True)
def _claim_all(queue, times_claimed, claimed_here, slot):
    """Claim rows until none is left, as a kernel does: count each row's
    claims (atomically: two threads could claim one row) and this caller's."""
    y = claim(queue)
    while y >= 0:
        atomic_add(times_claimed, (y,), 1)
        claimed_here[slot] += 1
        y = claim(queue)


def test_one_thread_claims_the_rows_in_the_queues_order_then_none():
    rows = interleaved_rows(7)
    queue = row_queue(rows)
    assert queue.dtype == np.int64 and queue[0] == 0 and list(queue[1:]) == list(rows)
    assert [claim(queue) for _ in range(9)] == list(rows) + [-1, -1]
    assert claim(row_queue(rows[:0])) == -1


def test_every_row_is_claimed_once_by_threads_racing_for_them():
    # Each claim is a few instructions: four threads claiming two million rows
    # at once contend on the count all the way (a count added without an
    # atomic operation hands some rows out twice here).
    n, threads = 2_000_000, 4
    rows = interleaved_rows(n)
    queue, times = row_queue(rows), np.zeros(n, dtype=np.int64)
    here = np.zeros(threads, dtype=np.int64)
    _claim_all(row_queue(rows[:1]), times.copy(), here.copy(), 0)        # compiled
    start = threading.Barrier(threads)

    def one(slot):
        start.wait()
        _claim_all(queue, times, here, slot)
    runners = [threading.Thread(target=one, args=(i,)) for i in range(threads)]
    for r in runners:
        r.start()
    for r in runners:
        r.join()
    assert times.min() == 1 and times.max() == 1
    assert here.sum() == n


def test_share_rows_gives_every_thread_one_queue_and_each_row_is_done_once():
    rows = interleaved_rows(301)
    times, here = np.zeros(301, dtype=np.int64), np.zeros(2, dtype=np.int64)
    seen, lock = [], threading.Lock()

    def work(queue):
        with lock:
            slot = len(seen)
            seen.append((id(queue), threading.get_ident()))
        _claim_all(queue, times, here, slot)
    share_rows(work, rows, 2)
    assert len(seen) == 2 and len({q for q, _ in seen}) == 1
    assert len({t for _, t in seen}) == 2 and threading.get_ident() in {t for _, t in seen}
    assert (times == 1).all() and here.sum() == 301
    seen.clear()
    share_rows(work, rows[:1], 2)                  # no more threads than rows
    assert len(seen) == 1
