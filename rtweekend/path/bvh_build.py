"""Building the BVH (bvh.py walks it): binned SAH, compiled, in seconds for
millions of triangles.

The split of a node with more than one object: for each axis, the objects'
centroids are put into BINS equal bins over the node's centroid extent; the
split after bin s costs

    TRAVERSAL_COST + (n_left x area_left + n_right x area_right) / area_node

(pbrt's BVHAggregate, Wald 2007) and the cheapest over the axes wins if it is
cheaper than a leaf (n object tests).  A node the SAH would keep whole but that
has more than LEAF_SIZE objects is halved at the median of its longest centroid
axis.  The objects of a node keep their order in both children (a stable
partition), and nodes are numbered depth first, left child first, so the walk
needs only a miss link per node (bvh.py).

The arithmetic is NumPy's, step for step (no fastmath: a reciprocal in place of
a division would move objects between bins), so the tree is the one the NumPy
version of this algorithm builds (tests/test_hittables.py compares them).
"""
import numpy as np
from numba import njit

from . import shapes
from .layout import OBJ_KIND, TRIANGLE
from .shapes import triangle

LEAF_SIZE = 4         # at most this many objects per leaf (unless they cannot be split)
BINS = 16             # centroid bins per axis for the SAH
TRAVERSAL_COST = 1.0  # cost of a box test relative to an object test
# bvh.closest_hit keeps at most one node per level on a stack of bvh.STACK:
# from this depth on nodes are halved at the median, whatever the SAH says,
# so no tree of up to 2^31 objects is deeper than 64 + 27 levels.
MEDIAN_FROM_DEPTH = 64


def object_bounds(obj_i, obj_f):
    """[N, 6] boxes around the objects (zero-thickness rects padded a hair)."""
    out = np.empty((len(obj_i), 6))
    tri = obj_i[:, OBJ_KIND] == TRIANGLE
    _triangle_bounds(obj_f, np.flatnonzero(tri), out)     # a mesh's, compiled
    for k in np.flatnonzero(~tri):
        lo, hi = shapes.bounds(obj_i[k, OBJ_KIND], obj_f[k])
        out[k, :3], out[k, 3:] = lo, hi
        _pad(out, k)
    return out


@njit(cache=True)
def _pad(out, k):
    """Widen box k by 1e-9 of its largest coordinate (at least 1e-9)."""
    big = 1.0
    for c in range(6):
        big = max(big, abs(out[k, c]))
    pad = 1e-9 * big
    for c in range(3):
        out[k, c] -= pad
        out[k, 3 + c] += pad


@njit(cache=True)
def _triangle_bounds(obj_f, rows, out):
    for k in rows:
        for c in range(3):
            a, b, d = obj_f[k, triangle.P0 + c], obj_f[k, triangle.P1 + c], \
                obj_f[k, triangle.P2 + c]
            out[k, c] = min(min(a, b), d)
            out[k, 3 + c] = max(max(a, b), d)
        _pad(out, k)


def build_bvh(obj_i, obj_f, ids=None):
    """(bvh_box [M, 6], bvh_node [M, 3] int64, bvh_prims [N] int64) over the
    objects `ids` (None: all; a constant medium's boundary is not searched)."""
    bounds = object_bounds(obj_i, obj_f)
    ids = np.arange(len(obj_i)) if ids is None else np.asarray(ids, dtype=np.int64)
    return _build(bounds, ids.astype(np.int64).copy())


@njit(cache=True)
def _area(lx, ly, lz, hx, hy, hz):
    ex, ey, ez = max(hx - lx, 0.0), max(hy - ly, 0.0), max(hz - lz, 0.0)
    return 2.0 * (ex * ey + ey * ez + ez * ex)


