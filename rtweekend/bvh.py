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
              an inner node has count 0.
The split is the binned surface-area heuristic (pbrt's BVHAggregate, Wald 2007).
"""
import numpy as np

from .tags import SPHERE

LEAF_SIZE = 4         # at most this many objects per leaf
BINS = 16             # centroid bins per axis for the SAH
TRAVERSAL_COST = 1.0  # cost of a box test relative to an object test


def object_bounds(obj_i, obj_f):
    """[N, 6] boxes around the objects (zero-thickness rects padded a hair)."""
    lo = np.empty((len(obj_i), 3))
    hi = np.empty((len(obj_i), 3))
    for k, (kind, _) in enumerate(obj_i):
        f = obj_f[k]
        if kind == SPHERE:
            r = abs(f[3])
            lo[k], hi[k] = f[0:3] - r, f[0:3] + r
        else:
            q, u, v = f[0:3], f[3:6], f[6:9]
            corners = np.array([q, q + u, q + v, q + u + v])
            lo[k], hi[k] = corners.min(axis=0), corners.max(axis=0)
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


def build_bvh(obj_i, obj_f):
    """(bvh_box [M, 6], bvh_node [M, 3] int64, bvh_prims [N] int64)."""
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

    build(np.arange(len(obj_i)))
    return (np.array(boxes, dtype=np.float64).reshape(-1, 6),
            np.array(nodes, dtype=np.int64).reshape(-1, 3),
            np.array(prims, dtype=np.int64))


def empty_bvh():
    """No hierarchy: closest_hit tests every object (small scenes)."""
    return np.zeros((0, 6)), np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64)
