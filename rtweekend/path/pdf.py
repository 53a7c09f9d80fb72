"""Direction PDFs of The Rest of Your Life: cosine, lights, and their mixture.

Every density is over solid angle at the shading point p, for unit directions.
A light pdf is the books' hittable_pdf: the density of directions from p that
hit the light, whatever lies in between (occlusion is the integrator's job).
How each kind of light is sampled is its own (shapes/<kind>.py).
"""
import math

from ..kernel import rng
from ..kernel.jit import jit, jit_inline
from ..kernel.vec3 import dot, local, onb
from . import shapes

INV_PI = 1.0 / math.pi


# -- cosine pdf: p(w) = cos(theta) / pi about the normal n ----------------------

@jit
def cosine_generate(n, state):
    u1, state = rng.uniform(state)
    u2, state = rng.uniform(state)
    return cosine_at(n, u1, u2), state


@jit
def cosine_at(n, u1, u2):
    """The direction of cosine_generate for the uniforms (u1, u2)."""
    phi = rng.TWO_PI * u1
    s = math.sqrt(u2)
    z = math.sqrt(max(0.0, 1.0 - u2))
    u, v = onb(n)
    return local(u, v, n, (math.cos(phi) * s, math.sin(phi) * s, z))


@jit
def cosine_value(n, d):
    c = dot(n, d)
    return c * INV_PI if c > 0.0 else 0.0


# -- all lights, one chosen uniformly (the books' hittable_list pdf) --------------

@jit_inline
def lights_generate(scene, p, state, time):
    """A unit direction from p towards one light chosen uniformly."""
    lights = scene.lights
    u, state = rng.uniform(state)
    k = lights[min(int(u * lights.shape[0]), lights.shape[0] - 1)]
    return shapes.sample_toward(scene, k, p, state, time)


@jit_inline
def lights_value(scene, p, d, from_obj, from_inside, time):
    """Solid-angle density at p of direction d under lights_generate.

    Each light's term is 0 when d misses it, so the mixture never divides by a
    density that a component could not have produced.
    """
    lights = scene.lights
    total = 0.0
    for j in range(lights.shape[0]):
        total += shapes.pdf_toward(scene, lights[j], p, d, from_obj, from_inside, time)
    return total / lights.shape[0]


# -- the mixture at a diffuse hit (The Rest of Your Life, chapter "Mixing") -------

@jit_inline
def mixture_generate(scene, p, n, light_weight, state, time):
    """A unit direction from (1 - w) cosine + w lights (w = light_weight)."""
    u, state = rng.uniform(state)
    if u < light_weight:
        return lights_generate(scene, p, state, time)
    return cosine_generate(n, state)


@jit_inline
def mixture_at(scene, p, n, light_weight, u1, u2, state, time):
    """mixture_generate from a 2-D point (u1, u2) (a low-discrepancy one): u1 <
    light_weight picks a light, by u1 / light_weight (its direction from the
    stream); otherwise ((u1 - w) / (1 - w), u2) is the cosine lobe's point, so
    stratified points stay stratified over the lobe."""
    if u1 < light_weight:
        lights = scene.lights
        k = lights[min(int(u1 / light_weight * lights.shape[0]), lights.shape[0] - 1)]
        return shapes.sample_toward(scene, k, p, state, time)
    return cosine_at(n, (u1 - light_weight) / (1.0 - light_weight), u2), state


@jit_inline
def mixture_value(scene, p, n, light_weight, d, from_obj, from_inside, time):
    value = (1.0 - light_weight) * cosine_value(n, d)
    if light_weight > 0.0:
        value += light_weight * lights_value(scene, p, d, from_obj, from_inside, time)
    return value
