"""Direction PDFs of The Rest of Your Life: cosine, lights, and their mixture.

Every density is over solid angle at the shading point p, for unit directions.
A light pdf is the books' hittable_pdf: the density of directions from p that
hit the light, whatever lies in between (occlusion is the integrator's job).
"""
import math

from . import rng
from .hittables import INF, rect_t, sphere_t
from .jit import jit, jit_inline
from .tags import OBJ_KIND, SPHERE
from .vec3 import dot, local, onb, scale

INV_PI = 1.0 / math.pi
INV_4PI = 1.0 / (4.0 * math.pi)


# -- cosine pdf: p(w) = cos(theta) / pi about the normal n ----------------------

@jit
def cosine_generate(n, state):
    u1, state = rng.uniform(state)
    u2, state = rng.uniform(state)
    phi = rng.TWO_PI * u1
    s = math.sqrt(u2)
    z = math.sqrt(max(0.0, 1.0 - u2))
    u, v = onb(n)
    return local(u, v, n, (math.cos(phi) * s, math.sin(phi) * s, z)), state


@jit
def cosine_value(n, d):
    c = dot(n, d)
    return c * INV_PI if c > 0.0 else 0.0


# -- one light: rect (uniform in area) or sphere (uniform in the cone) ----------

@jit
def _one_minus_cos_theta_max(r2, dist2):
    """1 - sqrt(1 - r^2/d^2), written so that it keeps its digits for small r/d."""
    x = r2 / dist2
    return x / (1.0 + math.sqrt(1.0 - x))


# -- all lights, chosen uniformly (the books' hittable_list pdf) -----------------
#
# Each light's sampling is written out inside the loop rather than in a helper
# of its own: every level of Numba inlining copies the whole callee IR at each
# call site, so nesting helpers here multiplied the kernel's compile time.

@jit_inline
def lights_generate(obj_i, obj_f, lights, p, state):
    """A unit direction from p towards one light chosen uniformly.

    A sphere light is sampled uniformly in the cone it subtends (uniformly
    over all directions from on or inside it); a rect uniformly in its area.
    """
    u, state = rng.uniform(state)
    k = lights[min(int(u * lights.shape[0]), lights.shape[0] - 1)]
    if obj_i[k, OBJ_KIND] == SPHERE:
        w = (obj_f[k, 0] - p[0], obj_f[k, 1] - p[1], obj_f[k, 2] - p[2])
        dist2 = dot(w, w)
        r2 = obj_f[k, 4]
        if dist2 <= r2:
            # On or inside the sphere every direction hits it: uniform sphere.
            return rng.unit_vector(state)
        u1, state = rng.uniform(state)
        u2, state = rng.uniform(state)
        z = 1.0 - u2 * _one_minus_cos_theta_max(r2, dist2)
        phi = rng.TWO_PI * u1
        s = math.sqrt(max(0.0, 1.0 - z * z))
        w = scale(w, 1.0 / math.sqrt(dist2))
        u, v = onb(w)
        return local(u, v, w, (math.cos(phi) * s, math.sin(phi) * s, z)), state
    u1, state = rng.uniform(state)
    u2, state = rng.uniform(state)
    dx = obj_f[k, 0] + u1 * obj_f[k, 3] + u2 * obj_f[k, 6] - p[0]
    dy = obj_f[k, 1] + u1 * obj_f[k, 4] + u2 * obj_f[k, 7] - p[1]
    dz = obj_f[k, 2] + u1 * obj_f[k, 5] + u2 * obj_f[k, 8] - p[2]
    inv = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    return (dx * inv, dy * inv, dz * inv), state


@jit_inline
def lights_value(obj_i, obj_f, lights, p, d, from_obj, from_inside):
    """Solid-angle density at p of direction d under lights_generate.

    Each light's term is 0 when d misses it, so the mixture never divides by a
    density that a component could not have produced.
    """
    total = 0.0
    for j in range(lights.shape[0]):
        k = lights[j]
        if obj_i[k, OBJ_KIND] == SPHERE:
            if k != from_obj:
                w = (obj_f[k, 0] - p[0], obj_f[k, 1] - p[1], obj_f[k, 2] - p[2])
                dist2 = dot(w, w)
                r2 = obj_f[k, 4]
                b = dot(d, w)
                if dist2 <= r2:
                    total += INV_4PI    # from inside every direction hits it
                # From outside, d hits the sphere iff it lies in the cone of
                # half-angle theta_max about w: d.w >= |w| cos(theta_max) =
                # sqrt(dist2 - r2), i.e. the quadratic's discriminant test,
                # without solving it.
                elif not (b <= 0.0 or b * b < dist2 - r2):
                    total += 1.0 / (rng.TWO_PI * _one_minus_cos_theta_max(r2, dist2))
            # Leaving this very sphere light: only inward, to its far side.
            elif from_inside and sphere_t(obj_f, k, p, d, INF, True) != INF:
                total += INV_4PI
        elif k != from_obj:             # a rect is never hit from itself
            t = rect_t(obj_f, k, p, d, INF)
            if t != INF:
                n = (obj_f[k, 9], obj_f[k, 10], obj_f[k, 11])
                cosine = abs(dot(n, d))
                total += t * t / (cosine * obj_f[k, 19])
    return total / lights.shape[0]


# -- the mixture at a diffuse hit (The Rest of Your Life, chapter "Mixing") -------

@jit_inline
def mixture_generate(obj_i, obj_f, lights, p, n, light_weight, state):
    """A unit direction from (1 - w) cosine + w lights (w = light_weight)."""
    u, state = rng.uniform(state)
    if u < light_weight:
        return lights_generate(obj_i, obj_f, lights, p, state)
    return cosine_generate(n, state)


@jit_inline
def mixture_value(obj_i, obj_f, lights, p, n, light_weight, d, from_obj, from_inside):
    value = (1.0 - light_weight) * cosine_value(n, d)
    if light_weight > 0.0:
        value += light_weight * lights_value(obj_i, obj_f, lights, p, d, from_obj,
                                             from_inside)
    return value
