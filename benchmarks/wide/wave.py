"""The wavefront renderer: rtweekend's estimator, traced a batch of rays at a time.

Work is cut into tiles of pixels; one prange over tiles (two threads).  For one
tile, `render_tile` traces `spw` samples of each of its pixels together, as a
WAVE of P = pixels x spw paths, one ray segment per path at a time:

  camera     one ray per path (rtweekend's get_ray, same random stream)
  intersect  closest hit of every live ray (intersect.py: per-kind loops, objects
             outer, rays inner, vectorised; or the BVH by packets)
  surface    per ray: hit point, normal, front face; background or emission
             added to the path's radiance; the event class (lambertian, metal,
             dielectric, or the path ends)
  compact    a stable counting sort of the live rays by class into the other
             buffer: rays that ended are dropped, those that go on are grouped
             by material, contiguous, in structure-of-arrays form
  shade      one loop per material over its contiguous range: the next
             direction and the throughput (rtweekend's materials.py, pdf.py:
             the mixture of cosine and light sampling for lambertian)
  film       the wave's radiance added to its pixels, in sample order

All paths of a wave are at the same depth, so max_depth is one loop bound.
Rays live in two buffers of the same shape (the sort reads one and writes the
other): a float64 array [fields, capacity] and an int64 one, and the uint64
random states; capacity = P rounded up to whole packets.  Buffers are allocated
once per tile, never per wave.

Every random number is drawn by the same calls in the same order as
rtweekend's render_row (the stream is keyed by pixel and sample), so the two
renderers trace the same paths up to floating-point rounding: the images agree
pixel by pixel, not only in expectation.
"""
import math
import time

import numba
import numpy as np

from rtweekend.kernel import rng
from rtweekend.kernel.rows import interleaved_rows
from rtweekend.kernel.vec3 import dot
from rtweekend.options import RenderOptions, thread_count
from rtweekend.path import materials, pdf, shapes
from rtweekend.path.bvh import closest_hit
from rtweekend.path.camera import get_ray
from rtweekend.path.integrator import background, face_normal
from rtweekend.path.layout import (DIFFUSE_LIGHT, MAT_COLOR, OBJ_MAT)
from rtweekend.path.renderer import freeze

from . import intersect as X
from .jitopts import cycles, kernel, parallel
from .wscene import FLAT, HYBRID, PACKET, wide_scene

INF = math.inf
# Float fields of a ray buffer.
OX, OY, OZ, DX, DY, DZ, TR, TG, TB, NX, NY, NZ, T, IX, IY, IZ = range(16)
NF = 16
# Int fields: the path (index into the wave's radiance), the object the ray
# leaves (from_obj), from_inside, front face, alive, the hit, the event class.
PATH, OBJ, INSIDE, FRONT, ALIVE, HIT, CLS = range(7)
NI = 7
DROP = 3               # event class of a path that ends (LAMBERTIAN..DIELECTRIC: 0..2)
# Phases of the profile (cycles of the time-stamp counter, per tile).
CAMERA, INTERSECT, SURFACE, COMPACT, SHADE, FILM = range(6)
PHASES = ("camera", "intersect", "surface", "compact", "shade", "film")
# Per-tile counters.
SEGMENTS, WAVES = range(2)


@kernel
def per_ray_bvh(n, scene, ox, oy, oz, dx, dy, dz, frm, fin, t, hit):
    """The comparison for weekend: rtweekend's own scalar BVH walk, ray by ray,
    on the SoA batch (the rest of the wave is unchanged)."""
    for i in range(n):
        if t[i] == 0.0:
            continue
        k, tt = closest_hit(scene, (ox[i], oy[i], oz[i]), (dx[i], dy[i], dz[i]), INF,
                            frm[i], fin[i] != 0, None)
        t[i] = tt
        hit[i] = k


