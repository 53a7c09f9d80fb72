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
import threading

import numba
import numpy as np

from ..kernel.jit import jit_host, jit_step
from ..kernel.rows import on_threads
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
# Subtrees are built on threads from this many objects (fewer: not worth one).
TASK_MIN = 4096


def object_bounds(obj_i, obj_f):
    """[N, 6] boxes around the objects (zero-thickness rects padded a hair)."""
    out = np.empty((len(obj_i), 6))
    tri = obj_i[:, OBJ_KIND] == TRIANGLE
    if tri.any():
        _triangle_bounds(obj_f, np.flatnonzero(tri), out)     # a mesh's, compiled
    others = np.flatnonzero(~tri)
    for k in others:
        out[k, :3], out[k, 3:] = shapes.bounds(obj_i[k, OBJ_KIND], obj_f[k])
    _pad_rows(out, others)
    return out


def _pad_rows(out, rows):
    """_pad each of rows, by NumPy (the same operations, so the same bits:
    tests/test_hittables.py): a scene without meshes compiles no bounds."""
    pad = 1e-9 * np.abs(out[rows]).max(axis=1, initial=1.0)
    out[rows, :3] -= pad[:, None]
    out[rows, 3:] += pad[:, None]


@jit_step(exact=True)
def _pad(out, k):
    """Widen box k by 1e-9 of its largest coordinate (at least 1e-9)."""
    big = 1.0
    for c in range(6):
        big = max(big, abs(out[k, c]))
    pad = 1e-9 * big
    for c in range(3):
        out[k, c] -= pad
        out[k, 3 + c] += pad


@jit_host
def _triangle_bounds(obj_f, rows, out):
    for k in rows:
        for c in range(3):
            a, b, d = obj_f[k, triangle.P0 + c], obj_f[k, triangle.P1 + c], \
                obj_f[k, triangle.P2 + c]
            out[k, c] = min(min(a, b), d)
            out[k, 3 + c] = max(max(a, b), d)
        _pad(out, k)


def _few_objects():
    """(obj_i, obj_f) of a few triangles and a sphere, typed as pack_scene's: a
    tree over them takes every compiled path of the build."""
    from .layout import OBJ_FLOATS, OBJ_INTS, SPHERE
    obj_i = np.zeros((9, OBJ_INTS), dtype=np.int64)
    obj_f = np.zeros((9, OBJ_FLOATS))
    obj_i[:8, OBJ_KIND], obj_i[8, OBJ_KIND] = TRIANGLE, SPHERE
    for k in range(8):
        obj_f[k, triangle.P0:triangle.P0 + 9] = np.arange(9.0) + 3.0 * k
    obj_f[8, 3] = 1.0            # the sphere's radius (shapes/sphere.py)
    return obj_i, obj_f


def compiled():
    """Is the builder compiled, in this process or in the cache (then loaded)?"""
    from ..kernel.disk_cache import loaded, signature
    _, obj_f = _few_objects()
    bounds = np.zeros((1, 6))
    ids, tasks = np.zeros(1, dtype=np.int64), np.zeros((1, 4), dtype=np.int64)
    grow = (bounds, bounds, ids, 0, 1, 0, bounds, tasks[:, :3].copy(), ids, 1, tasks)
    return (loaded(_triangle_bounds, signature((obj_f, ids, bounds)))
            and loaded(_grow, signature(grow)))


def build_bvh(obj_i, obj_f, ids=None):
    """(bvh_box [M, 6], bvh_node [M, 3] int64, bvh_prims [N] int64) over the
    objects `ids` (None: all; a constant medium's boundary is not searched)."""
    bounds = object_bounds(obj_i, obj_f)
    ids = np.arange(len(obj_i)) if ids is None else np.asarray(ids, dtype=np.int64)
    return _build(bounds, ids.astype(np.int64).copy())


@jit_step(exact=True)
def _area(lx, ly, lz, hx, hy, hz):
    ex, ey, ez = max(hx - lx, 0.0), max(hy - ly, 0.0), max(hz - lz, 0.0)
    return 2.0 * (ex * ey + ey * ez + ez * ex)


@jit_step(exact=True)
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


@jit_step(exact=True)
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


@jit_step(exact=True)
def _first_extreme(a, largest):
    """np.argmax(a) (largest) or np.argmin(a): the first index of the extreme
    value, or of the first NaN.  Written out: Numba's np.argmin and np.argmax
    live in numba.np.arraymath, which a cached builder would import at every
    start, and that module imports SciPy's BLAS when SciPy is installed
    (kernel/disk_cache.py, _load)."""
    best = 0
    for i in range(1, a.shape[0]):
        if a[best] != a[best]:
            break
        if a[i] != a[i] or (a[i] > a[best] if largest else a[i] < a[best]):
            best = i
    return best


