"""The Rest of Your Life's integrator, written as a loop over path segments.

At each hit the material says what it emits and how it scatters
(materials.py).  A specular scatter is followed with weight = attenuation.  At
a diffuse one the next direction is drawn from the mixture
    p(w) = (1 - light_weight) * cosine(w) + light_weight * lights(w)
and the throughput is multiplied by attenuation * scattering_pdf / p.  The
books use light_weight 0.5; 0 is The Next Week's cosine sampling, 1 samples
lights only.  max_depth counts ray segments, as the books' depth does.

With next-event estimation (`events`, nee.py) each diffuse hit also
aims a shadow ray at one emitter, traced by the same nearest-hit call before
the path goes on, and an emitter the path hits after a diffuse bounce counts
with its MIS weight; paths end by Russian roulette from segment `events` on.
Shadow rays count as rays in the statistics, not as path segments of max_depth.

The Next Week's features reach the kernel the same way, each as an argument
that is None when the scene does not use it, so that the kernel compiled for
a scene without them has none of their code (Numba prunes `is None` tests on
arguments): `textures` (textures.py: colours looked up at the hit), `media`
(media.py: where a ray scatters inside a constant medium before it reaches
the surface it would hit), `motion` (spheres that move: each camera sample
draws a time on the shutter, and every segment of its path keeps it).
"""
import numpy as np

from ..kernel import rng, sobol
from ..kernel.jit import jit, jit_inline, jit_row
from ..kernel.vec3 import dot, madd
from . import film as films
from . import materials, media as volumes, nee, pdf, shapes
from . import textures as texturing
from .bvh import INF, closest_hit
from .camera import get_ray, get_ray_at
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


@jit
def behind_every_light(sides, p):
    """Is p behind every half-space of `sides` (pack.dark_sides; none: no)?"""
    if sides.shape[0] == 0:
        return False
    for j in range(sides.shape[0]):
        if sides[j, 0] * p[0] + sides[j, 1] * p[1] + sides[j, 2] * p[2] >= sides[j, 3]:
            return False
    return True


@jit
def roulette(tr, tg, tb, state):
    """Russian roulette: (survives, throughput, state); a path goes on with
    probability q = its largest channel (at most 1), divided by q (unbiased)."""
    q = min(1.0, max(tr, tg, tb))
    u, state = rng.uniform(state)
    return u < q, tr / q, tg / q, tb / q, state


