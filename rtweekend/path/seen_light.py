"""The light the camera sees emitted, estimated again for the denoiser.

The denoiser keeps the light each pixel's camera rays see emitted -- a lamp in
view, or one seen in a mirror or through glass -- out of what Open Image
Denoise filters, and adds it back after (denoise.py).  The render's own
estimate of that light, the emission feature (film.py), is an average of the
pixel's samples: where the light varies inside a pixel (a light's edge, the
light's small image in a glass ball) it is as noisy as those samples are few,
and the filter, which never sees it, cannot take that noise out.  This pass
estimates the same light again, with many cheap rays, where it varies:

  pilot     a ray through every corner of the pixels and one through each
            pixel's centre, each followed through mirrors and glass to the
            first surface that is neither (or out of the scene); a pixel
            whose corners and centre do not all see the same light (to within
            SPREAD of the brightest) is marked, and so are its 8 neighbours
            (for what lies between the points)
  refine    a marked pixel gets the mean of n such rays through points of the
            pixel: n = N_PER_SPP per sample of the render (N_MIN at least,
            N_MAX at most) down to a power of 2, halved while the marked
            pixels would trace more than SHARE of the render's ray segments;
            below N_MIN, nothing is refined
  elsewhere the render's own estimate stays

The refining rays' points in the pixel are an Owen-scrambled Sobol sequence
(kernel/sobol.py: 2^k points fill the pixel's square evenly, so the part of
it a light covers is found with an error that falls like n^-3/4).  At the
first SPLITS glass surfaces a ray meets it follows both the reflection and
the refraction, weighted by Schlick's reflectance, where the render picks one
with that probability (the same expectation, without the noise of the pick);
after those it picks as the render does.  A fuzzy metal draws its direction
as the render does; media weigh each segment by their transmittance, the
chance that the render's ray crosses it.

Unbiased: both estimates a pixel can get, the render's and the refined one,
have the light seen as their expectation, and which one it gets depends on
the pilot's rays, which are independent of both, and on n, whose budget is
the render's total of ray segments: a sum over every pixel's samples, of
which one pixel's are about 1 / (width x height).
Deterministic: every ray is keyed by (point, index, key), the key being the
render's seed with bits of this pass's own flipped (PILOT_KEY, REFINE_KEY),
so that no number of the render's is drawn (its image is the same bits with
or without the denoiser), and a pixel's estimate is the same for any thread
count.
"""
import math
from typing import NamedTuple

import numpy as np

from ..kernel import sampler
from ..kernel.jit import jit_kernel, jit_step
from ..kernel.ref import by_ref
from ..kernel.rows import interleaved_rows, on_threads
from ..kernel.vec3 import add, mul, neg, scale
from . import materials, media as volumes, shapes
from .bvh import closest_hit
from .camera import get_ray_at
from .layout import NO_HIT
from .lights import background
from .materials import FORKS
from .surface import surface_at

SPREAD = 0.02           # a pixel varies when its pilot rays differ by more, relatively
SPLITS = 2              # glass surfaces at which a ray follows both ways (its stack's rows)
N_PER_SPP = 8           # refining rays per marked pixel and sample rendered, at most
N_MAX = 16384           # ... and in all
N_MIN = 16              # fewer than this: the render's own estimate is kept
SHARE = 0.02            # the refining rays' segments, at most, as a share of the render's
PILOT_KEY = 0x2545F4914F6CDD1D      # xor'd into the seed: streams of this pass's own
REFINE_KEY = 0x1B873593CC9E2D51
INF = math.inf
ZERO = (0.0, 0.0, 0.0)
ONE = (1.0, 1.0, 1.0)


class Refined(NamedTuple):
    """What estimate did: pixels estimated again, rays each, segments traced."""
    pixels: int
    rays: int
    segments: int


# Columns of a branch waiting on the stack.
ORIGIN, DIRECTION, BETA = 0, 3, 6
FROM_OBJ, FROM_INSIDE, DEPTH = 0, 1, 2


@jit_step
def push(stack_f, stack_i, top, o, d, beta, from_obj, from_inside, depth):
    for c in range(3):
        stack_f[top, ORIGIN + c] = o[c]
        stack_f[top, DIRECTION + c] = d[c]
        stack_f[top, BETA + c] = beta[c]
    stack_i[top, FROM_OBJ] = from_obj
    stack_i[top, FROM_INSIDE] = 1 if from_inside else 0
    stack_i[top, DEPTH] = depth


@jit_step
def _col(a, top, c):
    return (a[top, c], a[top, c + 1], a[top, c + 2])


