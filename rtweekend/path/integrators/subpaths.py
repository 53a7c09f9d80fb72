"""The two subpaths of bidirectional path tracing: one from the camera, one
from a light, each a random walk that records its vertices (vertices.py).

Both walks bounce as the path tracer and the light tracer do -- a material's
own sampling at a surface, the isotropic phase function in a medium, Russian
roulette from ROULETTE_VERTICES on -- and record at each new vertex the area
density it was drawn with (FWD) and, once the next direction is known, the
density of drawing the previous vertex the other way (its REV: Veach's
reverse pdf).  A delta material has neither: both are left 0 and the MIS
weights skip them (bdpt.py).

The camera subpath starts at the lens with the pixel's ray (throughput 1) and
may hold max_depth + 1 vertices; the light subpath starts at a point of an
emitter picked by power and drawn by area (lights.py), density FWD = P(row) /
area, leaves it along the cosine lobe about its front with throughput
Le pi / FWD, and may hold max_depth vertices, so that every strategy's path
has at most max_depth segments; its refractions carry the adjoint's weight
(materials.adjoint).
"""
import math

import numpy as np

from ...kernel import sampler
from ...kernel.jit import jit_step
from ...kernel.vec3 import madd, mul, neg, scale
from .. import camera, lights, materials, media as volumes, shapes
from ..bvh import closest_hit
from ..layout import NO_HIT
from ..materials import isotropic, lambertian
from ..roulette import roulette
from ..surface import color_of, surface_at
from .vertices import BACK, CAMERA, LIGHT, MEDIUM, REV, SURFACE, put

INF = math.inf
ONE = (1.0, 1.0, 1.0)
ZERO = (0.0, 0.0, 0.0)
ROULETTE_VERTICES = 3      # a subpath of this many vertices may end by roulette


@jit_step
def set_reverse(vf, i, pdf):
    """Vertex i's REV: its area density as drawn with solid-angle density pdf
    from vertex i + 1 (whose BACK converts it)."""
    vf[i, REV] = pdf * vf[i + 1, BACK]


@jit_step(inline=False)
def walk(scene, path, n, ray, beta, limit, start, adjoint, textures, media, time, smp):
    """Extend the subpath whose vertex arrays are path (vf, vi) and whose last
    vertex is n - 1 up to `limit` vertices, from the ray that leaves it, ray =
    (o, d, pdf_dir, from_obj, from_inside): at o along d, drawn with
    solid-angle density pdf_dir, with throughput beta; adjoint: it carries
    light (materials.adjoint).  Returns (vertices, escaped, d, beta, segments,
    smp): escaped, the last ray left the scene along d with throughput beta."""
    vf, vi = path
    o, d, pdf_dir, from_obj, from_inside = ray
    segments = 0
    while n < limit:
        k, t = closest_hit(scene, o, d, INF, from_obj, from_inside, time)
        segments += 1
        if media is not None:
            medium, tm, smp = volumes.free_flight(scene, media, o, d, t, time, smp)
            if medium != NO_HIT:            # scattered in a medium, at no surface
                p = madd(o, d, tm)
                albedo = color_of(scene, textures, medium, p, np.int64(NO_HIT), time)
                put(path, n, MEDIUM, p, (ZERO, ZERO), beta, albedo, materials.NO_PARAMS, NO_HIT,
                    materials.kind_of(scene, medium),
                    False, pdf_dir)
                n += 1
                if n >= limit:
                    break
                d, state = isotropic.sample(smp.state)
                smp = sampler.resume(smp, state)
                pdf_dir = isotropic.pdf()
                set_reverse(vf, n - 2, pdf_dir)
                beta = mul(beta, albedo)
                o, from_obj, from_inside = p, np.int64(NO_HIT), np.bool_(False)
                if n >= ROULETTE_VERTICES:
                    alive, beta, smp = roulette(beta, start, smp)
                    if not alive:
                        break
                continue
        if k == NO_HIT:
            return n, True, d, beta, segments, smp
        hit = surface_at(scene, textures, k, o, d, t, time)
        bsdf = materials.at(scene, hit)
        ns = hit.n if hit.front else neg(hit.n)        # the shading normal, outward
        put(path, n, SURFACE, hit.p, (hit.n_out, ns), beta, hit.albedo, bsdf.params, k,
            bsdf.kind, materials.delta(bsdf), pdf_dir)
        n += 1
        if n >= limit or not materials.scatters(bsdf):
            break
        wo = neg(d)
        d, weight, density, delta, smp = materials.sample_by_turns(bsdf, wo, smp)
        if density == 0.0:
            break                               # absorbed
        if delta:
            pdf_dir = 0.0                       # no density: MIS skips the vertex
        else:
            pdf_dir = density
            # The reverse density: wo drawn having come from d.
            set_reverse(vf, n - 2, materials.reverse_pdf(bsdf, wo, d))
        if adjoint:
            weight = scale(weight, materials.adjoint(bsdf, wo, d))
        beta = mul(beta, weight)
        o, from_obj = hit.p, k
        from_inside = shapes.enters(scene, k, hit.n_out, d)
        if n >= ROULETTE_VERTICES:
            alive, beta, smp = roulette(beta, start, smp)
            if not alive:
                break
    return n, False, d, beta, segments, smp


@jit_step
def camera_subpath(scene, params, vf, vi, x, y, textures, media, time, smp):
    """The camera subpath of a sample of pixel (x, y): (vertices, escaped, d,
    beta, segments, smp) as walk returns them."""
    o, d, smp = camera.sample_ray(params.cam, x, y, params.width, params.height, smp)
    put((vf, vi), 0, CAMERA, o, (ZERO, ZERO), ONE, ZERO, materials.NO_PARAMS, NO_HIT, 0, False,
        1.0)
    ray = (o, d, camera.pdf_direction(params.cam, d), np.int64(NO_HIT), np.bool_(False))
    return walk(scene, (vf, vi), 1, ray, ONE, params.max_depth + 1, 1.0, False, textures, media,
                time, smp)


@jit_step
def light_subpath(scene, params, vf, vi, textures, media, time, smp):
    """The light subpath of a sample: (vertices, segments, smp)."""
    k, p, n, emit, origin, smp = lights.light_point(scene, textures, time, smp)
    put((vf, vi), 0, LIGHT, p, (n, n), scale(emit, 1.0 / origin), emit, materials.NO_PARAMS, k,
        materials.kind_of(scene, k), False,
        origin)
    u1, u2, smp = sampler.next_2d(smp)
    d = lambertian.cosine_lobe(n, u1, u2)     # density cos / pi: Le cos / pdf = Le pi
    beta = scale(emit, math.pi / origin)
    start = max(beta[0], beta[1], beta[2])
    if not start > 0.0 or params.max_depth < 2:
        return 1, 0, smp
    ray = (p, d, lambertian.cosine_pdf(n, d), k, shapes.enters(scene, k, n, d))
    vertices, _, _, _, segments, smp = walk(scene, (vf, vi), 1, ray, beta, params.max_depth, start,
                                            True, textures, media, time, smp)
    return vertices, segments, smp
