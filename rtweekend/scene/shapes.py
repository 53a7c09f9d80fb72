"""Shapes as plain Python values, built the way the books' main.cc builds them:

    box1 = box((0, 0, 0), (165, 330, 165), white).rotate_y(15).translate((265, 0, 295))

Every builder checks its fields and raises SceneError naming the object and the
field.  A shape is a description only: each integrator turns it into what its
kernels read (path/layout.py, classic/render.py).
"""
import math
from dataclasses import dataclass, replace

import numpy as np

from . import fields
from ..errors import FieldError, SceneError, checked, label
from .materials import Material, check_material


@dataclass(frozen=True, eq=False)
class Shape:
    """A sphere, rect or box with its material and its placement.

    Placement is rotate_y (degrees, about the world y axis) then translate;
    any chain of .rotate_y() and .translate() calls reduces to that pair.
    """
    kind: str             # "sphere", "xy_rect", ... (the builder's name)
    geometry: tuple
    material: Material
    angle: float = 0.0
    offset: tuple = (0.0, 0.0, 0.0)
    flipped: bool = False
    name: str | None = None

    @property
    def label(self):
        return label(self.kind, self.name)

    def rotate_y(self, degrees):
        try:
            degrees = fields.number(degrees, "rotate_y")
        except FieldError as e:
            raise SceneError(f"{self.label}: {e}") from None
        s, c = math.sin(math.radians(degrees)), math.cos(math.radians(degrees))
        ox, oy, oz = self.offset
        return replace(self, angle=self.angle + degrees,
                       offset=(c * ox + s * oz, oy, -s * ox + c * oz))

    def translate(self, offset):
        try:
            offset = fields.vec3(offset, "translate")
        except FieldError as e:
            raise SceneError(f"{self.label}: {e}") from None
        return replace(self, offset=tuple(a + b for a, b in zip(self.offset, offset)))

    def flip_face(self):
        return replace(self, flipped=not self.flipped)

    def named(self, name):
        return replace(self, name=name)

    def placement(self):
        """Object-to-world map of rotate_y then translate: a 3x3 matrix and an offset."""
        s, c = math.sin(math.radians(self.angle)), math.cos(math.radians(self.angle))
        # The books' rotate_y: x' = cos x + sin z, z' = -sin x + cos z.
        rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        return rot, np.asarray(self.offset, dtype=np.float64)


@checked("sphere")
def sphere(center, radius, material, *, name=None):
    """A negative radius makes the book-1 hollow bubble (normals point inward)."""
    return Shape("sphere", (fields.vec3(center, "center"),
                            fields.length(radius, "radius", signed=True)),
                 check_material(material), name=name)


def _interval(lo, hi, lo_name, hi_name):
    lo, hi = fields.number(lo, lo_name), fields.number(hi, hi_name)
    if not hi > lo:
        raise FieldError(hi_name, f"must be greater than {lo_name} ({lo:g}), got {hi:g}"
                         " (a rect needs a non-zero area)")
    if hi - lo < fields.SMALLEST:
        raise FieldError(hi_name, f"is only {hi - lo:g} from {lo_name}: sides below "
                         f"{fields.SMALLEST:g} underflow when squared")
    return lo, hi


@checked("xy_rect")
def xy_rect(x0, x1, y0, y1, k, material, *, name=None):
    return Shape("xy_rect", (*_interval(x0, x1, "x0", "x1"), *_interval(y0, y1, "y0", "y1"),
                             fields.number(k, "k")), check_material(material), name=name)


@checked("xz_rect")
def xz_rect(x0, x1, z0, z1, k, material, *, name=None):
    return Shape("xz_rect", (*_interval(x0, x1, "x0", "x1"), *_interval(z0, z1, "z0", "z1"),
                             fields.number(k, "k")), check_material(material), name=name)


@checked("yz_rect")
def yz_rect(y0, y1, z0, z1, k, material, *, name=None):
    return Shape("yz_rect", (*_interval(y0, y1, "y0", "y1"), *_interval(z0, z1, "z0", "z1"),
                             fields.number(k, "k")), check_material(material), name=name)


@checked("box")
def box(p0, p1, material, *, name=None):
    """The axis-aligned box with opposite corners p0 and p1."""
    p0, p1 = fields.vec3(p0, "p0"), fields.vec3(p1, "p1")
    for axis, a, b in zip("xyz", p0, p1):
        if a == b:
            raise FieldError("p1", f"{axis} equals p0's {axis} ({a:g}): the box has no volume")
        if abs(a - b) < fields.SMALLEST:
            raise FieldError("p1", f"{axis} is only {abs(a - b):g} from p0's {axis}: sides "
                             f"below {fields.SMALLEST:g} underflow when squared")
    lo = tuple(min(a, b) for a, b in zip(p0, p1))
    hi = tuple(max(a, b) for a, b in zip(p0, p1))
    return Shape("box", (lo, hi), check_material(material), name=name)


SHAPES = {f.kind: f for f in (sphere, xy_rect, xz_rect, yz_rect, box)}
