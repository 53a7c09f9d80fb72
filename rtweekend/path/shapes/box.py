"""The oriented box: an axis-aligned box in its own frame, turned by any
rotation and moved by translate, tested as one slab test in that frame.

Row of obj_f: the box's own corners LO (0:3) and HI (3:6); its rotation, the
box-to-world 3x3 matrix M, with M[0][0] in COS (6) and M[0][2] in SIN (7) -- for
a turn about y alone, its cosine and sine -- and the rest in M01 .. M22
(12:19); OFFSET (8:11), its translate; FLIP (11): 1 when flip_face turned its
normals inward, else 0; OFF_Y (19): 1 when the rotation is not about y alone.
World to box frame: q = p - offset, then M's transpose applied to q.  A face's
area is the product of two sides (hi - lo), computed where a light needs it
rather than stored, so that the row fits OBJ_FLOATS -- by one function
(_face_area), which the light table's packing runs as Python.

A box turned about y alone (the books' rotate_y, every bundled scene's) is
turned by its cosine and sine in the columns the slab test has always read
(the full product was measurably slower: benchmarks/results/measurements.md);
any other rotation by the full matrix.

A ray leaving the box outward never meets it again (it is convex); one that went
inside meets it next where it leaves it, at the slab test's far distance: so no
epsilon is needed.  The normal at a hit is the one of the face p lies on.  As a
light it is sampled uniformly over its surface.
"""
import math

import numpy as np

from ...kernel.jit import jit_step, like

INF = math.inf
LO = 0
HI = 3
COS = M00 = 6
SIN = M02 = 7
OFFSET = 8
FLIP = 11
M01, M10, M11, M12, M20, M21, M22 = range(12, 19)
OFF_Y = 19
FLOATS = 20
# The matrix's columns in obj_f, row by row.
MATRIX = (M00, M01, M02, M10, M11, M12, M20, M21, M22)


def pack(lo, hi, rot, offset, flipped, row):
    """Fill a row with the box lo..hi (its own frame), turned by the 3x3 matrix
    rot and moved by offset."""
    row[LO:LO + 3] = np.asarray(lo, dtype=np.float64)
    row[HI:HI + 3] = np.asarray(hi, dtype=np.float64)
    row[list(MATRIX)] = np.asarray(rot, dtype=np.float64).reshape(9)
    row[OFFSET:OFFSET + 3] = offset
    row[FLIP] = 1.0 if flipped else 0.0
    about_y = (row[M01] == 0.0 and row[M10] == 0.0 and row[M11] == 1.0 and row[M12] == 0.0
               and row[M21] == 0.0)
    row[OFF_Y] = 0.0 if about_y else 1.0


def to_world(row, p):
    """A point of the box's frame in the world (NumPy; for bounds and tests),
    summed in the kernel's order."""
    m = row[list(MATRIX)]
    return np.array([m[3 * i] * p[0] + m[3 * i + 1] * p[1] + m[3 * i + 2] * p[2]
                     for i in range(3)]) + row[OFFSET:OFFSET + 3]


