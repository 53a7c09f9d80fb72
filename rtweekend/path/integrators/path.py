"""The path tracer: The Rest of Your Life's integrator, and next-event estimation.

One camera sample is a loop over path segments (`trace`), each step a
function below:

  the nearest hit   one call of bvh.closest_hit, for the path's ray or for a
                    pending shadow ray (one call site: each inlined copy of the
                    search costs seconds of compile)
  in a medium       media.py: the ray may scatter before the surface it found
  escaping          the background's radiance
  emission          what the surface emits towards the ray, MIS-weighted
                    against next-event estimation after a smooth bounce
  a delta bounce    the material's own direction, weight = its attenuation
  a smooth bounce   a shadow ray to an emitter (nee.py), then the next
                    direction from the books' mixture pdf (pdf.py) or the
                    material's sampling, weight = f |cos| / pdf
  roulette          dim paths end early, unbiased (next-event estimation only)

light_weight (PathParams) is the mixture's share of the lights list: the books
use 0.5, 0 is The Next Week's cosine sampling, 1 samples lights only; a glossy
hit draws from its own lobe alone.  max_depth
counts ray segments, as the books' depth does; shadow rays count as rays in the
statistics, not as segments of max_depth.

`events` is None for the books' estimators, else the segment from which
Russian roulette may end a path (0: never); textures, media and motion are The
Next Week's features, None for a scene without them.  Each is tested with
`is None` on an argument, which Numba prunes when compiling for None: a kernel
holds only the code its scene and strategy use.
"""
import math
from typing import NamedTuple

import numpy as np

from ...kernel import sampler
from ...kernel.ref import by_ref
from ...kernel.jit import jit_kernel, jit_step
from ...kernel.vec3 import add, at_most, madd, mul, neg, scale
from .. import film as films
from .. import lights, materials, media as volumes, mnee, nee, pdf, shapes
from . import pixels
from .needs import Needs, emitters_left_out
from .sampling import Sampling
from ..bvh import closest_hit
from ..camera import sample_ray
from ..film import CONNECTIONS, UNSOLVED
from ..layout import LISTED, NO_HIT
from ..roulette import roulette
from ..lights import background
from ..surface import color_of, surface_at

INF = math.inf


def _lights(strategy, arrays):
    """Next events reach the emitters by shadow rays (needs.emitters_left_out)."""
    return emitters_left_out(arrays) if _next_events(strategy, arrays) else arrays


def _features(strategy, scene, arrays):
    """With next events, Russian roulette from strategy.roulette_depth; with
    manifold connections (strategy.manifold), `manifold` on: light through
    smooth glass (mnee.py), in a scene without media."""
    if not _next_events(strategy, arrays):
        return {}
    features = {"events": strategy.roulette_depth}
    if strategy.manifold and not any(s.medium for s in scene.objects):
        features["manifold"] = mnee.MAX_CHAIN
    return features


def _next_events(strategy, arrays):
    return strategy.next_event and len(lights.emitters(arrays)) > 0


NEEDS = Needs(splats=False, lights=_lights, features=_features)   # samples only (film.py)
STRATEGIES = {
    "cosine": Sampling(0.0),             # The Next Week
    "mixture": Sampling(0.5),            # The Rest of Your Life
    "light": Sampling(1.0),              # the lights list only
    "nee": Sampling(0.5, next_event=True, roulette_depth=1),
    # Ours beyond the books: Sobol points; no light samples where no light shines.
    # The points: the position in the pixel, then at the first smooth bounce
    # the shadow ray's point on its emitter (nee) and the mixture's point,
    # which picks its component and places its direction (pdf.mixture_sample).
    "mixture+sobol": Sampling(0.5, sobol_pairs=2, facing=True),
    "nee+sobol": Sampling(0.5, next_event=True, roulette_depth=1, sobol_pairs=3, facing=True),
    # nee+sobol, and at each smooth hit a connection to an emitter through smooth
    # glass (manifold next-event estimation, manifold.py); the paths it renders
    # -- a smooth vertex, 1 .. MAX_CHAIN refractions, an emitter -- the
    # continuation leaves out.  Sobol pairs: the pixel, the connection, the
    # shadow ray, the mixture.
    "mnee": Sampling(0.5, next_event=True, roulette_depth=1, sobol_pairs=4, facing=True,
                     manifold=True),
}

