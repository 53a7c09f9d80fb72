"""A scene: camera, render defaults, objects and lights; frozen into flat arrays.

    scene = Scene(camera=Camera(lookfrom=(278, 278, -800), lookat=(278, 278, 0),
                                vfov=40, width=600, height=600))
    scene.add(yz_rect(0, 555, 0, 555, 555, green))
    scene.add(xz_rect(213, 343, 227, 332, 554, light).flip_face(), light=True)

`arrays()` gives what the kernels read (see hittables.py for the layout).
"""
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from . import fields
from .bvh import build_bvh, empty_bvh
from .camera import camera_array
from .errors import FieldError, SceneError
from .hittables import OBJ_FLOATS
from .materials import MAT_FLOATS
from .classic_scene import ClassicCamera, ClassicLight
from .shapes import MATERIAL_NAMES, Shape, _label, flatten
from .tags import BG_COLOR, BG_SKY, PHONG, RECT, SPHERE

SKY = "sky"
MAX_SIZE = 65536         # pixels per side, a sanity bound (65536^2 would need ~200 GB of sums)
# From this many primitives on, the BVH beats testing every object (whose loop
# Numba compiles tightly).  Measured, one thread, flat -> BVH, samples/s:
# metals (4 spheres) 2.25 -> 1.76 M; random spheres (benchmarks/throughput.py)
# 10: 0.17 -> 0.19 us/sample, 30: equal, 100: 0.55 -> 0.30; cornell_glass (13
# rects and a sphere) 0.59 -> 0.64 M; cornell_box (18) 0.96 -> 1.16 M.
BVH_MIN_OBJECTS = 12


@dataclass(frozen=True)
class Camera:
    """The books' positionable thin-lens camera; defaults are book 1's."""
    lookfrom: tuple = (0.0, 0.0, 0.0)
    lookat: tuple = (0.0, 0.0, -1.0)
    vup: tuple = (0.0, 1.0, 0.0)
    vfov: float = 90.0                 # vertical, degrees
    aperture: float = 0.0              # lens diameter; 0 = pinhole
    focus_dist: float | None = None    # None: |lookfrom - lookat|
    width: int = 400
    height: int = 225

    def __post_init__(self):
        try:
            self._check()
        except FieldError as e:
            raise SceneError(f"camera: {e}") from None

    def _check(self):
        set_ = object.__setattr__          # normalise the frozen fields once
        for name in ("lookfrom", "lookat", "vup"):
            set_(self, name, fields.vec3(getattr(self, name), name))
        set_(self, "vfov", fields.number(self.vfov, "vfov", lo=0.0, hi=180.0,
                                         lo_open=True, hi_open=True))
        set_(self, "aperture", fields.number(self.aperture, "aperture", lo=0.0))
        set_(self, "width", fields.integer(self.width, "width", hi=MAX_SIZE))
        set_(self, "height", fields.integer(self.height, "height", hi=MAX_SIZE))
        view = np.subtract(self.lookat, self.lookfrom)
        dist = float(np.linalg.norm(view))
        if dist == 0.0:
            raise FieldError("lookat", "equals lookfrom: the view direction is undefined")
        up = np.asarray(self.vup)
        if np.linalg.norm(np.cross(up, view)) <= 1e-12 * dist * np.linalg.norm(up):
            raise FieldError("vup", f"{list(self.vup)} is parallel to the view direction")
        if self.focus_dist is None:
            set_(self, "focus_dist", dist)
        set_(self, "focus_dist", fields.number(self.focus_dist, "focus_dist",
                                               lo=0.0, lo_open=True))

    def array(self):
        return camera_array(self.lookfrom, self.lookat, self.vup, self.vfov,
                            self.aperture, self.focus_dist, self.width, self.height)


