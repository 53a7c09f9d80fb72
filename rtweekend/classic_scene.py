"""The classic integrator's side of a scene: its lights, the book's camera, and
rendering a Scene with classic.py.

    scene = Scene(camera=ClassicCamera(width=600, height=600), max_depth=3)
    scene.add(sphere((0, -1, 3), 1, phong((255, 0, 0), specular=500, reflective=0.2)))
    scene.lights += [ambient(0.2), point(0.6, (2, 1, 0)), directional(0.2, (1, 4, 4))]
"""
import time
from dataclasses import dataclass

import numba
import numpy as np

from . import fields
from .classic import classic_arrays, render_canvas
from .errors import FieldError, SceneError
from .result import RenderResult, RenderStats


@dataclass(frozen=True, eq=False)
class ClassicLight:
    """A white light of Computer Graphics from Scratch."""
    kind: str               # "ambient", "point" or "directional"
    intensity: float
    vector: tuple = None    # point: position; directional: direction


def _light(kind, intensity, field=None, vector=None):
    try:
        intensity = fields.number(intensity, "intensity", lo=0.0)
        if field is not None:
            vector = fields.vec3(vector, field)
            if field == "direction" and not any(vector):
                raise FieldError("direction", "must not be [0, 0, 0]")
    except FieldError as e:
        raise SceneError(f"{kind} light: {e}") from None
    return ClassicLight(kind, intensity, vector)


def ambient(intensity):
    return _light("ambient", intensity)


def point(intensity, position):
    return _light("point", intensity, "position", position)


def directional(intensity, direction):
    """A light from infinitely far away; `direction` points towards the light."""
    return _light("directional", intensity, "direction", direction)


LIGHTS = {"ambient": ambient, "point": point, "directional": directional}

IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@dataclass(frozen=True)
class ClassicCamera:
    """The book's camera: at `position`, turned by the 3x3 `rotation`, looking
    through a viewport Vw x Vh at distance d; the canvas is width x height."""
    position: tuple = (0.0, 0.0, 0.0)
    rotation: tuple = IDENTITY
    viewport: tuple = (1.0, 1.0)
    d: float = 1.0
    width: int = 600
    height: int = 600

    def __post_init__(self):
        set_ = object.__setattr__
        try:
            set_(self, "position", fields.vec3(self.position, "position"))
            rot = self.rotation
            if isinstance(rot, (str, bytes)) or not hasattr(rot, "__len__") or len(rot) != 3:
                raise FieldError("rotation", "expected a 3x3 matrix [[..], [..], [..]]")
            set_(self, "rotation", tuple(fields.vec3(row, "rotation") for row in rot))
            vp = self.viewport
            if isinstance(vp, (str, bytes)) or not hasattr(vp, "__len__") or len(vp) != 2:
                raise FieldError("viewport", "expected [width, height]")
            set_(self, "viewport", tuple(fields.number(v, "viewport", lo=0.0, lo_open=True)
                                         for v in vp))
            set_(self, "d", fields.number(self.d, "d", lo=0.0, lo_open=True))
            set_(self, "width", fields.integer(self.width, "width", hi=65536))
            set_(self, "height", fields.integer(self.height, "height", hi=65536))
        except FieldError as e:
            raise SceneError(f"camera: {e}") from None


def render_classic_scene(scene, *, width=None, height=None, max_depth=None):
    """Render with the classic integrator: one ray per pixel, no tone map.

    The image holds the canvas colour / 255 (what the PNG stores exactly).
    """
    camera = scene.resolved_camera()
    w = width or camera.width
    h = height or camera.height
    depth = scene.resolved_max_depth() if max_depth is None else max_depth
    spheres = [dict(center=c, radius=r, color=m.color, specular=m.param,
                    reflective=m.reflective) for c, r, m in scene.classic_spheres()]
    lights = [dict(type=lt.kind, intensity=lt.intensity,
                   **({"position": lt.vector} if lt.kind == "point" else
                      {"direction": lt.vector} if lt.kind == "directional" else {}))
              for lt in scene.lights]
    arrays = classic_arrays(spheres, lights)
    options = dict(background=scene.resolved_background(), position=camera.position,
                   rotation=camera.rotation, viewport=camera.viewport, d=camera.d)
    t0 = time.perf_counter()
    render_canvas(*arrays, 1, 1, depth, **options)          # compile / load the cache
    t1 = time.perf_counter()
    rays = np.zeros(h, dtype=np.int64)
    canvas = render_canvas(*arrays, w, h, depth, rays=rays, **options)
    t2 = time.perf_counter()
    stats = RenderStats(width=w, height=h, spp=1, spp_requested=1, seconds=t2 - t1,
                        compile_seconds=t1 - t0, samples=w * h, rays=int(rays.sum()),
                        nan_dropped=0, interrupted=False, threads=numba.get_num_threads(),
                        seed=0, integrator="classic")
    image = canvas.astype(np.float32) / np.float32(255.0)
    return RenderResult(image, stats, np.zeros_like(image), display="canvas")
