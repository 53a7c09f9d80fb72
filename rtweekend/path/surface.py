"""The surface record: everything an estimator knows about a ray's hit, made in
one place (the books' hit_record).

    hit = surface_at(scene, textures, k, o, d, t, time)
    hit.p, hit.n, hit.front, hit.mat, hit.albedo, ...

The shading normal n faces the incoming ray (the books' set_face_normal: it is
what makes their materials two-sided); n_out is the shape's outward normal,
which says where the ray goes next (shapes.enters).  The analytic kinds have
one normal, so n is n_out or its opposite; a smooth mesh shades with its
interpolated vertex normals (shapes/triangle.py), turned the same way.  albedo is the material's
colour at p, from its texture if it has one (textures.py; `textures` is None
for a scene without any, and the kernel then has none of that code), and uv
the coordinates it was looked up with ((0, 0) where nothing needed them).
"""
from typing import NamedTuple

import numpy as np

from ..kernel.jit import jit_step
from ..kernel.vec3 import dot, madd
from . import materials, shapes
from . import textures as texturing
from .layout import NON_NEGATIVE, OBJ_MAT

NO_PRIM = -1


class Surface(NamedTuple):
    p: tuple               # the point
    n_out: tuple           # the shape's outward (geometric) unit normal there
    n: tuple               # the shading normal, on the incoming ray's side
    front: bool            # did the ray meet the front (outward) side?
    obj: np.int64          # the object (a row of obj_i)
    prim: np.int64         # the part of it (a mesh's triangle); NO_PRIM for the others
    mat: np.int64          # its material (a row of mat_i)
    albedo: tuple          # the material's colour at p (emitted radiance for a light)
    uv: tuple              # texture coordinates, where a texture needed them


@jit_step
def face_normal(d, n_out):
    """The books' set_face_normal: (front_face, normal facing the ray)."""
    if dot(d, n_out) < 0.0:
        return True, n_out
    return False, (-n_out[0], -n_out[1], -n_out[2])


@jit_step
def color_of(scene, textures, k, p, uv_from, time):
    """The colour of object k's material at p (albedo, or emitted radiance),
    from its texture if it has one; uv_from: the object whose uv a texture
    reads (k on a surface, NO_HIT inside a medium)."""
    m = scene.obj_i[k, OBJ_MAT] & NON_NEGATIVE
    color = materials.color(scene, m)
    if textures is not None:
        color = texturing.color_at(scene, textures, m, uv_from, p, color, time)
    return color


@jit_step
def surface_at(scene, textures, k, o, d, t, time):
    """The record of the hit of the ray o + t d on object k."""
    p = madd(o, d, t)
    n_out = shapes.outward_normal(scene, k, p, time)
    front, n = face_normal(d, n_out)
    if scene.tris is not None:      # a smooth mesh's normal, turned the same way
        n = shapes.shading_normal(scene, scene.tris, k, p, n_out)
        if not front:
            n = (-n[0], -n[1], -n[2])
    m = scene.obj_i[k, OBJ_MAT] & NON_NEGATIVE
    albedo = materials.color(scene, m)
    uv = (0.0, 0.0)
    if textures is not None:
        albedo, uv = texturing.color_and_uv(scene, textures, m, k, p, albedo, time)
    return Surface(p, n_out, n, front, k, np.int64(NO_PRIM), m, albedo, uv)
