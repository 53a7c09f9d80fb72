"""Next-event estimation with multiple importance sampling (the "nee" strategy).

At a diffuse hit p the integrator has two ways to find the light of an emitter:

  next event   pick one emitter by power (lights.py), a direction towards it by
               its own sampling (shapes/<kind>.py: sample_toward), and trace a
               shadow ray; its density is p_e(w) = P(emitter) pdf_toward(emitter, w)
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
shadow_ray and emitter_pdf are compiled apart and called, not inlined.  The
material at p is asked, never its kind: its density of the shadow ray's
direction (materials.pdf: 0 below a lambertian) and f |cos| (materials.eval).
"""
from ..kernel.jit import jit_step
from ..kernel.vec3 import dot, madd
from . import lights, materials, pdf, shapes
from . import textures as texturing
from .bvh import INF
from .layout import NO_HIT, OBJ_MAT

NONE = (0.0, 0.0, 0.0)


@jit_step
def power_heuristic(pdf_a, pdf_b):
    """Veach's power heuristic (beta = 2) for strategy a against b."""
    a2 = pdf_a * pdf_a
    return a2 / (a2 + pdf_b * pdf_b)


@jit_step
def emitter_pdf(scene, k, p, d, from_obj, from_inside, time):
    """Solid-angle density at p of direction d under next-event sampling, for
    the emitter k that d reaches (0 where d misses it): how often k is picked,
    times the density of its own sampling."""
    return shapes.pdf_toward(scene, k, p, d, from_obj, from_inside, time) * \
        scene.light_pick[k]


@jit_step
def continuation_pdf(scene, bsdf, wo, p, light_weight, d, from_obj, from_inside, time):
    """Density of d under the continuation at a smooth hit (material record
    bsdf): the mixture with the lights list, or the material's own sampling."""
    if light_weight > 0.0:
        return pdf.mixture_value(scene, bsdf, wo, p, light_weight, d, from_obj, from_inside,
                                 time)
    return materials.pdf(bsdf, wo, d)


@jit_step
def shadow_ray(scene, p, n_out, k, bsdf, wo, light_weight, beta, xi, time, textures):
    """One next-event sample at the point p of object k (outward normal n_out;
    its material: bsdf), reached by a path of throughput beta coming from wo:
    (emitter, direction, from_inside, t, (r, g, b)).

    The shadow ray leaves p along the direction and reaches the sampled emitter
    at distance t; if nothing else is met before t (the integrator traces it),
    it adds (r, g, b): beta x the emitter's radiance there (0 on its back:
    one-sided) x MIS weight x f |cos| / p_e.  emitter NO_HIT: nothing to trace
    (a direction the material gives nothing, a zero density, or the emitter's
    back).  xi = (u, u1, u2): u picks the emitter, (u1, u2) places the
    direction towards it (the caller's sampler draws them: this function is
    called, not inlined).
    """
    u, u1, u2 = xi
    e = lights.pick_emitter(scene, u)
    w = shapes.sample_toward(scene, e, p, k, u1, u2, time)
    inside = shapes.enters(scene, k, n_out, w)
    gives = materials.pdf(bsdf, wo, w) > 0.0
    p_e = emitter_pdf(scene, e, p, w, k, inside, time) if gives else 0.0
    if p_e <= 0.0:
        return NO_HIT, w, inside, INF, NONE
    t = shapes.distance(scene, e, p, w, INF, k, inside, time)
    if not t < INF:
        return NO_HIT, w, inside, INF, NONE
    q = madd(p, w, t)
    front = dot(w, shapes.outward_normal(scene, e, q, time)) < 0.0
    m = scene.obj_i[e, OBJ_MAT]
    color = materials.color(scene, m)
    if textures is not None:
        color = texturing.color_at(scene, textures, m, e, q, color, time)
    emits, radiance = materials.emitted_by(scene, m, front, color)
    if not emits:
        return NO_HIT, w, inside, INF, NONE
    p_c = continuation_pdf(scene, bsdf, wo, p, light_weight, w, k, inside, time)
    att, f = materials.eval(bsdf, wo, w, power_heuristic(p_e, p_c))
    c = f / p_e
    return e, w, inside, t, (beta[0] * att[0] * (radiance[0] * c),
                             beta[1] * att[1] * (radiance[1] * c),
                             beta[2] * att[2] * (radiance[2] * c))
