"""The BVH of a scene with meshes: four children to a node, and the leaves'
triangles copied out in the order the walk reads them.

A binary BVH over a million triangles is ~40 levels of nodes; a ray visits
some 25 of them, one box test each, one after the other.  Collapsing the tree
(bvh_build.py's) into 4-wide nodes -- each node keeps its children's four
boxes side by side, so that their slab tests run as one vector operation
(kernel/simd.py) -- halves the levels (Wald, Benthin and Boulos 2008;
Embree's BVH4).  A ray's time goes to work, not to waiting for memory: rays
that find every node in the cache are no faster (measured), so what counts is
how few node visits and how little work each takes.  The triangles'
vertices, copied in leaf order into leaf_tri, sit next to each other instead
of one 160-byte obj_f row apart.

Collapse: a wide node starts with one binary node and opens, while it has
fewer than four children, its child of largest surface area that is not a
leaf (the SAH's measure of how often a ray enters it).  A subtree of at most
MERGE objects becomes one leaf: fewer nodes to visit for more triangle tests,
which come four at a time (MERGE chosen by rays per second on a large mesh:
benchmarks/results/measurements.md).
Nodes are numbered depth first.

    wide_box[w, r, c]  row r (min x, y, z, max x, y, z) of child c's box;
                       an unused child has the empty box (min inf, max -inf)
    wide_child[w, c]   >= 0: the wide node it is; < 0: a leaf, -1 - (block << 32 | count):
                       its count objects are lanes 0.. of blocks block, block + 1, ...
    leaf_prim[4 b + q] the object in lane q of block b: k for a triangle, -1 - k for
                       another kind (NO_HIT: no object)
    leaf_tri[b, r, q]  coordinate r of P0, P1, P2 (shapes/triangle.py's columns 0:9)
                       of lane q's triangle (NaN: not a triangle): the four of a
                       block side by side, tested at once (simd.watertight4)

A leaf holds at most MERGE objects (bvh_build.LEAF_SIZE is smaller): three
blocks at most.

A scene without a hierarchy (bvh=False, or few objects) has none of this: its
search tests every object (bvh.py).

Which hit is nearest depends neither on the tree nor on the order of the
walk (tests/test_hittables.py: the same objects and distances, bit for bit,
as the binary tree's walk), and a triangle's copied vertices give its test
the same bits as its obj_f row.
"""
import math

import numpy as np
from numba import literal_unroll

from ..kernel import simd
from ..kernel.disk_cache import loaded, signature
from ..kernel.jit import jit_host, jit_step, like
from ..kernel.stack import stack_array
from ..kernel.vec3 import reciprocal
from . import bvh_build, shapes
from .bvh_build import MEDIAN_FROM_DEPTH
from .layout import NO_HIT, NON_NEGATIVE, OBJ_FLOATS, OBJ_INTS, OBJ_KIND, TRIANGLE
from .shapes import triangle

INF = math.inf
WIDTH = 4
COUNT_BITS = 32
COUNT_MASK = (1 << COUNT_BITS) - 1
MERGE = 12
# The walk keeps at most WIDTH - 1 nodes per level; bvh_build's trees are no
# deeper than MEDIAN_FROM_DEPTH + 31 levels, and collapsing never deepens one.
STACK = (WIDTH - 1) * (MEDIAN_FROM_DEPTH + 32)


def wide_tables(obj_i, obj_f, bvh_box, bvh_node, bvh_prims, triangles=True):
    """(box, child, leaf_prim, leaf_tri) of layout.WideBVH for the binary tree
    (bvh_box, bvh_node, bvh_prims: bvh_build.build_bvh's, at least one node).
    triangles: the scene has some (else leaf_tri is empty: never read)."""
    wide_box, wide_child = _collapse(bvh_box, bvh_node, MERGE)
    blocks = _count_blocks(wide_child)
    leaf_prim = np.full(blocks * WIDTH, NO_HIT, dtype=np.int64)
    leaf_tri = np.full((blocks if triangles else 0, 9, WIDTH), np.nan)
    _blocks(obj_i, obj_f, bvh_prims, wide_child, leaf_prim, leaf_tri)
    return wide_box, wide_child, leaf_prim, leaf_tri


