"""The Rest of Your Life's integrator, written as a loop over path segments.

At a diffuse hit the next direction is drawn from the mixture
    p(w) = (1 - light_weight) * cosine(w) + light_weight * lights(w)
and the throughput is multiplied by albedo * scattering_pdf / p.  The books use
light_weight 0.5; 0 is The Next Week's cosine sampling, 1 samples lights only.
Specular materials (metal, dielectric) follow their one scattered ray with
weight = attenuation.  max_depth counts ray segments, as the books' depth does.
"""
from . import pdf
from .hittables import INF, closest_hit, enters, face_normal, outward_normal
from .jit import jit, jit_inline
from .materials import dielectric_scatter, metal_scatter
from .tags import BG_SKY, DIELECTRIC, DIFFUSE_LIGHT, METAL, NO_HIT, OBJ_MAT
from .vec3 import madd, unit


@jit
def background(bg_kind, bg, d):
    """Radiance of a ray that escapes: a constant, or book 1's sky gradient."""
    if bg_kind == BG_SKY:
        a = 0.5 * (d[1] + 1.0)
        return (1.0 - 0.5 * a, 1.0 - 0.3 * a, 1.0)
    return bg


@jit_inline
def trace(obj_i, obj_f, bvh_box, bvh_node, bvh_prims, mat_i, mat_f, lights, bg_kind, bg,
          max_depth, light_weight, o, d, state):
    """Radiance along the camera ray (o, d): (r, g, b), segments traced, state."""
    lr, lg, lb = 0.0, 0.0, 0.0           # radiance gathered so far
    tr, tg, tb = 1.0, 1.0, 1.0          # path throughput (the books' attenuation product)
    from_obj = NO_HIT
    from_inside = False
    n_lights = lights.shape[0]
    segments = 0
    for _ in range(max_depth):
        k, t = closest_hit(obj_i, obj_f, bvh_box, bvh_node, bvh_prims, o, d, INF,
                           from_obj, from_inside)
        segments += 1
        if k == NO_HIT:
            e = background(bg_kind, bg, d)
            lr += tr * e[0]
            lg += tg * e[1]
            lb += tb * e[2]
            break
        p = madd(o, d, t)
        front_face, n = face_normal(d, outward_normal(obj_i, obj_f, k, p))
        m = obj_i[k, OBJ_MAT]
        kind = mat_i[m]
        cr, cg, cb, param = mat_f[m, 0], mat_f[m, 1], mat_f[m, 2], mat_f[m, 3]

        if kind == DIFFUSE_LIGHT:
            if front_face:
                lr += tr * cr
                lg += tg * cg
                lb += tb * cb
            break
        if kind == METAL:
            d, ok, state = metal_scatter(d, n, param, state)
            if not ok:
                break
            d = unit(d)
            tr *= cr
            tg *= cg
            tb *= cb
        elif kind == DIELECTRIC:
            d, state = dielectric_scatter(d, n, front_face, param, state)
        elif n_lights == 0 or light_weight == 0.0:
            # LAMBERTIAN, cosine sampling alone: scattering_pdf / pdf == 1.
            d, state = pdf.cosine_generate(n, state)
            tr *= cr
            tg *= cg
            tb *= cb
        else:
            # LAMBERTIAN, importance-sampling the mixture pdf.
            d, state = pdf.mixture_generate(obj_i, obj_f, lights, p, n, light_weight,
                                            state)
            density = pdf.mixture_value(obj_i, obj_f, lights, p, n, light_weight, d, k,
                                        enters(obj_i, obj_f, k, p, d))
            scattering = pdf.cosine_value(n, d)
            # A direction below the surface, or one no component can make,
            # carries no light: stop instead of dividing by zero.
            if scattering <= 0.0 or density <= 0.0:
                break
            w = scattering / density
            tr *= cr * w
            tg *= cg * w
            tb *= cb * w
        from_inside = enters(obj_i, obj_f, k, p, d)
        from_obj = k
        o = p
    return (lr, lg, lb), segments, state
