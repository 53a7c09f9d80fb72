"""Shapes as plain Python values, built the way the books' main.cc builds them:

    box1 = box((0, 0, 0), (165, 330, 165), white).rotate_y(15).translate((265, 0, 295))

Every builder checks its fields and raises SceneError naming the object and the
field.  A shape is a description only: each integrator turns it into what its
kernels read (path/layout.py, classic/render.py).
"""
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from . import fields, meshes
from .fields import Color, Vec3
from .textures import Texture
from ..errors import FieldError, SceneError, checked, label
from .materials import Material, check_material, isotropic


@dataclass(frozen=True, eq=False)
class Shape:
    """A sphere, rect, box or mesh with its material and its placement.

    Placement is a rotation then translate; any chain of .rotate(),
    .rotate_y() and .translate() calls reduces to that pair.  The rotation is
    kept as the turns that make it, (axis, degrees) about the world x (0), y (1)
    or z (2) axis in the order applied, so that the books' rotate_y gives the
    matrix the books compute from its angle, bit for bit.
    """
    kind: str             # "sphere", "xy_rect", ... (the builder's name)
    geometry: tuple
    material: Material
    turns: tuple = ()
    offset: tuple = (0.0, 0.0, 0.0)
    flipped: bool = False
    name: str | None = None
    # Motion blur: how far the shape moves over the shutter (time 0 to 1), in
    # the world (a sphere's center1 - center, turned with it by rotate_y).
    velocity: tuple = (0.0, 0.0, 0.0)

    @property
    def medium(self):
        """A constant medium's boundary (its material is isotropic)."""
        return self.material.medium

    @property
    def moving(self):
        return any(self.velocity)

    @property
    def area(self):
        """Surface area (placement keeps it: rotations and translate are rigid)."""
        g = self.geometry
        if self.kind == "sphere":
            return 4.0 * math.pi * g[1] * g[1]
        if self.kind == "quad":
            return float(np.linalg.norm(np.cross(g[1], g[2])))
        if self.kind == "box":
            a, b, c = (abs(hi - lo) for lo, hi in zip(g[0], g[1]))
            return 2.0 * (a * b + b * c + c * a)
        if self.kind == "mesh":
            return float(meshes.areas(g[0], g[1]).sum())
        return (g[1] - g[0]) * (g[3] - g[2])        # xy/xz/yz_rect: (a0, a1, b0, b1, k)

    @property
    def label(self):
        return label("constant_medium" if self.medium else self.kind, self.name)

    def rotate_y(self, degrees):
        """The books' rotate_y: degrees about the world y axis (x' = cos x + sin z,
        z' = -sin x + cos z)."""
        try:
            degrees = fields.number(degrees, "rotate_y")
        except FieldError as e:
            raise SceneError(f"{self.label}: {e}") from None
        return self._turn(1, degrees)

    def rotate(self, degrees):
        """Turn by [rx, ry, rz] degrees about the world x, then y, then z axis
        (right-handed, as rotate_y): rotate([0, a, 0]) is rotate_y(a)."""
        try:
            degrees = fields.angles(degrees, "rotate")
        except FieldError as e:
            raise SceneError(f"{self.label}: {e}") from None
        shape = self
        for axis, d in enumerate(degrees):
            if d != 0.0:
                shape = shape._turn(axis, d)
        return shape

    def _turn(self, axis, degrees):
        """Turned about one world axis: what is already placed (its offset and
        velocity) turns with it; a turn about the same axis as the last one
        adds to its angle."""
        s, c = math.sin(math.radians(degrees)), math.cos(math.radians(degrees))
        turns = self.turns
        if turns and turns[-1][0] == axis:
            turns = turns[:-1] + ((axis, turns[-1][1] + degrees),)
        else:
            turns = turns + ((axis, degrees),)
        return replace(self, turns=turns, offset=_turned(axis, s, c, self.offset),
                       velocity=_turned(axis, s, c, self.velocity))

    @property
    def turned(self):
        """Is it rotated at all (by other than whole turns)?"""
        return any(d % 360.0 != 0.0 for _, d in self.turns)

    def translate(self, offset):
        try:
            offset = fields.vec3(offset, "translate")
        except FieldError as e:
            raise SceneError(f"{self.label}: {e}") from None
        return replace(self, offset=tuple(a + b for a, b in zip(self.offset, offset)))

    def flip_face(self):
        return replace(self, flipped=not self.flipped)

    @property
    def primitives(self):
        """How many primitives it packs into: a mesh's triangles, else one (a
        box is one primitive too)."""
        return len(self.geometry[1]) if self.kind == "mesh" else 1

    def named(self, name):
        return replace(self, name=name)

    def placement(self):
        """Object-to-world map of the rotation then translate: a 3x3 matrix and
        an offset."""
        rot = np.eye(3)
        for i, (axis, degrees) in enumerate(self.turns):
            turn = turn_matrix(axis, degrees)
            rot = turn if i == 0 else turn @ rot
        return rot, np.asarray(self.offset, dtype=np.float64)


