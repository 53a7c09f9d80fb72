"""The GGX (Trowbridge-Reitz) microfacet distribution that the glossy kinds
share (rough_conductor.py, rough_dielectric.py): its normals' density D,
Smith's separable shadowing G1, and the draw of the normals a direction sees
(Heitz 2018, "Sampling the GGX Distribution of Visible Normals").  Vectors are
in the frame of the record's shading normal (to_frame), z along it.

    D(m)   = 1 / (pi alpha^2 ((m_x^2 + m_y^2) / alpha^2 + m_z^2)^2)
    G1(v)  = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta_v))
    D_o(m) = G1(o) max(0, o.m) D(m) / cos theta_o   (the normals o sees)

With alpha <= 1 the denominators of D stay >= pi alpha^2: alpha near 0 gives
large but finite values.
"""
import math

from ...kernel.jit import jit_step
from ...kernel.vec3 import cross, dot, onb, unit


@jit_step
def ggx(m, alpha):
    """D(m), m a unit vector in the normal's frame."""
    a2 = alpha * alpha
    t = (m[0] * m[0] + m[1] * m[1]) / a2 + m[2] * m[2]
    return 1.0 / (math.pi * a2 * t * t)


@jit_step
def smith_g1(v, alpha):
    """G1(v) for v (in the normal's frame, above or below it), seen from a
    microfacet that faces it: the caller checks that it does (every h of a
    reflection faces both wo and wi; a refraction's, wo from above and wi
    from below)."""
    xy = alpha * alpha * (v[0] * v[0] + v[1] * v[1])
    if xy == 0.0:
        return 1.0
    return 2.0 / (1.0 + math.sqrt(1.0 + xy / (v[2] * v[2])))


@jit_step
def to_frame(bsdf, d):
    """d in the frame (u, v, n) of the record's normal."""
    u, v = onb(bsdf.n)
    return (dot(d, u), dot(d, v), dot(d, bsdf.n))


@jit_step
def visible_normal(o, alpha, u1, u2):
    """A microfacet normal drawn with the density of the normals o sees,
    D_o(m) = G1(o) max(0, o.m) D(m) / cos theta_o, for the point (u1, u2):
    the hemisphere of the stretched direction, a disk point warped towards it."""
    vh = unit((alpha * o[0], alpha * o[1], o[2]))
    lensq = vh[0] * vh[0] + vh[1] * vh[1]
    t1 = (1.0, 0.0, 0.0)
    if lensq > 0.0:
        inv = 1.0 / math.sqrt(lensq)
        t1 = (-vh[1] * inv, vh[0] * inv, 0.0)
    t2 = cross(vh, t1)
    r, phi = math.sqrt(u1), 2.0 * math.pi * u2
    p1, p2 = r * math.cos(phi), r * math.sin(phi)
    s = 0.5 * (1.0 + vh[2])
    p2 = (1.0 - s) * math.sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2
    z = math.sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2))
    nh = (p1 * t1[0] + p2 * t2[0] + z * vh[0], p1 * t1[1] + p2 * t2[1] + z * vh[1],
          p1 * t1[2] + p2 * t2[2] + z * vh[2])
    return unit((alpha * nh[0], alpha * nh[1], max(0.0, nh[2])))