@jit_step
def light_seen(scene, params, x, y, jx, jy, smp, stack_f, stack_i, textures, media, motion):
    """(light, segments): what the ray through point (x + jx, y + jy) of the
    image sees emitted, directly or through mirrors and glass (both ways at
    the first SPLITS glass surfaces), within max_depth segments as the
    render's paths do; the lens, the time and fuzzy metal from smp's stream."""
    o, d, state = get_ray_at(params.cam, x, y, params.width, params.height, jx, jy, smp.state)
    smp = sampler.resume(smp, state)
    if motion is not None:
        time, smp = sampler.uniform(smp)
    else:
        time = None
    total, beta = ZERO, ONE
    from_obj, from_inside = np.int64(NO_HIT), np.bool_(False)
    depth, top, splits, segments = 0, 0, 0, 0
    while True:
        k, t = closest_hit(scene, o, d, INF, from_obj, from_inside, time)
        segments += 1
        if media is not None:
            beta = scale(beta, volumes.transmittance(scene, media, o, d, t, time))
        going = False
        if k == NO_HIT:
            total = add(total, mul(beta, background(scene, d)))
        else:
            hit = surface_at(scene, textures, k, o, d, t, time)
            bsdf = materials.at(scene, hit)
            if not materials.delta(bsdf):
                emits, e = materials.emitted(bsdf)
                if emits:
                    total = add(total, mul(beta, e))
            elif depth + 1 < params.max_depth:
                if materials.has(bsdf.kind, FORKS) and splits < stack_f.shape[0]:
                    r, tr, reflectance = materials.branches(bsdf, d)
                    beta = mul(beta, bsdf.albedo)
                    d = r
                    if reflectance < 1.0:
                        if reflectance > 0.0:
                            push(stack_f, stack_i, top, hit.p, r, scale(beta, reflectance), k,
                                 shapes.enters(scene, k, hit.n_out, r), depth + 1)
                            top, splits = top + 1, splits + 1
                        beta, d = scale(beta, 1.0 - reflectance), tr
                    going = True
                else:
                    d, weight, density, _, smp = materials.sample_delta(bsdf, neg(d), smp)
                    if density > 0.0:
                        beta = mul(beta, weight)
                        going = True
                if going:
                    o, from_obj = hit.p, k
                    from_inside = shapes.enters(scene, k, hit.n_out, d)
                    depth += 1
        if not going:
            if top == 0:
                break
            top -= 1
            o, d, beta = (_col(stack_f, top, ORIGIN), _col(stack_f, top, DIRECTION),
                          _col(stack_f, top, BETA))
            from_obj = stack_i[top, FROM_OBJ]
            from_inside = stack_i[top, FROM_INSIDE] != 0
            depth = stack_i[top, DEPTH]
    return total, segments


@jit_kernel
def pilot_pass(corners, centres, segments, scene, params, rows, key, textures, media, motion):
    """The light seen at the corners of the pixels of `rows` (rows of corners:
    0 .. height), and at the centres of those that are rows of pixels;
    segments: the centres' ray segments."""
    width, height = params.width, params.height
    stack_f, stack_i = np.zeros((SPLITS, 9)), np.zeros((SPLITS, 3), dtype=np.int64)
    scene_r, params_r, textures_r = by_ref(scene), by_ref(params), by_ref(textures)
    for j in range(rows.shape[0]):
        y = rows[j]
        for x in range(width + 1):
            smp = sampler.start(y * (width + 1) + x, 0, key, 0)
            v, _ = light_seen(scene_r, params_r, x, y, 0.0, 0.0, smp, stack_f, stack_i,
                              textures_r, media, motion)
            corners[y, x, 0], corners[y, x, 1], corners[y, x, 2] = v
            if y < height and x < width:
                smp = sampler.start(y * width + x, 1, key, 0)
                v, m = light_seen(scene_r, params_r, x, y, 0.5, 0.5, smp, stack_f, stack_i,
                                  textures_r, media, motion)
                centres[y, x, 0], centres[y, x, 1], centres[y, x, 2] = v
                segments[y, x] = m


