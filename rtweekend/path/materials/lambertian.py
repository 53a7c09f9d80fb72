"""The lambertian (ideal diffuse) material: f = albedo / pi on the side the
light comes from, sampled by the cosine lobe.

Every function takes the shading normal n (the Bsdf's) on the side of wo
(Surface.n: the books' set_face_normal turns it towards the incoming ray),
which is how the books make the material two-sided.  The density of the cosine lobe is the
books' scattering_pdf, cos(theta) / pi, so f |cos| = albedo x scattering_pdf and
a cosine-sampled direction carries weight = albedo exactly.  Called the other
way round (wi as the first direction) the same normal serves whenever wi is on
its side, the only case where f is not 0: eval and pdf are reciprocal.
"""
import math

from ...kernel.jit import jit_step
from ...kernel.trig import cos_sin_turns
from ...kernel.vec3 import dot, local, onb
from .flags import JOIN, PHOTON

FLAGS = JOIN | PHOTON
INV_PI = 1.0 / math.pi
TWO_PI = 2.0 * math.pi


def params(material):
    """No parameters: its colour is all."""
    return ()


@jit_step
def cosine_at(n, u1, u2):
    """The direction of the cosine lobe about n for the point (u1, u2) of the
    unit square (Malley's method: a point of the disk lifted to the hemisphere)."""
    phi = TWO_PI * u1
    s = math.sqrt(u2)
    z = math.sqrt(max(0.0, 1.0 - u2))
    u, v = onb(n)
    return local(u, v, n, (math.cos(phi) * s, math.sin(phi) * s, z))


@jit_step
def cosine_lobe(n, u1, u2):
    """cosine_at with the angle's cosine and sine from kernel/trig.py instead
    of libm's (a tenth of bidirectional path tracing's time): the same lobe,
    other last bits.  bdpt draws with it; the other estimators keep cosine_at
    and their images, bit for bit."""
    c, s_phi = cos_sin_turns(u1)
    s = math.sqrt(u2)
    z = math.sqrt(max(0.0, 1.0 - u2))
    u, v = onb(n)
    return local(u, v, n, (c * s, s_phi * s, z))


@jit_step
def cosine_pdf(n, wi):
    """scattering_pdf: cos(theta_i) / pi above the surface, else 0 (also a
    diffuse light's density of emitting along wi: integrators/subpaths.py)."""
    c = dot(n, wi)
    return c * INV_PI if c > 0.0 else 0.0


@jit_step
def eval(bsdf, wo, wi, scale):
    """(albedo, scale x scattering_pdf): their product is scale x f |cos theta_i|.
    `scale` is multiplied in before 1/pi (see materials.eval)."""
    c = dot(bsdf.n, wi)
    if c > 0.0:
        return bsdf.albedo, scale * c * INV_PI
    return bsdf.albedo, 0.0


@jit_step
def pdf(bsdf, wo, wi):
    """The cosine lobe's density of wi (wo does not matter)."""
    return cosine_pdf(bsdf.n, wi)


@jit_step
def sample(bsdf, wo, u1, u2):
    """(wi, weight, pdf) of the cosine lobe for the point (u1, u2): weight =
    f |cos| / pdf = albedo."""
    wi = cosine_at(bsdf.n, u1, u2)
    return wi, bsdf.albedo, cosine_pdf(bsdf.n, wi)
