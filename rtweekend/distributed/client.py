"""The Dask driver: render a path-traced image on a cluster, bit-identical to a
local render.

    pip install 'rtweekend[dask]'
    rtweekend render cornell_glass --workers 4                 # a LocalCluster here
    rtweekend render cornell_glass --scheduler tcp://HOST:8786
    rt.render(scene, spp=1000, seed=1, client=distributed.Client("tcp://HOST:8786"))

The scene is frozen once (path/renderer.freeze: a picklable Frame) and
scattered to every worker, so a task carries only its sample range.  One task
renders one block of BLOCK_SPP samples per pixel from a fresh film
(path/renderer.block_film, in worker.py); the
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
import math
import threading
import time as _time
import uuid
import warnings

from ..io.progress import Progress, StopOnInterrupt
from ..path.film import BLOCK_SPP
from .cluster import ClusterError, distributed_module, quietly
from .worker import environment, render_block, unpack, warm_worker

NO_WORKERS_TIMEOUT = 60.0   # a cluster without workers this long is gone
RETRIES = 2                 # reruns of a task that raised (dead workers: the scheduler's job)
RESCATTERS = 5              # times the frame is sent again after every copy was lost
POLL = 0.25                 # seconds between looks at Ctrl-C and the cluster's health


def render_on_cluster(client, renderer, spp, time):
    """render(..., client=client): the same image, its blocks rendered by Dask workers.

    With `time`, blocks are submitted while they are expected to finish within
    the budget (whole blocks of BLOCK_SPP samples: at least one).
    """
    distributed_module()
    return _Render(client, renderer, spp, time).run()


class _Render:
    """The client's side: submit blocks, merge them in order, watch the cluster."""

    def __init__(self, client, renderer, spp, budget):
        self.client, self.r = client, renderer
        self.spp, self.budget = spp, budget
        self.report = Progress(renderer.options.progress, spp, budget)
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
        self.r.remote_compile_seconds = _time.perf_counter() - t0

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
        quietly(self.client.cancel, futures)
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
            self.r.merge(unpack(out, self.r.height, self.r.width), out["s1"])
            self.passes += 1
            self.r.seconds = _time.perf_counter() - self.t0
            self.report.update(self.r, self.passes)

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
        quietly(self.client.cancel, queued)

    def _release(self):
        if self.client.status == "running":
            quietly(self.client.cancel, list(self.pending)
                     + ([self.frame] if self.frame is not None else []))
        self.pending.clear()
        self.finished.clear()
