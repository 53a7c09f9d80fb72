"""A flat bounding volume hierarchy, built once per scene in NumPy.

Nodes are stored in depth-first order, so a node's left child is the next
node, and each node keeps a "miss" link: the node to visit when the ray misses
its box (the next node after its subtree).  Traversal is then a single loop
with no stack, nothing allocated per ray:

    i = 0
    while i < n_nodes:
        if ray hits box[i]: test the leaf's objects (leaf) / go to i + 1 (inner)
        else: i = miss[i]
    (a leaf continues at miss[i] == i + 1 too)

bvh_box[i]  = (min x, y, z, max x, y, z)
bvh_node[i] = (first, count, miss): a leaf holds objects bvh_prims[first:first+count];
              an inner node has count 0.  Without a hierarchy (no nodes), bvh_prims
              lists every object once.
The split is the binned surface-area heuristic (pbrt's BVHAggregate, Wald 2007).
closest_hit walks it (or, for small scenes, tests every object).
"""
import math

import numpy as np

from ..kernel.jit import jit_step, like
from . import shapes
from .layout import NO_HIT, OBJ_KIND

INF = math.inf
NON_NEGATIVE = 0x7FFFFFFFFFFFFFFF
LEAF_SIZE = 4         # at most this many objects per leaf
BINS = 16             # centroid bins per axis for the SAH
TRAVERSAL_COST = 1.0  # cost of a box test relative to an object test
# From this many primitives on, the BVH beats testing every object (whose loop
# Numba compiles tightly): measured per scene in benchmarks/results/measurements.md.
BVH_MIN_OBJECTS = 10


def object_bounds(obj_i, obj_f):
    """[N, 6] boxes around the objects (zero-thickness rects padded a hair)."""
    lo = np.empty((len(obj_i), 3))
    hi = np.empty((len(obj_i), 3))
    for k in range(len(obj_i)):
        lo[k], hi[k] = shapes.bounds(obj_i[k, OBJ_KIND], obj_f[k])
    pad = 1e-9 * np.maximum(np.abs(lo).max(axis=1, initial=1.0),
                            np.abs(hi).max(axis=1, initial=1.0))[:, None]
    return np.hstack([lo - pad, hi + pad])


def _area(lo, hi):
    e = np.maximum(hi - lo, 0.0)
    return 2.0 * (e[..., 0] * e[..., 1] + e[..., 1] * e[..., 2] + e[..., 2] * e[..., 0])


def _sah_split(bounds, centroids, ids):
    """(axis, mask of ids going left) of the cheapest binned split, or None."""
    lo_c, hi_c = centroids[ids].min(axis=0), centroids[ids].max(axis=0)
    parent = _area(bounds[ids, :3].min(axis=0), bounds[ids, 3:].max(axis=0))
    best = (len(ids) * 1.0, None)          # cost of a leaf, in object tests
    for axis in range(3):
        extent = hi_c[axis] - lo_c[axis]
        if extent <= 0.0:
            continue
        b = np.minimum(((centroids[ids, axis] - lo_c[axis]) / extent * BINS).astype(int),
                       BINS - 1)
        count = np.bincount(b, minlength=BINS)
        blo = np.full((BINS, 3), np.inf)
        bhi = np.full((BINS, 3), -np.inf)
        np.minimum.at(blo, b, bounds[ids, :3])
        np.maximum.at(bhi, b, bounds[ids, 3:])
        # Left of split s = bins [0, s), right = [s, BINS).
        left_n = np.cumsum(count)[:-1]
        right_n = np.cumsum(count[::-1])[::-1][1:]
        left_a = _area(np.minimum.accumulate(blo)[:-1], np.maximum.accumulate(bhi)[:-1])
        right_a = _area(np.minimum.accumulate(blo[::-1])[::-1][1:],
                        np.maximum.accumulate(bhi[::-1])[::-1][1:])
        cost = TRAVERSAL_COST + (left_n * left_a + right_n * right_a) / parent
        cost[(left_n == 0) | (right_n == 0)] = np.inf
        s = int(np.argmin(cost))
        if cost[s] < best[0]:
            best = (cost[s], (axis, b < s + 1))
    return best[1]