ZERO = (0.0, 0.0, 0.0)
ONE = (1.0, 1.0, 1.0)


class Shadow(NamedTuple):
    """A shadow ray to trace before the path goes on: aimed at emitter `target`
    (NO_HIT: none) from o along d up to t, adding `light` if nothing else is
    met before (nee.py)."""
    target: np.int64
    o: tuple
    d: tuple
    inside: bool
    t: float
    light: tuple


@jit_step
def no_shadow(o, d):
    return Shadow(np.int64(NO_HIT), o, d, np.bool_(False), INF, ZERO)


@jit_step
def roulette_after(events, alive, depth, beta, smp):
    """Roulette from segment `events` on (next-event estimation only)."""
    if events is not None:
        if alive and events > 0 and depth >= events:
            return roulette(beta, 1.0, smp)
    return alive, beta, smp


@jit_step
def shadow_light(scene, media, shadow, k, time):
    """What a traced shadow ray adds: its light if the first thing it met is its
    emitter (or nothing, by a rounding), times the media's transmittance."""
    if k != NO_HIT and k != shadow.target:
        return ZERO
    if media is not None:
        tau = volumes.transmittance(scene, media, shadow.o, shadow.d, shadow.t, time)
        return scale(shadow.light, tau)
    return shadow.light


@jit_step
def scatter_in_medium(scene, params, textures, medium, p, use_lights, time, smp):
    """(direction, weight, albedo, smp) at p, where the ray scattered inside
    `medium` (an object whose material is its phase function)."""
    albedo = color_of(scene, textures, medium, p, np.int64(NO_HIT), time)
    d, w, smp = volumes.phase_scatter(
        scene, p, params.light_weight if use_lights else 0.0, use_lights, time, smp)
    return d, scale(albedo, w), albedo, smp


@jit_step
def first_seen(bsdf, hit, beta):
    """The feature images' (albedo, normal) at the first hit that is no mirror
    or glass (beta: the colour of those on the way): the material's albedo, or
    a light's radiance capped at 1, and the shading normal facing the ray."""
    emits, e = materials.emitted(bsdf)
    if emits or not materials.scatters(bsdf):
        return mul(beta, at_most(e, 1.0)), hit.n
    return mul(beta, bsdf.albedo), hit.n


@jit_step
def emission(scene, hit, bsdf, o, d, from_obj, from_inside, continuation, time, events):
    """(emits, radiance, MIS weight) of what `hit` emits towards the ray from o
    along d.  After a smooth bounce (continuation > 0) next-event estimation
    could have found the same light: the power heuristic weighs the two."""
    emits, e = materials.emitted(bsdf)
    w = 1.0
    if events is not None:
        if emits and continuation > 0.0:
            w = nee.power_heuristic(continuation, nee.emitter_pdf(
                scene, hit.obj, o, d, from_obj, from_inside, time))
    return emits, e, w


