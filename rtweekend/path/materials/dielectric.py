"""The books' dielectric: reflect with Schlick's probability (always under total
internal reflection), else refract; weight = 1 either way.

A delta material: its directions are chosen, never evaluated (materials.py).
The choice takes one number of the stream.
"""
import math

from ...kernel.jit import jit_step
from ...kernel.vec3 import dot, reflect, refract
from .flags import DELTA, FORKS, REFRACTS

FLAGS = DELTA | FORKS | REFRACTS
IOR = 0             # its parameter (Bsdf.params): the index of refraction


def params(material):
    """Its parameters, as packed (scene/materials.py's Material)."""
    return (material.param,)


@jit_step
def schlick(cosine, ref_idx):
    """Schlick's approximation of Fresnel reflectance."""
    r0 = (1.0 - ref_idx) / (1.0 + ref_idx)
    r0 = r0 * r0
    x = 1.0 - cosine
    x2 = x * x
    return r0 + (1.0 - r0) * (x2 * x2 * x)      # (1 - cos)^5 without a call to pow


@jit_step
def total_internal(cos_theta, ratio):
    """Does a ray arriving at cos_theta reflect totally (Snell's law has no
    refraction for eta_from / eta_to = ratio)?"""
    sin_theta = math.sqrt(max(0.0, 1.0 - cos_theta * cos_theta))
    return ratio * sin_theta > 1.0


@jit_step
def scatter_at(d, n, front_face, ior, u):
    """The direction for a unit d meeting the normal n that faces it, and u in [0, 1):
    reflected when u < the reflectance.

    Total internal reflection is decided before refract() is called, so the
    square root there never sees a negative argument."""
    ratio = 1.0 / ior if front_face else ior
    cos_theta = min(-dot(d, n), 1.0)
    if total_internal(cos_theta, ratio) or schlick(cos_theta, ratio) > u:
        return reflect(d, n)
    return refract(d, n, ratio)


@jit_step
def branches(d, n, front_face, ior):
    """scatter_at's two directions and the chance it picks the first:
    (reflected, refracted, reflectance); under total internal reflection the
    reflectance is 1 and the refracted direction is the reflected one."""
    ratio = 1.0 / ior if front_face else ior
    cos_theta = min(-dot(d, n), 1.0)
    r = reflect(d, n)
    if total_internal(cos_theta, ratio):
        return r, r, 1.0
    return r, refract(d, n, ratio), schlick(cos_theta, ratio)


@jit_step
def adjoint_weight(cos_from, cos_to, front_face, ior):
    """The weight of a refraction for light followed from its source, from the
    side where the light meets the surface at cos_from to the other at cos_to.

    The books' rule -- weight 1, Schlick's reflectance of the cosine the ray
    arrives with -- is the camera's: a camera ray crossing the other way
    transmits 1 - schlick(cos_to) of what it finds there.  Followed from the
    light, the same paths need the adjoint (Veach's thesis, 5.2): that
    transmittance over the probability 1 - schlick(cos_from) the light's draw
    gave the refraction, times (eta_from / eta_to)^2, since refraction squeezes
    radiance into a narrower cone (pbrt's non-symmetric scattering).  The
    Schlick ratio is not 1: the books' rule is not reciprocal."""
    ratio = 1.0 / ior if front_face else ior     # eta_from / eta_to
    t_camera = 1.0 - schlick(min(cos_to, 1.0), 1.0 / ratio)
    t_drawn = 1.0 - schlick(min(cos_from, 1.0), ratio)
    return ratio * ratio * t_camera / t_drawn


@jit_step
def transmittance(d, n_out, ior):
    """What a ray along d (unit) carries through the surface of outward normal
    n_out, by the books' rule: 1 - schlick(cos) with the cosine it arrives
    with; 0 under total internal reflection."""
    c = dot(d, n_out)
    front_face = c < 0.0
    ratio = 1.0 / ior if front_face else ior
    cos_theta = min(abs(c), 1.0)
    if total_internal(cos_theta, ratio):
        return 0.0
    return 1.0 - schlick(cos_theta, ratio)