def build_bvh(obj_i, obj_f, ids=None):
    """(bvh_box [M, 6], bvh_node [M, 3] int64, bvh_prims [N] int64) over the
    objects `ids` (None: all; a constant medium's boundary is not searched)."""
    bounds = object_bounds(obj_i, obj_f)
    centroids = 0.5 * (bounds[:, :3] + bounds[:, 3:])
    boxes, nodes, prims = [], [], []

    def build(ids):
        i = len(nodes)
        boxes.append(np.concatenate([bounds[ids, :3].min(axis=0), bounds[ids, 3:].max(axis=0)]))
        nodes.append([0, 0, 0])
        split = _sah_split(bounds, centroids, ids) if len(ids) > 1 else None
        if split is None and len(ids) > LEAF_SIZE:
            # SAH prefers one leaf, but leaves stay small: halve on the longest axis.
            axis = int(np.argmax(np.ptp(centroids[ids], axis=0)))
            order = np.argsort(centroids[ids, axis], kind="stable")
            split = (axis, np.isin(np.arange(len(ids)), order[:len(ids) // 2]))
        if split is None:
            nodes[i] = [len(prims), len(ids), 0]
            prims.extend(ids.tolist())
        else:
            _, left = split
            build(ids[left])
            build(ids[~left])
        nodes[i][2] = len(nodes)            # miss: the node after this subtree

    build(np.arange(len(obj_i)) if ids is None else np.asarray(ids, dtype=np.int64))
    return (np.array(boxes, dtype=np.float64).reshape(-1, 6),
            np.array(nodes, dtype=np.int64).reshape(-1, 3),
            np.array(prims, dtype=np.int64))


def empty_bvh(n_objects, ids=None):
    """No hierarchy: closest_hit tests every object (small scenes).  bvh_prims
    lists them all (or `ids`), so that both walks read object indices the same way."""
    return (np.zeros((0, 6)), np.zeros((0, 3), dtype=np.int64),
            np.arange(n_objects, dtype=np.int64) if ids is None
            else np.asarray(ids, dtype=np.int64))


@jit_step
def reciprocal(x):
    """1/x, with 1/0 = inf of the same sign, under any error model (in x's precision)."""
    return like(x, 1.0) / x if x != 0.0 else math.copysign(like(x, INF), x)


@jit_step
def box_entry(bvh_box, i, o, inv_d, t_max):
    """Does the ray enter box i before t_max?  (slab test, inv_d = 1 / d)"""
    t0 = (bvh_box[i, 0] - o[0]) * inv_d[0]
    t1 = (bvh_box[i, 3] - o[0]) * inv_d[0]
    near, far = min(t0, t1), max(t0, t1)
    t0 = (bvh_box[i, 1] - o[1]) * inv_d[1]
    t1 = (bvh_box[i, 4] - o[1]) * inv_d[1]
    near, far = max(near, min(t0, t1)), min(far, max(t0, t1))
    t0 = (bvh_box[i, 2] - o[2]) * inv_d[2]
    t1 = (bvh_box[i, 5] - o[2]) * inv_d[2]
    near, far = max(near, min(t0, t1)), min(far, max(t0, t1))
    return near <= far and far > 0.0 and near < t_max


@jit_step
def closest_hit(scene, o, d, t_max, from_obj, from_inside, time):
    """(object index, t) of the nearest hit before t_max, or (NO_HIT, inf), for a
    ray leaving object from_obj (NO_HIT: none; from_inside: into its ball), at
    `time` on the shutter (None: nothing moves).

    With an empty BVH every object is tested; otherwise the stackless walk
    described above.
    """
    bvh_box, bvh_node, bvh_prims = scene.bvh_box, scene.bvh_node, scene.bvh_prims
    best = np.int64(NO_HIT)     # typed int64, not the literal -1 (see integrators/path.py)
    # One loop for both cases, so shapes.distance is inlined at one call site
    # only (each inlined copy costs compile time): no BVH is a single leaf node.
    no_bvh = bvh_node.shape[0] == 0
    n_nodes = 1 if no_bvh else bvh_node.shape[0]
    inv_d = d                   # only the box tests of a hierarchy need 1 / d
    if not no_bvh:
        inv_d = (reciprocal(d[0]), reciprocal(d[1]), reciprocal(d[2]))
    i = 0
    while i < n_nodes:
        if no_bvh:
            first, count, after = 0, bvh_prims.shape[0], 1
        elif box_entry(bvh_box, i, o, inv_d, t_max):
            count = bvh_node[i, 1]
            if count == 0:
                i += 1                      # inner node: on to its left child
                continue
            first, after = bvh_node[i, 0], bvh_node[i, 2]
        else:
            i = bvh_node[i, 2]
            continue
        for j in range(first, first + count):
            # An object index is >= 0: saying so spares every array access the
            # test for a negative index (Python's a[-1]).
            k = bvh_prims[j] & NON_NEGATIVE
            t = shapes.distance(scene, k, o, d, t_max, from_obj, from_inside, time)
            if t < t_max:
                t_max = t
                best = k
        i = after
    return best, t_max



@jit_step
def unoccluded(scene, o, d, t_max, from_obj, from_inside, time):
    """Is the segment o + t d, 0 < t < t_max, clear of every object?  (The
    visibility of a connection between two points; what a ray leaving object
    from_obj may meet, as for closest_hit.)"""
    k, _ = closest_hit(scene, o, d, t_max, from_obj, from_inside, time)
    return k == NO_HIT
