"""The Rest of Your Life's integrator, written as a loop over path segments.

At a diffuse hit the next direction is drawn from the mixture
    p(w) = (1 - light_weight) * cosine(w) + light_weight * lights(w)
and the throughput is multiplied by albedo * scattering_pdf / p.  The books use
light_weight 0.5; 0 is The Next Week's cosine sampling, 1 samples lights only.
Specular materials (metal, dielectric) follow their one scattered ray with
weight = attenuation.  max_depth counts ray segments, as the books' depth does.
A sample that is NaN or Inf is dropped and counted, never summed.
"""
import math

from . import pdf, rng
from .camera import get_ray
from .hittables import INF, closest_hit, enters, face_normal, outward_normal
from .jit import jit
from .materials import dielectric_scatter, metal_scatter
from .sums import BINS_PER_OCTAVE, BLOCK_SPP, HIST_BINS, LOG2_LOWEST
from .tags import BG_SKY, DIELECTRIC, DIFFUSE_LIGHT, METAL, NO_HIT, OBJ_MAT
from .vec3 import madd, unit


@jit
def background(bg_kind, bg, d):
    """Radiance of a ray that escapes: a constant, or book 1's sky gradient."""
    if bg_kind == BG_SKY:
        a = 0.5 * (d[1] + 1.0)
        return (1.0 - 0.5 * a, 1.0 - 0.3 * a, 1.0)
    return bg


@jit
def trace_row(y, accum, accum2, partial, partial2, valid, row_stats, hist_n, hist_e,
              s0, s1, seed, cam, width, height, obj_i, obj_f, bvh_box, bvh_node,
              bvh_prims, mat_i, mat_f, lights, bg_kind, bg, max_depth, light_weight,
              clamp):
    """Trace samples s0..s1-1 of every pixel of row y and add them to the sums
    (see sums.py and render.render_pass for what each array holds).

    One function per row, called from the prange kernel, so that get_ray and
    the hit and pdf helpers can be inlined into it (inlined into the prange
    body itself they trip Numba's parfor analysis), and the path loop written
    out in it rather than called as an inlined trace(): Numba inlines by
    copying the callee's whole IR, with all that was inlined into it, at each
    call site -- that copy was 40% of the cold compile."""
    segments = 0
    dropped = 0
    n_lights = lights.shape[0]
    for x in range(width):
        pixel = y * width + x
        for s in range(s0, s1):
            state = rng.seed_state(pixel, s, seed)
            o, d, state = get_ray(cam, x, y, width, height, state)
            # -- the path: radiance (lr, lg, lb) along the camera ray (o, d) --
            lr, lg, lb = 0.0, 0.0, 0.0      # radiance gathered so far
            tr, tg, tb = 1.0, 1.0, 1.0      # path throughput
            from_obj = NO_HIT
            from_inside = False
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
                    d, state = pdf.mixture_generate(obj_i, obj_f, lights, p, n,
                                                    light_weight, state)
                    density = pdf.mixture_value(obj_i, obj_f, lights, p, n, light_weight,
                                                d, k, enters(obj_i, obj_f, k, p, d))
                    scattering = pdf.cosine_value(n, d)
                    # A direction below the surface, or one no component can
                    # make, carries no light: stop instead of dividing by zero.
                    if scattering <= 0.0 or density <= 0.0:
                        break
                    w = scattering / density
                    tr *= cr * w
                    tg *= cg * w
                    tb *= cb * w
                from_inside = enters(obj_i, obj_f, k, p, d)
                from_obj = k
                o = p
            # -- the sample, added to its pixel --
            if math.isfinite(lr + lg + lb):
                r, g, b = min(lr, clamp), min(lg, clamp), min(lb, clamp)
                partial[y, x, 0] += r
                partial[y, x, 1] += g
                partial[y, x, 2] += b
                partial2[y, x, 0] += r * r
                partial2[y, x, 1] += g * g
                partial2[y, x, 2] += b * b
                valid[y, x] += 1
                v = (r + g + b) / 3.0
                if v > 0.0:
                    i = int((math.log2(v) - LOG2_LOWEST) * BINS_PER_OCTAVE)
                    i = min(max(i, 0), HIST_BINS - 1)
                    hist_n[y, i] += 1
                    hist_e[y, i] += v
            else:
                dropped += 1
            if (s + 1) % BLOCK_SPP == 0:
                for ch in range(3):
                    accum[y, x, ch] += partial[y, x, ch]
                    accum2[y, x, ch] += partial2[y, x, ch]
                    partial[y, x, ch] = 0.0
                    partial2[y, x, ch] = 0.0
    row_stats[y, 0] += segments
    row_stats[y, 1] += dropped
