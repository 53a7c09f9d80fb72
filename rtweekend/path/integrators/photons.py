"""Caustic photon maps for bidirectional path tracing: the light that reaches a
diffuse surface through glass or off a mirror, where the camera too sees that
surface only through glass or in a mirror (Jensen's caustic photon map,
progressive as Knaus and Zwicker's PPM).

Why: such a path -- light, glass, floor, glass, camera: the caustic under a
glass ball seen through the ball -- has one strategy in bdpt only, the camera
subpath reaching the emitter through the glass by chance (s = 0): light
tracing cannot join the camera through glass, nor a shadow ray cross it.
With a small light those pixels held almost all of bdpt's squared error on
the caustic scene (benchmarks/results/measurements.md).  A photon map
estimates the light arriving at the floor point from many light paths at
once, at the price of a bias that shrinks as the radius does.

The paths it takes over, exactly: camera, one or more delta vertices (metal,
glass), a lambertian point z -- the first smooth vertex of the camera path --,
one or more delta vertices, an emitter, whose first segment leaves the
emitter towards one of the lights list's attractors (its objects that do not
emit: the books' way to say "the light worth aiming at is behind this").
The camera subpath's own s = 0 strategy skips these paths (covered), and no
other strategy can make them (each would join at a delta vertex), so the two
estimates never count a path twice.

Per sample index s, one map shared by every pixel (so a pixel's value depends
on its sample indices only, as film.py requires): PHOTONS light paths, each
from a point drawn on an emitter by power and area (lights.light_point), along
a direction drawn towards an attractor (pdf.lights_value), followed through
delta vertices with the adjoint's weight (materials.adjoint); one that reaches
a lambertian surface after at least one delta vertex is stored there with its
flux.  The estimate at z is f(z) x (the flux of the map's photons within
radius r_s of z, on the same surface -- object, or mesh -- and arriving on
z's side) / (pi r_s^2),
r_s = r0 (s + 1)^((ALPHA - 1) / 2): the bias (r^2) and the variance (1 / r^2
per map) both fall as samples add up.  Each map's photons are traced from
keys of their own and sorted into a hashed grid of cells 2 r_s wide in a fixed
order, so the maps -- and the image -- are the same bits on any thread count,
pass split or machine.
"""
import math
from typing import NamedTuple

import numpy as np

from ...kernel import sampler
from ...kernel.ref import by_ref
from ...kernel.jit import jit_kernel, jit_step
from ...kernel.rows import on_threads
from ...kernel.stack import stack_array
from ...kernel.vec3 import dot, neg
from .. import lights, materials, mesh_light, pdf, shapes
from ..bvh import closest_hit
from ..bvh_build import object_bounds
from ..layout import NO_HIT
from ..film import BLOCK_SPP
from ..materials import PHOTON
from ..surface import surface_at
from .needs import emitters_left_out
from .vertices import BETA, COLOR, DELTA, MKIND, NG, NS, OBJ, P, SURFACE, TYPE, WO, col

INF = math.inf
PHOTONS = 1024          # light paths traced per map (per sample index)
RADIUS = 0.015          # r0 as a fraction of the attractors' bounding-box diagonal
ALPHA = 2.0 / 3.0       # Knaus and Zwicker's: the radius^2 shrinks as s^(ALPHA - 1)
CELLS = 4096            # hash table size of a map's grid (a power of two)
# A photon's row: where it landed, its flux (RGB), the unit direction it came
# from, and (photon_i) the object it landed on and its segments from the light.
POS, FLUX, CAME = 0, 3, 6
PF = 9


class Caustics(NamedTuple):
    """The maps of samples s0 .. s0 + len(radius) - 1 (build); with no map, the
    settings that say the strategy uses them."""
    photon_f: np.ndarray     # float64 [N, PF], each map's photons sorted by cell
    photon_i: np.ndarray     # int64 [N, 2]: object, segments
    cell_start: np.ndarray   # int64 [maps, CELLS + 1]: a cell's photons, from its map's first
    first: np.ndarray        # int64 [maps]: the map's first photon row
    radius: np.ndarray       # float64 [maps]
    s0: int
    r0: float


def settings(arrays):
    """Caustics with no map yet, r0 from the size of the attractors (the lights
    list, emitters left out: renderer.freeze), whose size is the caustics'
    scale -- not the scene's, which a ground sphere of radius 1000 would make
    blur every caustic."""
    covered = mesh_light.objects(arrays)
    boxes = object_bounds(arrays.obj_i[covered], arrays.obj_f[covered])
    return empty(RADIUS * float(np.linalg.norm(boxes[:, 3:].max(axis=0) -
                                               boxes[:, :3].min(axis=0))))


