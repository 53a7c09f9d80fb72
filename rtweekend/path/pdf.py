"""Direction PDFs of The Rest of Your Life: the lights' pdf, and its mixture with
the material's own sampling.

Every density is over solid angle at the shading point p, for unit directions.
A light pdf is the books' hittable_pdf: the density of directions from p that
hit the light, whatever lies in between (occlusion is the integrator's job).
How each kind of light is sampled is its own (shapes/<kind>.py; a mesh as a
whole: mesh_light.py, which toward_light and density_toward pick).  The
mixture's other component is the material's sampling (materials.py): for the
books' lambertian, their cosine_pdf.
"""
from ..kernel import sampler
from ..kernel.jit import jit_step
from . import lights, materials, mesh_light, shapes
from .layout import LIGHT_OBJ, LISTED, NON_NEGATIVE


@jit_step
def toward_light(scene, k, p, from_obj, u1, u2, time):
    """The unit direction from p (a point of object from_obj, or NO_HIT)
    towards the lights list's entry k (an object, or the first triangle of a
    mesh: then the whole mesh) for the unit square's point (u1, u2), by its own
    sampling."""
    g = mesh_light.group_of(scene.tris, k)
    if g >= 0:
        return mesh_light.sample_toward(scene.tris, scene.obj_f, g, p, u1, u2)
    return shapes.sample_toward(scene, k, p, from_obj, u1, u2, time)


@jit_step
def density_toward(scene, k, p, d, from_obj, from_inside, time):
    """Density of d under toward_light(k) at p; 0 where d misses it."""
    g = mesh_light.group_of(scene.tris, k)
    if g >= 0:
        return mesh_light.pdf_toward(scene.tris, scene.wide, scene.obj_f, g, p, d, from_obj)
    return shapes.pdf_toward(scene, k, p, d, from_obj, from_inside, time)


@jit_step
def behind_every_light(sides, p):
    """Is p behind every half-space of `sides` (pack.dark_sides; none: no)?"""
    if sides.shape[0] == 0:
        return False
    for j in range(sides.shape[0]):
        if sides[j, 0] * p[0] + sides[j, 1] * p[1] + sides[j, 2] * p[2] >= sides[j, 3]:
            return False
    return True


@jit_step
def mixture_weight(scene, bsdf, p, light_weight):
    """The mixture's weight on the lights list at p, on the material of record
    bsdf: 0 where no light of it shines (Sampling.facing: scene.dark_sides,
    empty for the other strategies), and at a glossy material, so that the
    material's sampling alone draws there.  Mixed into a narrow lobe, the
    lights list's share would double the weight of every draw the lobe makes
    (up to 2 G1 instead of G1), and a path caught between glossy surfaces --
    reflected inside a frosted ball named in the list -- would grow without
    bound, kept by roulette."""
    if materials.is_glossy(bsdf):
        return 0.0
    if scene.dark_sides.shape[0] > 0 and behind_every_light(scene.dark_sides, p):
        return 0.0
    return light_weight


# -- the lights list, one entry chosen uniformly (the books' hittable_list pdf) ----

@jit_step
def lights_generate(scene, p, from_obj, smp, time):
    """A unit direction from p (a point of object from_obj, or NO_HIT) towards
    one entry of the lights list (lights.py: the table's LISTED rows): one
    number of the stream picks it, the sampler's next 2-D point places the
    direction."""
    u, smp = sampler.uniform(smp)
    k = scene.light_rows[lights.pick(scene, LISTED, u), LIGHT_OBJ]
    u1, u2, smp = sampler.next_2d(smp)
    return toward_light(scene, k, p, from_obj, u1, u2, time), smp


@jit_step
def lights_value(scene, p, d, from_obj, from_inside, time):
    """Solid-angle density at p of direction d under lights_generate: the mean
    of the entries' densities (the list is picked uniformly).

    Each light's term is 0 when d misses it, so the mixture never divides by a
    density that a component could not have produced.
    """
    first, end = scene.light_ranges[LISTED, 0], scene.light_ranges[LISTED, 1]
    total = 0.0
    for row in range(first, end):
        k = scene.light_rows[row & NON_NEGATIVE, LIGHT_OBJ] & NON_NEGATIVE
        total += density_toward(scene, k, p, d, from_obj, from_inside, time)
    return total / (end - first)


# -- the mixture at a smooth hit (The Rest of Your Life, chapter "Mixing") ---------

@jit_step
def mixture_sample(scene, bsdf, wo, p, from_obj, light_weight, use_lights, smp, time):
    """(direction, weight, smp): a direction from p, a point of object from_obj,
    drawn from (1 - w) material + w lights
    (w = light_weight, 0 without use_lights), and the material's weight when
    its component drew it.

    With the lights list (use_lights), the books' way: one number of the stream
    picks the component, then the component draws its own (the light: one to
    pick it, then a 2-D point for its direction; the material: a 2-D point).
    When the sampler has a low-discrepancy point left, or without lights, one
    2-D point (u1, u2) decides everything: u1 < w picks a light, by
    t = u1 / w (lights.pick), and (t stretched back within the light's share,
    u2) is the light's point; otherwise ((u1 - w) / (1 - w), u2) is the
    material's.  Each component's share of the unit square is stretched back
    to the whole, so that a stratified point stays stratified over the lobe
    and over each light's surface."""
    row, v1, v2 = 0, 0.0, 0.0
    if sampler.low_discrepancy(smp) or not use_lights:
        u1, u2, smp = sampler.next_2d(smp)
        light = u1 < light_weight
        if light:
            t = u1 / light_weight
            row = lights.pick(scene, LISTED, t)
            v1, v2 = lights.stretched(scene, LISTED, row, t), u2
        else:
            v1, v2 = (u1 - light_weight) / (1.0 - light_weight), u2
    else:
        u, smp = sampler.uniform(smp)
        light = u < light_weight
        if light:
            pick, smp = sampler.uniform(smp)
            row = lights.pick(scene, LISTED, pick)
            v1, v2, smp = sampler.next_2d(smp)          # past the Sobol pairs: the stream
        else:
            v1, smp = sampler.uniform(smp)
            v2, smp = sampler.uniform(smp)
    if light:
        k = scene.light_rows[row & NON_NEGATIVE, LIGHT_OBJ] & NON_NEGATIVE
        return toward_light(scene, k, p, from_obj, v1, v2, time), materials.NO_COLOR, smp
    wi, weight, _, smp = materials.sample_at(bsdf, wo, v1, v2, smp)
    return wi, weight, smp


@jit_step
def mixture_value(scene, bsdf, wo, p, light_weight, d, from_obj, from_inside, time):
    """Density of d under the mixture (the material's share from materials.pdf)."""
    value = (1.0 - light_weight) * materials.pdf(bsdf, wo, d)
    if light_weight > 0.0:
        value += light_weight * lights_value(scene, p, d, from_obj, from_inside, time)
    return value
