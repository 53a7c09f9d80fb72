"""The options of a render, validated once, in one place.

    options = RenderOptions("path", spp=64, seed=1, sampling="mixture")

Every option the command line, the API or a Renderer passes goes through here;
a bad one raises SceneError with a one-line message naming it.
"""
import math
from contextlib import contextmanager
from dataclasses import dataclass

import numba

from .errors import SceneError

# Sampling strategies of the path tracer: each one's share of light sampling in
# the mixture pdf at diffuse hits (path/pdf.py).
SAMPLINGS = {"cosine": 0.0, "mixture": 0.5, "light": 1.0}
DEFAULT_SAMPLING = "mixture"
# Options of the path tracer only: the classic ray tracer casts one ray per pixel.
PATH_ONLY = ("spp", "time", "sampling", "clamp", "bvh")


@dataclass(frozen=True)
class RenderOptions:
    """How to render: the budget, the image size, the seed and the estimator.

    integrator: "path" or "classic" (the scene's; it decides what applies).
    spp / time: samples per pixel, or seconds of passes (None, None: the scene's spp).
    width, height, max_depth: None for the scene's.  threads: None for all.
    sampling: a key of SAMPLINGS (path only; None: DEFAULT_SAMPLING).
    clamp: cap on each sample's channels (biased; None: off).
    bvh: force the hierarchy on or off (None: by the scene's size).
    progress: True for a bar on stderr, a callable, or False.
    """
    integrator: str = "path"
    spp: int | None = None
    time: float | None = None
    seed: int = 0
    width: int | None = None
    height: int | None = None
    max_depth: int | None = None
    threads: int | None = None
    sampling: str | None = None
    clamp: float | None = None
    bvh: bool | None = None
    progress: object = False

    def __post_init__(self):
        if self.integrator == "classic":
            self._check_classic()
        else:
            self._check_path()

    def _check_path(self):
        clamp, spp, time = self.clamp, self.spp, self.time
        if clamp is not None and not (isinstance(clamp, (int, float)) and clamp > 0):
            raise SceneError(f"render: clamp must be a number > 0, got {clamp!r}")
        if spp is not None and time is not None:
            raise SceneError("render: give either spp or time, not both")
        if spp is not None and (isinstance(spp, bool) or not isinstance(spp, int) or spp < 1):
            raise SceneError(f"render: spp must be an integer >= 1, got {spp!r}")
        if time is not None and not (isinstance(time, (int, float)) and time > 0):
            raise SceneError(f"render: time must be a number of seconds > 0, got {time!r}")
        depth = self.max_depth
        if depth is not None and (not isinstance(depth, int) or depth < 1):
            raise SceneError(f"render: max_depth must be an integer >= 1, got {depth!r}")
        if self.sampling is not None and self.sampling not in SAMPLINGS:
            raise SceneError(f"render: sampling must be one of {', '.join(SAMPLINGS)}, "
                             f"got {self.sampling!r}")
        seed = self.seed
        if not isinstance(seed, int) or not 0 <= seed < 2**63:
            raise SceneError(f"render: seed must be an integer in [0, 2**63), got {seed!r}")
        self._check_threads()

    def _check_classic(self):
        for name in PATH_ONLY:
            if getattr(self, name) is not None:
                raise SceneError(f"render: {name} does not apply to the classic ray tracer "
                                 "(one ray per pixel, no sampling)")
        depth = self.max_depth
        if depth is not None and (not isinstance(depth, int) or depth < 0):
            raise SceneError(f"render: max_depth must be an integer >= 0, got {depth!r}")
        self._check_threads()

    def _check_threads(self):
        available = numba.config.NUMBA_NUM_THREADS
        threads = self.threads
        if threads is not None and (not isinstance(threads, int)
                                    or not 1 <= threads <= available):
            raise SceneError(f"render: threads must be between 1 and {available}, "
                             f"got {threads!r}")

    @property
    def light_weight(self):
        """The mixture's share of light sampling for this sampling strategy."""
        return SAMPLINGS[self.sampling or DEFAULT_SAMPLING]

    @property
    def clamp_value(self):
        return math.inf if self.clamp is None else float(self.clamp)


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
