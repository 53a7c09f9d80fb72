"""Progressive rendering: the prange kernel, the accumulating Renderer, render().

A pass adds samples [s0, s1) to every pixel.  Each sample's random stream is
keyed by (pixel, sample index, seed) and is added to its pixel's float64 sum in
sample order, so the image is bit-identical for any thread count and any way of
splitting the samples into passes.
"""
import math
import time as _time
from contextlib import contextmanager
from typing import NamedTuple

import numba
import numpy as np

from .classic_scene import render_classic_scene
from .errors import SceneError
from .jit import collector_paused, jit_parallel
from .path import trace_row
from .progress import Progress, StopOnInterrupt
from .result import RenderResult, RenderStats, firefly_stats, mean_and_stderr
from .rows import interleaved_rows
from .scene import SceneArrays
from .sums import BINS_PER_OCTAVE, BLOCK_SPP, HIST_BINS, LOG2_LOWEST, Sums

__all__ = ["BLOCK_SPP", "HIST_BINS", "Renderer", "Sums", "block_sums", "render"]

SAMPLING = {"cosine": 0.0, "mixture": 0.5, "light": 1.0}
PASS_SECONDS = 0.5      # short passes: a smooth progress bar, a quick Ctrl-C


@jit_parallel
def render_pass(accum, accum2, partial, partial2, valid, row_stats, hist_n, hist_e, rows,
                s0, s1, seed, cam, width, height, obj_i, obj_f, bvh_box, bvh_node,
                bvh_prims, mat_i, mat_f, lights, bg_kind, bg, max_depth, light_weight,
                clamp):
    """Add samples s0..s1-1 of every pixel; rows[k] spreads the work over threads.

    Radiance and its square (for the standard error) are summed per block of
    BLOCK_SPP samples into partial/partial2, which is added to accum/accum2
    when the block is complete: so the sums depend only on the sample indices,
    never on how passes, threads or machines split the work.
    row_stats[y] += (ray segments traced, samples dropped as NaN/Inf);
    hist_n/hist_e[y] count and sum the samples by value, for the firefly stats.
    clamp (inf: none) caps each sample's channels -- biased, but tames fireflies.
    """
    for k in numba.prange(rows.shape[0]):
        trace_row(rows[k], accum, accum2, partial, partial2, valid, row_stats, hist_n,
                  hist_e, s0, s1, seed, cam, width, height, obj_i, obj_f, bvh_box,
                  bvh_node, bvh_prims, mat_i, mat_f, lights, bg_kind, bg, max_depth,
                  light_weight, clamp)


def check_options(*, spp=None, time=None, threads=None, seed=0, sampling="mixture",
                  max_depth=None, clamp=None):
    """Raise SceneError for a render option that cannot be used."""
    if clamp is not None and not (isinstance(clamp, (int, float)) and clamp > 0):
        raise SceneError(f"render: clamp must be a number > 0, got {clamp!r}")
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


@contextmanager
def thread_count(threads):
    """Run with `threads` Numba threads (None: leave as is), then restore."""
    previous = numba.get_num_threads()
    if threads is not None:
        numba.set_num_threads(threads)
    try:
        yield numba.get_num_threads()
    finally:
        numba.set_num_threads(previous)


class Frame(NamedTuple):
    """Everything a pass needs, frozen and picklable (sent once to each worker)."""
    arrays: SceneArrays
    cam: np.ndarray
    width: int
    height: int
    max_depth: int
    light_weight: float
    seed: int
    clamp: float
    rows: np.ndarray


def freeze(scene, *, seed=0, width=None, height=None, max_depth=None, sampling="mixture",
           bvh=None, clamp=None):
    """The Frame for rendering `scene` with these options (SceneError if bad)."""
    check_options(seed=seed, sampling=sampling, max_depth=max_depth, clamp=clamp)
    changes = {k: v for k, v in (("width", width), ("height", height)) if v is not None}
    if changes:
        scene = scene.with_camera(**changes)
    arrays = scene.arrays(bvh=bvh)
    camera = scene.resolved_camera()
    return Frame(arrays=arrays, cam=camera.array(), width=camera.width,
                 height=camera.height,
                 max_depth=max_depth if max_depth is not None else scene.resolved_max_depth(),
                 light_weight=SAMPLING[sampling] if len(arrays.lights) else 0.0,
                 seed=seed, clamp=math.inf if clamp is None else float(clamp),
                 rows=interleaved_rows(camera.height))


def render_samples(frame, sums, s0, s1):
    """Add samples s0 .. s1 - 1 of every pixel to `sums`."""
    a = frame.arrays
    render_pass(sums.accum, sums.accum2, sums.partial, sums.partial2, sums.valid,
                sums.row_stats, sums.hist_n, sums.hist_e, frame.rows, s0, s1, frame.seed,
                frame.cam, frame.width, frame.height, a.obj_i, a.obj_f, a.bvh_box,
                a.bvh_node, a.bvh_prims, a.mat_i, a.mat_f, a.lights, a.bg_kind, a.bg,
                frame.max_depth, frame.light_weight, frame.clamp)


def block_sums(frame, s0, s1):
    """Fresh sums of samples s0 .. s1 - 1, s0 on a block boundary (for workers)."""
    if s0 % BLOCK_SPP:
        raise ValueError(f"block_sums: s0 = {s0} is not a multiple of {BLOCK_SPP}")
    sums = Sums(frame.height, frame.width)
    render_samples(frame, sums, s0, s1)
    return sums