def turn_matrix(axis, degrees):
    """The right-handed rotation by degrees about world axis 0, 1 or 2 (about y:
    the books' x' = cos x + sin z, z' = -sin x + cos z)."""
    s, c = math.sin(math.radians(degrees)), math.cos(math.radians(degrees))
    i, j = (axis + 1) % 3, (axis + 2) % 3
    m = np.eye(3)
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def _turned(axis, s, c, v):
    """The vector v turned about world axis `axis` by the angle of sine s and
    cosine c: the axes after it, i and j, turn as i' = c i - s j, j' = s i + c j."""
    i, j = (axis + 1) % 3, (axis + 2) % 3
    out = list(v)
    out[i], out[j] = c * v[i] - s * v[j], s * v[i] + c * v[j]
    return tuple(out)


@checked("sphere")
def sphere(center: Vec3, radius: float, material: Material, center1: Vec3 | None = None, *,
           name: str | None = None) -> Shape:
    """A negative radius makes the book-1 hollow bubble (normals point inward).
    center1: the centre at the end of the shutter (time 1), for motion blur;
    the sphere moves in a straight line from `center` (time 0)."""
    center = fields.vec3(center, "center")
    velocity = (0.0, 0.0, 0.0)
    if center1 is not None:
        velocity = tuple(b - a for a, b in zip(center, fields.vec3(center1, "center1")))
        if max(map(abs, velocity)) > fields.LARGEST:
            raise FieldError("center1", "is too far from center")
    return Shape("sphere", (center, fields.length(radius, "radius", signed=True)),
                 check_material(material), name=name, velocity=velocity)


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
def xy_rect(x0: float, x1: float, y0: float, y1: float, k: float, material: Material, *,
            name: str | None = None) -> Shape:
    """The books' rectangle [x0, x1] x [y0, y1] in the plane z = k, facing +z."""
    return Shape("xy_rect", (*_interval(x0, x1, "x0", "x1"), *_interval(y0, y1, "y0", "y1"),
                             fields.number(k, "k")), check_material(material), name=name)


@checked("xz_rect")
def xz_rect(x0: float, x1: float, z0: float, z1: float, k: float, material: Material, *,
            name: str | None = None) -> Shape:
    """The books' rectangle [x0, x1] x [z0, z1] in the plane y = k, facing +y."""
    return Shape("xz_rect", (*_interval(x0, x1, "x0", "x1"), *_interval(z0, z1, "z0", "z1"),
                             fields.number(k, "k")), check_material(material), name=name)


@checked("yz_rect")
def yz_rect(y0: float, y1: float, z0: float, z1: float, k: float, material: Material, *,
            name: str | None = None) -> Shape:
    """The books' rectangle [y0, y1] x [z0, z1] in the plane x = k, facing +x."""
    return Shape("yz_rect", (*_interval(y0, y1, "y0", "y1"), *_interval(z0, z1, "z0", "z1"),
                             fields.number(k, "k")), check_material(material), name=name)


@checked("box")
def box(p0: Vec3, p1: Vec3, material: Material, *, name: str | None = None) -> Shape:
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


@checked("quad")
def quad(Q: Vec3, u: Vec3, v: Vec3, material: Material, *,
         name: str | None = None) -> Shape:
    """The Next Week v4's quadrilateral: the parallelogram with corner Q and edges
    u and v; its front side is the one u x v points to."""
    Q, u, v = fields.vec3(Q, "Q"), fields.vec3(u, "u"), fields.vec3(v, "v")
    n = np.cross(u, v)
    area = float(np.linalg.norm(n))
    size = max(float(np.linalg.norm(u)), float(np.linalg.norm(v)))
    if not area > 0.0 or area <= 1e-12 * size * size:
        raise FieldError("v", f"{list(v)} is parallel to u {list(u)} (or one is zero): "
                         "the quad has no area")
    if min(float(np.linalg.norm(u)), float(np.linalg.norm(v))) < fields.SMALLEST:
        raise FieldError("v", f"edges shorter than {fields.SMALLEST:g} underflow when "
                         "squared")
    return Shape("quad", (Q, u, v), check_material(material), name=name)


