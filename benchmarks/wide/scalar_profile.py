"""The scalar kernel's phase split: rtweekend's render_row, copied with a cycle
counter around its nearest-hit search, so that the share of its time spent
intersecting can be set beside the wavefront's phases.

The copy is line for line integrator.render_row (film and radiance included),
with two reads of the time-stamp counter per ray segment added: they cost tens
of cycles against the hundreds a segment takes, so the split, not the speed, is
what this measures.  One thread, no prange (the split does not depend on it).
"""
import time

import numpy as np

from rtweekend.kernel import rng
from rtweekend.kernel.vec3 import madd
from rtweekend.path import film as films
from rtweekend.path import materials, pdf, shapes
from rtweekend.path.bvh import INF, closest_hit
from rtweekend.path.camera import get_ray
from rtweekend.path.integrator import background, face_normal
from rtweekend.path.layout import NO_HIT, OBJ_MAT
from rtweekend.path.renderer import freeze
from rtweekend.options import RenderOptions

from .jitopts import cycles, plain


@plain
def profile_rows(film, scene, params, s0, s1, prof):
    """render_row for every row; prof[0] += cycles in closest_hit, prof[1] += all."""
    use_lights = scene.lights.shape[0] > 0 and params.light_weight > 0.0
    width = params.width
    c_all = cycles()
    for y in range(params.height):
        for x in range(width):
            pixel = y * width + x
            for s in range(s0, s1):
                state = rng.seed_state(pixel, s, params.seed)
                o, d, state = get_ray(params.cam, x, y, width, params.height, state)
                lr, lg, lb = 0.0, 0.0, 0.0
                tr, tg, tb = 1.0, 1.0, 1.0
                er, eg, eb = 0.0, 0.0, 0.0      # emitted towards the camera ray (no firefly)
                from_obj = NO_HIT
                from_inside = False
                for depth in range(params.max_depth):
                    c0 = cycles()
                    k, t = closest_hit(scene, o, d, INF, from_obj, from_inside, None)
                    prof[0] += cycles() - c0
                    if k == NO_HIT:
                        e = background(scene, d)
                        lr += tr * e[0]
                        lg += tg * e[1]
                        lb += tb * e[2]
                        break
                    p = madd(o, d, t)
                    n_out = shapes.outward_normal(scene, k, p, None)
                    front_face, n = face_normal(d, n_out)
                    m = scene.obj_i[k, OBJ_MAT]
                    emits, e = materials.emitted(scene, m, front_face, materials.color(scene, m))
                    if emits:
                        lr += tr * e[0]
                        lg += tg * e[1]
                        lb += tb * e[2]
                        if depth == 0:
                            er, eg, eb = e[0], e[1], e[2]
                    scatters, specular, d_out, att, state = materials.scatter(
                        scene, m, d, n, front_face, materials.color(scene, m), state)
                    if not scatters:
                        break
                    if specular:
                        d = d_out
                    elif use_lights:
                        d, state = pdf.mixture_generate(scene, p, n, params.light_weight,
                                                        state, None)
                    else:
                        d, state = pdf.cosine_generate(n, state)
                    from_inside = shapes.enters(scene, k, n_out, d)
                    if specular or not use_lights:
                        tr *= att[0]
                        tg *= att[1]
                        tb *= att[2]
                    else:
                        density = pdf.mixture_value(scene, p, n, params.light_weight, d, k,
                                                    from_inside, None)
                        scattering = pdf.cosine_value(n, d)
                        if scattering <= 0.0 or density <= 0.0:
                            break
                        w = scattering / density
                        tr *= att[0] * w
                        tg *= att[1] * w
                        tb *= att[2] * w
                    from_obj = k
                    o = p
                films.add_sample(film, y, x, s, lr, lg, lb, params.clamp, er, eg, eb)
    prof[1] += cycles() - c_all


def scalar_split(scene, width, height, spp, seed=1):
    """(share of the scalar kernel's cycles in closest_hit, seconds) for spp
    samples after a warm-up sample."""
    frame = freeze(scene, RenderOptions("path", seed=seed, width=width, height=height,
                                        sampling="mixture"))
    film = films.new_film(frame.height, frame.width)
    prof = np.zeros(2, dtype=np.int64)
    profile_rows(film, frame.scene, frame.params, 0, 1, prof)
    prof[:] = 0
    t0 = time.perf_counter()
    profile_rows(film, frame.scene, frame.params, 1, 1 + spp, prof)
    return float(prof[0] / prof[1]), time.perf_counter() - t0