@kernel
def intersect(n, cap, packet, depth, scene, ws, f, g):
    """Closest hit of rays [0, n) of buffer (f, g): t and HIT (depth: the
    segment's index along the paths, 0 for camera rays)."""
    t, hit, frm, fin = f[T], g[HIT], g[OBJ], g[INSIDE]
    ox, oy, oz, dx, dy, dz = f[OX], f[OY], f[OZ], f[DX], f[DY], f[DZ]
    X.init_hits(n, cap, g[ALIVE], t, hit)
    if ws.bvh_mode == FLAT:
        # The axes of each kind: (a, b) the plane's, n the normal's.
        if ws.xy.shape[0] > 0:
            X.rects(n, ws.xy, ws.xy_id, ox, oy, oz, dx, dy, dz, frm, t, hit)
        if ws.xz.shape[0] > 0:
            X.rects(n, ws.xz, ws.xz_id, ox, oz, oy, dx, dz, dy, frm, t, hit)
        if ws.yz.shape[0] > 0:
            X.rects(n, ws.yz, ws.yz_id, oy, oz, ox, dy, dz, dx, frm, t, hit)
        if ws.sph.shape[0] > 0:
            X.spheres(n, ws.sph, ws.sph_id, ox, oy, oz, dx, dy, dz, frm, fin, t, hit)
        if ws.box.shape[0] > 0:
            X.boxes(n, ws.box, ws.box_id, ox, oy, oz, dx, dy, dz, frm, fin, t, hit)
    elif ws.bvh_mode == PACKET or (ws.bvh_mode == HYBRID and depth == 0):
        X.reciprocals(cap, dx, dy, dz, f[IX], f[IY], f[IZ])
        X.packet_bvh(n, packet, scene.bvh_box, scene.bvh_node, scene.bvh_prims, ws.sph,
                     ws.sph_row, ox, oy, oz, dx, dy, dz, f[IX], f[IY], f[IZ], frm, fin, t, hit)
    else:
        per_ray_bvh(n, scene, ox, oy, oz, dx, dy, dz, frm, fin, t, hit)


@kernel
def surface(n, scene, f, g, rad, counts):
    """Per ray of [0, n): background or emission into the path's radiance, the
    hit point (into O), the normal facing the ray (N), front face, and the event
    class; counts[c] = rays of class c.  Returns the live rays traced."""
    for c in range(4):
        counts[c] = 0
    traced = 0
    for i in range(n):
        k = g[HIT, i]
        p = g[PATH, i]
        live = g[ALIVE, i] != 0
        traced += live
        d = (f[DX, i], f[DY, i], f[DZ, i])
        if k < 0:
            g[CLS, i] = DROP
            if live:
                e = background(scene, d)
                rad[p, 0] += f[TR, i] * e[0]
                rad[p, 1] += f[TG, i] * e[1]
                rad[p, 2] += f[TB, i] * e[2]
            continue
        t = f[T, i]
        q = (f[OX, i] + t * d[0], f[OY, i] + t * d[1], f[OZ, i] + t * d[2])
        n_out = shapes.outward_normal(scene, k, q, None)
        front = dot(d, n_out) < 0.0
        m = scene.obj_i[k, OBJ_MAT]
        kind = scene.mat_i[m]
        if kind == DIFFUSE_LIGHT:
            if front:
                rad[p, 0] += f[TR, i] * scene.mat_f[m, MAT_COLOR]
                rad[p, 1] += f[TG, i] * scene.mat_f[m, MAT_COLOR + 1]
                rad[p, 2] += f[TB, i] * scene.mat_f[m, MAT_COLOR + 2]
            g[CLS, i] = DROP           # a light does not scatter: the path ends
            continue
        s = 1.0 if front else -1.0
        f[OX, i], f[OY, i], f[OZ, i] = q
        f[NX, i], f[NY, i], f[NZ, i] = s * n_out[0], s * n_out[1], s * n_out[2]
        g[FRONT, i] = front
        g[CLS, i] = kind
        counts[kind] += 1
    return traced


