"""The primitive kinds, and the one place that dispatches on them.

Each kind is a module (sphere.py, rect.py, axis_rect.py, box.py, triangle.py) that provides,
for the row k of obj_f it packed:

  distance(obj_f, k, o, d, t_max, from_self, from_inside)  nearest hit in (0, t_max)
  outward_normal(obj_f, k, p)          unit normal on its front side
  shading_normal(...)                  triangles only (a smooth mesh's normal)
  enters(obj_f, k, n, d)               does a ray leaving it along d (its outward
                                       normal there: n) go inside it?
  sample_toward(obj_f, k, p, u1, u2)   the direction from p towards its point for
                                       the unit square's (u1, u2) (as a light; a
                                       sphere is told whether p is on it)
  pdf_toward(obj_f, k, p, d, from_self, from_inside)   that direction's density
  sample_area(obj_f, k, [part,] u1, u2)  a point uniform over its surface (a box's
                                       faces one at a time) and its normal
  uv(obj_f, k, p)                      texture coordinates of a point on it
  interval(obj_f, k, o, d)             where a line is inside it (closed kinds:
                                       a constant medium's boundary)
  bounds(row), pack(..., row)          NumPy, for the BVH and pack.py
  light_parts(row)                     NumPy: [(part, area)], its rows as a light:
                                       the one place its area as a light is
                                       computed (lights.py keeps it in the table)

Spheres can move (motion blur): their functions also take the ray's time,
which is None in a kernel for a scene where nothing moves (sphere.py).  A
mesh's triangles take the mesh tables (scene.tris), None in a scene without
meshes, which then compiles none of their code (triangle.py).

(axis_rect.py serves three kinds, xy, xz and yz: its functions take the axes.)
Here each operation is an explicit branch per kind (adding a kind: its module,
its tag in layout.py, one line per operation below).  pack.py writes only the
tags in PRIMITIVE_KINDS, so the last line of each chain is never reached; it
returns NaN, which would make a bad sample that is dropped and counted, not an
object that silently looks like another kind.

Self-intersection is avoided without an epsilon: a ray remembers the object it
leaves (from_obj) and whether it went inside that object (from_inside); each
kind knows where it can be met again.
"""
import math

from ...kernel.jit import jit_step, like
from ..layout import BOX, OBJ_KIND, RECT, SPHERE, TRIANGLE, XY_RECT, XZ_RECT, YZ_RECT
from . import axis_rect, box, rect, sphere, triangle

NAN = math.nan
MODULES = {SPHERE: sphere, RECT: rect, XY_RECT: axis_rect, XZ_RECT: axis_rect,
           YZ_RECT: axis_rect, BOX: box, TRIANGLE: triangle}
# The axes (a, b, n) of the three axis-aligned kinds: the plane's and the normal's.
XY, XZ, YZ = axis_rect.XY, axis_rect.XZ, axis_rect.YZ
AXES = {XY_RECT: XY, XZ_RECT: XZ, YZ_RECT: YZ}


def bounds(kind, row):
    """(lo, hi) corners of the axis-aligned box around one primitive."""
    if kind in AXES:
        return axis_rect.bounds(AXES[kind], row)
    return MODULES[kind].bounds(row)


def light_parts(kind, row):
    """[(part, area)] of one primitive as a light: the rows of lights.pack_lights
    (part -1 for a kind sampled whole, a box's faces 0..5)."""
    return MODULES[kind].light_parts(row)


@jit_step
def distance(scene, k, o, d, t_max, from_obj, from_inside, time):
    """Distance to object k for a ray leaving object from_obj (NO_HIT: none)."""
    return distance_as(scene, scene.obj_i[k, OBJ_KIND], k, o, d, t_max, from_obj, from_inside,
                       time)


