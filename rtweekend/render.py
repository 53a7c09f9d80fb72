"""Progressive rendering: the prange kernel and the Python loop of passes.

A pass adds samples [s0, s1) to every pixel.  Each sample's random stream is
keyed by (pixel, sample index, seed) and is added to its pixel's float64 sum in
sample order, so the image is bit-identical for any thread count and any way of
splitting the samples into passes.
"""
import math
import signal
import sys
import threading
import time as _time
from dataclasses import dataclass

import numba
import numpy as np

from . import rng
from .camera import get_ray
from .errors import SceneError
from .jit import jit_parallel
from .path import trace

SAMPLING = {"cosine": 0.0, "mixture": 0.5, "light": 1.0}
PASS_SECONDS = 0.5      # short passes: a smooth progress bar, a quick Ctrl-C


@jit_parallel
def render_pass(accum, accum2, valid, row_stats, rows, s0, s1, seed, cam, width, height,
                obj_i, obj_f, bvh_box, bvh_node, bvh_prims, mat_i, mat_f, lights,
                bg_kind, bg, max_depth, light_weight):
    """Add samples s0..s1-1 of every pixel; rows[k] spreads the work over threads.

    accum/accum2 sum each sample's radiance and its square (for the standard
    error); row_stats[y] += (ray segments traced, samples dropped as NaN/Inf).
    """
    for k in numba.prange(rows.shape[0]):
        y = rows[k]
        segments = 0
        dropped = 0
        for x in range(width):
            pixel = y * width + x
            for s in range(s0, s1):
                state = rng.seed_state(pixel, s, seed)
                o, d, state = get_ray(cam, x, y, width, height, state)
                c, n, state = trace(obj_i, obj_f, bvh_box, bvh_node, bvh_prims, mat_i,
                                    mat_f, lights, bg_kind, bg, max_depth, light_weight,
                                    o, d, state)
                segments += n
                if math.isfinite(c[0] + c[1] + c[2]):
                    accum[y, x, 0] += c[0]
                    accum[y, x, 1] += c[1]
                    accum[y, x, 2] += c[2]
                    accum2[y, x, 0] += c[0] * c[0]
                    accum2[y, x, 1] += c[1] * c[1]
                    accum2[y, x, 2] += c[2] * c[2]
                    valid[y, x] += 1
                else:
                    dropped += 1
        row_stats[y, 0] += segments
        row_stats[y, 1] += dropped


def interleaved_rows(height):
    """A permutation of the rows such that any contiguous chunk of it (what a
    thread gets from prange) samples the whole image: cost is balanced."""
    step = max(1, int(height * 0.6180339887))
    while math.gcd(step, height) != 1:
        step += 1
    return (np.arange(height, dtype=np.int64) * step) % height


@dataclass
class RenderStats:
    width: int
    height: int
    spp: int                 # samples per pixel reached
    spp_requested: int | None
    seconds: float           # rendering wall time, compile excluded
    compile_seconds: float   # first-call cost (near 0 when the cache is warm)
    samples: int
    rays: int                # path segments traced
    nan_dropped: int         # samples that were NaN/Inf and left out of the mean
    interrupted: bool
    threads: int
    seed: int

    @property
    def samples_per_s(self):
        return self.samples / self.seconds if self.seconds > 0 else float("nan")

    @property
    def rays_per_s(self):
        return self.rays / self.seconds if self.seconds > 0 else float("nan")

    @property
    def mean_path_length(self):
        return self.rays / self.samples if self.samples else float("nan")

    def summary(self):
        note = (f" (interrupted: {self.spp} of {self.spp_requested} spp)"
                if self.interrupted and self.spp_requested else
                " (interrupted)" if self.interrupted else "")
        return (f"{self.width}x{self.height}, {self.spp} spp, {self.seconds:.2f} s, "
                f"{self.samples_per_s / 1e6:.3f} M samples/s, "
                f"{self.rays_per_s / 1e6:.3f} M rays/s, "
                f"{self.nan_dropped} NaN/Inf samples dropped{note}")