@jit_step
def smooth_bounce(scene, params, hit, bsdf, wo, beta, use_lights, events, textures, time, smp):
    """At a hit on a material that evaluates: a shadow ray (next-event
    estimation), then the next direction.  Returns (shadow, d, from_inside,
    weight, continuation, ok, smp): weight = f |cos| / the density d was drawn
    with (continuation, for MIS; 0 when not needed); ok False: d carries no
    light (the path ends)."""
    lw = pdf.mixture_weight(scene, bsdf, hit.p, params.light_weight)
    shadow = no_shadow(hit.p, wo)
    if events is not None:
        # The emitter from the stream, the point on it from the sampler's
        # next 2-D point (a Sobol pair at the first bounce of +sobol).
        u, smp = sampler.uniform(smp)
        u1, u2, smp = sampler.next_2d(smp)
        target, sd, s_inside, st, light = nee.shadow_ray(
            scene, hit.p, hit.n_out, hit.obj, bsdf, wo, lw, beta, (u, u1, u2), time, textures)
        shadow = Shadow(target, hit.p, sd, s_inside, st, light)
    d, weight, smp = pdf.mixture_sample(scene, bsdf, wo, hit.p, hit.obj,
                                        lw if use_lights else 0.0, use_lights, smp, time)
    from_inside = shapes.enters(scene, hit.obj, hit.n_out, d)
    if not (use_lights or events is not None):
        # The material's own draw; one behind a smooth mesh's triangle is absorbed.
        return shadow, d, from_inside, weight, 0.0, not materials.behind(bsdf, d), smp
    density = nee.continuation_pdf(scene, bsdf, wo, hit.p, lw, d, hit.obj, from_inside, time)
    att, scattering = materials.eval(bsdf, wo, d, 1.0)
    # A direction below the surface, or one no component can make, carries no
    # light: stop instead of dividing by zero.
    if scattering <= 0.0 or density <= 0.0:
        return shadow, d, from_inside, weight, 0.0, False, smp
    return shadow, d, from_inside, scale(att, scattering / density), density, True, smp


