"""The workers' side of a distributed render: warm up (compile or load the
cache), then render blocks of samples from fresh films."""
import os
import threading
import time as _time

import llvmlite
import numba
import numpy as np
from llvmlite import binding

from ..kernel.jit import SOURCE_DIGEST, collector_paused
from ..path import film as films
from ..path.film import BLOCK_SPP
from ..path.renderer import block_film, render_samples, splats
from .cluster import THREADS_VAR


def unpack(out, height, width):
    """A task's result as a Film (the emptied partial sums of a full block come as None)."""
    fresh = films.new_film(height, width, out["fields"]["splat"].size > 0,
                           out["fields"]["albedo"].size > 0)
    return fresh._replace(**{name: value for name, value in out["fields"].items()
                             if value is not None})


_KERNEL = threading.Lock()   # one kernel at a time per process, on all its Numba threads
_WORKER = {}                 # what this process learned when it warmed up


def environment():
    """What decides the bits: the sources, the compiler and the CPU it targets."""
    features = numba.config.CPU_FEATURES or binding.get_host_cpu_features().flatten()
    return {"digest": SOURCE_DIGEST, "numba": numba.__version__,
            "llvmlite": llvmlite.__version__,
            "cpu": numba.config.CPU_NAME or binding.get_host_cpu_name(),
            "cpu_features": features}


def _address():
    try:
        from distributed import get_worker
        return get_worker().address
    except (ImportError, ValueError):
        return f"pid {os.getpid()}"


def _local(frame):
    """The frame with arrays Numba takes as it does locally: C-ordered, aligned,
    writeable (an array unpickled from a network buffer may be read-only, which
    would be another signature, another compile)."""
    def fix(a):
        ok = a.flags.c_contiguous and a.flags.aligned and a.flags.writeable
        return a if ok else np.array(a, order="C")
    arrays = frame.scene._replace(**{k: fix(v) for k, v in frame.scene._asdict().items()
                                     if isinstance(v, np.ndarray)})
    params = frame.params._replace(cam=fix(frame.params.cam))
    return frame._replace(scene=arrays, params=params, rows=fix(frame.rows))


def _numba_threads():
    """This task's Numba threads: $RTWEEKEND_NUMBA_THREADS if set, else all.

    Not NUMBA_NUM_THREADS in the Nanny's env=: a spawned worker may import Numba
    before the Nanny sets it (when the parent's main module imports rtweekend, as
    the `rtweekend` script does), and Numba refuses a compile whose environment
    says another thread count than the one its threads were launched with."""
    try:
        n = int(os.environ[THREADS_VAR])
    except (KeyError, ValueError):
        return
    numba.set_num_threads(max(1, min(n, numba.config.NUMBA_NUM_THREADS)))


def warm_worker(frame):
    """Task: compile the kernel here (or load it from the on-disk cache), once per
    process; returns what the worker runs on and what that first call cost."""
    if "info" not in _WORKER:
        frame = _local(frame)
        t0 = _time.perf_counter()
        with _KERNEL, collector_paused():
            _numba_threads()
            render_samples(frame, films.new_film(frame.height, frame.width, splats(frame),
                                                 frame.aov), 0, 0)
            threads = numba.get_num_threads()
        _WORKER["info"] = dict(environment(), compile_seconds=_time.perf_counter() - t0,
                               pid=os.getpid(), address=_address(), numba_threads=threads)
        return dict(_WORKER["info"], first=True)
    return dict(_WORKER["info"], compile_seconds=0.0, first=False)


def worker_info():
    """What this process said when it warmed up (None before), for benchmarks."""
    return _WORKER.get("info")


def render_block(frame, s0, s1):
    """Task: a fresh film of samples s0 .. s1 - 1 (a block), packed for the trip back."""
    frame = _local(frame)
    t0 = _time.perf_counter()
    with _KERNEL:
        _numba_threads()
        film = block_film(frame, s0, s1)
    seconds = _time.perf_counter() - t0
    fields = film._asdict()
    if s1 % BLOCK_SPP == 0:       # a whole block: the kernel has emptied its partial sums
        fields["partial"] = fields["partial2"] = None
    return {"s0": s0, "s1": s1, "seconds": seconds, "fields": fields, "pid": os.getpid()}
