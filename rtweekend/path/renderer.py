"""A path-traced image being rendered: the frozen scene and the running film.

    r = Renderer(scene, seed=1)
    r.compile()
    r.add_samples(4); r.add_samples(12)    # 16 spp, bit-identical to one pass of 16
    image, stats = r.result()

Drivers decide when to add samples: the local one (local.py) in passes on this
machine, the Dask one (distributed/) by merging blocks rendered elsewhere.
"""
import math
import time as _time
import warnings
from typing import NamedTuple

import numba
import numpy as np

from ..kernel import compile_workers
from ..kernel.compile_clock import Stopwatch
from ..kernel.disk_cache import loaded, signature
from ..kernel.jit import collector_paused
from .. import checks, memory
from ..denoise import denoise as denoise_image
from ..errors import FieldError, SceneError, SceneWarning
from ..kernel.rows import interleaved_rows, row_queue, share_rows
from ..options import RenderOptions, thread_count
from ..result import RenderResult, RenderStats
from ..scene.scene import Scene
from . import film as films
from . import seen_light
from .camera import pack_camera
from .lights import listed
from .film import BLOCK_SPP, CONNECTIONS, DROPPED, SEGMENTS, UNSOLVED
from .integrators import ESTIMATORS, needs_of
from .layout import Features, PathParams, SceneArrays
from . import pack, wide_bvh
from .pack import dark_sides, pack_features, pack_scene, scene_bytes


class Frame(NamedTuple):
    """Everything a pass needs, frozen and picklable (sent once to each worker)."""
    scene: SceneArrays
    params: PathParams
    rows: np.ndarray        # the order rows go to threads
    features: Features = Features()   # what the kernel is compiled with (layout.py)
    estimator: str = "path"           # which of integrators.ESTIMATORS renders it
    aov: bool = False                 # the film keeps feature images (film.py)

    @property
    def width(self):
        return self.params.width

    @property
    def height(self):
        return self.params.height


def freeze(scene, options, stand_in=False):
    """The Frame for rendering `scene` with validated RenderOptions.  stand_in:
    one of the same types, made in a moment (pack_scene), to compile the
    kernels with before the scene is packed."""
    scene = options.sized(scene)          # one side alone keeps the aspect ratio
    arrays = pack_scene(scene, bvh=options.bvh, stand_in=stand_in)
    strategy = options.strategy
    needs = needs_of(strategy)
    arrays = needs.lights(strategy, arrays)
    if strategy.facing:
        arrays = arrays._replace(dark_sides=dark_sides(arrays))
    camera = scene.resolved_camera()
    max_depth = scene.resolved_max_depth() if options.max_depth is None else options.max_depth
    params = PathParams(cam=pack_camera(camera), width=camera.width, height=camera.height,
                        seed=options.seed, max_depth=max_depth,
                        light_weight=strategy.light_weight if len(listed(arrays)) else 0.0,
                        clamp=options.clamp_value, pairs=strategy.sobol_pairs or None)
    features = Features(None, *pack_features(scene, arrays))._replace(
        **needs.features(strategy, scene, arrays))
    needs.check(options.sampling, arrays)
    return Frame(arrays, params, interleaved_rows(camera.height), features, strategy.estimator,
                 options.features)


def _missing_kernels(stand_in, options):
    """kernel_calls of the stand-in Frame if any of its kernels is missing from
    the cache, else None."""
    film = films.new_film(1, 1, splats(stand_in), stand_in.aov)
    calls = kernel_calls(stand_in, film, bool(options.denoise))
    return None if all(loaded(d, signature(args)) for d, args in calls) else calls


