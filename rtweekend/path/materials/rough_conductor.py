"""A rough metal: GGX (Trowbridge-Reitz) microfacets of roughness alpha with
Smith's shadowing and masking, reflecting `albedo` with no Fresnel term --
what Mitsuba 3's roughconductor with material = "none" and
specular_reflectance = albedo computes -- sampled by the microfacet normals
that wo sees (Heitz 2018, "Sampling the GGX Distribution of Visible Normals").

In the frame of the shading normal n (on wo's side: two-sided, as the books'
metal), with h the unit half vector of wo and wi, both above the surface, and
D, G1 the GGX distribution's (microfacet.py):

    f |cos theta_i| = albedo D(h) G1(wo) G1(wi) / (4 cos theta_o)
    pdf(wi) = D(h) G1(wo) / (4 cos theta_o)   (the visible normals' density,
                                               reflected: dwi = 4 |wo.h| dh)
    weight = f |cos theta_i| / pdf = albedo G1(wi)

A microfacet drawn facing wo can reflect wo below the surface: that draw is
absorbed (pdf 0: the path ends), so the density integrates to less than 1 --
the energy single scattering loses on a rough surface, as in Mitsuba.  Alpha
near 0 gives large but finite values that tend to a mirror.
"""
from ...kernel.jit import jit_step
from ...kernel.vec3 import add, dot, local, onb, scale, unit
from .flags import GLOSSY, JOIN
from .microfacet import ggx, smith_g1, to_frame, visible_normal

FLAGS = GLOSSY | JOIN   # evaluated, sampled and joined; keeps no photons
ALPHA = 0          # its parameter (Bsdf.params): the GGX roughness, 0 < alpha <= 1
NOTHING = (0.0, 0.0, 0.0)


def params(material):
    """Its parameters, as packed (scene/materials.py's Material)."""
    return (material.alpha,)


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


@jit_step
def adjoint(bsdf, wo, wi):
    """What light carried the other way (a light subpath) multiplies eval and
    sample's weight by: 1, a reflection is symmetric (materials.eval_adjoint)."""
    return 1.0
