"""How the drivers call compiled code: in a worker thread, one call at a time,
while the calling (main) thread waits awake to Ctrl-C.

Python runs signal handlers in the main thread only, between bytecodes.  A
kernel called from the main thread holds it until it returns, and Numba's
compiler runs for seconds in the main thread too: Ctrl-C was answered only
afterwards, and two Ctrl-C within one pass were delivered as one.  So the
kernels (compiled with nogil: kernel/jit.py jit_parallel) and the compiler run
in a worker thread, and the main thread waits for it in short sleeps, during
which its handler runs at once (io/progress.py StopOnInterrupt).

Why a thread and not a child process: the film stays in this process (no copy
of hundreds of MB per pass), the compiled kernels are shared, and Numba's
cache, thread pool and the API's return values work as before.  The price: a
compile or a pass cannot be cancelled, only abandoned -- it goes on in its
daemon thread, and its result is dropped.  Calls run in order in one worker
thread, so a new call waits for an abandoned one, and the command, which
abandons a compile on Ctrl-C, leaves with os._exit, not through interpreter
shutdown under a running compiler.
"""
import queue
import threading

import numba

POLL = 0.05                    # seconds between looks at Ctrl-C while waiting

# One worker thread for the process, started at the first call and reused: the
# calls run one at a time, in order (a new call waits for an abandoned one:
# Numba's thread pools are not made for two parallel kernels launched at once),
# and the threading layer's team of threads belongs to the thread that launches
# the kernel -- with OpenMP a new launching thread per call built a new team per
# call, which cost a classic render (tens of ms) a quarter of its time.
_JOBS = queue.SimpleQueue()
_WORKER = None
_STARTING = threading.Lock()


class Abandoned(Exception):
    """The call was left running in the background (Ctrl-C during it)."""


def _serve():
    while True:
        _JOBS.get()()


def _submit(job):
    global _WORKER
    with _STARTING:
        if _WORKER is None or not _WORKER.is_alive():
            # A daemon: an abandoned compile must not keep the interpreter alive.
            _WORKER = threading.Thread(target=_serve, name="rtweekend-kernel", daemon=True)
            _WORKER.start()
    _JOBS.put(job)


def call_awake(fn, stop=None, *, abandon=False, tick=None):
    """fn() in the worker thread with this thread's Numba thread count; returns
    its value (or raises its exception).

    stop: a StopOnInterrupt; its handler runs while this thread waits, so a
    second Ctrl-C raises KeyboardInterrupt at once.  With abandon=True the
    first Ctrl-C (stop.requested) raises Abandoned instead of waiting for fn.
    tick: called while waiting, every POLL seconds (a progress line's clock).
    """
    threads = numba.get_num_threads()      # thread-local in Numba: pass it on
    box = {}
    done = threading.Event()

    def work():
        try:
            if box.get("abandoned"):
                return
            numba.set_num_threads(threads)
            box["value"] = fn()
        except BaseException as e:           # handed to the waiting thread
            box["error"] = e
        finally:
            done.set()

    _submit(work)
    try:
        while not done.wait(POLL):
            if tick is not None:
                tick()
            if abandon and stop is not None and stop.requested:
                box["abandoned"] = True
                raise Abandoned
    except BaseException:
        box["abandoned"] = True
        raise
    if "error" in box:
        raise box["error"]
    return box.get("value")
