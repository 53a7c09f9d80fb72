"""Bidirectional path tracing (Veach's thesis ch. 10; pbrt-v4's BDPTIntegrator):
per sample, a camera subpath and a light subpath (subpaths.py), and every way
of joining them, each weighted by multiple importance sampling (mis.py).

A strategy (s, t) takes s vertices of the light subpath and t of the camera
subpath and joins their ends (at most max_depth segments in all):

  s = 0      the camera subpath reached an emitter: its radiance (the path
             tracer's own estimate)
  s = 1      next-event estimation: a point drawn anew on an emitter, joined
             to camera vertex t - 1 by a shadow ray
  t = 1      light tracing: light vertex s - 1 joined to a point of the lens
             and splatted into the pixel it lands in (film.add_splat)
  s, t >= 2  light vertex s - 1 joined to camera vertex t - 1:
             beta_l f_l G f_c beta_c, G = |cos_l cos_c| / distance^2

Only smooth vertices are joined (vertices.connectible): metal (the books' fuzz
has no density) and glass are followed by both subpaths and never joined, so
light that reaches the camera through them alone -- a caustic seen in a
mirror -- comes from the strategies that sample through them.  Connections
through media carry their transmittance.  A ray that leaves the scene takes
the background's radiance with weight 1: no light subpath starts there.

With params.only_s/only_t set, one strategy is rendered alone with weight 1
(pbrt's per-strategy images): what it adds is every path of s + t vertices it
can draw, which the tests compare with the path tracer's.

The camera's part of each sample goes to its own pixel (film.add_sample) and
light tracing's to any pixel, atomically and exactly (film.py), so the image
is the same for any thread count, pass split or cluster.
"""
import math

import numpy as np

from ...kernel import sampler
from ...kernel.ref import by_ref
from ...kernel.jit import jit_kernel, jit_step
from ...kernel.vec3 import add, at_most, dot, mul, neg, scale
from .. import camera, lights, materials, media as volumes, shapes
from .. import film as films
from ..bvh import unoccluded
from ..film import CONNECTIONS, UNSOLVED
from ..layout import EMITTED, NO_HIT
from ..lights import background
from ..materials import EMITS
from . import caustics as caustic_paths
from . import mis, photons, pixels, through_glass
from .needs import Needs
from .sampling import Sampling
from .subpaths import camera_subpath, light_subpath
from .vertices import (BACK, BETA, COLOR, DELTA, FWD, MEDIUM, MKIND, NF, NG, NI, NS, OBJ, P,
                       SURFACE, TYPE, WO, area_factor, back_density, col, connectible,
                       direction_pdf, light_scatter, on_surface, scatter, toward)


def _features(strategy, scene, arrays):
    return {**photons.features(strategy, scene, arrays),
            **through_glass.features(strategy, scene, arrays)}


def _runs_as(strategy, scene):
    return photons.runs_as(strategy, scene) or through_glass.runs_as(strategy, scene)


# Light tracing's strategies splat (film.py); the photon maps' needs
# (photons.py), the manifold connections' (through_glass.py).
NEEDS = Needs(splats=True, lights=photons.aimed_lights, features=_features,
              runs_as=_runs_as, extra_bytes=photons.extra_bytes,
              kernels=photons.kernels, block=photons.block)
STRATEGIES = {
    # Bidirectional path tracing (pbrt's bdpt): every way of joining a camera
    # subpath to a light subpath, weighted by MIS.
    "bdpt": Sampling(0.0, estimator="bdpt"),
    # +sobol: the position in the pixel and the camera subpath's first bounce.
    "bdpt+sobol": Sampling(0.0, sobol_pairs=2, estimator="bdpt"),
    # bdpt+sobol, and caustic photon maps for the diffuse surfaces seen through
    # glass or in mirrors (consistent: their bias shrinks as samples add up).
    "bdpt+photons": Sampling(0.0, sobol_pairs=2, estimator="bdpt", photons=True),
    # bdpt+sobol, and manifold connections through smooth glass for the surfaces
    # seen through glass or in mirrors (through_glass.py; unbiased).
    "bdpt+mnee": Sampling(0.0, sobol_pairs=2, estimator="bdpt", manifold=True),
}
ZERO = (0.0, 0.0, 0.0)
INV_PI = 1.0 / math.pi
# A connection's far end may be found by the search a rounding short of it.
REACHED = 1.0 - 1e-9


@jit_step
def nonzero(c):
    return c[0] > 0.0 or c[1] > 0.0 or c[2] > 0.0