@checked("constant_medium")
def constant_medium(boundary: Shape, density: float, albedo: Color | Texture, *,
                    name: str | None = None) -> Shape:
    """The Next Week's constant medium: the volume inside `boundary` (a sphere or
    a box, with any placement; its material is not used) filled with a
    participating medium of `density` (extinction per unit length) that scatters
    isotropically, keeping `albedo` (a colour or a texture) of the light.  The
    boundary itself is invisible."""
    if not isinstance(boundary, Shape):
        raise FieldError("boundary", f"expected a sphere or a box, got "
                         f"{type(boundary).__name__}")
    if boundary.kind not in MEDIUM_BOUNDARIES:
        raise FieldError("boundary", f"must be a sphere or a box (a closed convex "
                         f"surface), got a {boundary.kind}")
    if boundary.medium:
        raise FieldError("boundary", "is already a constant_medium")
    if boundary.kind == "sphere" and boundary.geometry[1] < 0:
        raise FieldError("boundary", "a sphere with a negative radius has no inside")
    material = isotropic.raw(albedo, density)
    return replace(boundary, material=material, name=name or boundary.name, flipped=False)


@checked("mesh")
def mesh(file: str | Path | tuple, material: Material, *, scale: float | Vec3 = 1.0,
         smooth: bool | None = None, name: str | None = None,
         base: str | Path | None = None) -> Shape:
    """A triangle mesh.  file: a mesh file -- OBJ, PLY, STL, OFF, glTF/GLB, read
    by trimesh (pip install 'rtweekend[meshes]'); a relative path is taken from
    `base` (the scene file's folder) or the current one -- or the arrays
    (vertices [V, 3], faces [F, 3]), (vertices, faces, uvs [V, 2] or None) or
    (vertices, faces, uvs, normals [V, 3]).  Every triangle has `material` (a
    file's own materials are not read); its front side is the one its
    vertices turn counter-clockwise around, as the formats define it.
    scale: a factor (or one per axis) on the vertices, applied before
    rotate/rotate_y and translate.  smooth: shade with vertex normals interpolated across each
    triangle -- None (the default): where the file or arrays give them; True:
    theirs, or made from the faces (weighted by area) if they give none;
    False: flat, each triangle its own normal.  A file's vertex normal that
    is not a direction (`vn 0 0 0`) is made from the faces around it; arrays
    with one are refused."""
    if smooth is not None:
        smooth = fields.boolean(smooth, "smooth")
    if isinstance(file, (str, Path)):
        path = Path(fields.text(str(file), "file"))
        if not path.is_absolute() and base is not None:
            path = Path(base) / path
        vertices, faces, uvs, normals = meshes.read(path)
        where = "file"
    else:
        try:
            vertices, faces, *rest = file
        except (TypeError, ValueError):
            raise FieldError("file", "expected a file name or the arrays (vertices, faces),"
                             " (vertices, faces, uvs) or (vertices, faces, uvs, normals)"
                             ) from None
        if len(rest) > 2:
            raise FieldError("file", f"expected at most 4 arrays (vertices, faces, uvs, "
                             f"normals), got {2 + len(rest)}")
        uvs = rest[0] if rest else None
        normals = rest[1] if len(rest) > 1 else None
        where = "mesh"
    if isinstance(scale, (list, tuple, np.ndarray)):
        factor = fields.vec3(scale, "scale")
    else:
        factor = (fields.number(scale, "scale"),) * 3
    if not all(abs(s) >= fields.SMALLEST for s in factor):
        raise FieldError("scale", f"must not be 0, got {scale}")
    vertices, faces, uvs, normals = meshes.check(vertices, faces, uvs,
                                                 None if smooth is False else normals, where,
                                                 from_file=where == "file")
    vertices = vertices * np.asarray(factor)
    if np.abs(vertices).max() > fields.LARGEST:
        raise FieldError("scale", f"puts vertices beyond {fields.LARGEST:g}")
    if np.prod(np.sign(factor)) < 0:
        faces = faces[:, ::-1].copy()      # a mirroring scale keeps the front side outward
    if normals is not None:                # normals go by the scale's inverse
        normals = normals / np.asarray(factor)
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    elif smooth:
        normals = meshes.smooth_normals(vertices, faces)
    return Shape("mesh", (vertices, faces, uvs, normals), check_material(material), name=name)


MEDIUM_BOUNDARIES = ("sphere", "box")
SHAPES = {f.kind: f for f in (sphere, xy_rect, xz_rect, yz_rect, box, quad, mesh)}