@kernel
def compact(n, f, g, u, f2, g2, u2, counts, starts):
    """Stable counting sort of the rays of (f, g, u) that go on into (f2, g2, u2),
    grouped by class; starts[c] = first ray of class c, starts[3] = their number.
    The hit object becomes the object the next segment leaves."""
    starts[0] = 0
    for c in range(3):
        starts[c + 1] = starts[c] + counts[c]
    pos0, pos1, pos2 = starts[0], starts[1], starts[2]
    for i in range(n):
        c = g[CLS, i]
        if c == DROP:
            continue
        if c == 0:
            j = pos0
            pos0 += 1
        elif c == 1:
            j = pos1
            pos1 += 1
        else:
            j = pos2
            pos2 += 1
        for a in range(NZ + 1):       # OX .. NZ: point, direction, throughput, normal
            f2[a, j] = f[a, i]
        g2[PATH, j] = g[PATH, i]
        g2[OBJ, j] = g[HIT, i]
        g2[FRONT, j] = g[FRONT, i]
        g2[ALIVE, j] = 1
        u2[j] = u[i]
    return starts[3]


@kernel
def shade_lambertian(j0, j1, scene, light_weight, f, g, u):
    """Diffuse bounces of rays [j0, j1): rtweekend's mixture of cosine and light
    sampling (pdf.py), weight albedo x cos/pi / mixture pdf."""
    use_lights = scene.lights.shape[0] > 0 and light_weight > 0.0
    for j in range(j0, j1):
        k = g[OBJ, j]
        m = scene.obj_i[k, OBJ_MAT]
        p = (f[OX, j], f[OY, j], f[OZ, j])
        nn = (f[NX, j], f[NY, j], f[NZ, j])
        s = 1.0 if g[FRONT, j] != 0 else -1.0
        n_out = (s * nn[0], s * nn[1], s * nn[2])
        state = u[j]
        if use_lights:
            d, state = pdf.mixture_generate(scene, p, nn, light_weight, state, None)
        else:
            d, state = pdf.cosine_generate(nn, state)
        inside = shapes.enters(scene, k, n_out, d)
        w = 1.0
        if use_lights:
            density = pdf.mixture_value(scene, p, nn, light_weight, d, k, inside, None)
            scattering = pdf.cosine_value(nn, d)
            if scattering <= 0.0 or density <= 0.0:
                g[ALIVE, j] = 0
            w = scattering / density
        f[DX, j], f[DY, j], f[DZ, j] = d
        f[TR, j] *= scene.mat_f[m, MAT_COLOR] * w
        f[TG, j] *= scene.mat_f[m, MAT_COLOR + 1] * w
        f[TB, j] *= scene.mat_f[m, MAT_COLOR + 2] * w
        g[INSIDE, j] = inside
        u[j] = state


@kernel
def shade_specular(j0, j1, scene, f, g, u):
    """Metal or dielectric bounces of rays [j0, j1) (materials.scatter; one
    material class per call, so its dispatch always goes the same way)."""
    for j in range(j0, j1):
        k = g[OBJ, j]
        m = scene.obj_i[k, OBJ_MAT]
        d = (f[DX, j], f[DY, j], f[DZ, j])
        nn = (f[NX, j], f[NY, j], f[NZ, j])
        front = g[FRONT, j] != 0
        s = 1.0 if front else -1.0
        n_out = (s * nn[0], s * nn[1], s * nn[2])
        scatters, specular, d_out, att, state = materials.scatter(scene, m, d, nn, front,
                                                                   materials.color(scene, m), u[j])
        if not scatters:
            g[ALIVE, j] = 0            # fuzzed under the surface: absorbed
        f[DX, j], f[DY, j], f[DZ, j] = d_out
        f[TR, j] *= att[0]
        f[TG, j] *= att[1]
        f[TB, j] *= att[2]
        g[INSIDE, j] = shapes.enters(scene, k, n_out, d_out)
        u[j] = state