@jit_step
def distance_as(scene, kind, k, o, d, t_max, from_obj, from_inside, time):
    """distance, for object k of the given kind: called with a constant kind
    (bvh.kind_walk), LLVM keeps that kind's test alone."""
    f = scene.obj_f
    from_self = k == from_obj
    if kind == XZ_RECT:
        return axis_rect.distance(f, k, o, d, t_max, from_self, from_inside, *XZ)
    if kind == YZ_RECT:
        return axis_rect.distance(f, k, o, d, t_max, from_self, from_inside, *YZ)
    if kind == XY_RECT:
        return axis_rect.distance(f, k, o, d, t_max, from_self, from_inside, *XY)
    if kind == SPHERE:
        return sphere.distance(f, k, o, d, t_max, from_self, from_inside, time)
    if kind == BOX:
        return box.distance(f, k, o, d, t_max, from_self, from_inside)
    if kind == RECT:
        return rect.distance(f, k, o, d, t_max, from_self, from_inside)
    if kind == TRIANGLE:
        return triangle.distance(scene.tris, f, k, o, d, t_max, from_self)
    return like(t_max, NAN)


@jit_step
def outward_normal(scene, k, p, time):
    """Unit normal at p on object k, pointing to its front side."""
    kind = scene.obj_i[k, OBJ_KIND]
    f = scene.obj_f
    if kind == XZ_RECT:
        return axis_rect.outward_normal(f, k, p, XZ[2])
    if kind == YZ_RECT:
        return axis_rect.outward_normal(f, k, p, YZ[2])
    if kind == XY_RECT:
        return axis_rect.outward_normal(f, k, p, XY[2])
    if kind == SPHERE:
        return sphere.outward_normal(f, k, p, time)
    if kind == BOX:
        return box.outward_normal(f, k, p)
    if kind == RECT:
        return rect.outward_normal(f, k, p)
    if kind == TRIANGLE:
        return triangle.outward_normal(scene.tris, f, k)
    return (NAN, NAN, NAN)


@jit_step
def shading_normal(scene, tris, k, p, n_out):
    """The unit normal the materials shade with at p on object k, on n_out's
    side: a smooth mesh's interpolated vertex normals, else n_out.  tris:
    scene.tris, a direct argument so that a scene without meshes compiles
    none of this."""
    if tris is None:
        return n_out
    if scene.obj_i[k, OBJ_KIND] == TRIANGLE:
        return triangle.shading_normal(tris, scene.obj_f, k, p, n_out)
    return n_out


@jit_step
def surface(scene, tris, k):
    """The surface object k is part of, for what is gathered over a surface
    (photons.py): a mesh's triangles are one surface (its first triangle's
    index), any other object its own.  tris: scene.tris, a direct argument."""
    if tris is None:
        return k
    if scene.obj_i[k, OBJ_KIND] == TRIANGLE:
        return triangle.surface(tris, scene.obj_f, k)
    return k


@jit_step
def enters(scene, k, n, d):
    """Does a ray leaving object k along d, where its outward normal is n, go
    inside it?  (from_inside of the next segment: where k may be met again)"""
    kind = scene.obj_i[k, OBJ_KIND]
    f = scene.obj_f
    if kind == XZ_RECT or kind == YZ_RECT or kind == XY_RECT:
        return axis_rect.enters(f, k, n, d)
    if kind == SPHERE:
        return sphere.enters(f, k, n, d)
    if kind == BOX:
        return box.enters(f, k, n, d)
    if kind == RECT:
        return rect.enters(f, k, n, d)
    if kind == TRIANGLE:
        return triangle.enters(scene.tris, f, k, n, d)
    return False


@jit_step
def sample_toward(scene, k, p, from_obj, u1, u2, time):
    """The unit direction from p (a point of object from_obj, or NO_HIT)
    towards object k for the unit square's point (u1, u2), by k's own light
    sampling: a point uniform over its area (a sphere: a direction uniform in
    the cone it subtends).  The point comes from the sampler, so a Sobol point
    stratifies the light's surface."""
    kind = scene.obj_i[k, OBJ_KIND]
    f = scene.obj_f
    if kind == XZ_RECT:
        return axis_rect.sample_toward(f, k, p, u1, u2, *XZ)
    if kind == YZ_RECT:
        return axis_rect.sample_toward(f, k, p, u1, u2, *YZ)
    if kind == XY_RECT:
        return axis_rect.sample_toward(f, k, p, u1, u2, *XY)
    if kind == SPHERE:
        return sphere.sample_toward(f, k, p, k == from_obj, u1, u2, time)
    if kind == BOX:
        return box.sample_toward(f, k, p, u1, u2)
    if kind == RECT:
        return rect.sample_toward(f, k, p, u1, u2)
    if kind == TRIANGLE:
        return triangle.sample_toward(scene.tris, f, k, p, u1, u2)
    return (NAN, NAN, NAN)


