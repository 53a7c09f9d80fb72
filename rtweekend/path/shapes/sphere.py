"""The sphere: intersection, normal, bounds, and sampling it as a light.

Row of obj_f: CENTER (0:3), RADIUS (3, signed), RADIUS2 (4, its square) and
VELOCITY (5:8): how far the centre moves over the shutter (motion blur; the
centre at time t is CENTER + t VELOCITY).  Every function that reads the centre
takes the ray's `time`: None in a kernel for a scene where nothing moves, which
Numba compiles without the motion (an `is None` test on an argument).
The outward normal is (p - center) / radius, so a negative radius (book 1's
hollow bubble) or flip_face turns it inward.

Leaving a sphere, a ray can meet it again only at the far root, and only if it
went inside: `distance` knows which (no epsilon, exact at every scale).
As a light it is sampled uniformly in the cone it subtends from the shading
point: from a point of its own surface (an attractor in the lights list that
scatters, such as a frosted glass ball) the inward hemisphere, every direction
of which meets its far side; uniformly over all directions from inside it.
"""
import math

import numpy as np

from ...kernel import rng
from ...kernel.jit import jit_step, like
from ...kernel.vec3 import dot, local, onb, scale

INF = math.inf
INV_4PI = 1.0 / (4.0 * math.pi)
INV_2PI = 1.0 / (2.0 * math.pi)
CENTER = 0
RADIUS = 3
RADIUS2 = 4
VELOCITY = 5
FLOATS = 8


def pack(center, radius, row, velocity=(0.0, 0.0, 0.0)):
    """Fill a row with a sphere placed in the world (radius < 0: inward normals),
    whose centre moves by `velocity` over the shutter."""
    row[CENTER:CENTER + 3], row[RADIUS], row[RADIUS2] = center, radius, radius * radius
    row[VELOCITY:VELOCITY + 3] = velocity


def bounds(row):
    """The box around the sphere's whole sweep (both ends: the sweep is convex)."""
    r = abs(row[RADIUS])
    c0 = row[CENTER:CENTER + 3]
    c1 = c0 + row[VELOCITY:VELOCITY + 3]
    return np.minimum(c0, c1) - r, np.maximum(c0, c1) + r


def light_parts(row):
    """[(part, area)] of the sphere as a light (lights.pack_lights): one part
    (NumPy; a point sample_area draws is dense by 1 / this area)."""
    return [(-1, 4.0 * math.pi * row[RADIUS2])]


@jit_step
def center(obj_f, k, time):
    """The centre at `time` (None: the sphere does not move)."""
    if time is None:
        return (obj_f[k, 0], obj_f[k, 1], obj_f[k, 2])
    return (obj_f[k, 0] + time * obj_f[k, VELOCITY], obj_f[k, 1] + time * obj_f[k, VELOCITY + 1],
            obj_f[k, 2] + time * obj_f[k, VELOCITY + 2])


@jit_step
def root(obj_f, k, o, d, t_max, far_only, time):
    """Nearest root in (0, t_max) of |o + t d - c| = |r| for unit d, else inf."""
    c = center(obj_f, k, time)
    oc = (o[0] - c[0], o[1] - c[1], o[2] - c[2])
    half_b = dot(oc, d)
    c = dot(oc, oc) - obj_f[k, RADIUS2]
    disc = half_b * half_b - c
    if disc < 0.0:
        return like(t_max, INF)
    sq = math.sqrt(disc)
    if not far_only:
        t = -half_b - sq
        if 0.0 < t < t_max:
            return t
    t = -half_b + sq
    if 0.0 < t < t_max:
        return t
    return like(t_max, INF)


@jit_step
def distance(obj_f, k, o, d, t_max, from_self, from_inside, time):
    """Distance to the sphere along d, for a ray leaving object from_self?."""
    if from_self and not from_inside:
        return like(t_max, INF)     # leaving a convex surface outward
    return root(obj_f, k, o, d, t_max, from_self, time)


@jit_step
def interval(obj_f, k, o, d, time):
    """(t0, t1): where the line o + t d is inside the ball (t0 > t1: never)."""
    c = center(obj_f, k, time)
    oc = (o[0] - c[0], o[1] - c[1], o[2] - c[2])
    half_b = dot(oc, d)
    disc = half_b * half_b - (dot(oc, oc) - obj_f[k, RADIUS2])
    if disc < 0.0:
        return INF, -INF
    sq = math.sqrt(disc)
    return -half_b - sq, -half_b + sq


