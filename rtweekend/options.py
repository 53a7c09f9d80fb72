"""The options of a render, validated once, in one place.

    options = RenderOptions("path", spp=64, seed=1, sampling="mixture")

Every option the command line, the API or a Renderer passes goes through here
(its numbers through checks.py, as the scene's do); a bad one raises SceneError
with a one-line message naming it.
"""
import dataclasses
import difflib
import math
from contextlib import contextmanager
from dataclasses import dataclass

import numba

from . import checks
from .errors import FieldError, SceneError
# The path tracer's strategies, each declared by its estimator, and the default.
from .path.integrators import (DEFAULT_SAMPLING, SAMPLINGS, Sampling,  # noqa: F401
                               default_sampling, needs_of)



# Options of the path tracer only: the classic ray tracer casts one ray per pixel.
PATH_ONLY = ("spp", "time", "sampling", "clamp", "bvh", "aov", "denoise", "preview")
# Feature images a path-traced render can add (film.py: for denoisers).
AOVS = ("albedo", "normal", "emission")
# What `aov` can name: the feature images, and the per-pixel standard error
# (always computed; named, it is saved as a layer beside the image too).
LAYERS = AOVS + ("stderr",)
# The numeric options (checks.option holds each one's rule).
NUMBERS = ("spp", "time", "seed", "width", "height", "max_depth", "threads", "clamp")