def empty(r0):
    """Caustics with no map yet, first radius r0."""
    return Caustics(np.zeros((0, PF)), np.zeros((0, 2), dtype=np.int64),
                    np.zeros((0, CELLS + 1), dtype=np.int64), np.zeros(0, dtype=np.int64),
                    np.zeros(0), 0, r0)


def radius(r0, s):
    """The radius of sample index s's map."""
    return r0 * (s + 1.0) ** ((ALPHA - 1.0) / 2.0)


def build(caustics, scene, params, textures, s0, s1, threads):
    """The maps of samples s0 .. s1 - 1 (the same bits wherever they are built)."""
    maps = s1 - s0
    raw_f = np.zeros((maps * PHOTONS, PF))
    raw_i = np.full((maps * PHOTONS, 2), -1, dtype=np.int64)
    on_threads(lambda part: trace_maps(scene, params, s0, part, raw_f, raw_i, textures),
               np.arange(maps * PHOTONS), threads)
    maps_f, maps_i = [], []
    for m in range(maps):
        rows = slice(m * PHOTONS, (m + 1) * PHOTONS)
        stored = raw_i[rows, 0] >= 0
        maps_f.append(raw_f[rows][stored])
        maps_i.append(raw_i[rows][stored])
    return grid(caustics, maps_f, maps_i, s0)


def kernel_call(frame):
    """(kernel, arguments) of the photon tracer for frame, with no photons:
    what Renderer.compile compiles (kernel/compile_workers.py)."""
    none = np.zeros(0, dtype=np.int64)
    return trace_maps, (frame.scene, frame.params, 0, none, np.zeros((0, PF)),
                        np.zeros((0, 2), dtype=np.int64), frame.features.textures)


def grid(caustics, maps_f, maps_i, s0):
    """Caustics holding the maps of samples s0, s0 + 1, ... made of the
    photons maps_f[m] / maps_i[m]: each map's photons sorted by the slot of their
    cell (2 r wide), then by their order (a stable sort: the same bits always)."""
    radii = np.array([radius(caustics.r0, s0 + m) for m in range(len(maps_f))])
    starts = np.zeros((len(maps_f), CELLS + 1), dtype=np.int64)
    first, sorted_f, sorted_i, row = [], [], [], 0
    for m, (f, i) in enumerate(zip(maps_f, maps_i)):
        h = cell_hashes(f[:, POS:POS + 3], 2.0 * radii[m])
        order = np.argsort(h, kind="stable")
        sorted_f.append(f[order])
        sorted_i.append(i[order])
        starts[m, 1:] = np.cumsum(np.bincount(h, minlength=CELLS))
        first.append(row)
        row += len(order)
    return caustics._replace(
        photon_f=np.concatenate(sorted_f) if sorted_f else np.zeros((0, PF)),
        photon_i=np.concatenate(sorted_i) if sorted_i else np.zeros((0, 2), dtype=np.int64),
        cell_start=starts, first=np.array(first, dtype=np.int64), radius=radii, s0=s0)


def skipped(scene):
    """Why bdpt+photons renders `scene` as bdpt+sobol, in a few words (the
    summary says so), or None when its photon maps serve it: they start on its
    emitters, are aimed at the lights list's objects that do not emit
    (attractors, such as a glass ball), follow smooth glass and mirrors (delta
    materials), and do not scatter in media or move with time."""
    def emits(shape):
        return materials.kind_has(shape.material.kind, materials.EMITS)

    if not any(emits(shape) for shape in scene.objects):
        return "no emitter to start photons on"
    if all(emits(light) for light in scene.lights):
        return "no photon targets in lights"
    if any(shape.medium or shape.moving for shape in scene.objects):
        return "no photon maps with media or motion blur"
    if not any(materials.kind_has(shape.material.kind, materials.DELTA)
               for shape in scene.objects):
        return "no smooth glass or mirror for caustics"
    return None


def serve(scene):
    """Do bdpt's caustic photon maps serve `scene` (skipped)?"""
    return skipped(scene) is None


# bdpt's needs (needs.py) for its strategies with photon maps (Sampling.photons).

def aimed_lights(strategy, arrays):
    """Photons are aimed at the lights list's objects that do not emit."""
    return emitters_left_out(arrays) if strategy.photons else arrays


def features(strategy, scene, arrays):
    return {"caustics": settings(arrays)} if strategy.photons and serve(scene) else {}


def runs_as(strategy, scene):
    """bdpt+photons is bdpt+sobol bit for bit where its maps have nothing to do."""
    why = skipped(scene) if strategy.photons else None
    return None if why is None else ("bdpt+sobol", why)


