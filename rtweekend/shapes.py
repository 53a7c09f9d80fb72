"""Materials and shapes as plain Python values, built the way the books' main.cc
builds them:

    white = lambertian((.73, .73, .73))
    box1 = box((0, 0, 0), (165, 330, 165), white).rotate_y(15).translate((265, 0, 295))

Every constructor checks its fields and raises SceneError naming the object and
the field.  `flatten` turns a shape into the primitives the kernels know.
"""
import functools
import math
from dataclasses import dataclass, replace

import numpy as np

from . import fields
from .errors import FieldError, SceneError
from .tags import DIELECTRIC, DIFFUSE_LIGHT, LAMBERTIAN, METAL, PHONG


def _label(kind, name):
    return f"{kind} '{name}'" if name else kind


def _checked(kind):
    """Expose a builder that raises FieldError as one that raises SceneError.

    The loader calls `.raw` instead, to put the file and the position in the
    message itself.
    """
    def wrap(build):
        @functools.wraps(build)
        def public(*args, name=None, **kwargs):
            try:
                return build(*args, name=name, **kwargs)
            except FieldError as e:
                raise SceneError(f"{_label(kind, name)}: {e}") from None
        public.raw = build
        public.kind = kind
        return public
    return wrap


# -- materials -------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Material:
    kind: int             # a tag from tags.py
    color: tuple          # albedo, or emitted radiance; phong: 0..255 colour
    param: float = 0.0    # metal: fuzz; dielectric: ior; phong: specular exponent
    name: str | None = None
    reflective: float = 0.0   # phong only: the mirror's share, in [0, 1]


@_checked("lambertian")
def lambertian(albedo, *, name=None):
    return Material(LAMBERTIAN, fields.color(albedo, "albedo", hi=1.0), 0.0, name)


@_checked("metal")
def metal(albedo, fuzz=0.0, *, name=None):
    # The book clamps fuzz to 1; a negative fuzz is a mistake, not a clamp.
    fuzz = min(fields.number(fuzz, "fuzz", lo=0.0), 1.0)
    return Material(METAL, fields.color(albedo, "albedo", hi=1.0), fuzz, name)


@_checked("dielectric")
def dielectric(ior, *, name=None):
    return Material(DIELECTRIC, (1.0, 1.0, 1.0),
                    fields.number(ior, "ior", lo=0.0, lo_open=True), name)


@_checked("diffuse_light")
def diffuse_light(emit, *, name=None):
    return Material(DIFFUSE_LIGHT, fields.color(emit, "emit"), 0.0, name)


@_checked("phong")
def phong(color, specular=-1, reflective=0.0, *, name=None):
    """Computer Graphics from Scratch's material (classic integrator only):
    a 0..255 colour, a Phong exponent (-1: matte) and a mirror share."""
    specular = fields.number(specular, "specular")
    if specular < 0 and specular != -1:
        raise FieldError("specular", f"must be -1 (matte) or >= 0, got {specular:g}")
    return Material(PHONG, fields.color(color, "color", hi=255.0), specular, name,
                    fields.number(reflective, "reflective", lo=0.0, hi=1.0))


MATERIALS = {f.kind: f for f in (lambertian, metal, dielectric, diffuse_light, phong)}
MATERIAL_NAMES = {LAMBERTIAN: "lambertian", METAL: "metal", DIELECTRIC: "dielectric",
                  DIFFUSE_LIGHT: "diffuse_light", PHONG: "phong"}


def _material(value):
    if not isinstance(value, Material):
        raise FieldError("material", f"expected a material, got {type(value).__name__}")
    return value


# -- shapes ----------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Shape:
    """A sphere, rect or box with its material and its placement.

    Placement is rotate_y (degrees, about the world y axis) then translate;
    any chain of .rotate_y() and .translate() calls reduces to that pair.
    """
    kind: str
    geometry: tuple
    material: Material
    angle: float = 0.0
    offset: tuple = (0.0, 0.0, 0.0)
    flipped: bool = False
    name: str | None = None

    def rotate_y(self, degrees):
        try:
            degrees = fields.number(degrees, "rotate_y")
        except FieldError as e:
            raise SceneError(f"{_label(self.kind, self.name)}: {e}") from None
        s, c = math.sin(math.radians(degrees)), math.cos(math.radians(degrees))
        ox, oy, oz = self.offset
        return replace(self, angle=self.angle + degrees,
                       offset=(c * ox + s * oz, oy, -s * ox + c * oz))

    def translate(self, offset):
        try:
            offset = fields.vec3(offset, "translate")
        except FieldError as e:
            raise SceneError(f"{_label(self.kind, self.name)}: {e}") from None
        return replace(self, offset=tuple(a + b for a, b in zip(self.offset, offset)))

    def flip_face(self):
        return replace(self, flipped=not self.flipped)

    def named(self, name):
        return replace(self, name=name)