@jit_step(inline=False)
def clear(scene, p, obj, n, w, dist, target, media, time):
    """The fraction of light that crosses from p (on object obj, normal n;
    NO_HIT in a medium) along w to the point at `dist` on object `target`:
    0 if anything else is in between, else the media's transmittance.

    Called, not inlined: three strategies connect through it (join,
    next_event, to_camera), and one copy of the search it holds, instead of
    three, is seconds less of compile for the same speed."""
    inside = np.bool_(False)
    if obj != NO_HIT:
        inside = shapes.enters(scene, obj, n, w)
    # Anything met short of the far end blocks, the target's own near side
    # included; the end itself, which the search may find a rounding short of
    # dist, must not: hence REACHED.
    reach = dist if target == NO_HIT else dist * REACHED
    if not unoccluded(scene, p, w, reach, obj, inside, time):
        return 0.0
    if media is not None:
        return volumes.transmittance(scene, media, p, w, dist, time)
    return 1.0


@jit_step
def alone(params, s, t):
    """The weight of strategy (s, t) when one is rendered alone: 1 for it, 0 for
    the others (params.only_s >= 0; else MIS weighs them all)."""
    return 1.0 if s == params.only_s and t == params.only_t else 0.0


@jit_step
def emitted(scene, params, cf, ci, t):
    """s = 0: (radiance, MIS weight) of camera vertex t - 1, an emitter,
    towards vertex t - 2 (its front side only)."""
    pt = t - 1
    c = dot(col(cf, pt, WO), col(cf, pt, NG))
    if c <= 0.0:
        return ZERO, 0.0
    if params.only_s >= 0:
        return col(cf, pt, COLOR), alone(params, 0, t)
    if t == 2:
        return col(cf, pt, COLOR), 1.0
    pt_rev = lights.origin_density(scene, ci[pt, OBJ])
    ptm_rev = c * INV_PI * cf[pt, BACK]
    return col(cf, pt, COLOR), mis.weight(cf, ci, cf, ci, 0, t, pt_rev, ptm_rev, 0.0, 0.0, 0.0)


@jit_step
def next_event(scene, params, cf, ci, lf, li, t, textures, media, time, smp):
    """s = 1: (light, rays traced, smp) of a point drawn on an emitter and
    joined to camera vertex t - 1."""
    k, q, nq, emit, origin, smp = lights.light_point(scene, textures, time, smp)
    pt = t - 1
    p = col(cf, pt, P)
    w, dist = toward(p, q)
    cos_q = -dot(w, nq)
    if cos_q <= 0.0:
        return ZERO, 0, smp                     # the emitter's back: it sends nothing
    wo = col(cf, pt, WO)
    f = scatter(scene.glossy, cf, ci, pt, wo, w)
    if not nonzero(f):
        return ZERO, 0, smp
    tr = clear(scene, p, ci[pt, OBJ], col(cf, pt, NG), w, dist, k, media, time)
    if tr == 0.0:
        return ZERO, 1, smp
    cam = params.cam
    pt_rev = cos_q * INV_PI * area_factor(w, dist, col(cf, pt, NG), on_surface(ci, pt))
    qs_rev = direction_pdf(cam, scene.glossy, cf, ci, pt, wo, w) * cos_q / (dist * dist)
    ptm_rev = back_density(cam, scene.glossy, cf, ci, pt, w)
    if params.only_s >= 0:
        w = alone(params, 1, t)
    else:
        w = mis.weight(cf, ci, lf, li, 1, t, pt_rev, ptm_rev, origin, qs_rev, 0.0)
    c = tr * cos_q / (dist * dist * origin) * w
    return scale(mul(mul(col(cf, pt, BETA), f), emit), c), 1, smp