def extra_bytes(strategy):
    return map_bytes(BLOCK_SPP) if strategy.photons else 0


def kernels(frame):
    return [kernel_call(frame)] if frame.features.caustics is not None else []


def block(frame, features, s0, s1, threads):
    """The maps of one block's samples (renderer.render_samples)."""
    if features.caustics is None or s1 <= s0:
        return features
    return features._replace(caustics=build(features.caustics, frame.scene, frame.params,
                                            features.textures, s0, s1, threads))


def map_bytes(maps):
    """Memory of `maps` maps at most (the raw photons and the sorted copy)."""
    return maps * (PHOTONS * (PF + 2) * 8 * 2 + (CELLS + 1) * 8)


# Large odd numbers that spread neighbouring cells over the table.
_HX, _HY, _HZ = 73856093, 19349663, 83492791


def cell_hashes(p, width):
    """The grid slot of each point of p [N, 3] (NumPy's twin of cell_hash)."""
    c = np.floor(p / width).astype(np.int64)
    return ((c[:, 0] * _HX) ^ (c[:, 1] * _HY) ^ (c[:, 2] * _HZ)) & (CELLS - 1)


@jit_step
def cell_hash(cx, cy, cz):
    return ((cx * _HX) ^ (cy * _HY) ^ (cz * _HZ)) & (CELLS - 1)


@jit_kernel
def trace_maps(scene, params, s0, rows, out_f, out_i, textures):
    """Trace photon j of map m into row n = m * PHOTONS + j for each n of `rows`
    (object -1: not stored); threads take parts of the rows (kernel/rows.py)."""
    scene_r, params_r, textures_r = by_ref(scene), by_ref(params), by_ref(textures)
    for r in range(rows.shape[0]):
        n = rows[r]
        m, j = n // PHOTONS, n % PHOTONS
        # Keys no camera sample uses (pixels are >= 0).
        smp = sampler.start(-1 - j, s0 + m, params.seed, 0)
        trace_photon(scene_r, params_r, out_f, out_i, n, textures_r, smp)


@jit_step
def trace_photon(scene, params, out_f, out_i, n, textures, smp):
    k, p, nl, emit, origin, smp = lights.light_point(scene, textures, None, smp)
    d, smp = pdf.lights_generate(scene, p, k, smp, None)      # towards the attractors
    c = dot(d, nl)
    if not c > 0.0:
        return                                   # behind the emitter: no light
    inside = shapes.enters(scene, k, nl, d)
    density = pdf.lights_value(scene, p, d, k, inside, None)
    if not density > 0.0:
        return
    w = c / (origin * density * PHOTONS)
    flux = (emit[0] * w, emit[1] * w, emit[2] * w)
    o, from_obj, from_inside = p, k, inside
    for segments in range(1, params.max_depth + 1):
        kh, t = closest_hit(scene, o, d, INF, from_obj, from_inside, None)
        if kh == NO_HIT:
            return
        hit = surface_at(scene, textures, kh, o, d, t, None)
        bsdf = materials.at(scene, hit)
        if not materials.delta(bsdf):
            if materials.has(bsdf.kind, PHOTON) and segments >= 2:
                for c3 in range(3):
                    out_f[n, POS + c3] = hit.p[c3]
                    out_f[n, FLUX + c3] = flux[c3]
                    out_f[n, CAME + c3] = -d[c3]
                out_i[n, 0] = shapes.surface(scene, scene.tris, kh)
                out_i[n, 1] = segments
            return
        wo = neg(d)
        d, weight, density, _, smp = materials.sample_delta(bsdf, wo, smp)
        if density == 0.0:
            return
        a = materials.adjoint(bsdf, wo, d)
        flux = (flux[0] * weight[0] * a, flux[1] * weight[1] * a, flux[2] * weight[2] * a)
        o, from_obj = hit.p, kh
        from_inside = shapes.enters(scene, kh, hit.n_out, d)