def bounds(row):
    lo, hi = row[LO:LO + 3], row[HI:HI + 3]
    corners = np.array([to_world(row, (x, y, z)) for x in (lo[0], hi[0])
                        for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    return corners.min(axis=0), corners.max(axis=0)


def light_parts(row):
    """[(face, area)] of the box as a light (lights.pack_lights): each of its six
    faces a part (sample_area draws on one face).  The areas are _face_area's,
    run by Python: the one place a face's area is written."""
    return [(face, _face_area.py_func(row[None], 0, face // 2)) for face in range(6)]


@jit_step
def _turned_back(obj_f, k, v):
    """v by the rotation's transpose: a world direction in the box's frame."""
    return (obj_f[k, M00] * v[0] + obj_f[k, M10] * v[1] + obj_f[k, M20] * v[2],
            obj_f[k, M01] * v[0] + obj_f[k, M11] * v[1] + obj_f[k, M21] * v[2],
            obj_f[k, M02] * v[0] + obj_f[k, M12] * v[1] + obj_f[k, M22] * v[2])


@jit_step
def _to_local(obj_f, k, p, d):
    """The point p and the direction d in the box's frame (one test of the
    rotation's kind for both: this is the slab test's way in)."""
    q = (p[0] - obj_f[k, OFFSET], p[1] - obj_f[k, OFFSET + 1], p[2] - obj_f[k, OFFSET + 2])
    if obj_f[k, OFF_Y] == 0.0:
        c, s = obj_f[k, COS], obj_f[k, SIN]
        return ((c * q[0] - s * q[2], q[1], s * q[0] + c * q[2]),
                (c * d[0] - s * d[2], d[1], s * d[0] + c * d[2]))
    return _turned_back(obj_f, k, q), _turned_back(obj_f, k, d)


@jit_step
def _local_direction(obj_f, k, d):
    return _to_local(obj_f, k, (0.0, 0.0, 0.0), d)[1]


@jit_step
def _local_point(obj_f, k, p):
    return _to_local(obj_f, k, p, (0.0, 0.0, 0.0))[0]


@jit_step
def _world_direction(obj_f, k, v):
    if obj_f[k, OFF_Y] == 0.0:
        c, s = obj_f[k, COS], obj_f[k, SIN]
        return (c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2])
    return (obj_f[k, M00] * v[0] + obj_f[k, M01] * v[1] + obj_f[k, M02] * v[2],
            obj_f[k, M10] * v[0] + obj_f[k, M11] * v[1] + obj_f[k, M12] * v[2],
            obj_f[k, M20] * v[0] + obj_f[k, M21] * v[1] + obj_f[k, M22] * v[2])


@jit_step
def _face_area(obj_f, k, axis):
    """The area of one face normal to axis 0, 1 or 2: the product of the other two
    sides (also run as plain Python on a NumPy row: light_parts)."""
    a, b = (1, 2) if axis == 0 else (0, 2) if axis == 1 else (0, 1)
    return (obj_f[k, HI + a] - obj_f[k, LO + a]) * (obj_f[k, HI + b] - obj_f[k, LO + b])


@jit_step
def _area(obj_f, k):
    """The box's surface area, summed as pack summed it before."""
    return 2.0 * (_face_area(obj_f, k, 0) + _face_area(obj_f, k, 1) + _face_area(obj_f, k, 2))


@jit_step
def _slab(lo, hi, o, d):
    """(near, far) distances along d between the planes lo and hi of one axis:
    with d = 0 the division gives +-inf (error_model numpy), so a line between
    the planes is inside for all t and one outside for none (nan: the line lies
    on a plane, which min/max below leave to the other axes)."""
    inv = like(d, 1.0) / d
    t0 = (lo - o) * inv
    t1 = (hi - o) * inv
    return min(t0, t1), max(t0, t1)


@jit_step
def slabs(obj_f, k, o, d):
    """(near, far) distances along d where the line o + t d is inside the box
    (near > far: it misses).  In the precision of o and d."""
    lo, ld = _to_local(obj_f, k, o, d)
    n0, f0 = _slab(obj_f[k, LO], obj_f[k, HI], lo[0], ld[0])
    n1, f1 = _slab(obj_f[k, LO + 1], obj_f[k, HI + 1], lo[1], ld[1])
    n2, f2 = _slab(obj_f[k, LO + 2], obj_f[k, HI + 2], lo[2], ld[2])
    return max(n0, n1, n2), min(f0, f1, f2)


@jit_step
def slab_axes(obj_f, k, o, d):
    """slabs, with the axis of the face where the line enters and where it
    leaves (for the light pdf's cosines)."""
    lo, ld = _to_local(obj_f, k, o, d)
    n0, f0 = _slab(obj_f[k, LO], obj_f[k, HI], lo[0], ld[0])
    n1, f1 = _slab(obj_f[k, LO + 1], obj_f[k, HI + 1], lo[1], ld[1])
    n2, f2 = _slab(obj_f[k, LO + 2], obj_f[k, HI + 2], lo[2], ld[2])
    near, near_axis = (n0, 0) if n0 >= n1 and n0 >= n2 else (n1, 1) if n1 >= n2 else (n2, 2)
    far, far_axis = (f0, 0) if f0 <= f1 and f0 <= f2 else (f1, 1) if f1 <= f2 else (f2, 2)
    return near, far, near_axis, far_axis


@jit_step
def distance(obj_f, k, o, d, t_max, from_self, from_inside):
    """Distance to the box along d: where the ray enters it, or leaves it if it
    starts inside; a ray leaving it outward never meets it again."""
    if from_self and not from_inside:
        return like(t_max, INF)
    near, far = slabs(obj_f, k, o, d)
    if near > far:
        return like(t_max, INF)
    if not from_self and 0.0 < near:
        return near if near < t_max else like(t_max, INF)
    if 0.0 < far < t_max:
        return far
    return like(t_max, INF)


@jit_step
def _face_normal(obj_f, k, p):
    """The box frame's unit normal (outward, before flip_face) of the face p is on."""
    lp = _local_point(obj_f, k, p)
    best = INF
    axis, sign = 0, 1.0
    for a in range(3):
        lo = abs(lp[a] - obj_f[k, LO + a])
        hi = abs(lp[a] - obj_f[k, HI + a])
        if lo < best:
            best, axis, sign = lo, a, -1.0
        if hi < best:
            best, axis, sign = hi, a, 1.0
    return (sign if axis == 0 else 0.0, sign if axis == 1 else 0.0,
            sign if axis == 2 else 0.0)


@jit_step
def uv(obj_f, k, p):
    """Texture coordinates on the face p is on: its fractions of the face's two
    edges, in the box's frame (x then y, or x then z, or y then z)."""
    lp = _local_point(obj_f, k, p)
    n = _face_normal(obj_f, k, p)
    a, b = (1, 2) if n[0] != 0.0 else (0, 2) if n[1] != 0.0 else (0, 1)
    return ((lp[a] - obj_f[k, LO + a]) / (obj_f[k, HI + a] - obj_f[k, LO + a]),
            (lp[b] - obj_f[k, LO + b]) / (obj_f[k, HI + b] - obj_f[k, LO + b]))


@jit_step
def interval(obj_f, k, o, d):
    """(t0, t1): where the line o + t d is inside the box (t0 > t1: never)."""
    return slabs(obj_f, k, o, d)


@jit_step
def outward_normal(obj_f, k, p):
    n = _world_direction(obj_f, k, _face_normal(obj_f, k, p))
    if obj_f[k, FLIP] != 0.0:
        return (-n[0], -n[1], -n[2])
    return n


@jit_step
def enters(obj_f, k, n, d):
    """Does a ray leaving the box along d, where its outward normal is n, go
    inside it?  (flip_face turned n inward)"""
    inward = d[0] * n[0] + d[1] * n[1] + d[2] * n[2] < 0.0
    return inward != (obj_f[k, FLIP] != 0.0)


@jit_step
def sample_toward(obj_f, k, p, u1, u2):
    """The unit direction from p to the box's surface point for the unit
    square's (u1, u2), uniform over its whole surface for a uniform point:
    u1 picks the axis of the face by area and is stretched back to [0, 1)
    within its share, the halves of u2 pick the side (so that a stratified
    point stays stratified over each face), and sample_area places it."""
    a_x, a_y = _face_area(obj_f, k, 0), _face_area(obj_f, k, 1)
    a_z = _face_area(obj_f, k, 2)
    s = u1 * (a_x + a_y + a_z)
    if s < a_x or a_y + a_z == 0.0:
        axis, v1 = 0, s / a_x
    elif s < a_x + a_y or a_z == 0.0:
        axis, v1 = 1, (s - a_x) / a_y
    else:
        axis, v1 = 2, (s - a_x - a_y) / a_z
    high = u2 >= 0.5
    v2 = 2.0 * u2 - 1.0 if high else 2.0 * u2
    q = sample_area(obj_f, k, 2 * axis + (1 if high else 0), min(v1, 1.0), v2)[0]
    dx, dy, dz = q[0] - p[0], q[1] - p[1], q[2] - p[2]
    inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    return (dx * inv, dy * inv, dz * inv)


@jit_step
def _face_coordinate(obj_f, k, a, axis, high, u1, u2):
    """Coordinate a, in the box's frame, of the point (u1, u2) of the face normal
    to `axis` on its high side or its low one."""
    lo, hi = obj_f[k, LO + a], obj_f[k, HI + a]
    if a == axis:
        return hi if high else lo
    u = u1 if a == (axis + 1) % 3 else u2
    return lo + u * (hi - lo)


@jit_step
def sample_area(obj_f, k, face, u1, u2):
    """(point, outward normal): a point uniform over face number `face` (2 x its
    normal's axis, + 1 for the high side), for the light layer's one row per
    face."""
    axis, high = face // 2, face % 2 == 1
    w = _world_direction(obj_f, k, (_face_coordinate(obj_f, k, 0, axis, high, u1, u2),
                                    _face_coordinate(obj_f, k, 1, axis, high, u1, u2),
                                    _face_coordinate(obj_f, k, 2, axis, high, u1, u2)))
    p = (w[0] + obj_f[k, OFFSET], w[1] + obj_f[k, OFFSET + 1], w[2] + obj_f[k, OFFSET + 2])
    sign = 1.0 if high else -1.0
    if obj_f[k, FLIP] != 0.0:
        sign = -sign
    n = _world_direction(obj_f, k, (sign if axis == 0 else 0.0, sign if axis == 1 else 0.0,
                                    sign if axis == 2 else 0.0))
    return p, n


@jit_step
def pdf_toward(obj_f, k, p, d, from_self, from_inside):
    """Solid-angle density at p of direction d under sample_toward: the line
    from p along d meets the surface where it enters and where it leaves the
    box, and either point could have been drawn (the far one is hidden, but
    that is the integrator's business), so their densities add up."""
    if from_self and not from_inside:
        return 0.0                  # leaving it outward: it is never met again
    near, far, near_axis, far_axis = slab_axes(obj_f, k, p, d)
    if near > far or far <= 0.0:
        return 0.0
    ld = _local_direction(obj_f, k, d)
    total = far * far / abs(ld[far_axis])
    if near > 0.0 and not from_self:
        total += near * near / abs(ld[near_axis])
    return total / _area(obj_f, k)