@jit_step
def join(scene, params, cf, ci, lf, li, s, t, media, time):
    """s, t >= 2: (light, rays traced) of light vertex s - 1 joined to camera
    vertex t - 1."""
    pt, qs = t - 1, s - 1
    if not connectible(li, qs):
        return ZERO, 0
    p, q = col(cf, pt, P), col(lf, qs, P)
    w, dist = toward(p, q)
    back = neg(w)
    wo_t, wo_s = col(cf, pt, WO), col(lf, qs, WO)
    f_s = light_scatter(scene.glossy, lf, li, qs, wo_s, back)
    if not nonzero(f_s):
        return ZERO, 0
    f_t = scatter(scene.glossy, cf, ci, pt, wo_t, w)
    if not nonzero(f_t):
        return ZERO, 0
    tr = clear(scene, p, ci[pt, OBJ], col(cf, pt, NG), w, dist, li[qs, OBJ], media, time)
    if tr == 0.0:
        return ZERO, 1
    cam = params.cam
    pt_rev = direction_pdf(cam, scene.glossy, lf, li, qs, wo_s, back) * \
        area_factor(w, dist, col(cf, pt, NG), on_surface(ci, pt))
    ptm_rev = back_density(cam, scene.glossy, cf, ci, pt, w)
    qs_rev = direction_pdf(cam, scene.glossy, cf, ci, pt, wo_t, w) * \
        area_factor(w, dist, col(lf, qs, NG), on_surface(li, qs))
    qsm_rev = back_density(cam, scene.glossy, lf, li, qs, back)
    if params.only_s >= 0:
        w = alone(params, s, t)
    else:
        w = mis.weight(cf, ci, lf, li, s, t, pt_rev, ptm_rev, lf[qs, FWD], qs_rev, qsm_rev)
    c = tr / (dist * dist) * w
    return scale(mul(mul(col(cf, pt, BETA), f_t), mul(f_s, col(lf, qs, BETA))), c), 1


@jit_step
def to_camera(scene, params, film, cf, ci, lf, li, s, source, media, time, smp):
    """t = 1: light vertex s - 1 joined to a point of the lens and splatted
    where it lands.  Returns (rays traced, smp)."""
    qs = s - 1
    if not connectible(li, qs):
        return 0, smp
    q = col(lf, qs, P)
    u1, u2, smp = sampler.next_2d(smp)
    cam = params.cam
    wi, dist, pdf, we, x, y, on_film = camera.sample_lens(cam, params.width, params.height, q,
                                                          u1, u2)
    if not on_film or pdf <= 0.0:
        return 0, smp
    wo_s = col(lf, qs, WO)
    f = light_scatter(scene.glossy, lf, li, qs, wo_s, wi)
    if not nonzero(f):
        return 0, smp
    tr = clear(scene, q, li[qs, OBJ], col(lf, qs, NG), wi, dist, np.int64(NO_HIT), media, time)
    if tr == 0.0:
        return 1, smp
    qs_rev = camera.pdf_direction(cam, neg(wi)) * \
        area_factor(wi, dist, col(lf, qs, NG), on_surface(li, qs))
    qsm_rev = back_density(cam, scene.glossy, lf, li, qs, wi)
    if params.only_s >= 0:
        w = alone(params, s, 1)
    else:
        w = mis.weight(cf, ci, lf, li, s, 1, 0.0, 0.0, lf[qs, FWD], qs_rev, qsm_rev)
    c = we / pdf * tr * w
    films.add_splat(film, min(int(x), params.width - 1), min(int(y), params.height - 1),
                    scale(mul(col(lf, qs, BETA), f), c), params.clamp, source)
    return 1, smp


@jit_step
def first_seen(scene, cf, ci, n, escaped, d, beta):
    """The feature images' (albedo, normal, emission) of the first camera vertex
    that is no mirror or glass (as the path tracer's): beta x its albedo (a
    light's radiance capped at 1, 0 from its back), the normal facing the ray,
    and beta x the light it emits (its s = 0 strategy, whose MIS weight is 1
    when only mirrors and glass lie before it)."""
    for i in range(1, n):
        if ci[i, DELTA] == 0:
            towards = col(cf, i, WO)
            c = col(cf, i, COLOR)
            if ci[i, TYPE] == MEDIUM:
                return mul(col(cf, i, BETA), c), towards, ZERO
            normal = col(cf, i, NS)             # the shading normal, NG's side
            facing = dot(col(cf, i, NG), towards) > 0.0
            if not facing:
                normal = neg(normal)
            if materials.has(ci[i, MKIND], EMITS):
                light = mul(col(cf, i, BETA), c) if facing else ZERO
                c = at_most(c, 1.0) if facing else ZERO
                return mul(col(cf, i, BETA), c), normal, light
            return mul(col(cf, i, BETA), c), normal, ZERO
    if escaped:
        e = background(scene, d)
        return mul(beta, at_most(e, 1.0)), ZERO, mul(beta, e)
    return ZERO, ZERO, ZERO