@jit_row
def render_row(y, film, scene, params, s0, s1, events, quasi, textures, media, motion):
    """Trace samples s0..s1-1 of every pixel of row y into the film.

    events: None for the books' estimators; for next-event estimation, the
    segment from which Russian roulette may end a path (0: never).  Every use is
    an `events is not None` test on the argument itself, which Numba prunes when
    compiling for None: the books' kernel has none of it, in code or in time.
    quasi: None, or the position in the pixel (pair 0) and the first diffuse
    bounce's direction (pair 1) come from Sobol points keyed by (pixel, sample
    index, pair, seed) (kernel/sobol.py), pruned the same way.
    textures, media, motion: The Next Week's features (above), None when unused.

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
            if quasi is not None:
                jx, jy = sobol.sample_2d(pixel, s, 0, params.seed)
                o, d, state = get_ray_at(params.cam, x, y, width, params.height, jx, jy,
                                         state)
            else:
                o, d, state = get_ray(params.cam, x, y, width, params.height, state)
            if motion is not None:
                time, state = rng.uniform(state)    # on the shutter, for the whole path
            else:
                time = None
            first_diffuse = True            # no diffuse bounce drawn yet (Sobol pair 1)
            # -- the path: radiance (lr, lg, lb) along the camera ray (o, d) --
            lr, lg, lb = 0.0, 0.0, 0.0      # radiance gathered so far
            tr, tg, tb = 1.0, 1.0, 1.0      # path throughput
            er, eg, eb = 0.0, 0.0, 0.0      # emitted towards the camera ray (no firefly)
            # np.int64 / np.bool_: typed as plain int64 and bool from the start,
            # not as the literals -1 and False, or Numba compiles the helpers
            # called apart (nee.py) once more for those literal types.
            from_obj = np.int64(NO_HIT)
            from_inside = np.bool_(False)
            # Density with which the continuation drew d at a diffuse hit (for
            # MIS against next-event estimation); 0: the camera ray or a
            # specular bounce, which next events could not have found.
            continuation = 0.0
            # A shadow ray to trace before the path goes on (nee.py): aimed at
            # emitter `target` (NO_HIT: none) from shadow_o along shadow_d up
            # to shadow_t, carrying (sr, sg, sb) if nothing else is met before.
            target = np.int64(NO_HIT)
            shadow_o, shadow_d, shadow_inside, shadow_t = o, d, False, INF
            sr, sg, sb = 0.0, 0.0, 0.0
            alive = params.max_depth > 0    # False: the path ended (a shadow ray may remain)
            depth = 0
            while target != NO_HIT or alive:
                # The one nearest-hit call: a shadow ray first, else the path's ray.
                shadow = target != NO_HIT
                if shadow:
                    ro, rd, r_inside, r_max = shadow_o, shadow_d, shadow_inside, shadow_t
                else:
                    ro, rd, r_inside, r_max = o, d, from_inside, INF
                k, t = closest_hit(scene, ro, rd, r_max, from_obj, r_inside, time)
                segments += 1
                if shadow:
                    if k == NO_HIT or k == target:     # nothing before the emitter
                        if media is not None:
                            tau = volumes.transmittance(scene, media, ro, rd, r_max, time)
                            sr, sg, sb = sr * tau, sg * tau, sb * tau
                        lr += sr
                        lg += sg
                        lb += sb
                    target = NO_HIT
                    continue
                if media is not None:
                    medium, tm, state = volumes.free_flight(scene, media, o, d, t, time, state)
                    if medium != NO_HIT:
                        # Scattered inside a medium, at no surface.
                        o = madd(o, d, tm)
                        m = scene.obj_i[medium, OBJ_MAT]
                        att = materials.color(scene, m)
                        if textures is not None:
                            att = texturing.color_at(scene, textures, m, NO_HIT, o, att, time)
                        d, w, state = volumes.phase_scatter(
                            scene, o, params.light_weight if use_lights else 0.0, use_lights,
                            time, state)
                        tr *= att[0] * w
                        tg *= att[1] * w
                        tb *= att[2] * w
                        from_obj = np.int64(NO_HIT)
                        from_inside = np.bool_(False)
                        continuation = 0.0      # next events are not drawn here
                        depth += 1
                        alive = depth < params.max_depth and (tr > 0.0 or tg > 0.0 or tb > 0.0)
                        if events is not None:
                            if alive and events > 0 and depth >= events:
                                alive, tr, tg, tb, state = roulette(tr, tg, tb, state)
                        continue
                if k == NO_HIT:
                    e = background(scene, d)
                    lr += tr * e[0]
                    lg += tg * e[1]
                    lb += tb * e[2]
                    break
                p = madd(o, d, t)
                n_out = shapes.outward_normal(scene, k, p, time)
                front_face, n = face_normal(d, n_out)
                m = scene.obj_i[k, OBJ_MAT]
                color = materials.color(scene, m)
                if textures is not None:
                    color = texturing.color_at(scene, textures, m, k, p, color, time)
                emits, e = materials.emitted(scene, m, front_face, color)
                if emits:
                    w = 1.0
                    if events is not None:
                        if continuation > 0.0:
                            w = nee.power_heuristic(continuation, nee.emitter_pdf(
                                scene, k, o, d, from_obj, from_inside, time))
                    lr += tr * e[0] * w
                    lg += tg * e[1] * w
                    lb += tb * e[2] * w
                    if depth == 0:
                        er, eg, eb = e[0], e[1], e[2]
                scatters, specular, d_out, att, state = materials.scatter(
                    scene, m, d, n, front_face, color, state)
                if not scatters:
                    break
                # The mixture's weight on the lights list here (Sampling.facing:
                # none where no light shines; then the cosine alone).
                lw = params.light_weight
                if quasi is not None:
                    if behind_every_light(scene.dark_sides, p):
                        lw = 0.0
                if events is not None:
                    if not specular:
                        target, shadow_d, shadow_inside, shadow_t, c, state = nee.shadow_ray(
                            scene, k, p, n, n_out, lw, state, time, textures)
                        shadow_o = p
                        sr, sg, sb = (tr * att[0] * c[0], tg * att[1] * c[1],
                                      tb * att[2] * c[2])
                drawn = False
                if quasi is not None:
                    if not specular and first_diffuse:
                        u1, u2 = sobol.sample_2d(pixel, s, 1, params.seed)
                        d, state = pdf.mixture_at(scene, p, n, lw if use_lights else 0.0, u1,
                                                  u2, state, time)
                        drawn = True
                        first_diffuse = False
                if drawn:
                    pass
                elif specular:
                    d = d_out
                elif use_lights:
                    d, state = pdf.mixture_generate(scene, p, n, lw, state, time)
                else:
                    d, state = pdf.cosine_generate(n, state)
                from_inside = shapes.enters(scene, k, n_out, d)
                from_obj = k
                o = p
                continuation = 0.0
                depth += 1
                alive = depth < params.max_depth
                if specular or not (use_lights or events is not None):
                    # Followed with weight = attenuation (for cosine sampling
                    # alone, scattering_pdf / pdf == 1).
                    tr *= att[0]
                    tg *= att[1]
                    tb *= att[2]
                else:
                    # Importance-sampling the mixture pdf (or cosine's, whose
                    # density next-event MIS needs).
                    density = nee.continuation_pdf(scene, p, n, lw, d, k, from_inside, time)
                    scattering = pdf.cosine_value(n, d)
                    # A direction below the surface, or one no component can
                    # make, carries no light: stop instead of dividing by zero.
                    if scattering <= 0.0 or density <= 0.0:
                        alive = False
                    else:
                        w = scattering / density
                        tr *= att[0] * w
                        tg *= att[1] * w
                        tb *= att[2] * w
                        continuation = density
                if events is not None:
                    spin = alive and events > 0 and depth >= events
                else:
                    spin = False
                if spin:
                    # Dim paths end early, unbiased.
                    alive, tr, tg, tb, state = roulette(tr, tg, tb, state)
            films.add_sample(film, y, x, s, lr, lg, lb, params.clamp, er, eg, eb)
    film.row_stats[y, SEGMENTS] += segments