@kernel
def bounce(n, scene, light_weight, f, g, u, rad, f2, g2, u2):
    """The unsorted variant: surface, shading and compaction of rays [0, n) of
    (f, g, u) in ONE pass, rtweekend's per-ray material dispatch (the scalar
    bounce, reading and writing SoA buffers): the rays that go on are written,
    in order, to (f2, g2, u2).  Returns (their number, the live rays traced)."""
    use_lights = scene.lights.shape[0] > 0 and light_weight > 0.0
    j = 0
    traced = 0
    for i in range(n):
        if g[ALIVE, i] == 0:
            continue
        traced += 1
        k = g[HIT, i]
        p = g[PATH, i]
        tr, tg, tb = f[TR, i], f[TG, i], f[TB, i]
        d = (f[DX, i], f[DY, i], f[DZ, i])
        if k < 0:
            e = background(scene, d)
            rad[p, 0] += tr * e[0]
            rad[p, 1] += tg * e[1]
            rad[p, 2] += tb * e[2]
            continue
        t = f[T, i]
        q = (f[OX, i] + t * d[0], f[OY, i] + t * d[1], f[OZ, i] + t * d[2])
        n_out = shapes.outward_normal(scene, k, q, None)
        front, nn = face_normal(d, n_out)
        m = scene.obj_i[k, OBJ_MAT]
        emits, e = materials.emitted(scene, m, front, materials.color(scene, m))
        if emits:
            rad[p, 0] += tr * e[0]
            rad[p, 1] += tg * e[1]
            rad[p, 2] += tb * e[2]
        scatters, specular, d_out, att, state = materials.scatter(scene, m, d, nn, front,
                                                                   materials.color(scene, m), u[i])
        if not scatters:
            continue
        if specular:
            d = d_out
        elif use_lights:
            d, state = pdf.mixture_generate(scene, q, nn, light_weight, state, None)
        else:
            d, state = pdf.cosine_generate(nn, state)
        inside = shapes.enters(scene, k, n_out, d)
        if specular or not use_lights:
            tr *= att[0]
            tg *= att[1]
            tb *= att[2]
        else:
            density = pdf.mixture_value(scene, q, nn, light_weight, d, k, inside, None)
            scattering = pdf.cosine_value(nn, d)
            if scattering <= 0.0 or density <= 0.0:
                continue
            w = scattering / density
            tr *= att[0] * w
            tg *= att[1] * w
            tb *= att[2] * w
        f2[OX, j], f2[OY, j], f2[OZ, j] = q
        f2[DX, j], f2[DY, j], f2[DZ, j] = d
        f2[TR, j], f2[TG, j], f2[TB, j] = tr, tg, tb
        g2[PATH, j] = p
        g2[OBJ, j] = k
        g2[INSIDE, j] = inside
        g2[ALIVE, j] = 1
        u2[j] = state
        j += 1
    return j, traced


@kernel
def camera_wave(x0, y0, x1, s0, ns, count, cap, params, f, g, u, rad):
    """The camera rays of paths [0, count): path p is sample s0 + p % ns of the
    tile's pixel p // ns (pixel-major, so a packet holds a few neighbours)."""
    tw = x1 - x0
    for p in range(count):
        pix = p // ns
        x = x0 + pix % tw
        y = y0 + pix // tw
        state = rng.seed_state(y * params.width + x, s0 + p % ns, params.seed)
        o, d, state = get_ray(params.cam, x, y, params.width, params.height, state)
        f[OX, p], f[OY, p], f[OZ, p] = o
        f[DX, p], f[DY, p], f[DZ, p] = d
        f[TR, p] = 1.0
        f[TG, p] = 1.0
        f[TB, p] = 1.0
        g[PATH, p] = p
        g[OBJ, p] = -1
        g[INSIDE, p] = 0
        g[ALIVE, p] = 1
        u[p] = state
        rad[p, 0] = 0.0
        rad[p, 1] = 0.0
        rad[p, 2] = 0.0
    for p in range(count, cap):            # padding: harmless finite rays
        f[OX, p], f[OY, p], f[OZ, p] = 0.0, 0.0, 0.0
        f[DX, p], f[DY, p], f[DZ, p] = 1.0, 0.0, 0.0
        g[ALIVE, p] = 0


