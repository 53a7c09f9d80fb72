"""Materials: what a surface emits and how it scatters (the books' material class).

mat_i[m] = kind; mat_f[m] = colour (MAT_COLOR, 0:3), parameter (MAT_PARAM)
  LAMBERTIAN    colour = albedo; a diffuse lobe, scattering_pdf = cos / pi
  METAL         colour = albedo, parameter = fuzz (clamped to 1 at load)
  DIELECTRIC    parameter = index of refraction; colour (1, 1, 1)
  DIFFUSE_LIGHT colour = emitted radiance, front face only; it does not scatter

The integrator asks `emitted` and `scatter` and branches on what they return,
never on a material's kind: a specular scatter is followed with weight =
attenuation; a diffuse one leaves the direction to the integrator, which draws
it from the pdf mixture (pdf.py) and weighs by attenuation x cos/pi / pdf.
"""
import math

from ..kernel import rng
from ..kernel.jit import jit, jit_inline
from ..kernel.vec3 import dot, madd, reflect, refract, unit
from .layout import DIELECTRIC, DIFFUSE_LIGHT, LAMBERTIAN, MAT_COLOR, MAT_PARAM, METAL

NO_COLOR = (0.0, 0.0, 0.0)


@jit
def schlick(cosine, ref_idx):
    """Schlick's approximation of Fresnel reflectance."""
    r0 = (1.0 - ref_idx) / (1.0 + ref_idx)
    r0 = r0 * r0
    x = 1.0 - cosine
    x2 = x * x
    return r0 + (1.0 - r0) * (x2 * x2 * x)      # (1 - cos)^5 without a call to pow


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


@jit_inline
def color(scene, m):
    """Material m's colour (albedo or emitted radiance) where it has no texture;
    a textured one's is looked up at the hit (textures.py)."""
    f = scene.mat_f
    return (f[m, MAT_COLOR], f[m, MAT_COLOR + 1], f[m, MAT_COLOR + 2])


@jit_inline
def emitted(scene, m, front_face, color):
    """(emits, radiance) of material m seen from its front side or not; color:
    its colour at the hit."""
    if scene.mat_i[m] == DIFFUSE_LIGHT and front_face:
        return True, color
    return False, NO_COLOR


@jit_inline
def scatter(scene, m, d, n, front_face, color, state):
    """(scatters, specular, direction, attenuation, state) at a hit with unit
    normal n facing the incoming unit direction d; color: the material's colour
    at the hit (its albedo).

    specular: the direction is the one to follow; otherwise the material is
    diffuse (lambertian) and the direction returned is only its normal.
    """
    kind = scene.mat_i[m]
    f = scene.mat_f
    if kind == LAMBERTIAN:
        return True, False, n, color, state
    if kind == METAL:
        r, ok, state = metal_scatter(d, n, f[m, MAT_PARAM], state)
        if not ok:
            return False, True, n, color, state     # fuzzed below the surface: absorbed
        return True, True, unit(r), color, state
    if kind == DIELECTRIC:
        r, state = dielectric_scatter(d, n, front_face, f[m, MAT_PARAM], state)
        return True, True, r, color, state
    if kind == DIFFUSE_LIGHT:
        return False, False, n, NO_COLOR, state
    # Never reached: pack.py writes only the tags of layout.MATERIAL_TAGS.
    return False, False, n, NO_COLOR, state