class SceneArrays(NamedTuple):
    """What the path-tracing kernel reads; plain arrays, picklable."""
    obj_i: np.ndarray      # int64 [N, 2]: kind, material
    obj_f: np.ndarray      # float64 [N, OBJ_FLOATS]
    mat_i: np.ndarray      # int64 [M]: kind
    mat_f: np.ndarray      # float64 [M, 4]: colour, parameter
    lights: np.ndarray     # int64 [L]: object indices the light pdf samples
    bg_kind: int
    bg: tuple
    bvh_box: np.ndarray    # the hierarchy (bvh.py); empty for small scenes
    bvh_node: np.ndarray
    bvh_prims: np.ndarray


INTEGRATORS = ("path", "classic")


@dataclass(eq=False)
class Scene:
    """Objects, lights, a camera and render defaults.

    The integrator follows from what the scene holds: phong materials, ambient /
    point / directional lights or a ClassicCamera make it a Computer Graphics
    from Scratch scene (classic); the books' materials, rects, boxes or area
    lights make it a path-traced one.  `integrator` forces the choice.
    """
    camera: object = None          # Camera, ClassicCamera, or None: the default one
    objects: list = field(default_factory=list)
    lights: list = field(default_factory=list)   # shapes (path) or ClassicLights
    background: object = None      # path: RGB radiance or "sky"; classic: 0..255 RGB
    spp: int = 100
    max_depth: int | None = None   # path: 50 segments; classic: 3 reflections
    description: str = ""
    name: str = "scene"
    integrator: str | None = None  # "path", "classic", or None: from the contents

    def add(self, shape, light=False):
        """Add a shape (and, with light=True, to the lights the pdf samples)."""
        if not isinstance(shape, Shape):
            raise SceneError(f"add: expected a shape, got {type(shape).__name__}")
        self.objects.append(shape)
        if light:
            self.add_light(shape)
        return shape

    def add_light(self, light):
        """A shape for the path tracer's light pdf, or a ClassicLight."""
        if isinstance(light, Shape) and light.kind == "box":
            raise SceneError(f"lights: {_label(light.kind, light.name)} is a box; "
                             "the light pdf samples rects and spheres only")
        if not isinstance(light, (Shape, ClassicLight)):
            raise SceneError(f"lights: expected a shape or a classic light, "
                             f"got {type(light).__name__}")
        self.lights.append(light)
        return light

    # -- which integrator, and its defaults --------------------------------------

    def resolved_integrator(self):
        """"path" or "classic"; SceneError if the scene mixes the two."""
        classic, path = [], []
        for shape in self.objects:
            label = _label(shape.kind, shape.name)
            kind = MATERIAL_NAMES[shape.material.kind]
            (classic if shape.material.kind == PHONG else path).append(
                f"{label} has a {kind} material")
            if shape.kind != "sphere":
                path.append(f"{label} is a {shape.kind} (the classic ray tracer has "
                            "spheres only)")
        for light in self.lights:
            if isinstance(light, ClassicLight):
                article = "an" if light.kind[0] in "aeiou" else "a"
                classic.append(f"it has {article} {light.kind} light")
            else:
                path.append(f"it has an area light ({_label(light.kind, light.name)})")
        if isinstance(self.camera, ClassicCamera):
            classic.append("its camera is the classic one (position, rotation, viewport)")
        elif isinstance(self.camera, Camera):
            path.append("its camera is the path tracer's (lookfrom, lookat, vfov)")
        chosen = self.integrator
        if chosen is not None and chosen not in INTEGRATORS:
            raise SceneError(f"integrator: expected one of {', '.join(INTEGRATORS)}, "
                             f"got {chosen!r}")
        if chosen == "classic" and path:
            raise SceneError(f"integrator: classic, but {path[0]}")
        if chosen == "path" and classic:
            raise SceneError(f"integrator: path, but {classic[0]}")
        if chosen is None and classic and path:
            raise SceneError("the scene mixes the classic ray tracer and the path tracer, "
                             f"which cannot be combined: {classic[0]}, but {path[0]}")
        return chosen or ("classic" if classic else "path")

    def resolved_camera(self):
        if self.camera is not None:
            return self.camera
        return ClassicCamera() if self.resolved_integrator() == "classic" else Camera()

    def resolved_max_depth(self):
        if self.max_depth is not None:
            return self.max_depth
        return 3 if self.resolved_integrator() == "classic" else 50

    def resolved_background(self):
        return (0.0, 0.0, 0.0) if self.background is None else self.background

    def with_camera(self, **changes):
        """A copy whose camera has some fields replaced (e.g. width, height)."""
        return replace(self, camera=replace(self.resolved_camera(), **changes))

    def check(self):
        """Validate the whole scene; raises SceneError."""
        classic = self.resolved_integrator() == "classic"
        try:
            fields.integer(self.spp, "spp")
            fields.integer(self.resolved_max_depth(), "max_depth", lo=0 if classic else 1)
            if classic:
                fields.color(self.resolved_background(), "background", hi=255.0)
            else:
                background_radiance(self.resolved_background())
        except FieldError as e:
            raise SceneError(f"render: {e}") from None
        for light in self.lights:
            if isinstance(light, Shape) and not any(light is s for s in self.objects):
                raise SceneError(f"lights: {_label(light.kind, light.name)} "
                                 "is not among the scene's objects")
        if not self.objects:
            raise SceneError("objects: the scene has no objects")

    def classic_spheres(self):
        """[(center, radius, material)] placed in the world, for classic.py."""
        out = []
        for shape in self.objects:
            for _, (center, radius) in flatten(shape):
                out.append((tuple(center), radius, shape.material))
        return out

    def arrays(self, bvh=None):
        """Freeze the scene into the flat arrays the path-tracing kernel reads.

        bvh: build a hierarchy (True), test every object (False), or decide by
        the number of primitives (None: from BVH_MIN_OBJECTS on).
        """
        self.check()
        if self.resolved_integrator() != "path":
            raise SceneError("this scene is rendered by the classic integrator")
        materials, mat_index = [], {}
        obj_i, obj_f, first = [], [], {}
        for shape in self.objects:
            m = mat_index.setdefault(id(shape.material), len(materials))
            if m == len(materials):
                materials.append(shape.material)
            first[id(shape)] = len(obj_i)
            for kind, geom in flatten(shape):
                row = np.zeros(OBJ_FLOATS)
                if kind == "sphere":
                    center, radius = geom
                    row[0:3], row[3], row[4] = center, radius, radius * radius
                    obj_i.append((SPHERE, m))
                else:
                    row[:] = rect_row(*geom)
                    obj_i.append((RECT, m))
                obj_f.append(row)
        mat_i = np.array([mt.kind for mt in materials], dtype=np.int64)
        mat_f = np.array([(*mt.color, mt.param) for mt in materials], dtype=np.float64)
        lights = np.array([first[id(s)] for s in self.lights], dtype=np.int64)
        bg_kind, bg = background_radiance(self.resolved_background())
        obj_i = np.array(obj_i, dtype=np.int64).reshape(-1, 2)
        obj_f = np.array(obj_f, dtype=np.float64).reshape(-1, OBJ_FLOATS)
        if bvh is None:
            bvh = len(obj_i) >= BVH_MIN_OBJECTS
        hierarchy = build_bvh(obj_i, obj_f) if bvh else empty_bvh()
        return SceneArrays(obj_i, obj_f, mat_i, mat_f.reshape(-1, MAT_FLOATS), lights,
                           bg_kind, bg, *hierarchy)


def rect_row(q, u, v):
    """The RECT row of obj_f: corner, edges, unit normal, plane offset,
    the dual edges u/|u|^2 and v/|v|^2 (u and v are perpendicular), area."""
    q, u, v = (np.asarray(a, dtype=np.float64) for a in (q, u, v))
    n = np.cross(u, v)
    area = float(np.linalg.norm(n))
    n = n / area
    return np.concatenate([q, u, v, n, [n @ q], u / (u @ u), v / (v @ v), [area]])


def background_radiance(value):
    """(kind, rgb) for a background given as an RGB triple or "sky"."""
    if isinstance(value, str):
        if value != SKY:
            raise FieldError("background", f'expected [r, g, b] or "sky", got "{value}"')
        return BG_SKY, (0.0, 0.0, 0.0)
    return BG_COLOR, fields.color(value, "background")