def _one_leaf():
    """(obj_i, obj_f, bvh_box, bvh_node, bvh_prims) of one object in one leaf,
    typed as pack_scene's."""
    return (np.zeros((1, OBJ_INTS), dtype=np.int64), np.zeros((1, OBJ_FLOATS)),
            np.zeros((1, 6)), np.array([[0, 1, 1]], dtype=np.int64),
            np.zeros(1, dtype=np.int64))


def empty():
    """A WideBVH of no nodes, typed as wide_tables' (the stand-in that types a
    render's kernels before its tree is built: pack.py)."""
    return (np.zeros((0, 6, WIDTH)), np.zeros((0, WIDTH), dtype=np.int64),
            np.zeros(0, dtype=np.int64), np.zeros((0, 9, WIDTH)))


def compile_ahead():
    """The builder's (bvh_build.py) and the 4-wide collapse's compiled
    functions, compiled (or loaded) for pack_scene's types: what a helper
    process compiles while the render's own process compiles its kernels
    (kernel/compile_workers.py compile_ahead; pack.py waits for it before
    building)."""
    obj_i, obj_f = bvh_build._few_objects()
    wide_tables(obj_i, obj_f, *bvh_build.build_bvh(obj_i, obj_f))


def compiled():
    """Are the builder and the collapse compiled, in this process or in the
    cache (then loaded)?"""
    _, _, box, node, _ = _one_leaf()
    return bvh_build.compiled() and loaded(_collapse, signature((box, node, MERGE)))


@jit_host
def _count_blocks(wide_child):
    blocks = 0
    for w in range(wide_child.shape[0]):
        for c in range(WIDTH):
            if wide_child[w, c] < 0:
                blocks += (((-1 - wide_child[w, c]) & COUNT_MASK) + WIDTH - 1) // WIDTH
    return blocks