@dataclass(frozen=True)
class RenderOptions:
    """How to render: the budget, the image size, the seed and the estimator.

    integrator: "path" or "classic" (the scene's; it decides what applies).
    spp / time: samples per pixel, or seconds of passes (None, None: the scene's spp).
    width, height, max_depth: None for the scene's.  threads: None for all.
    sampling: a key of SAMPLINGS (path only; None: DEFAULT_SAMPLING).
    clamp: cap on each sample's channels (biased; None: off).
    bvh: force the hierarchy on or off (None: by the scene's size).
    aov: feature images to add, some of AOVS (None or (): none): the albedo and
    normal of what each pixel's paths first see through mirrors and glass, and
    the light they see emitted there.
    denoise: also make the image denoised by Open Image Denoise (denoise.py).
    preview: show the image as it renders: True in a Jupyter notebook
    (io/preview.py), "tev" or "tev://HOST:PORT" in the tev viewer (io/tev.py).
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
    aov: tuple | None = None
    denoise: bool | None = None
    preview: bool | str | None = None
    progress: object = False

    def __post_init__(self):
        if self.integrator not in ("path", "classic"):
            raise SceneError(f"render: integrator must be 'path' or 'classic', "
                             f"got {self.integrator!r}")
        if self.seed is None:
            raise SceneError("render: seed: expected an integer, got None")
        if self.integrator == "classic":
            self._check_classic()
        else:
            self._check_path()

    def _check_path(self):
        if self.spp is not None and self.time is not None:
            raise SceneError("render: give either spp or time, not both")
        self._check_numbers()
        if self.sampling is not None and self.sampling not in SAMPLINGS:
            raise SceneError(f"render: sampling: must be one of {', '.join(SAMPLINGS)}, "
                             f"got {self.sampling!r}")
        if self.bvh is not None and not isinstance(self.bvh, bool):
            raise SceneError(f"render: bvh: must be True, False or None, got {self.bvh!r}")
        self._check_aov()
        self._check_denoise()
        if self.preview is not None:
            if isinstance(self.preview, str) and self.preview.startswith("tev"):
                from .io.tev import address
                address(self.preview)                 # SceneError if malformed
            elif not isinstance(self.preview, bool):
                raise SceneError("render: preview: must be True (a notebook), \"tev\" or "
                                 f"\"tev://HOST:PORT\", or False; got {self.preview!r}")
            elif self.preview:
                from .io.preview import require
                require()

    def _check_denoise(self):
        """denoise: a bool; with it, paths from the camera, and OIDN installed."""
        if self.denoise is None:
            return
        if not isinstance(self.denoise, bool):
            raise SceneError(f"render: denoise: must be True or False, got {self.denoise!r}")
        if self.denoise:
            if not needs_of(self.strategy).feature_images:
                raise SceneError(f"render: denoise: {self.sampling} traces no paths from the "
                                 "camera, so it has no feature images to denoise with; use "
                                 "a path-tracing sampling")
            from .denoise import require
            require()

    @property
    def features(self):
        """Does the film keep feature images: asked for, or for the denoiser."""
        return any(a in AOVS for a in self.aov or ()) or bool(self.denoise)

    def _check_aov(self):
        """aov: None, or names of LAYERS (a string of them separated by commas too)."""
        aov = self.aov
        if aov is None:
            return
        if isinstance(aov, str):
            aov = [a.strip() for a in aov.split(",") if a.strip()]
        if not isinstance(aov, (list, tuple)) or not all(isinstance(a, str) for a in aov):
            raise SceneError(f"render: aov: expected names among {', '.join(LAYERS)}, "
                             f"got {aov!r}")
        for a in aov:
            if a not in LAYERS:
                close = difflib.get_close_matches(a, LAYERS, n=1)
                hint = f" (did you mean '{close[0]}'?)" if close else ""
                raise SceneError(f"render: aov: unknown feature '{a}'{hint}; expected "
                                 f"{', '.join(LAYERS)}")
        if set(aov) & set(AOVS) and not needs_of(self.strategy).feature_images:
            raise SceneError(f"render: aov: {self.sampling} traces no paths from the camera, "
                             "so it has no feature images; use a path-tracing sampling")
        object.__setattr__(self, "aov", tuple(dict.fromkeys(aov)) or None)

    def _check_classic(self):
        for name in PATH_ONLY:
            if getattr(self, name) is not None:
                raise SceneError(f"render: {name} does not apply to the classic ray tracer "
                                 "(one ray per pixel, no sampling)")
        self._check_numbers()

    def _check_numbers(self):
        """Every number through checks.option: type, finite, range (normalised:
        4.0 samples become 4)."""
        for name in NUMBERS:
            try:
                value = checks.option(name, getattr(self, name), integrator=self.integrator,
                                      threads_available=numba.config.NUMBA_NUM_THREADS)
            except FieldError as e:
                raise SceneError(f"render: {e}") from None
            object.__setattr__(self, name, value)

    @classmethod
    def named(cls, where, integrator, **fields):
        """RenderOptions(integrator, **fields), an unknown field a SceneError
        naming `where` (Renderer's keyword arguments are these fields)."""
        known = [f for f in cls.__dataclass_fields__ if f != "integrator"]
        for key in fields:
            if key not in known:
                close = difflib.get_close_matches(key, known, n=1)
                hint = f" (did you mean '{close[0]}'?)" if close else ""
                raise SceneError(f"{where}: unknown option '{key}'{hint}; expected one of: "
                                 + ", ".join(known))
        return cls(integrator, **fields)

    @property
    def strategy(self):
        """The Sampling of this render (path only; for_scene resolves the default)."""
        return SAMPLINGS[self.sampling or DEFAULT_SAMPLING]

    def for_scene(self, scene):
        """These options with the sampling named: the default_sampling of `scene`
        when none is given."""
        if self.sampling is not None or self.integrator != "path":
            return self
        return dataclasses.replace(self, sampling=default_sampling(scene))

    def image_size(self, camera):
        """(width, height) of the image: the options', the camera's where not
        given; one side alone keeps the camera's aspect ratio."""
        w, h = self.width, self.height
        if w is not None and h is None:
            h = max(1, round(w * camera.height / camera.width))
        elif h is not None and w is None:
            w = max(1, round(h * camera.width / camera.height))
        return (camera.width, camera.height) if w is None else (w, h)

    def size_origin(self, scene):
        """What set the image's size, for messages: the options or the camera."""
        if self.width is not None or self.height is not None:
            return "the width/height asked for"
        return f"the camera of scene '{scene.name}'"

    def sized(self, scene):
        """`scene` with its camera at image_size."""
        camera = scene.resolved_camera()
        w, h = self.image_size(camera)
        if (w, h) == (camera.width, camera.height):
            return scene
        return scene.with_camera(width=w, height=h)

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
