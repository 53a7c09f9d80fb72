"""The search for the nearest hit (closest_hit) and for any hit before a
distance (unoccluded), over a bounding volume hierarchy built once per scene.

The hierarchy is built binary (bvh_build.py: the binned surface-area
heuristic, pbrt's BVHAggregate, Wald 2007) and collapsed into 4-wide nodes,
which both searches walk nearer children first (wide_bvh.py).  A scene too
small for a hierarchy (fewer than BVH_MIN_OBJECTS) tests every object, kind
by kind (kind_walk).

stackless_walk also walks the binary tree itself, by the nodes' "miss" links
-- nodes in depth-first order, so a node's left child is the next node and its
miss link the node after its subtree -- with no stack:

    i = 0
    while i < n_nodes:
        if ray hits box[i]: test the leaf's objects (leaf) / go to i + 1 (inner)
        else: i = miss[i]
    (a leaf continues at miss[i] == i + 1 too)

bvh_box[i]  = (min x, y, z, max x, y, z)
bvh_node[i] = (first, count, miss): a leaf holds objects bvh_prims[first:first+count];
              an inner node has count 0 and its right child as `first` (its left
              one is i + 1).  Without a hierarchy (no nodes), bvh_prims lists every
              object once (sorted by kind, for kind_walk: SceneArrays.kind_first).
The renderer keeps no binary nodes once the tree is 4-wide; the tests and the
float32 probe (benchmarks/precision.py) walk it this way, as a reference.
"""
import math

import numpy as np

from ..kernel.jit import jit_step, like
from ..kernel.vec3 import reciprocal
from . import shapes, wide_bvh
from .bvh_build import build_bvh, object_bounds  # noqa: F401  (the builder)
from .layout import (BOX, NO_HIT, NON_NEGATIVE, OBJ_KIND, PRIMITIVE_KINDS, RECT, SPHERE,
                     TRIANGLE, XY_RECT, XZ_RECT, YZ_RECT)

INF = math.inf
# From this many primitives on, the BVH beats testing every object (whose loop
# Numba compiles tightly): measured per scene in benchmarks/results/measurements.md.
BVH_MIN_OBJECTS = 10


def empty_bvh(n_objects, ids=None):
    """No hierarchy: closest_hit tests every object (small scenes).  bvh_prims
    lists them all (or `ids`), so that both walks read object indices the same way."""
    return (np.zeros((0, 6)), np.zeros((0, 3), dtype=np.int64),
            np.arange(n_objects, dtype=np.int64) if ids is None
            else np.asarray(ids, dtype=np.int64))


def sorted_by_kind(obj_i, prims):
    """(prims sorted by kind, in index order within a kind; kind_first) for
    kind_walk: bvh_prims[kind_first[K]:kind_first[K + 1]] are the kind K ones."""
    kinds = obj_i[prims, OBJ_KIND]
    order = np.argsort(kinds, kind="stable")
    first = np.searchsorted(kinds[order], np.arange(len(PRIMITIVE_KINDS) + 1))
    return np.asarray(prims, dtype=np.int64)[order], first.astype(np.int64)


@jit_step
def box_near(bvh_box, i, o, inv_d, t_max):
    """Where the ray enters box i (0 if it starts inside), or inf if it misses
    it or enters at t_max or later.  (slab test, inv_d = 1 / d)"""
    t0 = (bvh_box[i, 0] - o[0]) * inv_d[0]
    t1 = (bvh_box[i, 3] - o[0]) * inv_d[0]
    near, far = min(t0, t1), max(t0, t1)
    t0 = (bvh_box[i, 1] - o[1]) * inv_d[1]
    t1 = (bvh_box[i, 4] - o[1]) * inv_d[1]
    near, far = max(near, min(t0, t1)), min(far, max(t0, t1))
    t0 = (bvh_box[i, 2] - o[2]) * inv_d[2]
    t1 = (bvh_box[i, 5] - o[2]) * inv_d[2]
    near, far = max(near, min(t0, t1)), min(far, max(t0, t1))
    if near <= far and far > 0.0 and near < t_max:
        return max(near, like(near, 0.0))
    return like(near, INF)


@jit_step
def box_entry(bvh_box, i, o, inv_d, t_max):
    """Does the ray enter box i before t_max?"""
    return box_near(bvh_box, i, o, inv_d, t_max) != INF


@jit_step
def closest_hit(scene, o, d, t_max, from_obj, from_inside, time):
    """(object index, t) of the nearest hit before t_max, or (NO_HIT, inf), for a
    ray leaving object from_obj (NO_HIT: none; from_inside: into its ball), at
    `time` on the shutter (None: nothing moves).

    A scene with a hierarchy walks it 4-wide, nearer children first
    (wide_bvh.py: faster than the binary tree's stackless walk, by
    benchmarks/results/measurements.md); a small one tests every object,
    kind by kind (kind_walk); arrays with binary nodes and neither (the
    tests' reference) walk those (stackless_walk).  Which runs is decided
    when compiling (scene.wide, scene.kind_first None or not), and only that
    one is compiled.
    """
    return _walk(scene, scene.wide, scene.tris, scene.kind_first, o, d, t_max, from_obj,
                 from_inside, time, False)


