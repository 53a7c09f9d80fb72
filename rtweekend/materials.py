"""Materials: the books' scatter() for the specular ones and their parameters.

mat_i[m] = kind; mat_f[m] = (colour r, g, b, parameter)
  LAMBERTIAN    colour = albedo                (scattered in path.py via pdf.py)
  METAL         colour = albedo, parameter = fuzz (clamped to 1 at load)
  DIELECTRIC    parameter = index of refraction; colour unused (attenuation 1)
  DIFFUSE_LIGHT colour = emitted radiance, front face only; it does not scatter
"""
import math

from . import rng
from .jit import jit
from .vec3 import dot, madd, reflect, refract

MAT_FLOATS = 4


@jit
def schlick(cosine, ref_idx):
    """Schlick's approximation of Fresnel reflectance."""
    r0 = (1.0 - ref_idx) / (1.0 + ref_idx)
    r0 = r0 * r0
    return r0 + (1.0 - r0) * (1.0 - cosine) ** 5


@jit
def metal_scatter(d, n, fuzz, state):
    """Mirror direction perturbed by a point in a ball of radius fuzz.

    Returns (direction, ok, state); ok is False when the fuzz pushed the ray
    under the surface (book 1 absorbs it), so the path ends with no light.
    """
    r = reflect(d, n)
    if fuzz > 0.0:
        b, state = rng.in_unit_sphere(state)
        r = madd(r, b, fuzz)
    return r, dot(r, n) > 0.0, state


@jit
def dielectric_scatter(d, n, front_face, ior, state):
    """Reflect or refract a unit direction d at a normal n facing it.

    Total internal reflection is decided before refract() is called, so the
    square root there never sees a negative argument.
    """
    ratio = 1.0 / ior if front_face else ior
    cos_theta = min(-dot(d, n), 1.0)
    sin_theta = math.sqrt(max(0.0, 1.0 - cos_theta * cos_theta))
    u, state = rng.uniform(state)
    if ratio * sin_theta > 1.0 or schlick(cos_theta, ratio) > u:
        return reflect(d, n), state
    return refract(d, n, ratio), state
