"""vec3 as a 3-tuple of floats: the books' vector algebra, allocation-free.

Tuples live in registers inside Numba kernels, so none of these allocate.
"""
import math

from .jit import jit_step, like


@jit_step
def reciprocal(x):
    """1/x, with 1/0 = inf of the same sign, under any error model (in x's
    precision): a ray's inverse direction, for slab tests."""
    return like(x, 1.0) / x if x != 0.0 else math.copysign(like(x, math.inf), x)


@jit_step
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@jit_step
def mul(a, b):
    """Componentwise: a colour times a colour."""
    return (a[0] * b[0], a[1] * b[1], a[2] * b[2])


@jit_step
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@jit_step
def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@jit_step
def at_most(a, m):
    """Componentwise min(a, m): a radiance capped (a light's albedo feature)."""
    return (min(a[0], m), min(a[1], m), min(a[2], m))


@jit_step
def madd(a, b, s):
    """a + s*b: a point moved along a direction."""
    return (a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2])


@jit_step
def neg(a):
    return (-a[0], -a[1], -a[2])


@jit_step
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit_step
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0])


@jit_step
def length(a):
    return math.sqrt(dot(a, a))


@jit_step
def unit(a):
    return scale(a, 1.0 / length(a))


@jit_step
def reflect(v, n):
    """Mirror v about the plane with unit normal n: v - 2(v.n)n."""
    return madd(v, n, -2.0 * dot(v, n))


@jit_step
def refract(uv, n, etai_over_etat):
    """Snell's law for a unit direction uv against the unit normal n facing it.

    The caller guarantees that refraction is possible (no total internal
    reflection); the max() guards the sqrt against rounding at grazing angles.
    """
    cos_theta = min(-dot(uv, n), 1.0)
    r_perp = scale(madd(uv, n, cos_theta), etai_over_etat)
    k = max(0.0, 1.0 - dot(r_perp, r_perp))
    return madd(r_perp, n, -math.sqrt(k))


@jit_step
def onb(w):
    """Two unit vectors (u, v) completing the unit vector w to a right-handed basis.

    Branch-light construction of Duff et al. (JCGT 2017), so no normalisation
    and no 'pick an axis' test.
    """
    sign = math.copysign(1.0, w[2])
    a = -1.0 / (sign + w[2])
    b = w[0] * w[1] * a
    u = (1.0 + sign * w[0] * w[0] * a, sign * b, -sign * w[0])
    v = (b, sign + w[1] * w[1] * a, -w[1])
    return u, v


@jit_step
def local(u, v, w, a):
    """The vector with coordinates a in the basis (u, v, w)."""
    return (a[0] * u[0] + a[1] * v[0] + a[2] * w[0],
            a[0] * u[1] + a[1] * v[1] + a[2] * w[1],
            a[0] * u[2] + a[1] * v[2] + a[2] * w[2])