class RenderResult:
    """What render() returns; unpacks as (image, stats).

    image: HxWx3 float32 linear radiance; stats: RenderStats; stderr: HxWx3
    float32 per-pixel standard error, estimated from the samples' own variance.
    """

    def __init__(self, image, stats, stderr):
        self.image, self.stats, self.stderr = image, stats, stderr

    def __iter__(self):
        return iter((self.image, self.stats))

    def __getitem__(self, i):
        return (self.image, self.stats)[i]

    def __len__(self):
        return 2

    def __repr__(self):
        return f"RenderResult({self.stats.summary()})"


class _StopOnInterrupt:
    """First Ctrl-C: finish the current pass and stop.  Second: abort at once."""

    def __init__(self):
        self.requested = False
        self._previous = None

    def _handler(self, signum, frame):
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc):
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)


def _check_options(spp, time, threads, seed, sampling, max_depth):
    if spp is not None and time is not None:
        raise SceneError("render: give either spp or time, not both")
    if spp is not None and (isinstance(spp, bool) or not isinstance(spp, int) or spp < 1):
        raise SceneError(f"render: spp must be an integer >= 1, got {spp!r}")
    if time is not None and not (isinstance(time, (int, float)) and time > 0):
        raise SceneError(f"render: time must be a number of seconds > 0, got {time!r}")
    if max_depth is not None and (not isinstance(max_depth, int) or max_depth < 1):
        raise SceneError(f"render: max_depth must be an integer >= 1, got {max_depth!r}")
    if sampling not in SAMPLING:
        raise SceneError(f"render: sampling must be one of {', '.join(SAMPLING)}, "
                         f"got {sampling!r}")
    if not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise SceneError(f"render: seed must be an integer in [0, 2**63), got {seed!r}")
    available = numba.config.NUMBA_NUM_THREADS
    if threads is not None and (not isinstance(threads, int) or not 1 <= threads <= available):
        raise SceneError(f"render: threads must be between 1 and {available}, got {threads!r}")


def render(scene, spp=None, *, seed=0, time=None, width=None, height=None,
           max_depth=None, threads=None, sampling="mixture", progress=False, bvh=None):
    """Path-trace `scene`; returns RenderResult(image, stats).

    spp: samples per pixel (default: the scene's); time: render passes until
    this many seconds are spent instead.  sampling: "mixture" (The Rest of Your
    Life, default), "cosine" (The Next Week) or "light" (lights only; misses
    indirect light).  progress: True for a bar on stderr, or a callable
    progress(spp_done, spp_total_or_None, samples_per_s).  bvh: force the
    hierarchy on (True) or off (False); by default scenes with many objects use it.
    Ctrl-C finishes the current pass and returns what was rendered
    (stats.interrupted); a second Ctrl-C raises KeyboardInterrupt.
    """
    _check_options(spp, time, threads, seed, sampling, max_depth)
    cam_changes = {k: v for k, v in (("width", width), ("height", height)) if v is not None}
    if cam_changes:
        scene = scene.with_camera(**cam_changes)
    if spp is None and time is None:
        spp = scene.spp
    arrays = scene.arrays(bvh=bvh)
    cam = scene.camera.array()
    w, h = scene.camera.width, scene.camera.height
    depth = max_depth if max_depth is not None else scene.max_depth
    light_weight = SAMPLING[sampling] if len(arrays.lights) else 0.0

    accum = np.zeros((h, w, 3), dtype=np.float64)
    accum2 = np.zeros((h, w, 3), dtype=np.float64)
    valid = np.zeros((h, w), dtype=np.int64)
    row_stats = np.zeros((h, 2), dtype=np.int64)
    rows = interleaved_rows(h)

    def run(s0, s1):
        render_pass(accum, accum2, valid, row_stats, rows, s0, s1, seed, cam, w, h,
                    arrays.obj_i, arrays.obj_f, arrays.bvh_box, arrays.bvh_node,
                    arrays.bvh_prims, arrays.mat_i, arrays.mat_f, arrays.lights,
                    arrays.bg_kind, arrays.bg, depth, light_weight)

    previous_threads = numba.get_num_threads()
    if threads is not None:
        numba.set_num_threads(threads)
    report = _Progress(progress, spp)
    try:
        t0 = _time.perf_counter()
        run(0, 0)                      # compile (or load from cache); no samples
        compile_seconds = _time.perf_counter() - t0
        report.started()
        done, passes, interrupted = 0, 0, False
        start = _time.perf_counter()
        with _StopOnInterrupt() as stop:
            while True:
                elapsed = _time.perf_counter() - start
                n = _next_pass(done, spp, time, elapsed)
                if n == 0:
                    break
                run(done, done + n)
                done += n
                passes += 1
                report.update(done, passes, _time.perf_counter() - start, w * h)
                if stop.requested:
                    interrupted = spp is None or done < spp
                    break
        seconds = _time.perf_counter() - start
    finally:
        report.close()
        numba.set_num_threads(previous_threads)

    image, stderr = _mean_and_stderr(accum, accum2, valid)
    stats = RenderStats(width=w, height=h, spp=done, spp_requested=spp, seconds=seconds,
                        compile_seconds=compile_seconds, samples=w * h * done,
                        rays=int(row_stats[:, 0].sum()),
                        nan_dropped=int(row_stats[:, 1].sum()),
                        interrupted=interrupted,
                        threads=threads or previous_threads, seed=seed)
    return RenderResult(image, stats, stderr)