@jit_step
def pdf_toward(scene, k, p, d, from_obj, from_inside, time):
    """Density of d under sample_toward(k) at p; 0 where d misses object k."""
    kind = scene.obj_i[k, OBJ_KIND]
    f = scene.obj_f
    from_self = k == from_obj
    if kind == XZ_RECT:
        return axis_rect.pdf_toward(f, k, p, d, from_self, from_inside, *XZ)
    if kind == YZ_RECT:
        return axis_rect.pdf_toward(f, k, p, d, from_self, from_inside, *YZ)
    if kind == XY_RECT:
        return axis_rect.pdf_toward(f, k, p, d, from_self, from_inside, *XY)
    if kind == SPHERE:
        return sphere.pdf_toward(f, k, p, d, from_self, from_inside, time)
    if kind == BOX:
        return box.pdf_toward(f, k, p, d, from_self, from_inside)
    if kind == RECT:
        return rect.pdf_toward(f, k, p, d, from_self, from_inside)
    if kind == TRIANGLE:
        return triangle.pdf_toward(scene.tris, f, k, p, d, from_self)
    return NAN


@jit_step
def sample_area(scene, k, part, u1, u2, time):
    """(point, outward normal) of a point uniform over object k (a box: over its
    face `part`; the others have one part) for the unit square's point (u1,
    u2): dense by 1 / the area light_parts gives (the light table's AREA)."""
    kind = scene.obj_i[k, OBJ_KIND]
    f = scene.obj_f
    if kind == XZ_RECT:
        return axis_rect.sample_area(f, k, u1, u2, *XZ)
    if kind == YZ_RECT:
        return axis_rect.sample_area(f, k, u1, u2, *YZ)
    if kind == XY_RECT:
        return axis_rect.sample_area(f, k, u1, u2, *XY)
    if kind == SPHERE:
        return sphere.sample_area(f, k, u1, u2, time)
    if kind == BOX:
        return box.sample_area(f, k, part, u1, u2)
    if kind == RECT:
        return rect.sample_area(f, k, u1, u2)
    if kind == TRIANGLE:
        return triangle.sample_area(scene.tris, f, k, u1, u2)
    return (NAN, NAN, NAN), (NAN, NAN, NAN)


@jit_step
def uv(scene, k, p, time):
    """Texture coordinates (u, v) of the point p on object k."""
    kind = scene.obj_i[k, OBJ_KIND]
    f = scene.obj_f
    if kind == XZ_RECT:
        return axis_rect.uv(f, k, p, XZ[0], XZ[1])
    if kind == YZ_RECT:
        return axis_rect.uv(f, k, p, YZ[0], YZ[1])
    if kind == XY_RECT:
        return axis_rect.uv(f, k, p, XY[0], XY[1])
    if kind == SPHERE:
        return sphere.uv(f, k, p, time)
    if kind == BOX:
        return box.uv(f, k, p)
    if kind == RECT:
        return rect.uv(f, k, p)
    if kind == TRIANGLE:
        return triangle.uv(scene.tris, f, k, p)
    return (NAN, NAN)


@jit_step
def interval(scene, k, o, d, time):
    """(t0, t1) where the line o + t d is inside closed object k (a sphere or a
    box: a constant medium's boundary); t0 > t1 if never."""
    kind = scene.obj_i[k, OBJ_KIND]
    f = scene.obj_f
    if kind == SPHERE:
        return sphere.interval(f, k, o, d, time)
    if kind == BOX:
        return box.interval(f, k, o, d)
    return (NAN, NAN)
