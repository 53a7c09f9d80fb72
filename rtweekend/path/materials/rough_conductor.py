"""A rough metal: GGX (Trowbridge-Reitz) microfacets of roughness alpha with
Smith's shadowing and masking, reflecting `albedo` with no Fresnel term --
what Mitsuba 3's roughconductor with material = "none" and
specular_reflectance = albedo computes -- sampled by the microfacet normals
that wo sees (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").

In the frame of the shading normal n (on wo's side: two-sided, as the books'
metal), with h the unit half vector of wo and wi, both above the surface:

    f |cos theta_i| = albedo D(h) G1(wo) G1(wi) / (4 cos theta_o)
    D(m)   = 1 / (pi alpha^2 ((m_x^2 + m_y^2) / alpha^2 + m_z^2)^2)
    G1(v)  = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta_v))   (Smith, separable)
    pdf(wi) = D(h) G1(wo) / (4 cos theta_o)   (the visible normals' density,
                                               reflected: dwi = 4 |wo.h| dh)
    weight = f |cos theta_i| / pdf = albedo G1(wi)

A microfacet drawn facing wo can reflect wo below the surface: that draw is
absorbed (pdf 0: the path ends), so the density integrates to less than 1 --
the energy single scattering loses on a rough surface, as in Mitsuba.  With
alpha <= 1 the denominators of D stay >= pi alpha^2: alpha near 0 gives large
but finite values that tend to a mirror.
"""
import math

from ...kernel.jit import jit_step
from ...kernel.vec3 import add, cross, dot, local, onb, scale, unit
from .flags import GLOSSY, JOIN

FLAGS = GLOSSY | JOIN   # evaluated, sampled and joined; keeps no photons
ALPHA = 0          # its parameter (Bsdf.params): the GGX roughness, 0 < alpha <= 1
NOTHING = (0.0, 0.0, 0.0)


def params(material):
    """Its parameters, as packed (scene/materials.py's Material)."""
    return (material.alpha,)


@jit_step
def ggx(m, alpha):
    """D(m), m a unit vector in the normal's frame."""
    a2 = alpha * alpha
    t = (m[0] * m[0] + m[1] * m[1]) / a2 + m[2] * m[2]
    return 1.0 / (math.pi * a2 * t * t)


@jit_step
def smith_g1(v, alpha):
    """G1(v) for v above the surface (in the normal's frame), seen from a
    microfacet that faces it (every h of a reflection faces both wo and wi)."""
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
def eval(bsdf, wo, wi, scale_by):
    """(albedo, scale_by x D G1 G1 / (4 cos theta_o)): f |cos theta_i| as
    materials.eval; 0 unless both directions are above the surface."""
    o, i = to_frame(bsdf, wo), to_frame(bsdf, wi)
    if o[2] <= 0.0 or i[2] <= 0.0:
        return bsdf.albedo, 0.0
    alpha = bsdf.params[ALPHA]
    h = unit(add(o, i))
    return bsdf.albedo, scale_by * ggx(h, alpha) * smith_g1(o, alpha) * smith_g1(i, alpha) \
        / (4.0 * o[2])


@jit_step
def pdf(bsdf, wo, wi):
    """sample()'s density of wi: D(h) G1(wo) / (4 cos theta_o)."""
    o, i = to_frame(bsdf, wo), to_frame(bsdf, wi)
    if o[2] <= 0.0 or i[2] <= 0.0:
        return 0.0
    alpha = bsdf.params[ALPHA]
    return ggx(unit(add(o, i)), alpha) * smith_g1(o, alpha) / (4.0 * o[2])


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


@jit_step
def sample(bsdf, wo, u1, u2):
    """(wi, weight, pdf): wo reflected about a visible normal drawn for the
    point (u1, u2); weight = albedo G1(wi); pdf 0 where it goes below."""
    u, v = onb(bsdf.n)
    o = (dot(wo, u), dot(wo, v), dot(wo, bsdf.n))
    if o[2] <= 0.0:
        return NOTHING, NOTHING, 0.0
    alpha = bsdf.params[ALPHA]
    m = visible_normal(o, alpha, u1, u2)
    c = 2.0 * dot(o, m)
    i = (c * m[0] - o[0], c * m[1] - o[1], c * m[2] - o[2])
    wi = local(u, v, bsdf.n, i)
    if i[2] <= 0.0:
        return wi, NOTHING, 0.0
    return wi, scale(bsdf.albedo, smith_g1(i, alpha)), \
        ggx(m, alpha) * smith_g1(o, alpha) / (4.0 * o[2])
