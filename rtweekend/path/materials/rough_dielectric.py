"""Rough glass: GGX microfacets of roughness alpha on the boundary between two
media of indices whose ratio is `ior`, each microfacet reflecting with the
exact dielectric Fresnel reflectance F and refracting the rest (Walter,
Marschner, Li and Torrance 2007, "Microfacet Models for Refraction through
Rough Surfaces"; what Mitsuba 3's roughdielectric computes), sampled by the
normals wo sees (microfacet.py) and then a reflection with probability F.
The books' smooth `dielectric` keeps its Schlick approximation.

In the frame of the shading normal n (on wo's side), with eta = the index on
the far side over the index on wo's side (ior from the front, 1 / ior from
inside) and G = G1(wo) G1(wi):

  reflection (wi above):  h = unit(wo + wi)
    f |cos theta_i| = F(wo.h) D(h) G / (4 cos theta_o)
    pdf(wi) = F D_o(h) / (4 wo.h)
  refraction (wi below):  h = unit(wo + eta wi), turned to face n
    f |cos theta_i| = (1 - F) D(h) G |wo.h| |wi.h| / (cos theta_o (wo.h + eta wi.h)^2)
    pdf(wi) = (1 - F) D_o(h) eta^2 |wi.h| / (wo.h + eta wi.h)^2
    weight = G1(wi) / eta^2;  reflection's: G1(wi)

f is the camera's (radiance): a refraction squeezes radiance by 1 / eta^2
(Mitsuba's "radiance" mode; the books' glass leaves it out, which makes no
difference where camera and lights are in the same medium).  Light carried the
other way takes eta^2 (adjoint), as f(wo, wi) / eta_wo^2 = f(wi, wo) / eta_wi^2.
A refraction must cross the microfacet (wo.h > 0 > wi.h): else it is 0, as
is a draw that leaves on the wrong side of the surface (absorbed, pdf 0);
under total internal reflection F = 1.
"""
import math

from ...kernel.jit import jit_step
from ...kernel.vec3 import dot, local, onb, scale, unit
from .flags import GLOSSY, JOIN
from .microfacet import ggx, smith_g1, to_frame, visible_normal

FLAGS = GLOSSY | JOIN   # evaluated, sampled and joined; keeps no photons
IOR, ALPHA = 0, 1   # its parameters (Bsdf.params): index of refraction, GGX roughness
NOTHING = (0.0, 0.0, 0.0)


def params(material):
    """Its parameters, as packed (scene/materials.py's Material)."""
    return (material.param, material.alpha)


@jit_step
def fresnel(cos_i, eta):
    """(F, cos theta_t): the unpolarised dielectric reflectance of light
    meeting a surface at cos_i (> 0) from the side of index 1 towards index
    eta (relative), and the refracted ray's cosine; F = 1 under total
    internal reflection."""
    sin2_t = (1.0 - cos_i * cos_i) / (eta * eta)
    if sin2_t >= 1.0:
        return 1.0, 0.0
    cos_t = math.sqrt(1.0 - sin2_t)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp), cos_t


@jit_step
def relative_ior(bsdf):
    """eta: the index on the far side over the one on wo's side."""
    ior = bsdf.params[IOR]
    return ior if bsdf.front else 1.0 / ior


@jit_step
def lobe(bsdf, wo, wi):
    """(h, eta, refracts, ok): the microfacet normal that takes wo to wi, in the
    normal's frame with o and i; ok False where none does (or wo is below)."""
    o, i = to_frame(bsdf, wo), to_frame(bsdf, wi)
    eta = relative_ior(bsdf)
    if o[2] <= 0.0 or i[2] == 0.0:
        return o, i, o, eta, False, False
    if i[2] > 0.0:
        return o, i, unit((o[0] + i[0], o[1] + i[1], o[2] + i[2])), eta, False, True
    h = unit((o[0] + eta * i[0], o[1] + eta * i[1], o[2] + eta * i[2]))
    if h[2] < 0.0:
        h = (-h[0], -h[1], -h[2])
    return o, i, h, eta, True, dot(o, h) > 0.0 and dot(i, h) < 0.0


@jit_step
def eval(bsdf, wo, wi, scale_by):
    """(colour, scale_by x f |cos theta_i| / colour): as materials.eval."""
    o, i, h, eta, refracts, ok = lobe(bsdf, wo, wi)
    if not ok:
        return bsdf.albedo, 0.0
    alpha = bsdf.params[ALPHA]
    c = dot(o, h)
    f, _ = fresnel(c, eta)
    g = ggx(h, alpha) * smith_g1(o, alpha) * smith_g1(i, alpha)
    if not refracts:
        return bsdf.albedo, scale_by * f * g / (4.0 * o[2])
    d = c + eta * dot(i, h)
    return bsdf.albedo, scale_by * (1.0 - f) * g * c * -dot(i, h) / (o[2] * d * d)


@jit_step
def pdf(bsdf, wo, wi):
    """sample()'s density of wi."""
    o, i, h, eta, refracts, ok = lobe(bsdf, wo, wi)
    if not ok:
        return 0.0
    alpha = bsdf.params[ALPHA]
    c = dot(o, h)
    f, _ = fresnel(c, eta)
    visible = smith_g1(o, alpha) * ggx(h, alpha) / o[2]      # D_o(h) / (wo.h)
    if not refracts:
        return f * visible / 4.0
    ih = dot(i, h)
    d = c + eta * ih
    return (1.0 - f) * visible * c * eta * eta * -ih / (d * d)


@jit_step
def sample(bsdf, wo, u1, u2, u):
    """(wi, weight, pdf): a visible normal drawn for the point (u1, u2), then
    wo reflected about it if u < F, else refracted through it; pdf 0 where
    the direction leaves on the wrong side."""
    un, vn = onb(bsdf.n)
    o = (dot(wo, un), dot(wo, vn), dot(wo, bsdf.n))
    if o[2] <= 0.0:
        return NOTHING, NOTHING, 0.0
    alpha, eta = bsdf.params[ALPHA], relative_ior(bsdf)
    m = visible_normal(o, alpha, u1, u2)
    c = dot(o, m)
    f, cos_t = fresnel(c, eta)
    visible = smith_g1(o, alpha) * ggx(m, alpha) / o[2]
    if u < f:
        i = (2.0 * c * m[0] - o[0], 2.0 * c * m[1] - o[1], 2.0 * c * m[2] - o[2])
        wi = local(un, vn, bsdf.n, i)
        if i[2] <= 0.0:
            return wi, NOTHING, 0.0
        return wi, scale(bsdf.albedo, smith_g1(i, alpha)), f * visible / 4.0
    k = c / eta - cos_t            # Snell's law about m: i = -o / eta + k m
    i = (k * m[0] - o[0] / eta, k * m[1] - o[1] / eta, k * m[2] - o[2] / eta)
    wi = local(un, vn, bsdf.n, i)
    if i[2] >= 0.0:
        return wi, NOTHING, 0.0
    ih = dot(i, m)
    d = c + eta * ih
    return wi, scale(bsdf.albedo, smith_g1(i, alpha) / (eta * eta)), \
        (1.0 - f) * visible * c * eta * eta * -ih / (d * d)


@jit_step
def adjoint(bsdf, wo, wi):
    """What light carried the other way (a light subpath, arriving along -wo)
    multiplies eval and sample's weight by: eta^2 through the surface, 1 for
    a reflection."""
    if dot(wi, bsdf.n) >= 0.0:
        return 1.0
    eta = relative_ior(bsdf)
    return eta * eta
