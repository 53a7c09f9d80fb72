"""kernel/simd.py: the four slab tests of a wide BVH node, and the watertight
test of four triangles, as vector code give the scalar tests' answers bit for
bit, edge cases (NaN from 0 x inf, rays along a face, empty boxes; rays
exactly through edges and vertices) included."""
import math

import numpy as np
from numba import njit

from rtweekend.kernel.simd import slab4, watertight4
from rtweekend.kernel.vec3 import reciprocal
from rtweekend.path.shapes import triangle
from rtweekend.path.wide_bvh import near_rows


@njit
def _vector(box, node, o, d, t_max):
    inv = (reciprocal(d[0]), reciprocal(d[1]), reciprocal(d[2]))
    return slab4(box, node, near_rows(inv), o, inv, t_max)


@njit
def _scalar(box, node, o, d, t_max):
    """The test as plain code, with Numba's max and min."""
    inv = (reciprocal(d[0]), reciprocal(d[1]), reciprocal(d[2]))
    nx, ny, nz, fx, fy, fz = near_rows(inv)
    out = np.empty(4)
    for c in range(4):
        t0 = max(max((box[node, nx, c] - o[0]) * inv[0], (box[node, ny, c] - o[1]) * inv[1]),
                 max((box[node, nz, c] - o[2]) * inv[2], 0.0))
        t1 = min(min((box[node, fx, c] - o[0]) * inv[0], (box[node, fy, c] - o[1]) * inv[1]),
                 (box[node, fz, c] - o[2]) * inv[2])
        out[c] = t0 if t0 <= t1 and t0 < t_max else math.inf
    return out


@njit
def _both(box, nodes, o, d, t_max):
    a = np.empty((nodes.shape[0], 4))
    b = np.empty((nodes.shape[0], 4))
    for i in range(nodes.shape[0]):
        oi, di = (o[i, 0], o[i, 1], o[i, 2]), (d[i, 0], d[i, 1], d[i, 2])
        a[i] = _scalar(box, nodes[i], oi, di, t_max[i])
        v = _vector(box, nodes[i], oi, di, t_max[i])
        b[i, 0], b[i, 1], b[i, 2], b[i, 3] = v
    return a, b


def test_four_slab_tests_at_once_are_the_scalar_ones_bit_for_bit():
    rng = np.random.default_rng(5)
    n_nodes = 64
    lo = rng.integers(-4, 4, (n_nodes, 3, 4)).astype(float)       # integer planes: rays
    box = np.concatenate([lo, lo + rng.integers(0, 3, (n_nodes, 3, 4))], axis=1)
    box[::7, :3, 3], box[::7, 3:, 3] = np.inf, -np.inf              # empty children
    n = 200_000
    o = rng.integers(-5, 5, (n, 3)).astype(float)                   # on planes, often
    o[n // 2:] += rng.random((n - n // 2, 3))
    nodes = rng.integers(0, n_nodes, n)
    # Most rays aimed at a child's centre, so that boxes are entered often.
    child = rng.integers(0, 4, n)
    with np.errstate(invalid="ignore"):                         # empty: inf - inf
        centre = 0.5 * (box[nodes, :3, child] + box[nodes, 3:, child])
    d = np.where(np.isfinite(centre), centre, 0.0) - o + 0.3 * rng.normal(size=(n, 3))
    axis = rng.integers(0, 3, n)
    d[np.arange(n) % 3 == 0, axis[np.arange(n) % 3 == 0]] = 0.0     # along faces: 0 x inf
    d[np.arange(n) % 5 == 0] = np.sign(d[np.arange(n) % 5 == 0])    # diagonals, axes
    d[np.arange(n) % 11 == 0, :] = (0.0, -0.0, 1.0)
    t_max = np.where(rng.random(n) < 0.5, np.inf, rng.random(n) * 4)
    a, b = _both(np.ascontiguousarray(box), nodes, o, d, t_max)
    assert np.isnan(a).sum() == 0
    entered = np.isfinite(a)
    assert 0.05 < entered.mean() < 0.9, entered.mean()       # measured 0.08
    assert np.array_equal(a.view(np.int64), b.view(np.int64))


@njit
def _triangles_both(tri4, rows, o, d, t_max):
    """Each ray against the 4 triangles of block i % blocks: (scalar t, vector t)."""
    n = o.shape[0]
    a = np.empty((n, 4))
    b = np.empty((n, 4))
    for i in range(n):
        oi, di = (o[i, 0], o[i, 1], o[i, 2]), (d[i, 0], d[i, 1], d[i, 2])
        block = i % tri4.shape[0]
        frame = triangle.ray_frame(di)
        tests = watertight4(tri4, block, oi, frame)
        for q in range(4):
            a[i, q] = triangle.hit_in_frame(rows, 4 * block + q, oi, frame, t_max[i])[0]
            b[i, q] = math.inf
            if triangle.within(tests[q], tests[4 + q], t_max[i]):
                b[i, q] = tests[4 + q] * (1.0 / tests[q])
    return a, b


def test_four_triangles_at_once_are_the_watertight_test_bit_for_bit():
    # Triangles on an integer lattice sharing edges and vertices, rays aimed
    # exactly at their vertices and edge midpoints (where the edge functions
    # are 0) and near them, some edge-on, some from behind, some with a
    # t_max that cuts them.
    rng = np.random.default_rng(9)
    n_tri = 256
    p = rng.integers(-3, 4, (n_tri, 3, 3)).astype(float)
    p[::5, 2] = p[::5, 0] + p[::5, 1] - p[::5, 0]             # some collapsed
    rows = np.zeros((n_tri, 9))
    rows[:, 0:9] = p.reshape(n_tri, 9)
    tri4 = np.ascontiguousarray(p.reshape(n_tri // 4, 4, 9).transpose(0, 2, 1))
    n = 200_000
    block = np.arange(n) % (n_tri // 4)
    lane = rng.integers(0, 4, n)
    corner = p[4 * block + lane]
    weights = rng.choice([0.0, 0.5, 1.0, 1 / 3], (n, 3))
    weights[:, 2] = np.where(rng.random(n) < 0.5, weights[:, 2], 1 - weights[:, 0] - weights[:, 1])
    target = (weights[:, :, None] * corner).sum(axis=1) + np.where(
        rng.random(n) < 0.3, 1e-12, 0.0)[:, None] * rng.normal(size=(n, 3))
    o = rng.integers(-6, 7, (n, 3)).astype(float)
    o += rng.random((n, 3)) * (rng.random(n) < 0.5)[:, None]
    d = target - o
    d[np.arange(n) % 13 == 0] *= -1.0                          # from behind
    keep = np.linalg.norm(d, axis=1) > 0
    o, d = o[keep], d[keep] / np.linalg.norm(d[keep], axis=1, keepdims=True)
    t_max = np.where(rng.random(len(o)) < 0.7, np.inf, rng.random(len(o)) * 8)
    a, b = _triangles_both(tri4, rows, o, d, t_max)
    assert 0.05 < np.isfinite(a).mean() < 0.95, np.isfinite(a).mean()
    assert np.array_equal(a.view(np.int64), b.view(np.int64))