def render_samples(frame, film, s0, s1, rows=None):
    """Add samples s0 .. s1 - 1 of every pixel (of `rows` only: a slice of
    frame.rows) to `film`.  A pixel's sums depend on its sample indices only,
    so rows rendered in several parts give the bits of one whole pass.  With
    every row, a film with splats is folded at each block's end (film.py)."""
    estimator = kernel(frame)
    part_of_the_rows = rows is not None
    rows = frame.rows if rows is None else rows
    threads = numba.get_num_threads() if s1 > s0 else 1
    for a, b in _block_parts(s0, s1) if film.splat.size else [(s0, s1)]:
        features = estimator.NEEDS.block(frame, frame.features, a, b, threads)
        share_rows(lambda queue: estimator.render_pass(film, frame.scene, frame.params, queue,
                                                       a, b, *features), rows, threads)
        if film.splat.size and not part_of_the_rows and b > a and b % BLOCK_SPP == 0:
            films.fold_splats(film)


def _block_parts(s0, s1):
    """[s0, s1) cut at the ends of blocks of BLOCK_SPP samples (at least one part)."""
    parts, a = [], s0
    while True:
        b = min(s1, (a // BLOCK_SPP + 1) * BLOCK_SPP)
        parts.append((a, b))
        if b >= s1:
            return parts
        a = b


def kernel(frame):
    """The module of the estimator that renders `frame` (integrators/)."""
    return ESTIMATORS[frame.estimator]


def kernel_calls(frame, film, denoise=False):
    """[(kernel, arguments)] of every kernel a render of `frame` calls, with no
    samples: the estimator's (and those it needs beside it, such as bdpt's
    photon tracer), the denoiser's passes."""
    estimator = kernel(frame)
    calls = [(estimator.render_pass, (film, frame.scene, frame.params,
                                      row_queue(frame.rows[:0]), 0, 0, *frame.features))]
    calls.extend(estimator.NEEDS.kernels(frame))
    if denoise:
        calls.extend(seen_light.kernel_calls(frame))
    return calls


def splats(frame):
    """Does the estimator of `frame` splat (its film needs the splat arrays)?"""
    return _splats(frame.estimator)


def _splats(estimator):
    return ESTIMATORS[estimator].NEEDS.splats


def block_film(frame, s0, s1):
    """A fresh film of samples s0 .. s1 - 1, s0 on a block boundary (for workers)."""
    if s0 % BLOCK_SPP:
        raise ValueError(f"block_film: s0 = {s0} is not a multiple of {BLOCK_SPP}")
    film = films.new_film(frame.height, frame.width, splats(frame), frame.aov)
    render_samples(frame, film, s0, s1)
    return film


def _check_memory(scene, options):
    """Before the scene is packed or the film allocated: beyond the memory, one
    line, nothing done (memory.py)."""
    scene.check()
    camera = scene.resolved_camera()
    width, height = options.image_size(camera)
    needs = needs_of(options.strategy)
    scene_part = scene_bytes(scene)
    memory.check(films.render_bytes(height, width, needs.splats, options.features,
                                    bool(options.denoise))
                 + scene_part + needs.extra_bytes(options.strategy), width, height,
                 scene=scene_part, objects=len(scene.objects),
                 primitives=sum(shape.primitives for shape in scene.objects),
                 origin=options.size_origin(scene))


class Renderer:
    """One image being rendered: the frozen scene and the running film.

    Renderer(scene, options) or Renderer(scene, seed=1, width=64, ...) with the
    fields of RenderOptions.
    """

    def __init__(self, scene: Scene, options: RenderOptions | None = None, **fields):
        if options is None:
            options = RenderOptions.named("Renderer", "path", **fields)
        elif fields:
            raise TypeError("Renderer: give options or fields, not both")
        self._compiling = Stopwatch()     # every compile from here on counts
        self.options = options = options.for_scene(scene)     # the default, named
        for doubt in scene.doubts():
            warnings.warn(doubt, SceneWarning, stacklevel=2)
        _check_memory(scene, options)
        # With a helper process standing by and kernels to compile, the scene
        # is packed after they are compiled (compile), typed meanwhile by a
        # stand-in of its arrays: the helper compiles the BVH builder while
        # this process starts on the kernels, then shares them.
        self._scene, self._frame, self._stand_in = scene, None, None
        with thread_count(options.threads):     # the BVH is built on threads too
            if compile_workers.standing_by():
                self._stand_in = _missing_kernels(freeze(scene, options, stand_in=True),
                                                  options)
            if self._stand_in is None:
                self._frame, self._scene = freeze(scene, options), None
        camera = options.sized(scene).resolved_camera()
        self.width, self.height = camera.width, camera.height
        self.name = scene.name     # what a preview calls the image
        # What runs, said by the summary (another strategy's bits, and why, or
        # the one asked for).
        self.sampling, self.sampling_note = needs_of(options.strategy).runs_as(
            options.strategy, scene) or (options.sampling, None)
        self.film = films.new_film(self.height, self.width,
                                   _splats(options.strategy.estimator), options.features)
        self.spp = 0               # samples per pixel so far, in every pixel
        self.band = 0              # a pass over part of the rows in progress: its spp
        self.rows_done = 0         # ... and how many of frame.rows have them
        self.seconds = 0.0         # time spent in passes
        self.remote_compile_seconds = 0.0   # waiting for Dask workers to compile
        self.threads = None        # Numba threads of the last pass here
        self._preview = None       # show()'s display in a notebook

    def compile(self) -> float:
        """Compile every kernel the render calls (or load them from the cache):
        the estimator's, the photon maps' tracer, the denoiser's passes when
        the options denoise -- those missing from the cache side by side
        (kernel/compile_workers.py).  Returns compile_seconds."""
        with collector_paused(), thread_count(self.options.threads):
            if self._stand_in is not None:
                if pack.hierarchy_wanted(self._scene, self.options.bvh) \
                        and not wide_bvh.compiled():
                    compile_workers.compile_ahead(wide_bvh.compile_ahead)
                compile_workers.compile_all(self._stand_in)
                self._stand_in = None
            compile_workers.compile_all(kernel_calls(self.frame, self.film,
                                                     bool(self.options.denoise)))
        return self.compile_seconds

    @property
    def frame(self) -> Frame:
        """The frozen scene, parameters and features (packed on first use)."""
        if self._frame is None:
            with thread_count(self.options.threads):
                self._frame = freeze(self._scene, self.options)
            self._scene = None
        return self._frame

    @frame.setter
    def frame(self, frame: Frame):
        """A Frame of one's own (tests, benchmarks): the same kernels' types."""
        self._frame, self._scene = frame, None

    @property
    def compile_seconds(self) -> float:
        """Seconds spent compiling since this Renderer was made: packing the
        scene and building its BVH, every kernel, and waiting for the helper
        processes (kernel/compile_clock.py) or Dask workers that compiled some."""
        return self._compiling.seconds() + self.remote_compile_seconds

    def show(self) -> None:
        """In a Jupyter notebook: show the result so far, in one display that
        later calls update in place (step-by-step rendering)."""
        from ..io.preview import NotebookPreview, require
        require()
        if self._preview is None:
            self._preview = NotebookPreview(self.result(denoise=False))
        else:
            self._preview.update(self, final=True)

    def add_samples(self, n: int) -> float:
        """Render samples spp .. spp + n - 1 of every pixel here, with the options'
        threads (None: as many as Numba has); returns the seconds."""
        n = self._count(n, "add_samples")
        if self.band:
            raise SceneError("add_samples: a pass over part of the rows is in progress "
                             "(add_rows); finish it first")
        with thread_count(self.options.threads) as self.threads:
            t0 = _time.perf_counter()
            render_samples(self.frame, self.film, self.spp, self.spp + n)
            dt = _time.perf_counter() - t0
        self.spp += n
        self.seconds += dt
        return dt

    def add_rows(self, n: int, count: int) -> float:
        """Render samples spp .. spp + n - 1 of the next `count` rows (in
        frame.rows order) of a pass over part of the rows; when every row has
        them, spp becomes spp + n.  The bits are those of add_samples(n).
        Returns the seconds."""
        n = self._count(n, "add_rows")
        if self.band and n != self.band:
            raise SceneError(f"add_rows: n: the pass in progress adds {self.band} spp, got {n}")
        try:
            count = checks.integer(count, "count", lo=1, hi=self.height - self.rows_done)
        except FieldError as e:
            raise SceneError(f"add_rows: {e}") from None
        if self.film.splat.size and self.spp // BLOCK_SPP != (self.spp + n - 1) // BLOCK_SPP:
            raise SceneError(f"add_rows: n: light carried to the camera is added up in blocks "
                             f"of {BLOCK_SPP} samples, and samples {self.spp} to "
                             f"{self.spp + n - 1} cross one; add fewer")
        rows = self.frame.rows[self.rows_done:self.rows_done + count]
        with thread_count(self.options.threads) as self.threads:
            t0 = _time.perf_counter()
            render_samples(self.frame, self.film, self.spp, self.spp + n, rows)
            dt = _time.perf_counter() - t0
        self.band, self.rows_done = n, self.rows_done + count
        if self.rows_done == self.height:
            self.spp, self.band, self.rows_done = self.spp + n, 0, 0
            if self.film.splat.size and self.spp % BLOCK_SPP == 0:
                films.fold_splats(self.film)
        self.seconds += dt
        return dt

    def _count(self, n, method):
        """n samples per pixel more, checked like every number (checks.py)."""
        try:
            return checks.integer(n, "n", lo=1, hi=checks.MAX_SPP - self.spp)
        except FieldError as e:
            raise SceneError(f"{method}: {e}") from None

    def merge(self, film, spp):
        """Add a film of the samples from self.spp up to `spp`, rendered elsewhere."""
        films.merge(self.film, film)
        self.spp = spp

    def result(self, *, spp_requested=None, interrupted=False, threads=None, stopped_by=None,
               denoise=None):
        """The RenderResult of the samples so far; denoise (None: the options')
        adds the image denoised by Open Image Denoise (denoise.py) beside it.
        Asks nothing of the frame before a sample is rendered: a render stopped
        while compiling may not have packed its scene, and packing would wait
        for the compile that was left behind (kernel/calls.py)."""
        denoise = self.options.denoise if denoise is None else denoise
        rendered = self.spp > 0 or self.rows_done > 0
        if denoise and not self.options.features:
            raise SceneError("result: denoise: this renderer keeps no feature images; "
                             "make it with denoise=True (or aov=...)")
        image, stderr = films.mean_and_stderr(self.film, self.spp)
        fireflies, firefly_energy = films.firefly_stats(self.film, float(image.mean()))
        row_stats = self.film.row_stats
        clamp = self.options.clamp_value            # as freeze packs it
        stats = RenderStats(
            width=self.width, height=self.height, spp=self.spp,
            spp_requested=spp_requested, seconds=self.seconds,
            compile_seconds=self.compile_seconds,
            samples=self.width * (self.height * self.spp + self.rows_done * self.band),
            rays=int(row_stats[:, SEGMENTS].sum()), nan_dropped=int(row_stats[:, DROPPED].sum()),
            interrupted=interrupted,
            threads=threads or self.threads or numba.get_num_threads(),
            seed=self.options.seed, fireflies=fireflies, firefly_energy=firefly_energy,
            clamp=None if math.isinf(clamp) else clamp,
            stopped_by=stopped_by if interrupted else None,
            partial_rows=self.rows_done, partial_spp=self.band, sampling=self.sampling,
            sampling_note=self.sampling_note,
            connections=int(row_stats[:, CONNECTIONS].sum()),
            unsolved=int(row_stats[:, UNSOLVED].sum()))
        wanted = self.options.aov or ()
        samples = np.full(self.height, self.spp)
        if self.rows_done:              # a pass over part of the rows
            samples[self.frame.rows[:self.rows_done]] += self.band
        features = films.features(self.film, samples)
        denoised = None
        if denoise and rendered:
            t0 = _time.perf_counter()
            with thread_count(self.options.threads) as threads:
                light, _ = seen_light.estimate(self.frame, features["emission"],
                                               int(samples.max()), stats.rays, threads)
            denoised, _ = denoise_image(image, **features, light=light)
            stats.denoise_seconds = _time.perf_counter() - t0
        layers = {**features, "stderr": stderr}
        return RenderResult(image, stats, stderr, {k: layers[k] for k in wanted}, denoised)
