"""Light tracing: paths start on the lights and connect to the camera (Veach's
particle tracing; pbrt-v4's LightPathIntegrator, Mitsuba 3's ptracer).

Each sample key (pixel, s) draws one light path, not tied to its pixel: a
light row picked by power and a point on it by area (lights.py), a direction
from the cosine lobe about its front, then bounces as a camera path does --
delta materials followed with their weight, smooth ones sampled by the
material, constant media scattering by their phase function, Russian roulette.
At its start and at every smooth or medium vertex the path is connected to a
point of the lens (camera.sample_lens): if nothing is in between, the light it
brings is splatted into the pixel it lands in (film.add_splat), so the film
adds up every pixel's light from every thread's paths.

The throughput of a light path starts at Le / p(point) x pi (the cosine draw
cancels cos / pi) and is multiplied by each bounce's weight f |cos| / pdf, the
cosine of the new direction, and, where transport in this direction is not
symmetric, by materials.adjoint: at a refraction, and where a smooth mesh
shades with a normal that is not its geometric one (on connections too:
materials.eval_adjoint).  A connection adds beta x f(wo, towards the lens)
|cos| x W_e / p_lens, which film.py divides by spp.

What it renders well: light reaching smooth surfaces through glass or off a
mirror (caustics), which camera paths find only by chance.  What it cannot:
a delta surface seen by the camera (a mirror, glass: black), and a background
that emits (the scene must have a black one; renderer.freeze says so).
max_depth counts segments as the path tracer's does, the last one to the camera
included, so both render the same set of paths.
"""
import math

import numpy as np

from ...errors import SceneError
from ...kernel import sampler
from ...kernel.ref import by_ref
from ...kernel.jit import jit_kernel, jit_step
from ...kernel.vec3 import madd, mul, neg, scale
from .. import camera, lights, materials, media as volumes, shapes
from .. import film as films
from ..bvh import closest_hit, unoccluded
from ..layout import BG_COLOR, NO_HIT
from ..materials import isotropic, lambertian
from ..roulette import roulette
from ..surface import color_of, surface_at
from . import pixels
from .needs import Needs
from .sampling import Sampling


def _check(sampling, arrays):
    """Light tracing starts every path on an emitter: a scene must have one, and
    no light may come from the background, which such paths never leave from."""
    if len(lights.emitters(arrays)) == 0:
        raise SceneError(f"render: sampling: {sampling} starts its paths on the scene's "
                         "emitters (diffuse_light), and this scene has none")
    if arrays.bg_kind != BG_COLOR or arrays.bg.any():
        raise SceneError(f"render: sampling: {sampling} starts its paths on emitters, so it "
                         "cannot render the light of this scene's background; use "
                         "another sampling, or a black background")


# Its film has the splat arrays (film.py); no path from the camera to see features.
NEEDS = Needs(splats=True, feature_images=False, check=_check)
# Light tracing (pbrt's lightpath): caustics on smooth surfaces, no glass seen.
STRATEGIES = {"lightpath": Sampling(0.0, estimator="light")}

ZERO = (0.0, 0.0, 0.0)
ROULETTE_DEPTH = 2      # segments before Russian roulette may end a path


@jit_step
def to_lens(params, p, smp):
    """(wi, distance, W_e / p_lens, x, y, on_film, smp): a point of the lens
    seen from p, and the factor a connection to it carries."""
    u1, u2, smp = sampler.next_2d(smp)
    wi, dist, pdf, we, x, y, on_film = camera.sample_lens(params.cam, params.width,
                                                          params.height, p, u1, u2)
    if not on_film or pdf <= 0.0:
        return wi, dist, 0.0, x, y, False, smp
    return wi, dist, we / pdf, x, y, True, smp


@jit_step
def deliver(scene, params, film, light, p, lens, from_obj, from_inside, source, time, media):
    """Splat `light` at pixel (x, y) if the segment from p towards the lens is
    clear (and through the media's transmittance); lens = (wi, dist, x, y), the
    direction and distance to the point on the lens and where it lands on the
    film (to_lens)."""
    wi, dist, x, y = lens
    if not unoccluded(scene, p, wi, dist, from_obj, from_inside, time):
        return
    if media is not None:
        light = scale(light, volumes.transmittance(scene, media, p, wi, dist, time))
    films.add_splat(film, min(int(x), params.width - 1), min(int(y), params.height - 1),
                    light, params.clamp, source)


@jit_step
def connect_surface(scene, params, film, hit, bsdf, wo, beta, source, time, media, smp):
    """Connect a smooth surface vertex (light arriving from wo with throughput
    beta) to the camera."""
    wi, dist, c, x, y, on_film, smp = to_lens(params, hit.p, smp)
    if not on_film:
        return smp
    att, f = materials.eval(bsdf, wo, wi, c * materials.eval_adjoint(bsdf, wo, wi))
    if f > 0.0:
        deliver(scene, params, film, (beta[0] * att[0] * f, beta[1] * att[1] * f,
                                      beta[2] * att[2] * f), hit.p, (wi, dist, x, y), hit.obj,
                shapes.enters(scene, hit.obj, hit.n_out, wi), source, time, media)
    return smp


