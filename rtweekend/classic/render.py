"""Rendering a classic scene: freeze it into classic/kernel.py's arrays, trace.

The image holds the canvas colour / 255 (what the PNG stores exactly).
"""
import time

import numpy as np

from ..options import thread_count
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
    changes = {k: v for k, v in (("width", options.width), ("height", options.height))
               if v is not None}
    if changes:
        scene = scene.with_camera(**changes)
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
    with thread_count(options.threads) as threads:
        t0 = time.perf_counter()
        render_canvas(*arrays, 1, 1, depth, **canvas_options)   # compile / load the cache
        t1 = time.perf_counter()
        rays = np.zeros(h, dtype=np.int64)
        canvas = render_canvas(*arrays, w, h, depth, rays=rays, **canvas_options)
        t2 = time.perf_counter()
    stats = RenderStats(width=w, height=h, spp=1, spp_requested=1, seconds=t2 - t1,
                        compile_seconds=t1 - t0, samples=w * h, rays=int(rays.sum()),
                        nan_dropped=0, interrupted=False, threads=threads,
                        seed=0, integrator="classic")
    image = canvas.astype(np.float32) / np.float32(255.0)
    return RenderResult(image, stats, np.zeros_like(image), display="canvas")