@jit_step
def gather(caustics, m, z, obj, n, ns, albedo, segments_left):
    """The radiance towards the camera at lambertian point z of surface obj
    (shapes.surface; n: its normal on the camera's side, ns its shading
    normal there) from map m's
    photons: albedo / pi x flux within the radius / (pi r^2), each photon's
    flux times |cos| about ns over |cos| about n where they differ (a smooth
    mesh: the flux is per unit of the surface's area, the material shades
    with ns).  Photons more than segments_left segments from their light are
    left out (max_depth)."""
    r = caustics.radius[m]
    width = 2.0 * r
    base = caustics.first[m]
    pf, pi_ = caustics.photon_f, caustics.photon_i
    total = (0.0, 0.0, 0.0)
    lo = (np.int64(math.floor((z[0] - r) / width)), np.int64(math.floor((z[1] - r) / width)),
          np.int64(math.floor((z[2] - r) / width)))
    # The 2 x 2 x 2 cells that hold the ball of radius r about z; two of them
    # may share a slot of the table, which is then read once.
    slots = stack_array(8, np.int64)
    for c in range(8):
        slots[c] = cell_hash(lo[0] + (c & 1), lo[1] + ((c >> 1) & 1), lo[2] + (c >> 2))
    r2 = r * r
    smooth = ns[0] != n[0] or ns[1] != n[1] or ns[2] != n[2]
    for c in range(8):
        h = slots[c]
        seen = False
        for e in range(c):
            seen = seen or slots[e] == h
        if seen:
            continue
        for q in range(base + caustics.cell_start[m, h], base + caustics.cell_start[m, h + 1]):
            if pi_[q, 0] != obj or pi_[q, 1] > segments_left:
                continue
            dx, dy, dz = pf[q, POS] - z[0], pf[q, POS + 1] - z[1], pf[q, POS + 2] - z[2]
            if dx * dx + dy * dy + dz * dz >= r2:
                continue
            cos_g = pf[q, CAME] * n[0] + pf[q, CAME + 1] * n[1] + pf[q, CAME + 2] * n[2]
            if cos_g <= 0.0:
                continue                    # lit from the other side
            if smooth:
                # Below the shading normal the lambertian's f is 0 (as for the
                # strategies the maps stand in for).
                c_s = pf[q, CAME] * ns[0] + pf[q, CAME + 1] * ns[1] + pf[q, CAME + 2] * ns[2]
                if c_s <= 0.0:
                    continue
                a = c_s / cos_g
                total = (total[0] + pf[q, FLUX] * a, total[1] + pf[q, FLUX + 1] * a,
                         total[2] + pf[q, FLUX + 2] * a)
            else:
                total = (total[0] + pf[q, FLUX], total[1] + pf[q, FLUX + 1],
                         total[2] + pf[q, FLUX + 2])
    s = 1.0 / (math.pi * math.pi * r2)
    return (albedo[0] * total[0] * s, albedo[1] * total[1] * s, albedo[2] * total[2] * s)


@jit_step
def seen_through(ci, nc):
    """The camera vertex where the maps are read: the first smooth vertex of the
    camera subpath (nc vertices), if one or more delta vertices lie before it
    and it is lambertian; else -1."""
    for i in range(1, nc):
        if ci[i, DELTA] == 0:
            if i >= 2 and ci[i, TYPE] == SURFACE and materials.has(ci[i, MKIND], PHOTON):
                return i
            return -1
    return -1


@jit_step
def seen(scene, caustics, s, cf, ci, nc, max_depth, smp):
    """(z, light, smp): the camera vertex where the maps are read (seen_through;
    -1: none) and what map s says reaches it (caustic_light)."""
    z = seen_through(ci, nc)
    if z > 0:
        return z, caustic_light(scene, caustics, s, cf, ci, z, max_depth), smp
    return z, (0.0, 0.0, 0.0), smp


@jit_step
def caustic_light(scene, caustics, s, cf, ci, z, max_depth):
    """What map s says reaches camera vertex z (seen_through) and goes on
    towards the camera: beta x the gathered radiance."""
    wo = col(cf, z, WO)
    n, ns = col(cf, z, NG), col(cf, z, NS)
    if dot(wo, n) < 0.0:
        n, ns = neg(n), neg(ns)
    light = gather(caustics, s - caustics.s0, col(cf, z, P),
                   shapes.surface(scene, scene.tris, ci[z, OBJ]), n, ns,
                   col(cf, z, COLOR), max_depth - z)
    beta = col(cf, z, BETA)
    return (beta[0] * light[0], beta[1] * light[1], beta[2] * light[2])


@jit_step
def covered(scene, cf, ci, z, t):
    """Is the path of camera vertices 0 .. t - 1 (vertex t - 1 on an emitter)
    one the maps estimate at vertex z?  Only delta vertices between z and the
    emitter, at least one, and the emitter's light leaving towards an attractor
    (as a photon is aimed)."""
    pt = t - 1
    if z < 0 or pt - 1 <= z:
        return False
    for i in range(z + 1, pt):
        if ci[i, DELTA] == 0 or ci[i, TYPE] != SURFACE:
            return False
    k = ci[pt, OBJ]
    d = col(cf, pt, WO)
    inside = shapes.enters(scene, k, col(cf, pt, NG), d)
    return pdf.lights_value(scene, col(cf, pt, P), d, k, inside, None) > 0.0
