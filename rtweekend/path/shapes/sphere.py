"""The sphere: intersection, normal, bounds, and sampling it as a light.

Row of obj_f: CENTER (0:3), RADIUS (3, signed), RADIUS2 (4, its square).
The outward normal is (p - center) / radius, so a negative radius (book 1's
hollow bubble) or flip_face turns it inward.

Leaving a sphere, a ray can meet it again only at the far root, and only if it
went inside: `distance` knows which (no epsilon, exact at every scale).
As a light it is sampled uniformly in the cone it subtends from the shading
point (uniformly over all directions from on or inside it).
"""
import math

from ...kernel import rng
from ...kernel.jit import jit, jit_leaf, like
from ...kernel.vec3 import dot, local, onb, scale

INF = math.inf
INV_4PI = 1.0 / (4.0 * math.pi)
CENTER = 0
RADIUS = 3
RADIUS2 = 4
FLOATS = 5


def pack(center, radius, row):
    """Fill a row with a sphere placed in the world (radius < 0: inward normals)."""
    row[CENTER:CENTER + 3], row[RADIUS], row[RADIUS2] = center, radius, radius * radius


def bounds(row):
    r = abs(row[RADIUS])
    return row[CENTER:CENTER + 3] - r, row[CENTER:CENTER + 3] + r


@jit_leaf
def root(obj_f, k, o, d, t_max, far_only):
    """Nearest root in (0, t_max) of |o + t d - c| = |r| for unit d, else inf."""
    oc = (o[0] - obj_f[k, 0], o[1] - obj_f[k, 1], o[2] - obj_f[k, 2])
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


@jit_leaf
def distance(obj_f, k, o, d, t_max, from_self, from_inside):
    """Distance to the sphere along d, for a ray leaving object from_self?."""
    if from_self and not from_inside:
        return like(t_max, INF)     # leaving a convex surface outward
    return root(obj_f, k, o, d, t_max, from_self)


@jit_leaf
def outward_normal(obj_f, k, p):
    inv_r = 1.0 / obj_f[k, RADIUS]
    return ((p[0] - obj_f[k, 0]) * inv_r,
            (p[1] - obj_f[k, 1]) * inv_r,
            (p[2] - obj_f[k, 2]) * inv_r)


@jit_leaf
def enters(obj_f, k, n, d):
    """Does a ray leaving the sphere along d, where its outward normal is n, go
    into its ball?  (n = (p - c) / r: the radius's sign says which way it faces)"""
    return dot(d, n) * obj_f[k, RADIUS] < 0.0


@jit
def one_minus_cos_theta_max(r2, dist2):
    """1 - sqrt(1 - r^2/d^2), written so that it keeps its digits for small r/d."""
    x = r2 / dist2
    return x / (1.0 + math.sqrt(1.0 - x))


@jit_leaf
def sample_toward(obj_f, k, p, state):
    """A unit direction from p, uniform in the cone the sphere subtends."""
    w = (obj_f[k, 0] - p[0], obj_f[k, 1] - p[1], obj_f[k, 2] - p[2])
    dist2 = dot(w, w)
    r2 = obj_f[k, RADIUS2]
    if dist2 <= r2:
        # On or inside the sphere every direction hits it: uniform sphere.
        return rng.unit_vector(state)
    u1, state = rng.uniform(state)
    u2, state = rng.uniform(state)
    z = 1.0 - u2 * one_minus_cos_theta_max(r2, dist2)
    phi = rng.TWO_PI * u1
    s = math.sqrt(max(0.0, 1.0 - z * z))
    w = scale(w, 1.0 / math.sqrt(dist2))
    u, v = onb(w)
    return local(u, v, w, (math.cos(phi) * s, math.sin(phi) * s, z)), state


@jit_leaf
def pdf_toward(obj_f, k, p, d, from_self, from_inside):
    """Solid-angle density at p of direction d under sample_toward; 0 if d misses."""
    if not from_self:
        w = (obj_f[k, 0] - p[0], obj_f[k, 1] - p[1], obj_f[k, 2] - p[2])
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
    # Leaving this very sphere light: only inward, to its far side.
    if from_inside and root(obj_f, k, p, d, INF, True) != INF:
        return INV_4PI
    return 0.0
