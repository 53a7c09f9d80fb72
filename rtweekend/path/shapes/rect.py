"""The rectangle: any parallelogram, placed in the world.

The books' xy/xz/yz rects when turned, and The Next Week v4's quads
(corner Q, edges u and v, not necessarily perpendicular), with their rotation +
translate already applied.

Row of obj_f: corner Q (0:3), edges U (3:6) and V (6:9), unit normal N (9:12),
plane offset PLANE = N.Q (12), the dual edges U_DUAL (13:16) and V_DUAL
(16:19) that give a hit's (alpha, beta) on the edges, p - Q = alpha u + beta v,
as dot products (u/|u|^2 and v/|v|^2 when the edges are perpendicular), AREA (19).
(alpha, beta) is also its texture coordinate (u, v).
Its outward normal is unit(u x v); flip_face swaps u and v.

A plane is never hit again by a ray leaving it, so `distance` needs no epsilon.
As a light it is sampled uniformly in area.
"""
import math

import numpy as np

from ...kernel.jit import jit_step, like
from ...kernel.vec3 import dot, madd

INF = math.inf
Q = 0
U = 3
V = 6
N = 9
PLANE = 12
U_DUAL = 13
V_DUAL = 16
AREA = 19
FLOATS = 20


def axis_frame(kind, g):
    """(corner Q, edge u, edge v) of a book rect, with u x v along its +axis normal."""
    if kind == "xy_rect":
        x0, x1, y0, y1, k = g
        return (x0, y0, k), (x1 - x0, 0.0, 0.0), (0.0, y1 - y0, 0.0)
    if kind == "xz_rect":
        x0, x1, z0, z1, k = g
        return (x0, k, z0), (0.0, 0.0, z1 - z0), (x1 - x0, 0.0, 0.0)
    if kind == "yz_rect":
        y0, y1, z0, z1, k = g
        return (k, y0, z0), (0.0, y1 - y0, 0.0), (0.0, 0.0, z1 - z0)
    raise ValueError(f"axis_frame: {kind} is not an axis-aligned rect")


def pack(q, u, v, row):
    """Fill a row with the rect of corner q and perpendicular edges u, v."""
    q, u, v = (np.asarray(a, dtype=np.float64) for a in (q, u, v))
    n = np.cross(u, v)
    area = float(np.linalg.norm(n))
    n = n / area
    row[Q:Q + 3], row[U:U + 3], row[V:V + 3], row[N:N + 3] = q, u, v, n
    row[PLANE], row[AREA] = n @ q, area
    if u @ v == 0.0:
        row[U_DUAL:U_DUAL + 3], row[V_DUAL:V_DUAL + 3] = u / (u @ u), v / (v @ v)
    else:
        # alpha = (p - Q).(v x w), beta = (p - Q).(w x u), w = (u x v) / |u x v|^2
        w = n / area
        row[U_DUAL:U_DUAL + 3], row[V_DUAL:V_DUAL + 3] = np.cross(v, w), np.cross(w, u)


def bounds(row):
    q, u, v = row[Q:Q + 3], row[U:U + 3], row[V:V + 3]
    corners = np.array([q, q + u, q + v, q + u + v])
    return corners.min(axis=0), corners.max(axis=0)


def light_parts(row):
    """[(part, area)] of the rect as a light (lights.pack_lights): one part."""
    return [(-1, row[AREA])]


@jit_step
def plane_hit(obj_f, k, o, d, t_max):
    """Distance along d to the rectangle, in (0, t_max), else inf.

    Inlined at Numba's level, so compiled with its caller's error model: the
    parallel ray is tested, not left to a division by zero.
    """
    n = (obj_f[k, N], obj_f[k, N + 1], obj_f[k, N + 2])
    denom = dot(n, d)
    if denom == 0.0:
        return like(t_max, INF)     # parallel to the plane
    t = (obj_f[k, PLANE] - dot(n, o)) / denom
    if not (0.0 < t < t_max):
        return like(t_max, INF)
    p = madd(o, d, t)
    q = (p[0] - obj_f[k, Q], p[1] - obj_f[k, Q + 1], p[2] - obj_f[k, Q + 2])
    alpha = q[0] * obj_f[k, U_DUAL] + q[1] * obj_f[k, U_DUAL + 1] + q[2] * obj_f[k, U_DUAL + 2]
    if alpha < 0.0 or alpha > 1.0:
        return like(t_max, INF)
    beta = q[0] * obj_f[k, V_DUAL] + q[1] * obj_f[k, V_DUAL + 1] + q[2] * obj_f[k, V_DUAL + 2]
    if beta < 0.0 or beta > 1.0:
        return like(t_max, INF)
    return t


@jit_step
def distance(obj_f, k, o, d, t_max, from_self, from_inside):
    """Distance to the rect along d; a ray leaving it never meets it again."""
    if from_self:
        return like(t_max, INF)
    return plane_hit(obj_f, k, o, d, t_max)


@jit_step
def outward_normal(obj_f, k, p):
    return (obj_f[k, N], obj_f[k, N + 1], obj_f[k, N + 2])


@jit_step
def uv(obj_f, k, p):
    """(alpha, beta) of p on the edges: its texture coordinates."""
    q = (p[0] - obj_f[k, Q], p[1] - obj_f[k, Q + 1], p[2] - obj_f[k, Q + 2])
    return (q[0] * obj_f[k, U_DUAL] + q[1] * obj_f[k, U_DUAL + 1] + q[2] * obj_f[k, U_DUAL + 2],
            q[0] * obj_f[k, V_DUAL] + q[1] * obj_f[k, V_DUAL + 1] + q[2] * obj_f[k, V_DUAL + 2])


@jit_step
def enters(obj_f, k, n, d):
    """A rect has no inside: a ray leaving it never goes into it."""
    return False


@jit_step
def sample_toward(obj_f, k, p, u1, u2):
    """The unit direction from p to the rect's point (u1, u2) of the unit
    square (uniform in its area for a uniform point)."""
    dx = obj_f[k, Q] + u1 * obj_f[k, U] + u2 * obj_f[k, V] - p[0]
    dy = obj_f[k, Q + 1] + u1 * obj_f[k, U + 1] + u2 * obj_f[k, V + 1] - p[1]
    dz = obj_f[k, Q + 2] + u1 * obj_f[k, U + 2] + u2 * obj_f[k, V + 2] - p[2]
    inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    return (dx * inv, dy * inv, dz * inv)


@jit_step
def sample_area(obj_f, k, u1, u2):
    """(point, outward normal): a point uniform over the rect."""
    p = (obj_f[k, Q] + u1 * obj_f[k, U] + u2 * obj_f[k, V],
         obj_f[k, Q + 1] + u1 * obj_f[k, U + 1] + u2 * obj_f[k, V + 1],
         obj_f[k, Q + 2] + u1 * obj_f[k, U + 2] + u2 * obj_f[k, V + 2])
    return p, (obj_f[k, N], obj_f[k, N + 1], obj_f[k, N + 2])


@jit_step
def pdf_toward(obj_f, k, p, d, from_self, from_inside):
    """Solid-angle density at p of direction d under sample_toward:
    distance^2 / (|cos| area) where d meets the rect, else 0."""
    if from_self:
        return 0.0                  # a rect is never hit from itself
    t = plane_hit(obj_f, k, p, d, INF)
    if t == INF:
        return 0.0
    n = (obj_f[k, N], obj_f[k, N + 1], obj_f[k, N + 2])
    cosine = abs(dot(n, d))
    return t * t / (cosine * obj_f[k, AREA])
