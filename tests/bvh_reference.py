"""The BVH builder as it was first written, in NumPy (a reference): the
compiled one (rtweekend/path/bvh_build.py) must build the same tree."""
import numpy as np

from rtweekend.path import shapes
from rtweekend.path.bvh_build import BINS, LEAF_SIZE, TRAVERSAL_COST
from rtweekend.path.layout import OBJ_KIND


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
            nodes[i][0] = len(nodes)        # an inner node's right child
            build(ids[~left])
        nodes[i][2] = len(nodes)            # miss: the node after this subtree

    build(np.arange(len(obj_i)) if ids is None else np.asarray(ids, dtype=np.int64))
    return (np.array(boxes, dtype=np.float64).reshape(-1, 6),
            np.array(nodes, dtype=np.int64).reshape(-1, 3),
            np.array(prims, dtype=np.int64))