@jit_kernel
def refine_pass(out, marks, scene, params, rows, n, key, textures, media, motion):
    """out[y, x] = the mean of n rays' light, for the marked pixels of `rows`;
    returns the ray segments traced."""
    stack_f, stack_i = np.zeros((SPLITS, 9)), np.zeros((SPLITS, 3), dtype=np.int64)
    scene_r, params_r, textures_r = by_ref(scene), by_ref(params), by_ref(textures)
    segments = 0
    for j in range(rows.shape[0]):
        y = rows[j]
        for x in range(params.width):
            if not marks[y, x]:
                continue
            r, g, b = 0.0, 0.0, 0.0
            pixel = y * params.width + x
            for s in range(n):
                smp = sampler.start(pixel, s, key, 1)
                jx, jy, smp = sampler.next_2d(smp)
                v, m = light_seen(scene_r, params_r, x, y, jx, jy, smp, stack_f, stack_i,
                                  textures_r, media, motion)
                r, g, b, segments = r + v[0], g + v[1], b + v[2], segments + m
            out[y, x, 0], out[y, x, 1], out[y, x, 2] = r / n, g / n, b / n
    return segments


def varying(corners, centres):
    """The pixels whose four corners and centre see light that differs by more
    than SPREAD of the brightest of them."""
    points = np.stack([corners[:-1, :-1], corners[:-1, 1:], corners[1:, :-1], corners[1:, 1:],
                       centres])
    hi, lo = points.max(axis=0), points.min(axis=0)
    return (hi - lo > SPREAD * hi.max(axis=-1, keepdims=True)).any(axis=-1)


def neighbours(marks):
    """marks spread to each pixel's eight neighbours."""
    padded = np.pad(marks, 1)
    h, w = marks.shape
    out = np.zeros_like(marks)
    for dy in range(3):
        for dx in range(3):
            out |= padded[dy:dy + h, dx:dx + w]
    return out


def rays_per_pixel(marked, per_ray, spp, render_segments):
    """n for `marked` pixels whose rays trace `per_ray` segments, after spp
    samples that traced render_segments: the largest power of 2 (the Sobol
    points' stratification) up to N_PER_SPP x spp (N_MIN at least, N_MAX at
    most) whose segments stay within SHARE of the render's; 0 (refine
    nothing) below N_MIN, or before any sample."""
    if spp < 1:
        return 0
    cap = min(N_MAX, max(N_MIN, N_PER_SPP * spp))
    n = 1 << (cap.bit_length() - 1)
    while n >= N_MIN and marked * n * per_ray > SHARE * render_segments:
        n //= 2
    return n if n >= N_MIN else 0


def kernel_calls(frame):
    """[(kernel, arguments)] of both passes for frame, with no rays: what
    Renderer.compile compiles (kernel/compile_workers.py)."""
    h, w = frame.height, frame.width
    f, none = frame.features, frame.rows[:0]
    return [(pilot_pass, (np.zeros((h + 1, w + 1, 3)), np.zeros((h, w, 3)),
                          np.zeros((h, w), np.int64), frame.scene, frame.params, none, 0,
                          f.textures, f.media, f.motion)),
            (refine_pass, (np.zeros((h, w, 3)), np.zeros((h, w), np.bool_), frame.scene,
                           frame.params, none, 1, 0, f.textures, f.media, f.motion))]


def pilot(frame, threads):
    """(marks, segments per ray in the marked pixels, segments traced): the
    pixels whose light varies (varying), and their neighbours."""
    h, w = frame.height, frame.width
    f, params = frame.features, frame.params
    corners, centres = np.zeros((h + 1, w + 1, 3)), np.zeros((h, w, 3))
    segments = np.zeros((h, w), np.int64)
    on_threads(lambda part: pilot_pass(corners, centres, segments, frame.scene, params, part,
                                       params.seed ^ PILOT_KEY, f.textures, f.media, f.motion),
               interleaved_rows(h + 1), threads)
    marks = varying(corners, centres)
    per_ray = float(segments[marks].mean()) if marks.any() else 1.0
    # The corners' segments are not counted: about one each.
    return neighbours(marks), per_ray, int(segments.sum()) + (h + 1) * (w + 1)


def estimate(frame, emission, spp, render_segments, threads):
    """(light seen HxWx3 float32, Refined): the emission feature, the
    render's estimate after spp samples that traced render_segments ray
    segments, with the pixels where that light varies estimated again."""
    marks, per_ray, traced = pilot(frame, threads)
    marked = int(marks.sum())
    n = rays_per_pixel(marked, per_ray, spp, render_segments)
    out = np.array(emission, dtype=np.float64)
    if n:
        parts = []
        on_threads(lambda part: parts.append(refine_pass(
            out, marks, frame.scene, frame.params, part, n, frame.params.seed ^ REFINE_KEY,
            frame.features.textures, frame.features.media, frame.features.motion)),
            frame.rows, threads)
        traced += sum(parts)
    return out.astype(np.float32), Refined(marked if n else 0, n, traced)
