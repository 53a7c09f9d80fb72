"""A scene: camera, render defaults, objects and lights, as plain Python values.

    scene = Scene(camera=Camera(lookfrom=(278, 278, -800), lookat=(278, 278, 0),
                                vfov=40, width=600, height=600))
    scene.add(yz_rect(0, 555, 0, 555, 555, green))
    scene.add(xz_rect(213, 343, 227, 332, 554, light).flip_face(), light=True)

A Scene describes; each integrator freezes it into what its kernels read
(path/layout.py for the path tracer, classic/render.py for the classic one).
"""
from dataclasses import dataclass, field, replace

from . import fields
from .. import checks
from ..errors import FieldError, SceneError
from .camera import Camera
from .classic import ClassicCamera, ClassicLight
from .materials import CLASSIC_MATERIALS
from .shapes import Shape

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

    def __repr__(self):
        """One line: name, size, what it holds (the dataclass's dump is pages)."""
        try:
            camera = self.resolved_camera()
            size = f"{camera.width}x{camera.height}"
        except SceneError:
            size = "no camera"
        kinds = {}
        for shape in self.objects:
            kind = "constant_medium" if shape.medium else shape.material.kind
            kinds[kind] = kinds.get(kind, 0) + 1
        held = ", ".join(f"{n} {k}" for k, n in kinds.items()) or "nothing"
        moving = sum(shape.moving for shape in self.objects)
        textured = sum(shape.material.texture is not None for shape in self.objects)
        extras = [f"{moving} moving"] * bool(moving) + [f"{textured} textured"] * bool(textured)
        return (f"Scene({self.name!r}, {size}, {len(self.objects)} objects: {held}"
                f"{'; ' + ', '.join(extras) if extras else ''}; {len(self.lights)} in lights)")

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
            kind = shape.material.kind
            (classic if kind in CLASSIC_MATERIALS else path).append(
                f"{shape.label} has a {kind} material")
            if shape.kind != "sphere":
                path.append(f"{shape.label} is a {shape.kind} (the classic ray tracer has "
                            "spheres only)")
        for light in self.lights:
            if isinstance(light, ClassicLight):
                article = "an" if light.kind[0] in "aeiou" else "a"
                classic.append(f"it has {article} {light.kind} light")
            else:
                path.append(f"it has an area light ({light.label})")
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
            checks.option("spp", self.spp)
            checks.option("max_depth", self.resolved_max_depth(),
                          integrator="classic" if classic else "path")
            if classic:
                fields.color(self.resolved_background(), "background", hi=255.0)
            else:
                fields.background(self.resolved_background())
        except FieldError as e:
            raise SceneError(f"render: {e}") from None
        for light in self.lights:
            if isinstance(light, Shape) and not any(light is s for s in self.objects):
                raise SceneError(f"lights: {light.label} is not among the scene's objects")
            if isinstance(light, Shape) and light.medium:
                raise SceneError(f"lights: {light.label} is a medium: its boundary is "
                                 "invisible, and only surfaces can be sampled as lights")
        if not self.objects:
            raise SceneError("objects: the scene has no objects")

    def doubts(self):
        """One-line warnings about a valid scene that may not be what its author
        meant: a lights list that names none of the scene's emitters, whose
        samples then aim where no light comes from (fireflies from the rest)."""
        out = []
        shapes = [light for light in self.lights if isinstance(light, Shape)]
        emitters = [s for s in self.objects if s.material.kind == "diffuse_light"]
        if shapes and emitters and not any(s.material.kind == "diffuse_light" for s in shapes):
            out.append(f"lights: names no emitter ({', '.join(s.label for s in shapes)}), "
                       f"while {', '.join(s.label for s in emitters[:3])}"
                       f"{' and others' if len(emitters) > 3 else ''} "
                       f"{'emit' if len(emitters) > 1 else 'emits'}: the light pdf aims at "
                       "objects that give no light; list the emitters too")
        return out
