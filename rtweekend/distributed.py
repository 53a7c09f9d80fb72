"""Rendering on a Dask cluster, bit-identical to a local render.

    pip install 'rtweekend[dask]'
    rtweekend render cornell_glass --workers 4                 # a LocalCluster here
    rtweekend render cornell_glass --scheduler tcp://HOST:8786
    rt.render(scene, spp=1000, seed=1, client=distributed.Client("tcp://HOST:8786"))

The scene is frozen once (render.freeze: a picklable Frame) and scattered to
every worker, so a task carries only its sample range.  One task renders one
block of BLOCK_SPP samples per pixel from fresh sums (render.block_sums); the
client merges the blocks strictly in sample order -- float sums are not
associative, and in order they give exactly the bits of a local render.  A
bounded window of tasks is in flight.  A worker that dies has its tasks rerun
elsewhere by the scheduler (every worker holds the frame; if all copies are
lost it is scattered again).  Ctrl-C or a lost cluster keeps the contiguous
prefix of merged blocks, as a local Ctrl-C keeps its passes.

Workers must run the same rtweekend sources (checked: a hash of them) and, for
the same bits, the same Numba/llvmlite on the same kind of CPU (warned about:
Numba compiles for the host CPU).  Dask is imported only when asked for.
"""
import logging
import math
import os
import threading
import time as _time
import uuid
import warnings
from contextlib import contextmanager

import numpy as np

from .errors import SceneError
from .jit import SOURCE_DIGEST, collector_paused
from .progress import Progress, StopOnInterrupt
from .render import BLOCK_SPP, Renderer, Sums, block_sums, check_options, render_samples

INSTALL = "pip install 'rtweekend[dask]'"
CONNECT_TIMEOUT = 5.0       # seconds for a scheduler to answer
NO_WORKERS_TIMEOUT = 60.0   # a cluster without workers this long is gone
RETRIES = 2                 # reruns of a task that raised (dead workers: the scheduler's job)
RESCATTERS = 5              # times the frame is sent again after every copy was lost
THREADS_VAR = "RTWEEKEND_NUMBA_THREADS"   # a worker's Numba threads per task (default: all)
POLL = 0.25                 # seconds between looks at Ctrl-C and the cluster's health


class ClusterError(SceneError):
    """A Dask cluster that cannot be used: not installed, unreachable, mismatched.

    A SceneError, so the command reports it in one line with exit status 2.
    """


def _no_threads():
    return ClusterError("render: threads does not apply on a Dask cluster (each worker uses "
                        "its NUMBA_NUM_THREADS)")


def _distributed():
    try:
        import distributed
    except ImportError:
        raise ClusterError(f"render: rendering on a Dask cluster needs Dask: {INSTALL}") from None
    return distributed


def check_scene(scene):
    if scene.resolved_integrator() == "classic":
        raise ClusterError("render: a classic scene is ray traced once per pixel, which is "
                           "not worth distributing: render it without --scheduler/--workers")


@contextmanager
def dask_client(scene=None, *, scheduler=None, workers=None, threads=None,
                timeout=CONNECT_TIMEOUT, quiet=True):
    """A Client of the scheduler at `scheduler`, or of a LocalCluster of `workers`
    single-threaded worker processes (closed on exit); None if neither is given.

    scene and threads (the render's) are checked first, before any cluster starts.
    quiet: keep Dask's own log lines off stderr (the command reports in one line).
    """
    if scheduler is None and workers is None:
        yield None
        return
    if scheduler is not None and workers is not None:
        raise ClusterError("render: give either --scheduler or --workers, not both")
    if threads is not None:
        raise _no_threads()
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise ClusterError(f"render: workers must be an integer >= 1, got {workers!r}")
    if scene is not None:
        check_scene(scene)
    distributed = _distributed()
    cluster = None
    with _silenced(quiet):
        try:
            if workers is not None:
                # One Numba thread per worker process: N processes share the cores.
                cluster = distributed.LocalCluster(
                    n_workers=workers, threads_per_worker=1, processes=True,
                    dashboard_address=None, scheduler_kwargs={"dashboard_address": ":0"},
                    env={THREADS_VAR: "1"},
                    silence_logs=logging.CRITICAL if quiet else logging.WARNING)
                client = distributed.Client(cluster, set_as_default=False)
            else:
                _check_address(scheduler)
                try:
                    client = distributed.Client(scheduler, timeout=timeout,
                                                set_as_default=False)
                except (OSError, ValueError, TypeError) as e:
                    raise ClusterError(f"render: cannot reach the Dask scheduler at "
                                       f"{scheduler}: " + " ".join(str(e).split())) from None
            try:
                yield client
            finally:
                _quietly(client.close, timeout=timeout)
        finally:
            if cluster is not None:
                _quietly(cluster.close, timeout=timeout)