@kernel
def film_wave(x0, y0, x1, ns, count, clamp, rad, film_sum, film_n, film_bad):
    """Add the wave's samples to their pixels, each pixel's in sample order,
    capped at clamp; a NaN/Inf sample is dropped and counted, as rtweekend's
    film does (which also keeps squares, blocks and a histogram: about 1% of
    its time)."""
    tw = x1 - x0
    for p in range(count):
        pix = p // ns
        x = x0 + pix % tw
        y = y0 + pix // tw
        r, gg, b = rad[p, 0], rad[p, 1], rad[p, 2]
        if math.isfinite(r + gg + b):
            film_sum[y, x, 0] += min(r, clamp)
            film_sum[y, x, 1] += min(gg, clamp)
            film_sum[y, x, 2] += min(b, clamp)
            film_n[y, x] += 1
        else:
            film_bad[y, x] += 1


@kernel
def render_tile(x0, y0, x1, y1, s0, s1, spw, packet, sort, scene, ws, params, fb, gb, ub,
                rad, counts, film_sum, film_n, film_bad, stats, prof):
    """Samples s0..s1-1 of the tile's pixels, spw samples per wave; sort: shade
    compacted by material (else the fused, unsorted bounce)."""
    npx = (x1 - x0) * (y1 - y0)
    for sa in range(s0, s1, spw):
        ns = min(spw, s1 - sa)
        count = npx * ns
        cap = (count + packet - 1) // packet * packet
        c = cycles()
        camera_wave(x0, y0, x1, sa, ns, count, cap, params, fb[0], gb[0], ub[0], rad)
        camera_wave(x0, y0, x1, sa, 0, 0, cap, params, fb[1], gb[1], ub[1], rad)  # padding
        c1 = cycles()
        prof[CAMERA] += c1 - c
        a = 0
        n = count
        for depth in range(params.max_depth):
            if n == 0:
                break
            f, g, u = fb[a], gb[a], ub[a]
            f2, g2, u2 = fb[1 - a], gb[1 - a], ub[1 - a]
            c = cycles()
            intersect(n, cap, packet, depth, scene, ws, f, g)
            c1 = cycles()
            prof[INTERSECT] += c1 - c
            if not sort:
                n, traced = bounce(n, scene, params.light_weight, f, g, u, rad, f2, g2, u2)
                stats[SEGMENTS] += traced
                prof[SHADE] += cycles() - c1
                a = 1 - a
                continue
            stats[SEGMENTS] += surface(n, scene, f, g, rad, counts)
            c2 = cycles()
            prof[SURFACE] += c2 - c1
            starts = counts[4:8]
            n = compact(n, f, g, u, f2, g2, u2, counts, starts)
            c3 = cycles()
            prof[COMPACT] += c3 - c2
            shade_lambertian(starts[0], starts[1], scene, params.light_weight, f2, g2, u2)
            shade_specular(starts[1], starts[3], scene, f2, g2, u2)
            prof[SHADE] += cycles() - c3
            a = 1 - a
        c = cycles()
        film_wave(x0, y0, x1, ns, count, params.clamp, rad, film_sum, film_n, film_bad)
        prof[FILM] += cycles() - c
        stats[WAVES] += 1


