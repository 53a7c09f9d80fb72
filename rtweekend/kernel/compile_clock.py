"""How long this process has spent compiling, and whether it is compiling now.

Numba announces every compile (not a load from the cache) with the event
"numba:compile", nested for the callees a compile brings in; the clock runs
from the outermost one's start to its end, whatever started it: packing a
scene, building a BVH, reading an OBJ file, a render kernel, the photon maps,
the denoiser's pass.  Waiting for kernels that helper processes compile
(kernel/compile_workers.py) counts as compiling too, and so do the cache's
look-up that finds nothing before a compile and its saving of what was
compiled after (kernel/disk_cache.py): Numba does both outside its event.
So the seconds a render reports as compiling are all of them, and a progress
display can say "compiling" exactly while something compiles (io/progress.py
Spinner).

Compiles hold Numba's compiler lock, so at most one thread of the process
compiles at a time; the clock is read from any thread.
"""
import threading
import time
from contextlib import contextmanager

from numba.core import event


class _Clock(event.Listener):
    def __init__(self):
        self._lock = threading.Lock()
        self._depth = 0
        self._since = None        # when the running compile (or wait) started
        self._total = 0.0         # seconds of the finished ones

    def on_start(self, ev):
        self.enter()

    def on_end(self, ev):
        self.leave()

    def enter(self):
        with self._lock:
            if self._depth == 0:
                self._since = time.perf_counter()
            self._depth += 1

    def leave(self):
        with self._lock:
            self._depth -= 1
            if self._depth == 0:
                self._total += time.perf_counter() - self._since
                self._since = None

    def add_since(self, since):
        """Count the time from `since` (perf_counter) to now, unless a compile
        running meanwhile counts it already."""
        with self._lock:
            if self._depth == 0:
                self._total += time.perf_counter() - since

    def seconds(self):
        """Seconds spent compiling so far (the running compile's too)."""
        with self._lock:
            running = 0.0 if self._since is None else time.perf_counter() - self._since
            return self._total + running

    def running(self):
        """Seconds the compile in progress has run, or None if none is."""
        with self._lock:
            return None if self._since is None else time.perf_counter() - self._since


_CLOCK = _Clock()
event.register("numba:compile", _CLOCK)
seconds = _CLOCK.seconds
running = _CLOCK.running
add_since = _CLOCK.add_since


@contextmanager
def waiting():
    """Time spent waiting for other processes' compiles counts as compiling."""
    _CLOCK.enter()
    try:
        yield
    finally:
        _CLOCK.leave()


class Stopwatch:
    """The compile seconds from its start: Stopwatch().seconds()."""

    def __init__(self):
        self._start = seconds()

    def seconds(self):
        return seconds() - self._start
