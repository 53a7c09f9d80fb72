"""The primitive kinds, and the one place that dispatches on them.

Each kind is a module (sphere.py, rect.py) that provides, for the row k of
obj_f it packed:

  distance(obj_f, k, o, d, t_max, from_self, from_inside)  nearest hit in (0, t_max)
  outward_normal(obj_f, k, p)          unit normal on its front side
  enters(obj_f, k, p, d)               does a ray leaving it at p go inside it?
  sample_toward(obj_f, k, p, state)    a direction from p towards it (as a light)
  pdf_toward(obj_f, k, p, d, from_self, from_inside)   that direction's density
  bounds(row), pack(..., row)          NumPy, for the BVH and pack.py

Here each operation is an explicit branch per kind (adding a kind: its module,
its tag in layout.py, one line per operation below).  pack.py writes only the
tags in PRIMITIVE_KINDS, so the last line of each chain is never reached; it
returns NaN, which would make a bad sample that is dropped and counted, not an
object that silently looks like another kind.

Self-intersection is avoided without an epsilon: a ray remembers the object it
leaves (from_obj) and whether it went into that object's ball (from_inside,
spheres only); each kind knows where it can be met again.
"""
import math

from ...kernel.jit import jit_inline, like
from ..layout import OBJ_KIND, RECT, SPHERE
from . import rect, sphere

NAN = math.nan
MODULES = {SPHERE: sphere, RECT: rect}


def bounds(kind, row):
    """(lo, hi) corners of the axis-aligned box around one primitive."""
    return MODULES[kind].bounds(row)


@jit_inline
def distance(scene, k, o, d, t_max, from_obj, from_inside):
    """Distance to object k for a ray leaving object from_obj (NO_HIT: none)."""
    kind = scene.obj_i[k, OBJ_KIND]
    from_self = k == from_obj
    if kind == SPHERE:
        return sphere.distance(scene.obj_f, k, o, d, t_max, from_self, from_inside)
    if kind == RECT:
        return rect.distance(scene.obj_f, k, o, d, t_max, from_self, from_inside)
    return like(t_max, NAN)


@jit_inline
def outward_normal(scene, k, p):
    """Unit normal at p on object k, pointing to its front side."""
    kind = scene.obj_i[k, OBJ_KIND]
    if kind == SPHERE:
        return sphere.outward_normal(scene.obj_f, k, p)
    if kind == RECT:
        return rect.outward_normal(scene.obj_f, k, p)
    return (NAN, NAN, NAN)


@jit_inline
def enters(scene, k, p, d):
    """Does a ray leaving object k at p along d go inside it?  (from_inside of
    the next segment: where the object may be met again)"""
    kind = scene.obj_i[k, OBJ_KIND]
    if kind == SPHERE:
        return sphere.enters(scene.obj_f, k, p, d)
    if kind == RECT:
        return rect.enters(scene.obj_f, k, p, d)
    return False


@jit_inline
def sample_toward(scene, k, p, state):
    """A unit direction from p towards object k, drawn by its own light sampling."""
    kind = scene.obj_i[k, OBJ_KIND]
    if kind == SPHERE:
        return sphere.sample_toward(scene.obj_f, k, p, state)
    if kind == RECT:
        return rect.sample_toward(scene.obj_f, k, p, state)
    return (NAN, NAN, NAN), state


@jit_inline
def pdf_toward(scene, k, p, d, from_obj, from_inside):
    """Density of d under sample_toward(k) at p; 0 where d misses object k."""
    kind = scene.obj_i[k, OBJ_KIND]
    from_self = k == from_obj
    if kind == SPHERE:
        return sphere.pdf_toward(scene.obj_f, k, p, d, from_self, from_inside)
    if kind == RECT:
        return rect.pdf_toward(scene.obj_f, k, p, d, from_self, from_inside)
    return NAN
