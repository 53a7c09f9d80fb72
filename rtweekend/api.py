"""render(): one entry point for every scene, integrator and driver.

The options are validated once (options.py); the scene's contents choose the
integrator (the classic ray tracer or the path tracer); for the path tracer,
`client` chooses the driver: this machine (local.py) or a Dask cluster
(distributed/), over the same Renderer, with the same bits.
"""
from collections.abc import Callable, Sequence

from .classic.render import render_classic
from .distributed import client as dask_driver
from .distributed.cluster import check_render
from .io.progress import Spinner
from .kernel.calls import call_awake
from .kernel.compile_workers import prestart
from .local import render_locally
from .options import RenderOptions
from .errors import SceneError
from .path.renderer import Renderer
from .result import RenderResult
from .scene import Scene


def render(scene: Scene, spp: int | None = None, *, seed: int = 0,
           time: float | None = None, width: int | None = None, height: int | None = None,
           max_depth: int | None = None, threads: int | None = None,
           sampling: str | None = None, progress: bool | Callable = False,
           bvh: bool | None = None, clamp: float | None = None, client: object = None,
           aov: str | Sequence[str] | None = None, denoise: bool = False,
           preview: bool | str = False) -> RenderResult:
    """Render `scene`; returns RenderResult, which unpacks as (image, stats).

    A classic (Computer Graphics from Scratch) scene is ray traced once per
    pixel; width, height, max_depth (its recursion depth) and threads apply,
    the sampling options do not.  Otherwise the scene is path traced:

    spp: samples per pixel (default: the scene's); time: render passes until
    this many seconds are spent instead.  sampling: "mixture" (The Rest of Your
    Life), "cosine" (The Next Week), "light" (lights only; misses indirect
    light) or "nee" (next-event estimation with MIS and Russian roulette);
    "mixture+sobol" and "nee+sobol" feed them low-discrepancy points for the
    pixel position and the first diffuse bounce (its light sample too);
    "mnee" (nee+sobol with manifold connections to the lights through smooth
    glass); "lightpath" (light tracing),
    "bdpt" and "bdpt+sobol" (bidirectional), "bdpt+photons" (bdpt+sobol with
    caustic photon maps: consistent), "bdpt+mnee" (bdpt+sobol with mnee's
    connections where the camera sees through glass).  None:
    options.default_sampling, bdpt+photons, bdpt+mnee or bdpt+sobol where
    emitters light much metal or glass, else mixture+sobol.
    progress: True for a bar on stderr, or a callable
    progress(spp_done, spp_total_or_None, samples_per_s).  bvh: force the
    hierarchy on (True) or off (False); by default scenes with many objects use it.
    clamp: cap every sample's channels at this value (biased: it removes energy;
    off by default).  Ctrl-C finishes the current pass and returns what was rendered
    (stats.interrupted); a second Ctrl-C raises KeyboardInterrupt.
    client: a dask.distributed Client: render blocks of samples on its workers
    instead, bit-identical to rendering here (rtweekend.distributed).
    aov: feature images for a denoiser, ("albedo", "normal") or one of them:
    result.aov["albedo"] is the albedo of what each pixel's paths first see
    through mirrors and glass (times their colour), result.aov["normal"] its
    normal facing the camera, both averaged over the pixel's samples; the image
    is the same as without them.  "emission": the light the camera sees emitted
    there (directly, or in mirrors and through glass).  "stderr": the per-pixel
    standard error (result.stderr) among them, for save_image's layers.
    denoise: also denoise the image with Open Image Denoise (pip install
    'rtweekend[denoise]'), fed with those features: result.denoised, beside the
    unbiased result.image; the light seen emitted is kept out of the filter.
    preview: show the image as it renders (a local render; the image is the
    same bits without it): True in a Jupyter notebook, updated in place;
    "tev" or "tev://HOST:PORT" streamed to the tev viewer, with the standard
    error as the channels stderr.R/G/B.
    """
    if not isinstance(scene, Scene):
        raise SceneError(f"render: expected a Scene (rt.load_scene or rt.Scene), "
                         f"got {type(scene).__name__}")
    integrator = scene.resolved_integrator()
    if client is not None:
        check_render(scene, threads)
    options = RenderOptions(integrator, spp=spp, time=time, seed=seed, width=width,
                            height=height, max_depth=max_depth, threads=threads,
                            sampling=sampling, clamp=clamp, bvh=bvh, aov=aov,
                            denoise=denoise or None, preview=preview or None,
                            progress=progress)
    if integrator == "classic":
        return render_classic(scene, options)
    if client is None:
        prestart()          # a helper process that can compile beside this one
    with Spinner(progress is True):         # from the first compile: packing, the BVH
        # Packing compiles: in the worker thread, this one awake to Ctrl-C
        # (kernel/calls.py), which Numba's compiler would not always pass on.
        renderer = call_awake(lambda: Renderer(scene, options))
        if spp is None and time is None:
            spp = scene.spp
        if client is not None:
            if preview:
                raise SceneError("render: preview: shows a local render; not with a client")
            return dask_driver.render_on_cluster(client, renderer, spp, time)
        return render_locally(renderer, spp, time)