@parallel
def render_pass(tiles, s0, s1, spw, packet, sort, cap, scene, ws, params, film_sum, film_n,
                film_bad, stats, prof):
    """One prange over tiles; each tile's buffers are its own (allocated here,
    once per tile: a few tens of KB, microseconds against milliseconds of work)."""
    for ti in numba.prange(tiles.shape[0]):
        fb = np.empty((2, NF, cap))
        gb = np.empty((2, NI, cap), dtype=np.int64)
        ub = np.empty((2, cap), dtype=np.uint64)
        rad = np.empty((cap, 3))
        counts = np.zeros(8, dtype=np.int64)
        render_tile(tiles[ti, 0], tiles[ti, 1], tiles[ti, 2], tiles[ti, 3], s0, s1, spw,
                    packet, sort, scene, ws, params, fb, gb, ub, rad, counts, film_sum, film_n,
                    film_bad, stats[ti], prof[ti])


def make_tiles(width, height, tw, th):
    """[T, 4] tiles (x0, y0, x1, y1) in an interleaved order, so that each
    thread's contiguous share of the prange spreads over the whole image."""
    tiles = np.array([(x, y, min(x + tw, width), min(y + th, height))
                      for y in range(0, height, th) for x in range(0, width, tw)],
                     dtype=np.int64)
    return np.ascontiguousarray(tiles[interleaved_rows(len(tiles))])


class WideRenderer:
    """The prototype, with the part of rtweekend's Renderer API the benchmark uses:

        r = WideRenderer(scene, seed=1, width=..., height=..., threads=1)
        r.compile(); seconds = r.add_samples(n); image = r.image()
    """

    def __init__(self, scene, *, mode=None, tile=(8, 8), spw=4, packet=16, sort=True,
                 threads=None, **fields):
        fields.setdefault("sampling", "mixture")
        self.options = RenderOptions("path", threads=threads, **fields)
        frame = freeze(scene, self.options)
        self.scene, self.params = frame.scene, frame.params
        self.ws = wide_scene(self.scene, mode)
        self.width, self.height = self.params.width, self.params.height
        self.tiles = make_tiles(self.width, self.height, *tile)
        self.spw, self.packet, self.sort = spw, packet, bool(sort)
        self.cap = (tile[0] * tile[1] * spw + packet - 1) // packet * packet
        self.film_sum = np.zeros((self.height, self.width, 3))
        self.film_n = np.zeros((self.height, self.width), dtype=np.int64)
        self.film_bad = np.zeros((self.height, self.width), dtype=np.int64)
        self.stats = np.zeros((len(self.tiles), 2), dtype=np.int64)
        self.prof = np.zeros((len(self.tiles), len(PHASES)), dtype=np.int64)
        self.spp = 0
        self.seconds = 0.0

    def _pass(self, s0, s1):
        render_pass(self.tiles, s0, s1, self.spw, self.packet, self.sort, self.cap,
                    self.scene, self.ws, self.params, self.film_sum, self.film_n,
                    self.film_bad, self.stats, self.prof)

    def compile(self):
        t0 = time.perf_counter()
        with thread_count(self.options.threads):
            self._pass(0, 0)
        return time.perf_counter() - t0

    def add_samples(self, n):
        with thread_count(self.options.threads):
            t0 = time.perf_counter()
            self._pass(self.spp, self.spp + n)
            dt = time.perf_counter() - t0
        self.spp += n
        self.seconds += dt
        return dt

    def image(self):
        n = np.maximum(self.film_n, 1)[..., None]
        return (self.film_sum / n).astype(np.float32)

    def segments(self):
        return int(self.stats[:, SEGMENTS].sum())

    def profile(self):
        """Share of the tiles' cycles spent in each phase, and the cycle total."""
        tot = self.prof.sum(axis=0).astype(np.float64)
        return {name: float(v / tot.sum()) for name, v in zip(PHASES, tot)}, float(tot.sum())

    def reset_profile(self):
        self.prof[:] = 0