@contextmanager
def _silenced(quiet):
    """Dask's and Tornado's loggers held at CRITICAL (Dask's config gives some of
    them levels of their own, so each is set), then restored."""
    if not quiet:
        yield
        return
    names = ["distributed", "tornado", "asyncio"] + [
        name for name in list(logging.root.manager.loggerDict)
        if name.startswith(("distributed.", "tornado."))]
    saved = {name: logging.getLogger(name).level for name in names}
    for name in names:
        logging.getLogger(name).setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        for name, level in saved.items():
            logging.getLogger(name).setLevel(level)


def _check_address(address):
    """A malformed address fails here, before a Client is half made."""
    from distributed.comm import get_address_host_port
    if not isinstance(address, str):
        raise ClusterError(f"render: a Dask scheduler address is a string, got {address!r}")
    if address.startswith("inproc://"):
        return
    try:
        get_address_host_port(address)
    except ValueError as e:
        raise ClusterError(f"render: bad Dask scheduler address {address!r}: "
                           + " ".join(str(e).split()) + " (expected tcp://HOST:PORT)") from None


def _quietly(fn, *args, **kwargs):
    """Clean-up that must not hide the real outcome (the cluster may be gone)."""
    try:
        fn(*args, **kwargs)
    except Exception:
        pass


def render_distributed(client, scene, spp=None, *, seed=0, time=None, width=None,
                       height=None, max_depth=None, threads=None, sampling=None,
                       progress=False, bvh=None, clamp=None):
    """render(..., client=client): the same image, its blocks rendered by Dask workers.

    With `time`, blocks are submitted while they are expected to finish within
    the budget (whole blocks of BLOCK_SPP samples: at least one).
    """
    check_scene(scene)
    if threads is not None:
        raise _no_threads()
    sampling = sampling or "mixture"
    check_options(spp=spp, time=time, seed=seed, sampling=sampling, max_depth=max_depth,
                  clamp=clamp)
    _distributed()
    renderer = Renderer(scene, seed=seed, width=width, height=height, max_depth=max_depth,
                        sampling=sampling, bvh=bvh, clamp=clamp)
    if spp is None and time is None:
        spp = scene.spp
    return _Render(client, renderer, spp, time, progress).run()