@jit_host
def _blocks(obj_i, obj_f, prims, wide_child, leaf_prim, leaf_tri):
    """The leaves' objects into blocks, in the order of the nodes that hold
    them; each leaf's code turned from (first object, count) to (first
    block, count)."""
    b = 0
    for w in range(wide_child.shape[0]):
        for c in range(WIDTH):
            code = wide_child[w, c]
            if code >= 0:
                continue
            first, count = (-1 - code) >> COUNT_BITS, (-1 - code) & COUNT_MASK
            for j in range(count):
                k = prims[first + j]
                lane = b * WIDTH + j
                if obj_i[k, OBJ_KIND] == TRIANGLE:    # (then leaf_tri has its rows)
                    leaf_prim[lane] = k
                    for r in range(9):
                        leaf_tri[lane // WIDTH, r, lane % WIDTH] = obj_f[k, triangle.P0 + r]
                else:
                    leaf_prim[lane] = -1 - k
            wide_child[w, c] = -1 - ((b << COUNT_BITS) | count)
            b += (count + WIDTH - 1) // WIDTH


@jit_host
def _area(box, i):
    ex, ey, ez = box[i, 3] - box[i, 0], box[i, 4] - box[i, 1], box[i, 5] - box[i, 2]
    return ex * ey + ey * ez + ez * ex


@jit_host
def _collapse(box, node, merge):
    n = node.shape[0]
    # each binary node's objects: bvh_prims[first[i]:first[i] + size[i]]
    first = np.empty(n, dtype=np.int64)
    size = np.empty(n, dtype=np.int64)
    for i in range(n - 1, -1, -1):
        if node[i, 1] == 0:
            first[i] = first[i + 1]
            size[i] = size[i + 1] + size[node[i, 0]]
        else:
            first[i], size[i] = node[i, 0], node[i, 1]
    leaf = np.empty(n, dtype=np.bool_)
    for i in range(n):
        leaf[i] = node[i, 1] > 0 or size[i] <= merge
    # (Written element by element: NumPy's slice and row assignments cost
    # seconds of compile, their shape checks' error messages most of it.)
    wide_box = np.empty((n, 6, WIDTH))
    wide_child = np.zeros((n, WIDTH), dtype=np.int64)
    for i in range(n):
        for s in range(WIDTH):
            for r in range(3):
                wide_box[i, r, s] = np.inf
                wide_box[i, r + 3, s] = -np.inf
    members = np.empty(WIDTH, dtype=np.int64)
    # Depth first: (binary node, the wide node and slot waiting for its number).
    stack = np.empty((n + 1, 3), dtype=np.int64)
    stack[0, 0], stack[0, 1], stack[0, 2] = 0, -1, 0
    top, count = 1, 0
    while top > 0:
        top -= 1
        b, parent, slot = stack[top, 0], stack[top, 1], stack[top, 2]
        w = count
        count += 1
        if parent >= 0:
            wide_child[parent, slot] = w
        members[0] = b
        m = 1
        while m < WIDTH:
            widest, best = -1, -1.0
            for s in range(m):
                if not leaf[members[s]] and _area(box, members[s]) > best:
                    widest, best = s, _area(box, members[s])
            if widest < 0:
                break
            # its children take its place, in order (left, right)
            inner = members[widest]
            for s in range(m, widest + 1, -1):
                members[s] = members[s - 1]
            members[widest], members[widest + 1] = inner + 1, node[inner, 0]
            m += 1
        for s in range(m - 1, -1, -1):            # first child numbered next
            c = members[s]
            for r in range(6):
                wide_box[w, r, s] = box[c, r]
            if leaf[c]:
                wide_child[w, s] = -1 - ((first[c] << COUNT_BITS) | size[c])
            else:
                stack[top, 0], stack[top, 1], stack[top, 2] = c, w, s
                top += 1
    return wide_box[:count].copy(), wide_child[:count].copy()


@jit_step
def walk(scene, wide, tris, o, d, t_max, from_obj, from_inside, time, first_hit):
    """(object, t) of the nearest hit before t_max, or with first_hit of the
    first one met (a segment is blocked by any), or (NO_HIT, t_max): the walk
    goes to the nearest child whose box the ray enters and keeps the others,
    with where the ray enters them, on a stack; one entered only beyond a hit
    already found is never opened.  wide: scene.wide; tris: scene.tris, a
    direct argument so that a scene without meshes compiles no triangle test
    here."""
    wide_box, wide_child = wide.box, wide.child
    leaf_prim, leaf_tri = wide.leaf_prim, wide.leaf_tri
    best = np.int64(NO_HIT)     # typed int64, not the literal -1 (see integrators/path.py)
    inv_d = (reciprocal(d[0]), reciprocal(d[1]), reciprocal(d[2]))
    frame = (0, 0, 0, 0.0, 0.0, 0.0)
    if tris is not None:
        frame = triangle.ray_frame(d)   # the triangle test's, made once per ray
    rows = near_rows(inv_d)
    nodes = stack_array(STACK, np.int64)
    entries = stack_array(STACK, np.float64)
    hit_t = stack_array(WIDTH, np.float64)
    hit_c = stack_array(WIDTH, np.int64)
    top = 0
    node = np.int64(0)
    while True:
        if node >= 0:
            # The children whose boxes the ray enters before t_max, nearest
            # first: the nearest is opened next, the others kept.
            m = 0
            c = 0
            for t in literal_unroll(simd.slab4(wide_box, node, rows, o, inv_d, t_max)):
                if t < INF:
                    hit_t[m], hit_c[m] = t, wide_child[node, c]
                    m += 1
                c += 1
            if m == 1:
                node = hit_c[0]
                continue
            if m == 2:
                near = 0 if hit_t[0] <= hit_t[1] else 1
                nodes[top], entries[top] = hit_c[1 - near], hit_t[1 - near]
                top += 1
                node = hit_c[near]
                continue
            if m > 2:
                for i in range(1, m):           # insertion sort of 3 or 4
                    t, child, j = hit_t[i], hit_c[i], i
                    while j > 0 and hit_t[j - 1] > t:
                        hit_t[j], hit_c[j] = hit_t[j - 1], hit_c[j - 1]
                        j -= 1
                    hit_t[j], hit_c[j] = t, child
                for j in range(m - 1, 0, -1):  # the farthest below
                    nodes[top], entries[top] = hit_c[j], hit_t[j]
                    top += 1
                node = hit_c[0]
                continue
        else:
            # A leaf: its triangles four at a time, then in order, as one by
            # one (triangle.within); its other objects by their own test.
            leaf = -1 - node
            first, count = (leaf >> COUNT_BITS) * WIDTH, leaf & COUNT_MASK
            tests = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
            for j in range(first, first + count):
                k = leaf_prim[j]
                t = like(t_max, INF)
                if tris is not None:            # (a scene without meshes: none)
                    q = j % WIDTH
                    if q == 0:
                        tests = simd.watertight4(leaf_tri, j // WIDTH, o, frame)
                    if k >= 0 and k != from_obj and triangle.within(
                            tests[q], tests[WIDTH + q], t_max):
                        t = tests[WIDTH + q] * (1.0 / tests[q])
                if k < 0:
                    k = (-1 - k) & NON_NEGATIVE
                    t = shapes.distance(scene, k, o, d, t_max, from_obj, from_inside, time)
                if t < t_max:
                    t_max, best = t, k
                    if first_hit:
                        return best, t_max
        # The nearest kept node still worth opening, if any.
        while top > 0:
            top -= 1
            if entries[top] < t_max:
                node = nodes[top]
                break
        else:
            return best, t_max


@jit_step
def near_rows(inv_d):
    """The rows of wide_box (simd.slab4) with each axis's near plane -- min
    where the ray goes up that axis -- then its far one."""
    nx = np.int64(0) if inv_d[0] >= 0.0 else np.int64(3)
    ny = np.int64(1) if inv_d[1] >= 0.0 else np.int64(4)
    nz = np.int64(2) if inv_d[2] >= 0.0 else np.int64(5)
    return nx, ny, nz, 3 - nx, 5 - ny, 7 - nz


@jit_step
def solid_angle_sum(wide, obj_f, o, d, first, count, from_obj):
    """Over every triangle of objects first .. first + count - 1 that the ray
    o + t d (t > 0) meets, wherever, t^2 / |cos| (cos between d and its
    normal): times 1 / area, the solid-angle density at o of d under a point
    drawn uniformly on them (mesh_light.py).  from_obj is not met again."""
    wide_box, wide_child = wide.box, wide.child
    leaf_prim, leaf_tri = wide.leaf_prim, wide.leaf_tri
    inv_d = (reciprocal(d[0]), reciprocal(d[1]), reciprocal(d[2]))
    frame = triangle.ray_frame(d)
    rows = near_rows(inv_d)
    nodes = stack_array(STACK, np.int64)
    total = 0.0
    top = 1
    nodes[0] = 0
    while top > 0:
        top -= 1
        node = nodes[top]
        if node >= 0:
            c = 0
            for t in literal_unroll(simd.slab4(wide_box, node, rows, o, inv_d, INF)):
                if t < INF:
                    nodes[top] = wide_child[node, c]
                    top += 1
                c += 1
            continue
        leaf = -1 - node
        start = (leaf >> COUNT_BITS) * WIDTH
        tests = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        for j in range(start, start + (leaf & COUNT_MASK)):
            q = j % WIDTH
            if q == 0:
                tests = simd.watertight4(leaf_tri, j // WIDTH, o, frame)
            k = leaf_prim[j]
            if k < first or k >= first + count or k == from_obj:
                continue                    # another object (or not a triangle: < 0)
            if triangle.within(tests[q], tests[WIDTH + q], INF):
                t = tests[WIDTH + q] * (1.0 / tests[q])
                cosine = abs(d[0] * obj_f[k, triangle.N] + d[1] * obj_f[k, triangle.N + 1] +
                             d[2] * obj_f[k, triangle.N + 2])
                if cosine > 0.0:
                    total += t * t / cosine
    return total
