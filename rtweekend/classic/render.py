"""Rendering a classic scene: freeze it into classic/kernel.py's arrays, trace.

The image is linear radiance like the path tracer's: the canvas colour c is
(c / 255)**2, which the tone map writes back as c (one rule for every scene).
"""
import time

import numpy as np

from .. import memory
from ..io.progress import StopOnInterrupt
from ..kernel.calls import Abandoned, call_awake
from ..options import thread_count
from . import kernel
from ..result import RenderResult, RenderStats
from .kernel import classic_arrays, render_canvas


def classic_spheres(scene):
    """[(center, radius, material)] of the scene's spheres, placed in the world."""
    out = []
    for shape in scene.objects:
        rot, offset = shape.placement()
        center, radius = shape.geometry
        radius = -radius if shape.flipped else radius     # as the path tracer packs it
        out.append((tuple(rot @ np.asarray(center) + offset), radius, shape.material))
    return out


def render_classic(scene, options):
    """Render a classic scene with validated RenderOptions (width, height,
    max_depth, threads): one ray per pixel, no tone map."""
    scene = options.sized(scene)          # one side alone keeps the aspect ratio
    scene.check()
    camera = scene.resolved_camera()
    w, h = camera.width, camera.height
    depth = scene.resolved_max_depth() if options.max_depth is None else options.max_depth
    spheres = [dict(center=c, radius=r, color=m.color, specular=m.param,
                    reflective=m.reflective) for c, r, m in classic_spheres(scene)]
    lights = [dict(type=lt.kind, intensity=lt.intensity,
                   **({"position": lt.vector} if lt.kind == "point" else
                      {"direction": lt.vector} if lt.kind == "directional" else {}))
              for lt in scene.lights]
    arrays = classic_arrays(spheres, lights)
    canvas_options = dict(background=scene.resolved_background(), position=camera.position,
                          rotation=camera.rotation, viewport=camera.viewport, d=camera.d)
    memory.check(BYTES_PER_PIXEL * w * h, w, h,      # before the canvas is allocated
                 origin=options.size_origin(scene))
    misses = sum(kernel.render_classic.stats.cache_misses.values())
    canvas, interrupted = None, False
    with thread_count(options.threads) as threads, StopOnInterrupt() as stop:
        # In a worker thread, this one awake to Ctrl-C (kernel/calls.py); there
        # are no passes to keep, so the first Ctrl-C stops at once.
        t0 = t1 = time.perf_counter()
        rays = np.zeros(h, dtype=np.int64)
        try:
            call_awake(lambda: render_canvas(*arrays, 1, 1, depth, **canvas_options),
                       stop, abandon=True)                 # compile / load the cache
            t1 = time.perf_counter()
            canvas = call_awake(lambda: render_canvas(*arrays, w, h, depth, rays=rays,
                                                      **canvas_options), stop, abandon=True)
        except Abandoned:
            interrupted = True
            t1 = t1 if t1 > t0 else time.perf_counter()
        t2 = time.perf_counter()
    stats = RenderStats(width=w, height=h, spp=0 if interrupted else 1, spp_requested=1,
                        seconds=t2 - t1, compile_seconds=t1 - t0,
                        samples=0 if interrupted else w * h,
                        rays=int(rays.sum()), nan_dropped=0, interrupted=interrupted,
                        threads=threads, seed=0, integrator="classic",
                        stopped_by="Ctrl-C" if interrupted else None,
                        compiled=sum(kernel.render_classic.stats.cache_misses.values()) > misses)
    if interrupted:
        return RenderResult(np.zeros((h, w, 3), np.float32), stats,
                            np.zeros((h, w, 3), np.float32))
    return RenderResult(canvas_radiance(canvas), stats, np.zeros((h, w, 3), np.float32))


# The canvas (uint8), its radiance (float32, via float64 steps) and the zero
# standard error: what a classic render holds at its peak, per pixel.
BYTES_PER_PIXEL = 3 + 24 + 24 + 12 + 12


def canvas_radiance(canvas):
    """The linear radiance whose tone map (gamma 2, io/image.py) is the canvas:
    (c / 255)**2, so every way of saving a classic render writes c exactly."""
    c = canvas.astype(np.float64) / 255.0
    return (c * c).astype(np.float32)
