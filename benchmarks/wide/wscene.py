"""rtweekend's SceneArrays regrouped for intersection loops that run over rays.

rtweekend keeps one row per object in obj_f and dispatches on each object's kind
per ray.  Here the objects are sorted by kind into one small table per kind, so
that the intersection kernel can loop over the objects of one kind (outer loop,
their parameters become loop-invariant scalars) and over rays (inner loop, no
dispatch, no branch): that inner loop is what LLVM can vectorise.

Hit ids stay rtweekend's object indices, so the shading reuses rtweekend's own
helpers (normals, light sampling, pdfs, materials) on the same rows: the
estimator is the same, only the order of work changes.
"""
from typing import NamedTuple

import numpy as np

from rtweekend.path.layout import BOX, RECT, SPHERE, XY_RECT, XZ_RECT, YZ_RECT
from rtweekend.path.shapes import axis_rect, box, sphere


# How the closest hit is searched:
FLAT = 0      # every object, in the per-kind loops (the cornell scenes: 8 objects)
PACKET = 1    # the BVH walked by packets of rays, spheres tested per packet (weekend)
PER_RAY = 2   # rtweekend's own closest_hit (BVH walk or all objects), rays one by one
HYBRID = 3    # PACKET for the camera rays (coherent), PER_RAY for the bounces
MODES = {"flat": FLAT, "packet": PACKET, "ray": PER_RAY, "hybrid": HYBRID}


class WideScene(NamedTuple):
    xy: np.ndarray        # float64 [n, 5]: A0, A1, B0, B1, K of each xy_rect
    xy_id: np.ndarray     # int64 [n]: its object index
    xz: np.ndarray
    xz_id: np.ndarray
    yz: np.ndarray
    yz_id: np.ndarray
    sph: np.ndarray       # float64 [n, 4]: centre x, y, z, radius^2
    sph_id: np.ndarray
    box: np.ndarray       # float64 [n, 16]: the box rows of obj_f (box.py's columns)
    box_id: np.ndarray
    sph_row: np.ndarray   # int64 [N objects]: row in sph of each object (-1: none)
    bvh_mode: int         # FLAT, PACKET, PER_RAY or HYBRID (above)


def wide_scene(a, mode=None):
    """The WideScene of SceneArrays `a`.  mode: "flat", "packet" or "ray"
    (None: flat without a BVH, packet with one; only sphere-only scenes have a
    BVH among those measured, and the packet walk tests spheres only)."""
    kinds = a.obj_i[:, 0]
    if np.any(kinds == RECT):
        raise NotImplementedError("turned rects: not in the scenes measured here")

    def table(kind, cols):
        ids = np.flatnonzero(kinds == kind).astype(np.int64)
        return np.ascontiguousarray(a.obj_f[ids][:, cols]).reshape(len(ids), len(cols)), ids

    rect_cols = [axis_rect.A0, axis_rect.A1, axis_rect.B0, axis_rect.B1, axis_rect.K]
    xy, xy_id = table(XY_RECT, rect_cols)
    xz, xz_id = table(XZ_RECT, rect_cols)
    yz, yz_id = table(YZ_RECT, rect_cols)
    sph, sph_id = table(SPHERE, [sphere.CENTER, sphere.CENTER + 1, sphere.CENTER + 2,
                                 sphere.RADIUS2])
    bx, box_id = table(BOX, list(range(box.FLOATS)))
    sph_row = np.full(len(kinds), -1, dtype=np.int64)
    sph_row[sph_id] = np.arange(len(sph_id))
    has_bvh = a.bvh_node.shape[0] > 0
    if mode is None:
        mode = "packet" if has_bvh else "flat"
    mode = MODES[mode]
    if mode in (PACKET, HYBRID) and not has_bvh:
        raise ValueError("this scene has no BVH: use mode='flat' or 'ray'")
    if mode in (PACKET, HYBRID) and len(sph_id) != len(kinds):
        raise NotImplementedError("the packet BVH walk handles sphere-only scenes")
    return WideScene(xy, xy_id, xz, xz_id, yz, yz_id, sph, sph_id, bx, box_id, sph_row, mode)