@jit_step
def _walk(scene, wide, tris, kind_first, o, d, t_max, from_obj, from_inside, time, first_hit):
    if wide is None:
        if kind_first is not None:
            return kind_walk(scene, tris, o, d, t_max, from_obj, from_inside, time, first_hit)
        return stackless_walk(scene, o, d, t_max, from_obj, from_inside, time, first_hit)
    return wide_bvh.walk(scene, wide, tris, o, d, t_max, from_obj, from_inside, time,
                         first_hit)


@jit_step
def stackless_walk(scene, o, d, t_max, from_obj, from_inside, time, first_hit):
    """The stackless walk of the binary tree described above: (object, t) of
    the nearest hit before t_max, or, with first_hit, of the first one met
    (unoccluded: any object blocks a segment).  The tests' reference and the
    float32 probe's; the renderer walks the tree 4-wide."""
    bvh_box, bvh_node = scene.bvh_box, scene.bvh_node
    best = np.int64(NO_HIT)     # typed int64, not the literal -1 (see integrators/path.py)
    inv_d = (reciprocal(d[0]), reciprocal(d[1]), reciprocal(d[2]))
    i = 0
    while i < bvh_node.shape[0]:
        if box_entry(bvh_box, i, o, inv_d, t_max):
            count = bvh_node[i, 1]
            if count == 0:
                i += 1                      # inner node: on to its left child
                continue
            first, after = bvh_node[i, 0], bvh_node[i, 2]
        else:
            i = bvh_node[i, 2]
            continue
        best, t_max = nearest_in_leaf(scene, first, first + count, np.int64(-1), o, d, t_max,
                                      best, from_obj, from_inside, time, first_hit)
        if first_hit and best != NO_HIT:
            return best, t_max
        i = after
    return best, t_max


@jit_step
def kind_walk(scene, tris, o, d, t_max, from_obj, from_inside, time, first_hit):
    """closest_hit's search in a scene without hierarchy: every object, kind by
    kind (bvh_prims sorted by kind, kind_first where each kind starts), each
    kind in a loop of its own that holds its test alone: no dispatch on the
    kind per object, which cost as much as the books' rects' own tests
    (benchmarks/results/measurements.md).  Of equal distances, the object
    tested first wins (as in any walk: the hierarchy's too)."""
    # Written out, not a loop over the kinds: each call's kind a constant.
    b = np.int64(NO_HIT)
    b, t_max = _of_kind(scene, np.int64(XZ_RECT), o, d, t_max, b, from_obj, from_inside,
                        time, first_hit)
    b, t_max = _of_kind(scene, np.int64(YZ_RECT), o, d, t_max, b, from_obj, from_inside,
                        time, first_hit)
    b, t_max = _of_kind(scene, np.int64(XY_RECT), o, d, t_max, b, from_obj, from_inside,
                        time, first_hit)
    b, t_max = _of_kind(scene, np.int64(SPHERE), o, d, t_max, b, from_obj, from_inside,
                        time, first_hit)
    b, t_max = _of_kind(scene, np.int64(BOX), o, d, t_max, b, from_obj, from_inside, time,
                        first_hit)
    b, t_max = _of_kind(scene, np.int64(RECT), o, d, t_max, b, from_obj, from_inside, time,
                        first_hit)
    if tris is not None:
        b, t_max = _of_kind(scene, np.int64(TRIANGLE), o, d, t_max, b, from_obj, from_inside,
                            time, first_hit)
    return b, t_max


@jit_step
def _of_kind(scene, kind, o, d, t_max, best, from_obj, from_inside, time, first_hit):
    """(best, t_max) after the objects of `kind` (an int64, not a literal: one
    compile, each constant kind folded by LLVM once inlined); with first_hit,
    nothing more once an object was met."""
    if first_hit and best != NO_HIT:
        return best, t_max
    return nearest_in_leaf(scene, scene.kind_first[kind], scene.kind_first[kind + 1], kind, o,
                           d, t_max, best, from_obj, from_inside, time, first_hit)


@jit_step
def nearest_in_leaf(scene, first, end, kind, o, d, t_max, best, from_obj, from_inside, time,
                    first_hit):
    """(best, t_max) after testing the objects scene.bvh_prims[first:end]: the
    nearest hit before t_max, or with first_hit the first one met.  kind: the
    kind they all are (kind_walk), or -1: each its own (a leaf)."""
    bvh_prims = scene.bvh_prims
    for j in range(first, end):
        k = bvh_prims[j & NON_NEGATIVE] & NON_NEGATIVE
        t = shapes.distance_as(scene, kind if kind >= 0 else scene.obj_i[k, OBJ_KIND], k, o, d,
                               t_max, from_obj, from_inside, time)
        if t < t_max:
            t_max = t
            best = k
            if first_hit:
                break
    return best, t_max


@jit_step
def unoccluded(scene, o, d, t_max, from_obj, from_inside, time):
    """Is the segment o + t d, 0 < t < t_max, clear of every object?  (The
    visibility of a connection between two points; what a ray leaving object
    from_obj may meet, as for closest_hit.)  closest_hit's walk, stopped at
    the first object met: any one blocks the segment."""
    k, _ = _walk(scene, scene.wide, scene.tris, scene.kind_first, o, d, t_max, from_obj,
                 from_inside, time, True)
    return k == NO_HIT