@_checked("sphere")
def sphere(center, radius, material, *, name=None):
    """A negative radius makes the book-1 hollow bubble (normals point inward)."""
    return Shape("sphere", (fields.vec3(center, "center"),
                            fields.number(radius, "radius", nonzero=True)),
                 _material(material), name=name)


def _interval(lo, hi, lo_name, hi_name):
    lo, hi = fields.number(lo, lo_name), fields.number(hi, hi_name)
    if not hi > lo:
        raise FieldError(hi_name, f"must be greater than {lo_name} ({lo:g}), got {hi:g}"
                         " (a rect needs a non-zero area)")
    return lo, hi


@_checked("xy_rect")
def xy_rect(x0, x1, y0, y1, k, material, *, name=None):
    return Shape("xy_rect", (*_interval(x0, x1, "x0", "x1"), *_interval(y0, y1, "y0", "y1"),
                             fields.number(k, "k")), _material(material), name=name)


@_checked("xz_rect")
def xz_rect(x0, x1, z0, z1, k, material, *, name=None):
    return Shape("xz_rect", (*_interval(x0, x1, "x0", "x1"), *_interval(z0, z1, "z0", "z1"),
                             fields.number(k, "k")), _material(material), name=name)


@_checked("yz_rect")
def yz_rect(y0, y1, z0, z1, k, material, *, name=None):
    return Shape("yz_rect", (*_interval(y0, y1, "y0", "y1"), *_interval(z0, z1, "z0", "z1"),
                             fields.number(k, "k")), _material(material), name=name)


@_checked("box")
def box(p0, p1, material, *, name=None):
    """The axis-aligned box with opposite corners p0 and p1, as six rects."""
    p0, p1 = fields.vec3(p0, "p0"), fields.vec3(p1, "p1")
    for axis, a, b in zip("xyz", p0, p1):
        if a == b:
            raise FieldError("p1", f"{axis} equals p0's {axis} ({a:g}): the box has no volume")
    lo = tuple(min(a, b) for a, b in zip(p0, p1))
    hi = tuple(max(a, b) for a, b in zip(p0, p1))
    return Shape("box", (lo, hi), _material(material), name=name)


SHAPES = {f.kind: f for f in (sphere, xy_rect, xz_rect, yz_rect, box)}


# -- flattening into primitives ---------------------------------------------------

def _rect_frame(kind, g):
    """(corner Q, edge u, edge v) with u x v along the book's +axis normal."""
    if kind == "xy_rect":
        x0, x1, y0, y1, k = g
        return (x0, y0, k), (x1 - x0, 0.0, 0.0), (0.0, y1 - y0, 0.0)
    if kind == "xz_rect":
        x0, x1, z0, z1, k = g
        return (x0, k, z0), (0.0, 0.0, z1 - z0), (x1 - x0, 0.0, 0.0)
    y0, y1, z0, z1, k = g   # yz_rect
    return (k, y0, z0), (0.0, y1 - y0, 0.0), (0.0, 0.0, z1 - z0)


def _box_faces(lo, hi):
    """Six rects with outward normals: the +axis faces as the book's rects, the
    -axis faces flipped (so a glass box refracts correctly on every side)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    return [
        (_rect_frame("xy_rect", (x0, x1, y0, y1, z1)), False),
        (_rect_frame("xy_rect", (x0, x1, y0, y1, z0)), True),
        (_rect_frame("xz_rect", (x0, x1, z0, z1, y1)), False),
        (_rect_frame("xz_rect", (x0, x1, z0, z1, y0)), True),
        (_rect_frame("yz_rect", (y0, y1, z0, z1, x1)), False),
        (_rect_frame("yz_rect", (y0, y1, z0, z1, x0)), True),
    ]


def _placement(shape):
    """Object-to-world map of rotate_y then translate, as a 3x3 matrix and offset."""
    s, c = math.sin(math.radians(shape.angle)), math.cos(math.radians(shape.angle))
    # The books' rotate_y: x' = cos x + sin z, z' = -sin x + cos z.
    rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return rot, np.asarray(shape.offset, dtype=np.float64)


def flatten(shape):
    """[(kind 'sphere', (center, radius)) | ('rect', (Q, u, v))] in world space."""
    rot, offset = _placement(shape)
    if shape.kind == "sphere":
        center, radius = shape.geometry
        radius = -radius if shape.flipped else radius
        return [("sphere", (rot @ np.asarray(center) + offset, radius))]
    if shape.kind == "box":
        faces = _box_faces(*shape.geometry)
    else:
        faces = [(_rect_frame(shape.kind, shape.geometry), False)]
    out = []
    for (q, u, v), flip in faces:
        if flip != shape.flipped:
            u, v = v, u     # swapping the edges reverses u x v, the front side
        out.append(("rect", (rot @ np.asarray(q) + offset, rot @ np.asarray(u),
                             rot @ np.asarray(v))))
    return out
