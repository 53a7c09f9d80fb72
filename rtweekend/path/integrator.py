"""The Rest of Your Life's integrator, written as a loop over path segments.

At each hit the material says what it emits and how it scatters
(materials.py).  A specular scatter is followed with weight = attenuation.  At
a diffuse one the next direction is drawn from the mixture
    p(w) = (1 - light_weight) * cosine(w) + light_weight * lights(w)
and the throughput is multiplied by attenuation * scattering_pdf / p.  The
books use light_weight 0.5; 0 is The Next Week's cosine sampling, 1 samples
lights only.  max_depth counts ray segments, as the books' depth does.
"""
from ..kernel import rng
from ..kernel.jit import jit, jit_inline, jit_row
from ..kernel.vec3 import dot, madd
from . import film as films
from . import materials, pdf, shapes
from .bvh import INF, closest_hit
from .camera import get_ray
from .film import SEGMENTS
from .layout import BG_SKY, NO_HIT, OBJ_MAT


@jit_inline
def background(scene, d):
    """Radiance of a ray that escapes: a constant, or book 1's sky gradient."""
    if scene.bg_kind == BG_SKY:
        a = 0.5 * (d[1] + 1.0)
        return (1.0 - 0.5 * a, 1.0 - 0.3 * a, 1.0)
    bg = scene.bg
    return (bg[0], bg[1], bg[2])


@jit
def face_normal(d, n_out):
    """The books' set_face_normal: (front_face, normal facing the ray)."""
    if dot(d, n_out) < 0.0:
        return True, n_out
    return False, (-n_out[0], -n_out[1], -n_out[2])


@jit_row
def render_row(y, film, scene, params, s0, s1):
    """Trace samples s0..s1-1 of every pixel of row y into the film.

    One function per row, called from the prange kernel (kernel.py), so that
    the camera, hit and pdf helpers can be inlined into it (inlined into the
    prange body itself they trip Numba's parfor analysis), and the path loop is
    written out here rather than called as an inlined trace(): Numba inlines by
    copying the callee's whole IR, with all that was inlined into it, at each
    call site."""
    segments = 0
    use_lights = scene.lights.shape[0] > 0 and params.light_weight > 0.0
    width = params.width
    for x in range(width):
        pixel = y * width + x
        for s in range(s0, s1):
            state = rng.seed_state(pixel, s, params.seed)
            o, d, state = get_ray(params.cam, x, y, width, params.height, state)
            # -- the path: radiance (lr, lg, lb) along the camera ray (o, d) --
            lr, lg, lb = 0.0, 0.0, 0.0      # radiance gathered so far
            tr, tg, tb = 1.0, 1.0, 1.0      # path throughput
            er, eg, eb = 0.0, 0.0, 0.0      # emitted towards the camera ray (no firefly)
            from_obj = NO_HIT
            from_inside = False
            for depth in range(params.max_depth):
                k, t = closest_hit(scene, o, d, INF, from_obj, from_inside)
                segments += 1
                if k == NO_HIT:
                    e = background(scene, d)
                    lr += tr * e[0]
                    lg += tg * e[1]
                    lb += tb * e[2]
                    break
                p = madd(o, d, t)
                n_out = shapes.outward_normal(scene, k, p)
                front_face, n = face_normal(d, n_out)
                m = scene.obj_i[k, OBJ_MAT]
                emits, e = materials.emitted(scene, m, front_face)
                if emits:
                    lr += tr * e[0]
                    lg += tg * e[1]
                    lb += tb * e[2]
                    if depth == 0:
                        er, eg, eb = e[0], e[1], e[2]
                scatters, specular, d_out, att, state = materials.scatter(
                    scene, m, d, n, front_face, state)
                if not scatters:
                    break
                if specular:
                    d = d_out
                elif use_lights:
                    d, state = pdf.mixture_generate(scene, p, n, params.light_weight, state)
                else:
                    d, state = pdf.cosine_generate(n, state)
                from_inside = shapes.enters(scene, k, n_out, d)
                if specular or not use_lights:
                    # Followed with weight = attenuation (for cosine sampling
                    # alone, scattering_pdf / pdf == 1).
                    tr *= att[0]
                    tg *= att[1]
                    tb *= att[2]
                else:
                    # Importance-sampling the mixture pdf.
                    density = pdf.mixture_value(scene, p, n, params.light_weight, d, k,
                                                from_inside)
                    scattering = pdf.cosine_value(n, d)
                    # A direction below the surface, or one no component can
                    # make, carries no light: stop instead of dividing by zero.
                    if scattering <= 0.0 or density <= 0.0:
                        break
                    w = scattering / density
                    tr *= att[0] * w
                    tg *= att[1] * w
                    tb *= att[2] * w
                from_obj = k
                o = p
            films.add_sample(film, y, x, s, lr, lg, lb, params.clamp, er, eg, eb)
    film.row_stats[y, SEGMENTS] += segments