class Renderer:
    """One image being rendered: the frozen scene and the running sums.

        r = Renderer(scene, seed=1)
        r.compile()
        r.add_samples(4); r.add_samples(12)    # 16 spp, same as one pass of 16
        image, stats = r.result()
    """

    def __init__(self, scene, **options):
        self.frame = freeze(scene, **options)
        self.width, self.height = self.frame.width, self.frame.height
        self.sums = Sums(self.height, self.width)
        self.spp = 0               # samples per pixel so far
        self.seconds = 0.0         # time spent in passes
        self.compile_seconds = 0.0

    def compile(self):
        """Compile the kernel (or load it from the cache) with no samples."""
        t0 = _time.perf_counter()
        with collector_paused():
            render_samples(self.frame, self.sums, 0, 0)
        self.compile_seconds = _time.perf_counter() - t0
        return self.compile_seconds

    def add_samples(self, n):
        """Render samples spp .. spp + n - 1 of every pixel; returns the seconds."""
        t0 = _time.perf_counter()
        render_samples(self.frame, self.sums, self.spp, self.spp + n)
        dt = _time.perf_counter() - t0
        self.spp += n
        self.seconds += dt
        return dt

    def result(self, *, spp_requested=None, interrupted=False, threads=None, stopped_by=None):
        s = self.sums
        image, stderr = mean_and_stderr(s.accum + s.partial, s.accum2 + s.partial2, s.valid)
        fireflies, firefly_energy = firefly_stats(
            s.hist_n.sum(axis=0), s.hist_e.sum(axis=0), float(image.mean()),
            LOG2_LOWEST, BINS_PER_OCTAVE)
        stats = RenderStats(
            width=self.width, height=self.height, spp=self.spp,
            spp_requested=spp_requested, seconds=self.seconds,
            compile_seconds=self.compile_seconds, samples=self.width * self.height * self.spp,
            rays=int(s.row_stats[:, 0].sum()), nan_dropped=int(s.row_stats[:, 1].sum()),
            interrupted=interrupted, threads=threads or numba.get_num_threads(),
            seed=self.frame.seed, fireflies=fireflies, firefly_energy=firefly_energy,
            clamp=None if math.isinf(self.frame.clamp) else self.frame.clamp,
            stopped_by=stopped_by if interrupted else None)
        return RenderResult(image, stats, stderr)


def render(scene, spp=None, *, seed=0, time=None, width=None, height=None,
           max_depth=None, threads=None, sampling=None, progress=False, bvh=None,
           clamp=None, client=None):
    """Render `scene`; returns RenderResult, which unpacks as (image, stats).

    A classic (Computer Graphics from Scratch) scene is ray traced once per
    pixel; width, height, max_depth (its recursion depth) and threads apply,
    the sampling options do not.  Otherwise the scene is path traced:

    spp: samples per pixel (default: the scene's); time: render passes until
    this many seconds are spent instead.  sampling: "mixture" (The Rest of Your
    Life, default), "cosine" (The Next Week) or "light" (lights only; misses
    indirect light).  progress: True for a bar on stderr, or a callable
    progress(spp_done, spp_total_or_None, samples_per_s).  bvh: force the
    hierarchy on (True) or off (False); by default scenes with many objects use it.
    clamp: cap every sample's channels at this value (biased: it removes energy;
    off by default).  Ctrl-C finishes the current pass and returns what was rendered
    (stats.interrupted); a second Ctrl-C raises KeyboardInterrupt.
    client: a dask.distributed Client: render blocks of samples on its workers
    instead, bit-identical to rendering here (rtweekend.distributed).
    """
    if client is not None:
        from .distributed import render_distributed
        return render_distributed(client, scene, spp, seed=seed, time=time, width=width,
                                  height=height, max_depth=max_depth, threads=threads,
                                  sampling=sampling, progress=progress, bvh=bvh, clamp=clamp)
    if scene.resolved_integrator() == "classic":
        return _render_classic(scene, spp=spp, time=time, width=width, height=height,
                               max_depth=max_depth, threads=threads, sampling=sampling,
                               clamp=clamp, bvh=bvh)
    sampling = sampling or "mixture"
    check_options(spp=spp, time=time, threads=threads, seed=seed, sampling=sampling,
                  max_depth=max_depth, clamp=clamp)
    renderer = Renderer(scene, seed=seed, width=width, height=height, max_depth=max_depth,
                        sampling=sampling, bvh=bvh, clamp=clamp)
    if spp is None and time is None:
        spp = scene.spp
    report = Progress(progress, spp)
    interrupted = False
    try:
        with thread_count(threads) as used, StopOnInterrupt() as stop:
            renderer.compile()
            report.started()
            passes = 0
            while n := _next_pass(renderer.spp, spp, time, renderer.seconds):
                renderer.add_samples(n)
                passes += 1
                report.update(renderer.spp, passes, renderer.seconds,
                              renderer.width * renderer.height)
                if stop.requested:
                    interrupted = spp is None or renderer.spp < spp
                    break
    finally:
        report.close()
    return renderer.result(spp_requested=spp, interrupted=interrupted, threads=used,
                           stopped_by="Ctrl-C")


def _render_classic(scene, *, width, height, max_depth, threads, **path_options):
    given = [name for name, value in path_options.items() if value is not None]
    if given:
        raise SceneError(f"render: {given[0]} does not apply to the classic ray tracer "
                         "(one ray per pixel, no sampling)")
    if max_depth is not None and (not isinstance(max_depth, int) or max_depth < 0):
        raise SceneError(f"render: max_depth must be an integer >= 0, got {max_depth!r}")
    check_options(threads=threads)
    if width is not None or height is not None:
        scene = scene.with_camera(**{k: v for k, v in (("width", width), ("height", height))
                                     if v is not None})
    scene.check()
    with thread_count(threads):
        return render_classic_scene(scene, max_depth=max_depth)


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