def _mean_and_stderr(accum, accum2, valid):
    n = valid[..., None].astype(np.float64)
    mean = np.divide(accum, n, out=np.zeros_like(accum), where=n > 0)
    # Unbiased sample variance / n; pixels with < 2 samples get no estimate (inf).
    var = np.divide(accum2 - n * mean * mean, n - 1, out=np.full_like(accum, np.inf),
                    where=n > 1)
    stderr = np.sqrt(np.maximum(var, 0.0) / np.maximum(n, 1))
    return mean.astype(np.float32), stderr.astype(np.float32)


def _next_pass(done, spp, budget, elapsed):
    """How many samples per pixel the next pass adds (0: finished).

    The first pass is 1 spp; later passes aim at PASS_SECONDS each, and a time
    budget stops before a pass that would clearly overrun it.
    """
    if done == 0:
        return 1
    per_spp = elapsed / done
    n = max(1, int(PASS_SECONDS / per_spp)) if per_spp > 0 else 1
    if spp is not None:
        return min(n, spp - done)
    remaining = budget - elapsed
    if remaining < 0.5 * per_spp:
        return 0
    return max(1, min(n, int(remaining / per_spp)))


class _Progress:
    """Reports passes to a callable, to a tqdm bar on stderr, or nowhere."""

    def __init__(self, progress, spp):
        self.callback = progress if callable(progress) else None
        self.spp = spp
        self.bar = None
        if progress is True:
            from tqdm import tqdm
            self.bar = tqdm(total=spp, unit="spp", desc="compiling", leave=False,
                            dynamic_ncols=True, file=sys.stderr)

    def started(self):
        """Compiling is over: restart the bar's clock so its rate is honest."""
        if self.bar is not None:
            self.bar.set_description("render", refresh=False)
            self.bar.reset(total=self.spp)

    def update(self, done, passes, seconds, pixels):
        rate = done * pixels / seconds if seconds > 0 else 0.0
        if self.callback is not None:
            self.callback(done, self.spp, rate)
        if self.bar is not None:
            self.bar.update(done - self.bar.n)
            self.bar.set_postfix_str(f"pass {passes}, {rate / 1e6:.2f} M samples/s")

    def close(self):
        if self.bar is not None:
            self.bar.close()