@njit(cache=True)
def _bins(bounds, centroids, ids, start, end, lo_c, extent, bin_of, count, blo, bhi):
    """Each object's bin on every axis of non-zero extent (bin_of[axis, j -
    start]), and the bins' counts and boxes (count, blo, bhi [axis, bin]): one
    pass over the objects for the three axes."""
    count[:] = 0
    blo[:] = np.inf
    bhi[:] = -np.inf
    for j in range(start, end):
        k = ids[j]
        for axis in range(3):
            if extent[axis] <= 0.0:
                continue
            i = min(int((centroids[k, axis] - lo_c[axis]) / extent[axis] * BINS), BINS - 1)
            bin_of[axis, j - start] = i
            count[axis, i] += 1
            for c in range(3):
                blo[axis, i, c] = min(blo[axis, i, c], bounds[k, c])
                bhi[axis, i, c] = max(bhi[axis, i, c], bounds[k, 3 + c])


@njit(cache=True)
def _costs(count, blo, bhi, parent, cost):
    """cost[s]: the SAH cost of splitting after bin s, s < BINS - 1 (a row of
    the arrays _bins fills)."""
    lx, ly, lz, hx, hy, hz = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
    left_n = 0
    for s in range(BINS - 1):           # the left side's area, kept in cost
        lx, ly, lz = min(lx, blo[s, 0]), min(ly, blo[s, 1]), min(lz, blo[s, 2])
        hx, hy, hz = max(hx, bhi[s, 0]), max(hy, bhi[s, 1]), max(hz, bhi[s, 2])
        cost[s] = _area(lx, ly, lz, hx, hy, hz)
    total = 0
    for s in range(BINS):
        total += count[s]
    lx, ly, lz, hx, hy, hz = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
    right_n = 0
    for s in range(BINS - 1, 0, -1):
        lx, ly, lz = min(lx, blo[s, 0]), min(ly, blo[s, 1]), min(lz, blo[s, 2])
        hx, hy, hz = max(hx, bhi[s, 0]), max(hy, bhi[s, 1]), max(hz, bhi[s, 2])
        right_a = _area(lx, ly, lz, hx, hy, hz)
        right_n += count[s]
        i = s - 1
        left_n = total - right_n
        if left_n == 0 or right_n == 0:
            cost[i] = np.inf
        else:
            cost[i] = TRAVERSAL_COST + (left_n * cost[i] + right_n * right_a) / parent


@njit(cache=True)
def _split(bounds, centroids, ids, start, end, goes_left, box, bin_of, count, blo, bhi,
           cost, c3):
    """Fill goes_left[:n] for the cheapest binned split of ids[start:end];
    False if a leaf is cheaper.  box: the objects' bounds (lo, hi), already
    made; the other arrays are scratch space."""
    n = end - start
    lo_c, hi_c, extent = c3[0], c3[1], c3[2]
    lo_c[:], hi_c[:] = np.inf, -np.inf
    for j in range(start, end):
        k = ids[j]
        for c in range(3):
            lo_c[c], hi_c[c] = min(lo_c[c], centroids[k, c]), max(hi_c[c], centroids[k, c])
    parent = _area(box[0], box[1], box[2], box[3], box[4], box[5])
    for c in range(3):
        extent[c] = hi_c[c] - lo_c[c]
    _bins(bounds, centroids, ids, start, end, lo_c, extent, bin_of, count, blo, bhi)
    best = n * 1.0                     # a leaf's cost, in object tests
    found = False
    for axis in range(3):
        if extent[axis] <= 0.0:
            continue
        _costs(count[axis], blo[axis], bhi[axis], parent, cost)
        s = np.argmin(cost)
        if cost[s] < best:
            best, found = cost[s], True
            for j in range(n):
                goes_left[j] = bin_of[axis, j] < s + 1
    return found