@jit_step(exact=True)
def _split(bounds, centroids, ids, start, end, goes_left, box, bins, cost, c3):
    """Fill goes_left[:n] for the cheapest binned split of ids[start:end];
    False if a leaf is cheaper.  box: the objects' bounds (lo, hi), already
    made; bins = (bin_of, count, blo, bhi), cost and c3: scratch space."""
    bin_of, count, blo, bhi = bins
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
        s = _first_extreme(cost, False)
        if cost[s] < best:
            best, found = cost[s], True
            for j in range(n):
                goes_left[j] = bin_of[axis, j] < s + 1
    return found


@jit_host
def _median_split(centroids, ids, start, end, goes_left):
    """The first half, by centroid on the longest centroid axis (stable), goes left."""
    n = end - start
    spread = np.empty(3)
    for c in range(3):
        lo, hi = np.inf, -np.inf
        for j in range(start, end):
            lo, hi = min(lo, centroids[ids[j], c]), max(hi, centroids[ids[j], c])
        spread[c] = hi - lo
    axis = _first_extreme(spread, True)
    keys = np.empty(n)
    for j in range(n):
        keys[j] = centroids[ids[start + j], axis]
    order = _stable_order(keys)
    goes_left[:n] = False
    for j in range(n // 2):
        goes_left[order[j]] = True


@jit_host
def _stable_order(keys):
    """The order that sorts keys, equal keys in their order (NumPy's argsort
    with kind="mergesort"): a bottom-up merge sort, written out because
    Numba's took two seconds to compile."""
    n = keys.shape[0]
    order, other = np.arange(n), np.empty(n, dtype=np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid, hi = min(lo + width, n), min(lo + 2 * width, n)
            a, b = lo, mid
            for k in range(lo, hi):
                # The left run's element first unless the right one is smaller.
                if a < mid and (b >= hi or keys[order[a]] <= keys[order[b]]):
                    other[k] = order[a]
                    a += 1
                else:
                    other[k] = order[b]
                    b += 1
        order, other = other, order
        width *= 2
    return order


def _build(bounds, ids, task=None):
    """The tree over the objects ids (reordered in place), built in parallel:
    the nodes of more than `task` objects one by one, then the subtrees below
    them each on its own thread.  Every node is split as the one-by-one
    build splits it (its objects and depth decide), and the subtrees are put
    back in depth-first order, so the tree is the same, bit for bit, for any
    `task` and any number of threads."""
    n = ids.shape[0]
    threads = numba.get_num_threads()
    if task is None:
        task = max(n // (4 * threads), TASK_MIN)
    centroids = 0.5 * (bounds[:, :3] + bounds[:, 3:])
    # The top: nodes of more than `task` objects; the rest are tasks.  (Rows
    # made with np.empty take memory only where they are written.)
    rows = max(2 * n - 1, 1)
    tbox, tnode = np.empty((rows, 6)), np.empty((rows, 3), dtype=np.int64)
    tright = np.empty(rows, dtype=np.int64)
    tasks = np.empty((max(n, 1), 4), dtype=np.int64)
    top_rows, made = _grow(bounds, centroids, ids, 0, n, 0, tbox, tnode, tright, task, tasks)
    tasks = tasks[:made]
    # Each task's subtree into its own rows of sbox, snode, sright (at most
    # 2m - 1 for m objects), on our threads (kernel/rows.py; not a Numba
    # prange, whose parallel compile took seconds), each taking the next task
    # left: the threads share the work however unequal the tasks.
    first = np.concatenate([[0], np.cumsum(2 * (tasks[:, 1] - tasks[:, 0]) - 1)])
    rows = max(int(first[-1]), 1)
    sbox, snode = np.empty((rows, 6)), np.empty((rows, 3), dtype=np.int64)
    sright = np.empty(rows, dtype=np.int64)
    used = np.zeros(made, dtype=np.int64)
    queue = iter(range(made))
    lock = threading.Lock()
    none = tasks[:0]

    def subtrees(_):
        while True:
            with lock:
                t = next(queue, None)
            if t is None:
                return
            a, b = first[t], first[t + 1]
            used[t] = _grow(bounds, centroids, ids, tasks[t, 0], tasks[t, 1], tasks[t, 2],
                            sbox[a:b], snode[a:b], sright[a:b], 0, none)[0]
    on_threads(subtrees, np.arange(max(1, min(threads, made))), threads)
    return _assemble(tbox, tnode, tright, top_rows, tasks, first, sbox, snode, sright, used,
                     ids)


@jit_host
def _scratch(n):
    """_grow's working arrays for a subtree of n objects."""
    # Made once per subtree: allocating them per node took most of the
    # build's time (a million triangles make two million nodes).
    return (np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.int64),
            np.empty((3, max(n, 1)), dtype=np.int64), np.empty((3, BINS), dtype=np.int64),
            np.empty((3, BINS, 3)), np.empty((3, BINS, 3)), np.empty(BINS - 1),
            np.empty((3, 3)), np.empty((n + 1, 4), dtype=np.int64))


@jit_host(nogil=True)
def _grow(bounds, centroids, ids, start0, end0, depth0, box, node, right, task, tasks):
    """Build the subtree of ids[start0:end0] (at depth0) into rows 0, 1, ...
    of box, node, right, depth first, left first; a node below the root with
    at most `task` objects (task > 0) is left for later: its row is kept and
    (start, end, depth, row) appended to tasks.  Returns (rows, tasks made).
    Leaves' first object is their start: ids[start:end] ends in leaf order."""
    goes_left, scratch, bin_of, count_b, blo, bhi, cost, c3, stack = _scratch(end0 - start0)
    # Depth first, left first: a stack of (start, end, the parent waiting for
    # this node's number as its right child; -1 for a left child or the root).
    # (Rows written element by element: a row assigned at once compiled the
    # shape checks' error messages, seconds of string code.)
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = start0, end0, -1, depth0
    top, count, made = 1, 0, 0
    while top > 0:
        top -= 1
        start, end, parent, depth = stack[top]
        i = count
        count += 1
        right[i] = -1
        if parent >= 0:
            right[parent] = i
        m = end - start
        if task > 0 and i > 0 and m <= task:
            tasks[made, 0], tasks[made, 1], tasks[made, 2], tasks[made, 3] = start, end, depth, i
            made += 1
            continue
        lx, ly, lz, hx, hy, hz = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
        for j in range(start, end):
            k = ids[j]
            lx, ly, lz = min(lx, bounds[k, 0]), min(ly, bounds[k, 1]), min(lz, bounds[k, 2])
            hx, hy, hz = max(hx, bounds[k, 3]), max(hy, bounds[k, 4]), max(hz, bounds[k, 5])
        box[i, 0], box[i, 1], box[i, 2], box[i, 3], box[i, 4], box[i, 5] = lx, ly, lz, hx, hy, hz
        # goes_left, bin_of: indexed from start0 (this subtree's scratch).
        split = m > 1 and depth < MEDIAN_FROM_DEPTH and _split(
            bounds, centroids, ids, start, end, goes_left[start - start0:], box[i],
            (bin_of[:, start - start0:], count_b, blo, bhi), cost, c3)
        if not split and m > LEAF_SIZE:
            _median_split(centroids, ids, start, end, goes_left[start - start0:])
            split = True
        if not split:
            node[i, 0], node[i, 1] = start, m
            continue
        node[i, 1] = 0
        # Stable partition: the left ones, then the right ones, each in order.
        a, b = start, 0
        for j in range(m):
            if goes_left[start - start0 + j]:
                ids[a] = ids[start + j]
                a += 1
            else:
                scratch[b] = ids[start + j]
                b += 1
        for j in range(b):
            ids[a + j] = scratch[j]
        # The right child, after the left subtree; then the left child, next.
        stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = a, end, i, depth + 1
        stack[top + 1, 0], stack[top + 1, 1] = start, a
        stack[top + 1, 2], stack[top + 1, 3] = -1, depth + 1
        top += 2
    return count, made


@jit_step(exact=True)
def _copy_row(box, node, i, from_box, from_node, j):
    for c in range(6):
        box[i, c] = from_box[j, c]
    for c in range(3):
        node[i, c] = from_node[j, c]


@jit_host
def _assemble(tbox, tnode, tright, top_rows, tasks, first, sbox, snode, sright, used, ids):
    """The tree put together, depth first: each top row, a task's subtree where
    its row is; then the miss links."""
    made = tasks.shape[0]
    total = top_rows - made
    for t in range(made):
        total += used[t]
    box, node = np.empty((total, 6)), np.zeros((total, 3), dtype=np.int64)
    right = np.full(total, -1, dtype=np.int64)
    final = np.empty(top_rows, dtype=np.int64)      # a top row's final number
    task_of = np.full(top_rows, -1, dtype=np.int64)
    for t in range(made):
        task_of[tasks[t, 3]] = t
    at = 0
    for i in range(top_rows):
        final[i] = at
        t = task_of[i]
        if t < 0:
            _copy_row(box, node, at, tbox, tnode, i)
            at += 1
            continue
        for r in range(used[t]):
            _copy_row(box, node, at + r, sbox, snode, first[t] + r)
            if sright[first[t] + r] >= 0:
                right[at + r] = at + sright[first[t] + r]
        at += used[t]
    for i in range(top_rows):
        if task_of[i] < 0 and tright[i] >= 0:
            right[final[i]] = final[tright[i]]
    # A node's miss link is the node after its subtree: sizes, children first.
    # An inner node's first column is its right child (its left is the next node).
    size = np.ones(total, dtype=np.int64)
    for i in range(total - 1, -1, -1):
        if node[i, 1] == 0:
            size[i] = 1 + size[i + 1] + size[right[i]]
            node[i, 0] = right[i]
        node[i, 2] = i + size[i]
    return box, node, ids.copy()