@jit_step
def camera_strategies(scene, params, camera_path, light_path, nc, nl, textures, media, time,
                      smp, glass, z):
    """Every strategy with t >= 2: (radiance for the pixel, what its camera ray
    saw emitted, rays traced, smp); camera_path, light_path: the subpaths'
    vertex arrays, (floats, ints) each.  With caustic maps or manifold
    connections (glass: the kernel's caustics and manifold), s = 0 leaves out
    the paths they estimate at camera vertex z (caustics.covered)."""
    cf, ci = camera_path
    lf, li = light_path
    radiance, seen, rays = ZERO, ZERO, 0
    has_lights = lights.count(scene, EMITTED) > 0
    for t in range(2, nc + 1):
        pt = t - 1
        if ci[pt, TYPE] == SURFACE and materials.has(ci[pt, MKIND], EMITS):
            if caustic_paths.covered(scene, glass[0], glass[1], cf, ci, z, t, time):
                continue
            e, w = emitted(scene, params, cf, ci, t)
            radiance = add(radiance, scale(mul(col(cf, pt, BETA), e), w))
            if t == 2:
                seen = e
            continue
        if not connectible(ci, pt):
            continue
        if has_lights and t <= params.max_depth:
            light, n, smp = next_event(scene, params, cf, ci, lf, li, t, textures, media, time,
                                       smp)
            radiance, rays = add(radiance, light), rays + n
        for s in range(2, min(nl, params.max_depth + 1 - t) + 1):
            light, n = join(scene, params, cf, ci, lf, li, s, t, media, time)
            radiance, rays = add(radiance, light), rays + n
    return radiance, seen, rays, smp


@jit_step
def bdpt_sample(film, scene, params, y, x, s, smp, state):
    """One sample of pixel (x, y) (pixels.render_row): the camera's part to the
    pixel, light tracing's splatted; with caustic maps (photons.py) or
    manifold connections (through_glass.py) -- glass: the kernel's caustics
    and manifold --, what they give where the camera sees a smooth surface
    through glass or in a mirror (caustics.py).  state: the kernel's features
    and the subpaths' vertex arrays, (floats, ints) each."""
    textures, media, motion, glass, camera_path, light_path = state
    cf, ci = camera_path
    lf, li = light_path
    time, smp = pixels.shutter(motion, smp)         # one time for both subpaths
    nc, escaped, d, beta, segments, smp = camera_subpath(scene, params, cf, ci, x, y,
                                                         textures, media, time, smp)
    mis.accumulate(cf, ci, 1, nc)
    radiance = mul(beta, background(scene, d)) if escaped else ZERO
    if params.only_s >= 0:          # the sky: strategy (0, nc + 1) alone
        radiance = scale(radiance, alone(params, 0, nc + 1))
    if film.albedo.shape[0] > 0:    # feature images: a run-time test, no variant
        albedo, normal, light = first_seen(scene, cf, ci, nc, escaped, d, beta)
        films.add_features(film, y, x, albedo, normal)
        films.add_emission(film, y, x, light)
    z, light, counts, smp = caustic_paths.seen(scene, glass[0], glass[1], s, cf, ci, nc,
                                               params.max_depth, textures, time, smp)
    if z > 0:
        radiance = add(radiance, light)
    if glass[1] is not None:             # manifold connections: what they did
        segments += counts[0]
        film.row_stats[y, CONNECTIONS] += counts[1]
        film.row_stats[y, UNSOLVED] += counts[2]
    nl = 0
    if lights.count(scene, EMITTED) > 0:
        nl, n, smp = light_subpath(scene, params, lf, li, textures, media, time, smp)
        segments += n
        mis.accumulate(lf, li, 0, nl)
    light, seen, n, smp = camera_strategies(scene, params, camera_path, light_path,
                                            nc, nl, textures, media, time, smp, glass, z)
    radiance, segments = add(radiance, light), segments + n
    for sl in range(2, min(nl, params.max_depth) + 1):
        n, smp = to_camera(scene, params, film, cf, ci, lf, li, sl, y, media, time, smp)
        segments += n
    return radiance, seen, segments


@jit_kernel
def render_pass(film, scene, params, queue, s0, s1, events, textures, media, motion, caustics,
                manifold):
    """The samples s0..s1-1 of the pixels of the rows this thread claims from
    the queue (kernel/rows.py), with one pair of subpath arrays for all of them."""
    n = params.max_depth + 2
    cf, ci = np.zeros((n, NF)), np.zeros((n, NI), dtype=np.int64)
    lf, li = np.zeros((n, NF)), np.zeros((n, NI), dtype=np.int64)
    film_r, scene_r, params_r, textures_r = (by_ref(film), by_ref(scene), by_ref(params),
                                             by_ref(textures))
    caustics_r = by_ref(caustics)
    pixels.render_rows(bdpt_sample, queue, film_r, scene_r, params_r, s0, s1,
                       (textures_r, media, motion, (caustics_r, manifold), (cf, ci), (lf, li)))