@njit(cache=True)
def _median_split(centroids, ids, start, end, goes_left):
    """The first half, by centroid on the longest centroid axis (stable), goes left."""
    n = end - start
    spread = np.empty(3)
    for c in range(3):
        lo, hi = np.inf, -np.inf
        for j in range(start, end):
            lo, hi = min(lo, centroids[ids[j], c]), max(hi, centroids[ids[j], c])
        spread[c] = hi - lo
    axis = np.argmax(spread)
    keys = np.empty(n)
    for j in range(n):
        keys[j] = centroids[ids[start + j], axis]
    order = np.argsort(keys, kind="mergesort")
    goes_left[:n] = False
    for j in range(n // 2):
        goes_left[order[j]] = True


@njit(cache=True)
def _build(bounds, ids):
    n = ids.shape[0]
    centroids = 0.5 * (bounds[:, :3] + bounds[:, 3:])
    box = np.empty((max(2 * n - 1, 1), 6))
    node = np.zeros((max(2 * n - 1, 1), 3), dtype=np.int64)
    right = np.full(max(2 * n - 1, 1), -1, dtype=np.int64)
    prims = np.empty(n, dtype=np.int64)
    goes_left = np.empty(n, dtype=np.bool_)
    scratch = np.empty(n, dtype=np.int64)
    # _split's scratch space, made once: allocating it per node took most of
    # the build's time (a million triangles make two million nodes).
    bin_of = np.empty((3, n), dtype=np.int64)
    count_b = np.empty((3, BINS), dtype=np.int64)
    blo, bhi = np.empty((3, BINS, 3)), np.empty((3, BINS, 3))
    cost = np.empty(BINS - 1)
    c3 = np.empty((3, 3))
    # Depth first, left first: a stack of (start, end, the parent waiting for
    # this node's number as its right child; -1 for a left child or the root).
    stack = np.empty((n + 1, 4), dtype=np.int64)
    stack[0] = (0, n, -1, 0)
    top, count, placed = 1, 0, 0
    while top > 0:
        top -= 1
        start, end, parent, depth = stack[top]
        i = count
        count += 1
        if parent >= 0:
            right[parent] = i
        lx, ly, lz, hx, hy, hz = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
        for j in range(start, end):
            k = ids[j]
            lx, ly, lz = min(lx, bounds[k, 0]), min(ly, bounds[k, 1]), min(lz, bounds[k, 2])
            hx, hy, hz = max(hx, bounds[k, 3]), max(hy, bounds[k, 4]), max(hz, bounds[k, 5])
        box[i, 0], box[i, 1], box[i, 2], box[i, 3], box[i, 4], box[i, 5] = lx, ly, lz, hx, hy, hz
        m = end - start
        split = m > 1 and depth < MEDIAN_FROM_DEPTH and _split(
            bounds, centroids, ids, start, end, goes_left, box[i], bin_of, count_b, blo, bhi,
            cost, c3)
        if not split and m > LEAF_SIZE:
            _median_split(centroids, ids, start, end, goes_left)
            split = True
        if not split:
            node[i, 0], node[i, 1] = placed, m
            prims[placed:placed + m] = ids[start:end]
            placed += m
            continue
        # Stable partition: the left ones, then the right ones, each in order.
        a, b = start, 0
        for j in range(m):
            if goes_left[j]:
                ids[a] = ids[start + j]
                a += 1
            else:
                scratch[b] = ids[start + j]
                b += 1
        ids[a:end] = scratch[:b]
        stack[top] = (a, end, i, depth + 1)         # the right child, after the left subtree
        stack[top + 1] = (start, a, -1, depth + 1)  # the left child: next
        top += 2
    # A node's miss link is the node after its subtree: sizes, children first.
    # An inner node's first column is its right child (its left is the next node).
    size = np.ones(count, dtype=np.int64)
    for i in range(count - 1, -1, -1):
        if node[i, 1] == 0:
            size[i] = 1 + size[i + 1] + size[right[i]]
            node[i, 0] = right[i]
        node[i, 2] = i + size[i]
    return box[:count].copy(), node[:count].copy(), prims[:placed].copy()