@jit_step
def trace(scene, params, ray, time, smp, events, textures, media, manifold, film, y, x):
    """The radiance along the camera ray (o, d): (radiance, seen, segments, smp),
    seen being what the camera ray saw emitted (no firefly: film.py).  When the
    film keeps feature images (a run-time test, no variant), the albedo and
    normal of what the path first sees through mirrors and glass, and the light
    it emits, go to pixel (x, y) of the film there and then (nothing more to
    carry round the loop).  manifold: connections through glass, the longest
    chain they solve (None: none; `chain` counts the smooth refractions since
    the last smooth vertex, whose emitter they render instead)."""
    o, d = ray
    looking = film.albedo.shape[0] > 0
    use_lights = lights.count(scene, LISTED) > 0 and params.light_weight > 0.0
    radiance, seen, beta = ZERO, ZERO, ONE
    # np.int64 / np.bool_: typed as plain int64 and bool from the start, not as
    # the literals -1 and False, or Numba compiles the helpers called apart
    # (nee.py) once more for those literal types.
    from_obj, from_inside = np.int64(NO_HIT), np.bool_(False)
    continuation = 0.0      # density d was drawn with at a smooth hit; 0: MIS not needed
    shadow = no_shadow(o, d)
    # manifold: the last smooth vertex (its point, its object), the chain's
    # first refraction, and how many since (-1: a reflection came between).
    chain, smooth_p, smooth_k, first_p = np.int64(-1), o, np.int64(NO_HIT), o
    alive, depth, segments = params.max_depth > 0, 0, 0
    while shadow.target != NO_HIT or alive:
        shadowing = shadow.target != NO_HIT
        if shadowing:
            ro, rd, r_inside, r_max = shadow.o, shadow.d, shadow.inside, shadow.t
        else:
            ro, rd, r_inside, r_max = o, d, from_inside, INF
        k, t = closest_hit(scene, ro, rd, r_max, from_obj, r_inside, time)
        segments += 1
        if shadowing:
            radiance = add(radiance, shadow_light(scene, media, shadow, k, time))
            shadow = no_shadow(o, d)
            continue
        if media is not None:
            medium, tm, smp = volumes.free_flight(scene, media, o, d, t, time, smp)
            if medium != NO_HIT:        # scattered inside a medium, at no surface
                o, towards_camera = madd(o, d, tm), neg(d)
                d, weight, medium_albedo, smp = scatter_in_medium(scene, params, textures,
                                                                  medium, o, use_lights, time,
                                                                  smp)
                if looking:
                    films.add_features(film, y, x, mul(beta, medium_albedo), towards_camera)
                    looking = False
                beta = mul(beta, weight)
                from_obj, from_inside, continuation = np.int64(NO_HIT), np.bool_(False), 0.0
                depth += 1
                alive = depth < params.max_depth and (beta[0] > 0.0 or beta[1] > 0.0 or
                                                         beta[2] > 0.0)
                alive, beta, smp = roulette_after(events, alive, depth, beta, smp)
                continue
        if k == NO_HIT:
            e = background(scene, d)
            radiance = add(radiance, mul(beta, e))
            if looking:
                films.add_features(film, y, x, mul(beta, at_most(e, 1.0)), ZERO)
                films.add_emission(film, y, x, mul(beta, e))
            break
        hit = surface_at(scene, textures, k, o, d, t, time)
        bsdf = materials.at(scene, hit)
        first = looking and not materials.delta(bsdf)
        if first:
            albedo, normal = first_seen(bsdf, hit, beta)
            films.add_features(film, y, x, albedo, normal)
            looking = False
        emits, e, w = emission(scene, hit, bsdf, o, d, from_obj, from_inside, continuation,
                               time, events)
        if manifold is not None and emits and 1 <= chain <= manifold:
            if mnee.renders(scene, smooth_p, smooth_k, first_p, hit.p, k, chain, time):
                w = 0.0                 # the connection at the last smooth vertex found it
        if emits:
            radiance = add(radiance, scale(mul(beta, e), w))
            if depth == 0:
                seen = e
            if first:                   # through mirrors and glass only: weight 1
                films.add_emission(film, y, x, scale(mul(beta, e), w))
        if not materials.scatters(bsdf):
            break
        wo = neg(d)
        if materials.delta(bsdf):
            d, weight, density, _, smp = materials.sample_delta(bsdf, wo, smp)
            if density == 0.0:
                break                   # absorbed (fuzzed below the surface)
            from_inside, continuation, ok = shapes.enters(scene, k, hit.n_out, d), 0.0, True
            if manifold is not None:
                chain = mnee.through_glass(chain, bsdf.kind, neg(wo), d, hit.n_out)
                if chain == 1:
                    first_p = hit.p
        else:
            if manifold is not None:
                u, smp = sampler.uniform(smp)
                u1, u2, smp = sampler.next_2d(smp)
                light, n, tried, unsolved = mnee.connect(scene, hit.p, k, bsdf, wo, beta,
                                                         (u, u1, u2), time, textures)
                radiance, segments = add(radiance, light), segments + n
                film.row_stats[y, CONNECTIONS] += tried
                film.row_stats[y, UNSOLVED] += unsolved
                chain, smooth_p, smooth_k = np.int64(0), hit.p, k
            shadow, d, from_inside, weight, continuation, ok, smp = smooth_bounce(
                scene, params, hit, bsdf, wo, beta, use_lights, events, textures, time, smp)
        o, from_obj = hit.p, k
        depth += 1
        alive = ok and depth < params.max_depth
        if alive:
            beta = mul(beta, weight)
        alive, beta, smp = roulette_after(events, alive, depth, beta, smp)
    return radiance, seen, segments, smp


@jit_step
def camera_sample(film, scene, params, y, x, s, smp, state):
    """One sample of pixel (x, y) (pixels.render_row): the camera ray, then the
    shutter's time, then its path.  state: the kernel's features."""
    events, textures, media, motion, manifold = state
    o, d, smp = sample_ray(params.cam, x, y, params.width, params.height, smp)
    time, smp = pixels.shutter(motion, smp)
    radiance, seen, n, smp = trace(scene, params, (o, d), time, smp, events, textures, media,
                                   manifold, film, y, x)
    return radiance, seen, n


@jit_kernel
def render_pass(film, scene, params, queue, s0, s1, events, textures, media, motion,
                caustics, manifold):
    """Add samples s0..s1-1 of every pixel of the rows this thread claims from
    the queue (kernel/rows.py) to the film.  Each row is written by the one
    thread that claimed it, and every sum is in sample order, so the film is
    the same whatever the thread count.  None compiles a kernel without a
    feature (above)."""
    film_r, scene_r, params_r, textures_r = (by_ref(film), by_ref(scene), by_ref(params),
                                             by_ref(textures))
    pixels.render_rows(camera_sample, queue, film_r, scene_r, params_r, s0, s1,
                       (events, textures_r, media, motion, manifold))