@jit_step
def outward_normal(obj_f, k, p, time):
    inv_r = 1.0 / obj_f[k, RADIUS]
    c = center(obj_f, k, time)
    return ((p[0] - c[0]) * inv_r,
            (p[1] - c[1]) * inv_r,
            (p[2] - c[2]) * inv_r)


@jit_step
def uv(obj_f, k, p, time):
    """The book's (u, v) on the sphere: u = angle about y from -x, over 2 pi;
    v = angle from -y, over pi (of the point's direction from the centre)."""
    c = center(obj_f, k, time)
    inv_r = 1.0 / abs(obj_f[k, RADIUS])
    x, y, z = (p[0] - c[0]) * inv_r, (p[1] - c[1]) * inv_r, (p[2] - c[2]) * inv_r
    theta = math.acos(min(1.0, max(-1.0, -y)))
    phi = math.atan2(-z, x) + math.pi
    return phi / rng.TWO_PI, theta / math.pi


@jit_step
def enters(obj_f, k, n, d):
    """Does a ray leaving the sphere along d, where its outward normal is n, go
    into its ball?  (n = (p - c) / r: the radius's sign says which way it faces)"""
    return dot(d, n) * obj_f[k, RADIUS] < 0.0


@jit_step
def one_minus_cos_theta_max(r2, dist2):
    """1 - sqrt(1 - r^2/d^2), written so that it keeps its digits for small r/d."""
    x = r2 / dist2
    return x / (1.0 + math.sqrt(1.0 - x))


@jit_step
def sample_toward(obj_f, k, p, from_self, u1, u2, time):
    """The unit direction from p for the unit square's point (u1, u2), uniform
    in the cone the sphere subtends for a uniform point; from a point of its
    own surface (from_self: rounding puts p either side of it), in the inward
    hemisphere, as pdf_toward says.  (The sphere's own override of sampling a
    light by its area: the cone wastes no direction on its hidden side.)"""
    c = center(obj_f, k, time)
    w = (c[0] - p[0], c[1] - p[1], c[2] - p[2])
    dist2 = dot(w, w)
    r2 = obj_f[k, RADIUS2]
    if dist2 <= r2 and not from_self:
        # Inside the sphere every direction hits it: uniform sphere.
        return rng.sphere_point(u1, u2)
    # On it: the cone is the inward hemisphere (cos theta_max = 0).
    z = 1.0 - u2 * (1.0 if from_self else one_minus_cos_theta_max(r2, dist2))
    phi = rng.TWO_PI * u1
    s = math.sqrt(max(0.0, 1.0 - z * z))
    w = scale(w, 1.0 / math.sqrt(dist2))
    u, v = onb(w)
    return local(u, v, w, (math.cos(phi) * s, math.sin(phi) * s, z))


@jit_step
def sample_area(obj_f, k, u1, u2, time):
    """(point, outward normal): a point uniform over the sphere's surface, for
    the unit square's point (u1, u2)."""
    z = 1.0 - 2.0 * u1
    s = math.sqrt(max(0.0, 1.0 - z * z))
    phi = rng.TWO_PI * u2
    w = (s * math.cos(phi), s * math.sin(phi), z)
    c = center(obj_f, k, time)
    r = obj_f[k, RADIUS]
    # p = c + |r| w; the outward normal (p - c) / r turns inward for r < 0.
    p = (c[0] + abs(r) * w[0], c[1] + abs(r) * w[1], c[2] + abs(r) * w[2])
    n = w if r > 0.0 else (-w[0], -w[1], -w[2])
    return p, n


@jit_step
def pdf_toward(obj_f, k, p, d, from_self, from_inside, time):
    """Solid-angle density at p of direction d under sample_toward; 0 if d misses."""
    if not from_self:
        c = center(obj_f, k, time)
        w = (c[0] - p[0], c[1] - p[1], c[2] - p[2])
        dist2 = dot(w, w)
        r2 = obj_f[k, RADIUS2]
        if dist2 <= r2:
            return INV_4PI      # from inside every direction hits it
        # From outside, d hits the sphere iff it lies in the cone of half-angle
        # theta_max about w: d.w >= |w| cos(theta_max) = sqrt(dist2 - r2), i.e.
        # the quadratic's discriminant test, without solving it.
        b = dot(d, w)
        if b <= 0.0 or b * b < dist2 - r2:
            return 0.0
        return 1.0 / (rng.TWO_PI * one_minus_cos_theta_max(r2, dist2))
    # Leaving this very sphere: only inward, to its far side, as sample_toward
    # draws from a point of its surface.
    if from_inside and root(obj_f, k, p, d, INF, True, time) != INF:
        return INV_2PI
    return 0.0
