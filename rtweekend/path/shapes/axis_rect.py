"""The books' axis-aligned rects (xy_rect, xz_rect, yz_rect) when they are not
turned: tested on their own axis, a division and two interval checks.

Each function takes the axes as constants from the dispatch: n, the axis of the
normal (z for an xy_rect), and a, b, the two axes of the plane.  Row of obj_f:
the rect's extents A0, A1 (along a) and B0, B1 (along b), its plane n = K, SIGN
(+1: facing +n, as the book's rects do; -1: flip_face) and AREA.

A plane is never met again by a ray leaving it, so `distance` needs no epsilon.
As a light it is sampled uniformly in area.
"""
import math
import sys

import numpy as np

from ...kernel.jit import jit_step, like

INF = math.inf
# A light's density bounds the hit by the largest float, not by inf: LLVM
# compiles `t < inf` as a test of t's bits (more instructions than a compare),
# and the two differ at t = FARTHEST alone.
FARTHEST = sys.float_info.max
A0 = 0
A1 = 1
B0 = 2
B1 = 3
K = 4
SIGN = 5
AREA = 6
FLOATS = 7
# (a, b, n) of each kind: the plane's two axes and the normal's.
XY = (0, 1, 2)
XZ = (0, 2, 1)
YZ = (1, 2, 0)
AXES = {"xy_rect": XY, "xz_rect": XZ, "yz_rect": YZ}


def pack(kind, geometry, offset, flipped, row):
    """Fill a row with a book rect (kind, its five numbers) moved by offset."""
    a, b, n = AXES[kind]
    lo_a, hi_a, lo_b, hi_b, k = geometry
    row[A0], row[A1] = lo_a + offset[a], hi_a + offset[a]
    row[B0], row[B1] = lo_b + offset[b], hi_b + offset[b]
    row[K] = k + offset[n]
    row[SIGN] = -1.0 if flipped else 1.0
    row[AREA] = (hi_a - lo_a) * (hi_b - lo_b)


def bounds(axes, row):
    """The rect's corners (lo, hi): axes = (a, b, n) of its kind."""
    a, b, n = axes
    lo, hi = [0.0] * 3, [0.0] * 3
    lo[a], hi[a], lo[b], hi[b] = row[A0], row[A1], row[B0], row[B1]
    lo[n] = hi[n] = row[K]
    return np.array(lo), np.array(hi)


def light_parts(row):
    """[(part, area)] of the rect as a light (lights.pack_lights): one part."""
    return [(-1, row[AREA])]


@jit_step
def plane_hit(obj_f, k, o, d, t_max, a, b, n):
    """Distance along d to the rect, in (0, t_max), else inf.  (d[n] = 0: the
    division gives inf or nan, which the interval test rejects.)

    A plane behind the ray ends the test at once.  In front of it, the
    bounds and t_max are tested without a branch, every test made and the
    answer chosen at the end (`&`, not `and`): whether a ray meets a wall
    within its bounds is a coin toss to the processor's branch predictor.
    Measured on cornell_glass (benchmarks/results/measurements.md): 6% more
    samples a second for `mixture`; with t's sign tested so too, `mixture`
    gained 2% and `nee` lost 1.5%.  The tests are those of the books' early
    returns (a NaN coordinate passes its bounds, as it did there)."""
    t = (obj_f[k, K] - o[n]) / d[n]
    if not 0.0 < t:
        return like(t_max, INF)
    x = o[a] + t * d[a]
    y = o[b] + t * d[b]
    within = ((not x < obj_f[k, A0]) & (not x > obj_f[k, A1])
              & (not y < obj_f[k, B0]) & (not y > obj_f[k, B1]))
    t = t if within else like(t_max, INF)
    # Apart from the bounds: in a search t_max is the last object's t, so this
    # test is the only one that waits for it.
    return t if t < t_max else like(t_max, INF)


@jit_step
def distance(obj_f, k, o, d, t_max, from_self, from_inside, a, b, n):
    if from_self:
        return like(t_max, INF)
    return plane_hit(obj_f, k, o, d, t_max, a, b, n)


@jit_step
def outward_normal(obj_f, k, p, n):
    s = obj_f[k, SIGN]
    return (s if n == 0 else 0.0, s if n == 1 else 0.0, s if n == 2 else 0.0)


@jit_step
def uv(obj_f, k, p, a, b):
    """The book's texture coordinates: p's fractions of the two extents."""
    return ((p[a] - obj_f[k, A0]) / (obj_f[k, A1] - obj_f[k, A0]),
            (p[b] - obj_f[k, B0]) / (obj_f[k, B1] - obj_f[k, B0]))


@jit_step
def enters(obj_f, k, n, d):
    return False


@jit_step
def sample_toward(obj_f, k, p, u1, u2, a, b, n):
    """The unit direction from p to the rect's point (u1, u2) of the unit
    square (uniform in its area for a uniform point)."""
    x = obj_f[k, A0] + u1 * (obj_f[k, A1] - obj_f[k, A0]) - p[a]
    y = obj_f[k, B0] + u2 * (obj_f[k, B1] - obj_f[k, B0]) - p[b]
    z = obj_f[k, K] - p[n]
    inv = 1.0 / math.sqrt(x * x + y * y + z * z)
    x, y, z = x * inv, y * inv, z * inv
    if n == 2:
        return (x, y, z)
    if n == 1:
        return (x, z, y)
    return (z, x, y)


@jit_step
def sample_area(obj_f, k, u1, u2, a, b, n):
    """(point, outward normal): a point uniform over the rect."""
    x = obj_f[k, A0] + u1 * (obj_f[k, A1] - obj_f[k, A0])
    y = obj_f[k, B0] + u2 * (obj_f[k, B1] - obj_f[k, B0])
    z = obj_f[k, K]
    normal = outward_normal(obj_f, k, (x, y, z), n)
    if n == 2:
        return (x, y, z), normal
    if n == 1:
        return (x, z, y), normal
    return (z, x, y), normal


@jit_step
def pdf_toward(obj_f, k, p, d, from_self, from_inside, a, b, n):
    """distance^2 / (|cos| area) where d meets the rect, else 0."""
    if from_self:
        return 0.0
    t = plane_hit(obj_f, k, p, d, FARTHEST, a, b, n)
    if t == INF:
        return 0.0
    return t * t / (abs(d[n]) * obj_f[k, AREA])