class _Render:
    """The client's side: submit blocks, merge them in order, watch the cluster."""

    def __init__(self, client, renderer, spp, budget, progress):
        self.client, self.r = client, renderer
        self.spp, self.budget = spp, budget
        self.report = Progress(progress, spp)
        self.pending = {}        # future -> (s0, s1) of the block it renders
        self.finished = {}       # s0 -> a task's result, waiting for the blocks below it
        self.next_s0 = 0         # the first sample not yet submitted
        self.block_seconds = []  # a worker's compute time per block (for time budgets)
        self.passes = 0          # blocks merged
        self.threads = 0         # worker threads in the cluster
        self.frame = None        # the future of the scattered Frame
        self.rescatters = 0
        self.lost = None         # why the render stopped early, if the cluster failed it
        self.stopping = False    # Ctrl-C: no more submissions
        self.t0 = None
        self.no_workers_since = None
        self.last_look = 0.0
        self.wake = threading.Event()

    def run(self):
        try:
            with StopOnInterrupt() as stop:
                self._start()
                self._warm_up(stop)
                self.report.started()
                self.t0 = _time.perf_counter()
                while self.lost is None and not self._complete():
                    if stop.requested and not self.stopping:
                        self._stop()
                    if not self.stopping:
                        self._submit()
                    if not self.pending:
                        break
                    self.wake.wait(POLL)
                    self.wake.clear()
                    self._collect()
                    self._merge()
                    self._look_at_cluster()
        finally:
            self._release()
            self.report.close()
        early = self.stopping or self.lost is not None
        interrupted = early and (self.spp is None or self.r.spp < self.spp)
        return self.r.result(spp_requested=self.spp, interrupted=interrupted,
                             threads=self.threads, stopped_by=self.lost or "Ctrl-C")

    # -- the cluster ---------------------------------------------------------

    def _start(self):
        if self.client.status != "running":
            raise ClusterError(f"render: the Dask client is {self.client.status}, not running")
        self.threads = self._threads()
        try:
            self.frame = self._scatter()
        except (TimeoutError, ValueError):
            raise ClusterError(f"render: the Dask cluster has no workers (waited "
                               f"{NO_WORKERS_TIMEOUT:g} s)") from None

    def _threads(self):
        return sum(self.client.nthreads().values())

    def _scatter(self):
        """The frame on every worker (waits up to NO_WORKERS_TIMEOUT for one)."""
        [frame] = self.client.scatter([self.r.frame], broadcast=True, hash=False,
                                      timeout=NO_WORKERS_TIMEOUT)
        return frame

    def _warm_up(self, stop):
        """Compile (or load from the cache) on every worker before the clock starts,
        and check that the workers run what this machine runs.  One worker per host
        goes first: on a cold cache it compiles, and the others load its cache."""
        from distributed.comm import get_address_host
        t0 = _time.perf_counter()
        workers = list(self.client.nthreads())
        first = {}
        for w in workers:
            first.setdefault(get_address_host(w), w)
        infos = self._warm(list(first.values()), stop)
        if not stop.requested and self.client.status == "running":
            infos += self._warm([w for w in workers if w not in first.values()], stop)
        if self.client.status != "running":
            self.lost = "lost the connection to the Dask scheduler"
            return
        here = environment()
        for info in infos:
            if info["digest"] != here["digest"]:
                raise ClusterError(
                    f"render: worker {info['address']} runs other rtweekend sources "
                    f"(hash {info['digest']}, here {here['digest']}): install the same "
                    "rtweekend on every worker")
        others = {(i["numba"], i["llvmlite"], i["cpu"], i["cpu_features"]) for i in infos}
        mine = (here["numba"], here["llvmlite"], here["cpu"], here["cpu_features"])
        if others - {mine}:
            warnings.warn("the Dask workers' CPU or Numba differ from this machine's: the "
                          "image may differ from a local render in its last bits",
                          RuntimeWarning, stacklevel=4)
        self.r.compile_seconds = _time.perf_counter() - t0

    def _warm(self, workers, stop):
        """warm_worker on each of these workers; what they say about themselves."""
        futures = [self.client.submit(warm_worker, self.frame, workers=[w],
                                      allow_other_workers=True, pure=False,
                                      key=f"rtweekend-warm-{uuid.uuid4().hex}")
                   for w in workers]
        for f in futures:
            f.add_done_callback(self._wake)
        while (any(f.status in ("pending", "lost") for f in futures) and not stop.requested
               and self.client.status == "running"):
            self.wake.wait(POLL)
            self.wake.clear()
        infos = []
        for w, f in zip(workers, futures):
            if f.status == "finished":
                infos.append(f.result())
            elif f.status == "error":
                e = f.exception()
                raise ClusterError(f"render: worker {w} cannot render: {type(e).__name__}: "
                                   + " ".join(str(e).split()))
        _quietly(self.client.cancel, futures)
        return infos

    def _look_at_cluster(self):
        """Give up if the scheduler is gone, or has had no worker for too long."""
        if self.lost is not None:
            return
        if self.client.status != "running":
            self.lost = "lost the connection to the Dask scheduler"
            return
        now = _time.monotonic()
        if now - self.last_look < 1.0:
            return
        self.last_look = now
        try:
            threads = self._threads()
        except Exception:                # the connection broke under the call
            self.lost = "lost the connection to the Dask scheduler"
            return
        if threads:
            self.threads, self.no_workers_since = threads, None
        elif self.no_workers_since is None:
            self.no_workers_since = now
        elif now - self.no_workers_since > NO_WORKERS_TIMEOUT:
            self.lost = f"the Dask cluster has had no workers for {NO_WORKERS_TIMEOUT:g} s"

    # -- the blocks ------------------------------------------------------------

    def _complete(self):
        return self.spp is not None and self.r.spp >= self.spp

    def _wake(self, future):
        self.wake.set()

    def _submit(self):
        window = 2 * max(self.threads, 1)       # keeps every worker busy between results
        while (len(self.pending) < window
               and self.next_s0 - self.r.spp < 2 * window * BLOCK_SPP   # bounds memory
               and self._more()):
            s0 = self.next_s0
            s1 = s0 + BLOCK_SPP if self.spp is None else min(s0 + BLOCK_SPP, self.spp)
            self._launch(s0, s1)
            self.next_s0 = s1

    def _more(self):
        """Is there another block to submit?"""
        if self.spp is not None:
            return self.next_s0 < self.spp
        if not self.block_seconds:              # nothing measured yet: one round
            return len(self.pending) < max(self.threads, 1) or self.next_s0 == 0
        per = sum(self.block_seconds) / len(self.block_seconds)
        rounds = math.ceil((len(self.pending) + 1) / max(self.threads, 1))
        elapsed = _time.perf_counter() - self.t0
        return elapsed + rounds * per <= self.budget + 0.5 * per

    def _launch(self, s0, s1):
        f = self.client.submit(render_block, self.frame, s0, s1, pure=False,
                               retries=RETRIES, priority=-(s0 // BLOCK_SPP),
                               key=f"rtweekend-block-{s0}-{uuid.uuid4().hex}")
        f.add_done_callback(self._wake)
        self.pending[f] = (s0, s1)

    def _collect(self):
        """Take the finished blocks; send again those whose frame was lost."""
        cancelled = []
        for f, (s0, s1) in list(self.pending.items()):
            if f.status == "finished":
                try:
                    out = f.result()
                except Exception:            # cancelled under us: seen next time round
                    continue
                del self.pending[f]
                self.finished[s0] = out
                self.block_seconds.append(out["seconds"])
            elif f.status == "error":
                del self.pending[f]
                e = f.exception()
                if type(e).__name__ == "KilledWorker":
                    self.lost = (f"samples {s0}..{s1 - 1} killed every worker they ran on "
                                 f"({' '.join(str(e).split())})")
                    return
                raise e
            elif f.status == "cancelled":
                del self.pending[f]
                cancelled.append((s0, s1))
        if not cancelled:
            return
        if self.client.status != "running":
            self.lost = "lost the connection to the Dask scheduler"
            return
        # Every copy of the frame went with its workers: send it again.
        if self.frame.status != "finished":
            if self.rescatters == RESCATTERS:
                self.lost = f"the Dask cluster lost the scene {RESCATTERS} times"
                return
            self.rescatters += 1
            try:
                self.frame = self._scatter()
            except Exception:
                self.lost = f"the Dask cluster has had no workers for {NO_WORKERS_TIMEOUT:g} s"
                return
        if not self.stopping:
            for s0, s1 in cancelled:
                self._launch(s0, s1)

    def _merge(self):
        """Add the blocks that continue the merged prefix, in order."""
        while self.r.spp in self.finished:
            out = self.finished.pop(self.r.spp)
            self.r.sums.add(unpack(out, self.r.height, self.r.width))
            self.r.spp = out["s1"]
            self.passes += 1
            self.r.seconds = _time.perf_counter() - self.t0
            self.report.update(self.r.spp, self.passes, self.r.seconds,
                               self.r.width * self.r.height)

    def _stop(self):
        """First Ctrl-C: cancel the blocks not yet running, finish those that are."""
        self.stopping = True
        try:
            running = {k for keys in self.client.processing().values() for k in keys}
        except Exception:
            running = set()
        queued = [f for f in self.pending if f.key not in running]
        for f in queued:
            del self.pending[f]
        _quietly(self.client.cancel, queued)

    def _release(self):
        if self.client.status == "running":
            _quietly(self.client.cancel, list(self.pending)
                     + ([self.frame] if self.frame is not None else []))
        self.pending.clear()
        self.finished.clear()


def unpack(out, height, width):
    """A task's result as Sums (the emptied partial sums of a full block come as None)."""
    sums = Sums(height, width)
    for name, value in out["fields"].items():
        if value is not None:
            setattr(sums, name, value)
    return sums


# -- the workers' side ---------------------------------------------------------

_KERNEL = threading.Lock()   # one kernel at a time per process, on all its Numba threads
_WORKER = {}                 # what this process learned when it warmed up


def environment():
    """What decides the bits: the sources, the compiler and the CPU it targets."""
    import llvmlite
    import numba
    from llvmlite import binding

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
    arrays = frame.arrays._replace(**{k: fix(v) for k, v in frame.arrays._asdict().items()
                                      if isinstance(v, np.ndarray)})
    return frame._replace(arrays=arrays, cam=fix(frame.cam), rows=fix(frame.rows))


def _numba_threads():
    """This task's Numba threads: $RTWEEKEND_NUMBA_THREADS if set, else all.

    Not NUMBA_NUM_THREADS in the Nanny's env=: a spawned worker may import Numba
    before the Nanny sets it (when the parent's main module imports rtweekend, as
    the `rtweekend` script does), and Numba refuses a compile whose environment
    says another thread count than the one its threads were launched with."""
    import numba
    try:
        n = int(os.environ[THREADS_VAR])
    except (KeyError, ValueError):
        return
    numba.set_num_threads(max(1, min(n, numba.config.NUMBA_NUM_THREADS)))


def warm_worker(frame):
    """Task: compile the kernel here (or load it from the on-disk cache), once per
    process; returns what the worker runs on and what that first call cost."""
    import numba
    if "info" not in _WORKER:
        frame = _local(frame)
        t0 = _time.perf_counter()
        with _KERNEL, collector_paused():
            _numba_threads()
            render_samples(frame, Sums(frame.height, frame.width), 0, 0)
            threads = numba.get_num_threads()
        _WORKER["info"] = dict(environment(), compile_seconds=_time.perf_counter() - t0,
                               pid=os.getpid(), address=_address(), numba_threads=threads)
        return dict(_WORKER["info"], first=True)
    return dict(_WORKER["info"], compile_seconds=0.0, first=False)


def render_block(frame, s0, s1):
    """Task: fresh sums of samples s0 .. s1 - 1 (a block), packed for the trip back."""
    frame = _local(frame)
    t0 = _time.perf_counter()
    with _KERNEL:
        _numba_threads()
        sums = block_sums(frame, s0, s1)
    seconds = _time.perf_counter() - t0
    fields = {name: getattr(sums, name) for name in Sums.FIELDS}
    if s1 % BLOCK_SPP == 0:       # a whole block: the kernel has emptied its partial sums
        fields["partial"] = fields["partial2"] = None
    return {"s0": s0, "s1": s1, "seconds": seconds, "fields": fields, "pid": os.getpid()}
