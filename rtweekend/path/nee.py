"""Next-event estimation with multiple importance sampling (the "nee" strategy).

At a diffuse hit p the integrator has two ways to find the light of an emitter:

  next event   pick one emitter uniformly, a direction towards it by its own
               sampling (shapes/<kind>.py: sample_toward), and trace a shadow
               ray; its density is p_e(w) = pdf_toward(emitter, w) / E
  continuation the path's next direction from the mixture pdf (pdf.py), p_c(w),
               and whatever emitter that ray happens to hit

Each is an unbiased estimator of the same direct light; both are kept and
weighted by Veach's power heuristic, w_e = p_e^2 / (p_e^2 + p_c^2) for the
shadow ray and w_c = p_c^2 / (p_c^2 + p_e^2) when the continuation hits an
emitter, so the weights of one direction sum to one (tests/test_nee.py).
After a specular bounce (or for the camera ray) only the continuation could
have found the emitter: its weight is one.  Emitters stay one-sided: a shadow
ray that reaches an emitter's back adds nothing.

The shadow ray is traced by the integrator's own nearest-hit call (one call
site: each inlined copy of the search costs seconds of compile) up to the
distance of the point it aims at: it counts if nothing but that emitter is met
before (the emitter itself may be, by a rounding: its distance computed inlined
in the search can differ in the last bit from the one computed here).
shadow_ray and emitter_pdf are compiled apart and called, not inlined.
"""
from ..kernel import rng
from ..kernel.jit import jit, jit_apart, jit_inline
from ..kernel.vec3 import dot, madd
from . import materials, pdf, shapes
from . import textures as texturing
from .bvh import INF
from .layout import NO_HIT, OBJ_MAT


@jit
def power_heuristic(pdf_a, pdf_b):
    """Veach's power heuristic (beta = 2) for strategy a against b."""
    a2 = pdf_a * pdf_a
    return a2 / (a2 + pdf_b * pdf_b)


@jit_apart
def emitter_pdf(scene, k, p, d, from_obj, from_inside, time):
    """Solid-angle density at p of direction d under next-event sampling, for
    the emitter k that d reaches (0 where d misses it)."""
    return shapes.pdf_toward(scene, k, p, d, from_obj, from_inside, time) / \
        scene.emitters.shape[0]


@jit_inline
def continuation_pdf(scene, p, n, light_weight, d, from_obj, from_inside, time):
    """Density of d under the continuation pdf at a diffuse hit."""
    if light_weight > 0.0:
        return pdf.mixture_value(scene, p, n, light_weight, d, from_obj, from_inside, time)
    return pdf.cosine_value(n, d)


@jit_apart
def shadow_ray(scene, k, p, n, n_out, light_weight, state, time, textures):
    """One next-event sample at p on diffuse object k (unit normal n facing the
    incoming ray; outward normal n_out): (emitter, direction, from_inside, t,
    (r, g, b), state).

    The shadow ray leaves p along the direction and reaches the sampled emitter
    at distance t; if nothing else is met before t (the integrator traces it),
    it adds (r, g, b) x albedo x throughput: the emitter's radiance there (0 on
    its back: one-sided) x MIS weight x f cos / p_e per unit albedo (Lambertian:
    f = albedo / pi).  emitter NO_HIT: nothing to trace (a direction below the
    surface, a zero density, or the emitter's back).
    """
    emitters = scene.emitters
    u, state = rng.uniform(state)
    e = emitters[min(int(u * emitters.shape[0]), emitters.shape[0] - 1)]
    w, state = shapes.sample_toward(scene, e, p, state, time)
    cosine = dot(n, w)
    inside = shapes.enters(scene, k, n_out, w)
    none = (0.0, 0.0, 0.0)
    p_e = emitter_pdf(scene, e, p, w, k, inside, time) if cosine > 0.0 else 0.0
    if p_e <= 0.0:
        return NO_HIT, w, inside, INF, none, state
    t = shapes.distance(scene, e, p, w, INF, k, inside, time)
    if not t < INF:
        return NO_HIT, w, inside, INF, none, state
    q = madd(p, w, t)
    front = dot(w, shapes.outward_normal(scene, e, q, time)) < 0.0
    m = scene.obj_i[e, OBJ_MAT]
    color = materials.color(scene, m)
    if textures is not None:
        color = texturing.color_at(scene, textures, m, e, q, color, time)
    emits, radiance = materials.emitted(scene, m, front, color)
    if not emits:
        return NO_HIT, w, inside, INF, none, state
    p_c = continuation_pdf(scene, p, n, light_weight, w, k, inside, time)
    c = power_heuristic(p_e, p_c) * cosine * pdf.INV_PI / p_e
    return e, w, inside, t, (radiance[0] * c, radiance[1] * c, radiance[2] * c), state