@jit_step
def connect_medium(scene, params, film, p, albedo, beta, source, time, media, smp):
    """Connect a point where the path scattered in a medium (isotropic phase
    function, no cosine) to the camera."""
    wi, dist, c, x, y, on_film, smp = to_lens(params, p, smp)
    if on_film:
        f = isotropic.pdf() * c
        deliver(scene, params, film, scale(mul(beta, albedo), f), p, (wi, dist, x, y),
                NO_HIT, False, source, time, media)
    return smp


@jit_step
def start_on_a_light(scene, params, film, source, time, textures, media, smp):
    """A light path's first vertex: connected to the camera, then its first
    direction.  Returns (p, direction, emitter, from_inside, throughput, smp);
    throughput 0: no path."""
    k, p, n, emit, origin, smp = lights.light_point(scene, textures, time, smp)
    beta = scale(emit, 1.0 / origin)             # Le / p(point)
    # The light seen directly: the emitter's cosine towards the lens (its front only).
    wi, dist, c, x, y, on_film, smp = to_lens(params, p, smp)
    cosine = wi[0] * n[0] + wi[1] * n[1] + wi[2] * n[2]
    if on_film and cosine > 0.0 and params.max_depth >= 1:
        deliver(scene, params, film, scale(beta, cosine * c), p, (wi, dist, x, y), k,
                shapes.enters(scene, k, n, wi), source, time, media)
    u1, u2, smp = sampler.next_2d(smp)
    d = lambertian.cosine_at(n, u1, u2)       # about the front: the density is cos / pi
    return p, d, k, shapes.enters(scene, k, n, d), scale(beta, math.pi), smp


@jit_step
def trace_light(scene, params, film, source, time, textures, media, smp):
    """One light path, its connections splatted: (segments traced, smp)."""
    o, d, from_obj, from_inside, beta, smp = start_on_a_light(scene, params, film, source,
                                                              time, textures, media, smp)
    start = max(beta[0], beta[1], beta[2])
    segments, depth = 0, 0
    while start > 0.0 and depth + 1 < params.max_depth:
        k, t = closest_hit(scene, o, d, math.inf, from_obj, from_inside, time)
        segments += 1
        depth += 1
        if media is not None:
            medium, tm, smp = volumes.free_flight(scene, media, o, d, t, time, smp)
            if medium != NO_HIT:
                o = madd(o, d, tm)
                albedo = color_of(scene, textures, medium, o, np.int64(NO_HIT), time)
                smp = connect_medium(scene, params, film, o, albedo, beta, source, time, media,
                                     smp)
                d, state = isotropic.sample(smp.state)
                smp = sampler.resume(smp, state)
                beta = mul(beta, albedo)
                from_obj, from_inside = np.int64(NO_HIT), np.bool_(False)
                if depth >= ROULETTE_DEPTH:
                    alive, beta, smp = roulette(beta, start, smp)
                    if not alive:
                        break
                continue
        if k == NO_HIT:
            break
        hit = surface_at(scene, textures, k, o, d, t, time)
        bsdf = materials.at(scene, hit)
        if not materials.scatters(bsdf):
            break                               # a light absorbs what reaches it
        wo = neg(d)
        if not materials.delta(bsdf):
            smp = connect_surface(scene, params, film, hit, bsdf, wo, beta, source, time, media,
                                  smp)
        d, weight, density, _, smp = materials.sample(bsdf, wo, smp)
        if density == 0.0:
            break
        beta = mul(beta, scale(weight, materials.adjoint(bsdf, wo, d)))
        o, from_obj = hit.p, np.int64(k)
        from_inside = shapes.enters(scene, k, hit.n_out, d)
        if depth >= ROULETTE_DEPTH:
            alive, beta, smp = roulette(beta, start, smp)
            if not alive:
                break
    return segments, smp


@jit_step
def light_sample(film, scene, params, y, x, s, smp, state):
    """The light path of a sample of pixel (x, y) (pixels.render_row; the
    pixel is its key), splatting what it brings to the camera.  The camera's
    part of the pixel: nothing (the film keeps its counts)."""
    textures, media, motion = state
    time, smp = pixels.shutter(motion, smp)
    n, smp = trace_light(scene, params, film, y, time, textures, media, smp)
    return ZERO, ZERO, n


@jit_kernel
def render_pass(film, scene, params, queue, s0, s1, events, textures, media, motion,
                caustics, manifold):
    """The light paths of samples s0..s1-1 of the pixels of the rows this
    thread claims from the queue (kernel/rows.py); their splats may land
    anywhere, atomically (film.py)."""
    film_r, scene_r, params_r, textures_r = (by_ref(film), by_ref(scene), by_ref(params),
                                             by_ref(textures))
    pixels.render_rows(light_sample, queue, film_r, scene_r, params_r, s0, s1,
                       (textures_r, media, motion))
