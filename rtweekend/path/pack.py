"""Freezing a Scene into the arrays the path tracer's kernels read (layout.py).

Each shape becomes one primitive, placed in the world (rotate_y, then
translate) and packed by its kind's module (shapes/<kind>.py).
"""
import numpy as np

from ..errors import SceneError
from ..scene.fields import SKY
from . import bvh as hierarchy
from .layout import (BG_COLOR, BG_SKY, BOX, DIFFUSE_LIGHT, MAT_FLOATS, MATERIAL_TAGS,
                     OBJ_FLOATS, OBJ_INTS, OBJ_MAT, PRIMITIVE_KINDS, RECT, SPHERE, XY_RECT,
                     XZ_RECT, YZ_RECT, SceneArrays)
from .shapes import axis_rect, box, rect, sphere


AXIS_RECTS = {"xy_rect": XY_RECT, "xz_rect": XZ_RECT, "yz_rect": YZ_RECT}


def primitives(shape):
    """[(kind tag, obj_f row)] of one shape, placed in the world.

    A book rect that is not turned stays on its axis (axis_rect.py); turned, it
    becomes a general rect (rect.py).  A box is one primitive in its own frame
    (box.py), whatever its turn.
    """
    row = np.zeros(OBJ_FLOATS)
    if shape.kind == "box":
        box.pack(*shape.geometry, shape.angle, shape.offset, shape.flipped, row)
        return [(BOX, row)]
    rot, offset = shape.placement()
    if shape.kind == "sphere":
        center, radius = shape.geometry
        sphere.pack(rot @ np.asarray(center) + offset, -radius if shape.flipped else radius,
                    row)
        return [(SPHERE, row)]
    if shape.angle % 360.0 == 0.0:
        axis_rect.pack(shape.kind, shape.geometry, offset, shape.flipped, row)
        return [(AXIS_RECTS[shape.kind], row)]
    q, u, v = rect.axis_frame(shape.kind, shape.geometry)
    if shape.flipped:
        u, v = v, u         # swapping the edges reverses u x v, the front side
    rect.pack(rot @ np.asarray(q) + offset, rot @ np.asarray(u), rot @ np.asarray(v), row)
    return [(RECT, row)]


def pack_background(value):
    """(kind, rgb array) for a validated background: an RGB triple or "sky"."""
    if isinstance(value, str) and value == SKY:
        return BG_SKY, np.zeros(3)
    return BG_COLOR, np.array(value, dtype=np.float64)


def pack_scene(scene, bvh=None):
    """The SceneArrays of a path-traced Scene (validated here).

    bvh: build a hierarchy (True), test every object (False), or decide by the
    number of primitives (None: from bvh.BVH_MIN_OBJECTS on).
    """
    scene.check()
    if scene.resolved_integrator() != "path":
        raise SceneError("this scene is rendered by the classic integrator")
    materials, mat_index = [], {}
    obj_i, obj_f, first = [], [], {}
    for shape in scene.objects:
        m = mat_index.setdefault(id(shape.material), len(materials))
        if m == len(materials):
            materials.append(shape.material)
        first[id(shape)] = len(obj_i)
        for kind, row in primitives(shape):
            assert kind in PRIMITIVE_KINDS     # the kernels' dispatch knows no other
            obj_i.append((kind, m))
            obj_f.append(row)
    mat_i = np.array([MATERIAL_TAGS[mt.kind] for mt in materials], dtype=np.int64)
    mat_f = np.array([(*mt.color, mt.param) for mt in materials], dtype=np.float64)
    lights = np.array([first[id(s)] for s in scene.lights], dtype=np.int64)
    bg_kind, bg = pack_background(scene.resolved_background())
    obj_i = np.array(obj_i, dtype=np.int64).reshape(-1, OBJ_INTS)
    obj_f = np.array(obj_f, dtype=np.float64).reshape(-1, OBJ_FLOATS)
    if bvh is None:
        bvh = len(obj_i) >= hierarchy.BVH_MIN_OBJECTS
    tree = hierarchy.build_bvh(obj_i, obj_f) if bvh else hierarchy.empty_bvh(len(obj_i))
    emitters = np.flatnonzero(mat_i[obj_i[:, OBJ_MAT]] == DIFFUSE_LIGHT).astype(np.int64)
    return SceneArrays(obj_i, obj_f, mat_i, mat_f.reshape(-1, MAT_FLOATS), lights, emitters,
                       bg_kind, bg, *tree)
