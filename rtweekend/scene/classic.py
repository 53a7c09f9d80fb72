"""The classic integrator's side of a scene description: Computer Graphics from
Scratch's white lights and its camera.

    scene = Scene(camera=ClassicCamera(width=600, height=600), max_depth=3)
    scene.add(sphere((0, -1, 3), 1, phong((255, 0, 0), specular=500, reflective=0.2)))
    scene.lights += [ambient(0.2), point(0.6, (2, 1, 0)), directional(0.2, (1, 4, 4))]
"""
import math
from dataclasses import dataclass

from . import fields
from .fields import Vec3
from .. import checks
from ..errors import FieldError, SceneError


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
            if field == "direction" and math.hypot(*vector) < fields.SMALLEST:
                raise FieldError("direction", f"{list(vector)} is too short: its length "
                                 f"must be at least {fields.SMALLEST:g}")
    except FieldError as e:
        raise SceneError(f"{kind} light: {e}") from None
    return ClassicLight(kind, intensity, vector)


def ambient(intensity: float) -> ClassicLight:
    """Computer Graphics from Scratch's ambient light: `intensity` everywhere."""
    return _light("ambient", intensity)


def point(intensity: float, position: Vec3) -> ClassicLight:
    """A point light of `intensity` at `position` (the book's point light)."""
    return _light("point", intensity, "position", position)


def directional(intensity: float, direction: Vec3) -> ClassicLight:
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
            set_(self, "viewport", tuple(fields.length(v, "viewport")
                                         for v in vp))
            set_(self, "d", fields.length(self.d, "d"))
            set_(self, "width", checks.option("width", self.width))
            set_(self, "height", checks.option("height", self.height))
        except FieldError as e:
            raise SceneError(f"camera: {e}") from None
