"""The classic ray tracer of Gambetta's *Computer Graphics from Scratch*.

Chapters "Light", "Shadows" and "Reflections": spheres lit by ambient, point and
directional white lights (diffuse + Phong specular), hard shadows, mirrors, and
the book's camera (position + 3x3 rotation).  One ray per pixel, no gamma.

Flat arrays (classic_arrays builds them from plain Python data):
  sph_f[k]   float64 [N, 9] = center(0:3), radius(3), color r,g,b (4:7, 0..255),
                              specular exponent(7, -1 = matte), reflective(8, 0..1)
  light_i[j] int64 [L]      = kind: AMBIENT, POINT or DIRECTIONAL
  light_f[j] float64 [L, 4] = intensity(0), position (point) or direction
                              (directional) (1:4); (1:4) unused for ambient

Camera: canvas point (x, y) is the ray D = rotation . (x Vw/Cw, y Vh/Ch, d) from
`position`, drawn on image column Cw/2 + x and row Ch/2 - y - 1.  The book's loops
run x from -Cw/2 to Cw/2 - 1 in JavaScript, whose division is real: so column
`col` is canvas x = col - Cw/2 for every size -- integers for even sizes, the
centred half-integers the book's code itself gives for odd sizes.

Output: each channel rounded half to even and clamped to 0..255 (NaN -> 0), as
the book's Uint8ClampedArray canvas stores it; render_classic writes uint8.

    sph_f, light_i, light_f = classic_arrays(spheres, lights)
    image = render_canvas(sph_f, light_i, light_f, 600, 600, depth=3)  # uint8 HxWx3
"""
import math
from typing import NamedTuple

import numba
import numpy as np

from ..kernel.jit import jit_parallel, jit_step
from ..kernel.rows import interleaved_rows
from ..kernel.vec3 import dot, length, madd, neg, scale, sub, unit

# Light kinds (light_i).
AMBIENT = 0
POINT = 1
DIRECTIONAL = 2
NO_HIT = -1         # closest_intersection found no sphere
INF = math.inf
EPSILON = 0.001     # the book's t_min for rays that leave a surface
SPH_FLOATS = 9
LIGHT_FLOATS = 4
LIGHT_KINDS = {"ambient": AMBIENT, "point": POINT, "directional": DIRECTIONAL}


@jit_step
def intersect_ray_sphere(sph_f, k, o, d):
    """IntersectRaySphere: both roots t of |o + t d - center|^2 = r^2, or (inf, inf).

    Not the path tracer's sphere root: that one assumes a unit d and t > 0, while the book's
    D is the unnormalised viewport point and its rays start at t = 1 or 0.001.
    The book's k2 = 2<OC,D> is halved here; the factors of 2 cancel exactly.
    """
    oc = (o[0] - sph_f[k, 0], o[1] - sph_f[k, 1], o[2] - sph_f[k, 2])
    r = sph_f[k, 3]
    a = dot(d, d)
    half_b = dot(oc, d)
    c = dot(oc, oc) - r * r
    disc = half_b * half_b - a * c
    if disc < 0.0:
        return INF, INF
    sq = math.sqrt(disc)
    return (-half_b + sq) / a, (-half_b - sq) / a


@jit_step
def closest_intersection(sph_f, o, d, t_min, t_max):
    """ClosestIntersection: (sphere, t) of the smallest root in (t_min, t_max),
    or (NO_HIT, inf).  Ties go to the first sphere and root, as in the book."""
    closest_t = INF
    closest = NO_HIT
    for k in range(sph_f.shape[0]):
        t1, t2 = intersect_ray_sphere(sph_f, k, o, d)
        if t1 < closest_t and t_min < t1 < t_max:
            closest_t = t1
            closest = k
        if t2 < closest_t and t_min < t2 < t_max:
            closest_t = t2
            closest = k
    return closest, closest_t


@jit_step
def occluded(sph_f, o, d, t_min, t_max):
    """Is any sphere hit in (t_min, t_max)?  The book asks ClosestIntersection,
    but a shadow only needs some blocker, so the first one found ends the search."""
    for k in range(sph_f.shape[0]):
        t1, t2 = intersect_ray_sphere(sph_f, k, o, d)
        if t_min < t1 < t_max or t_min < t2 < t_max:
            return True
    return False


@jit_step
def compute_lighting(sph_f, light_i, light_f, p, n, v, s):
    """ComputeLighting: (intensity I_P at p, shadow rays cast), for the unit
    normal n, the direction to the viewer v and specular exponent s (-1: matte)."""
    i = 0.0
    shadow_rays = 0
    for j in range(light_i.shape[0]):
        kind = light_i[j]
        intensity = light_f[j, 0]
        if kind == AMBIENT:
            i += intensity
            continue
        vec = (light_f[j, 1], light_f[j, 2], light_f[j, 3])
        if kind == POINT:
            # L is not normalised: the light sits at t = 1 along the shadow ray.
            vec_l = sub(vec, p)
            t_max = 1.0
        elif kind == DIRECTIONAL:
            vec_l = vec
            t_max = INF
        else:
            continue
        shadow_rays += 1
        if occluded(sph_f, p, vec_l, EPSILON, t_max):
            continue
        # Diffuse: <N,L> / (|N||L|), with |N| = 1.
        n_dot_l = dot(n, vec_l)
        if n_dot_l > 0.0:
            i += intensity * n_dot_l / length(vec_l)
        # Specular: (<R,V> / (|R||V|))^s, R = L mirrored about N.
        if s != -1.0:
            r = sub(scale(n, 2.0 * n_dot_l), vec_l)
            r_dot_v = dot(r, v)
            if r_dot_v > 0.0:
                i += intensity * (r_dot_v / (length(r) * length(v))) ** s
    return i, shadow_rays


@jit_step
def reflect_ray(r, n):
    """ReflectRay: r mirrored about n, 2N<N,R> - R (r points away from the surface)."""
    return sub(scale(n, 2.0 * dot(n, r)), r)


@jit_step
def trace_ray(world, o, d, t_min, t_max, depth):
    """TraceRay: (colour on the 0..255 scale, unclamped; rays cast) along o + t d
    in `world` (a World).

    The book's recursion  (1 - r) local + r TraceRay(reflected ray, depth - 1)
    unrolled into a loop: `weight` is the product of the r's of the mirrors
    passed so far, and each hit adds its share of its local colour.
    """
    sph_f = world.sph_f
    color = (0.0, 0.0, 0.0)
    weight = 1.0
    rays = 0
    while True:
        k, t = closest_intersection(sph_f, o, d, t_min, t_max)
        rays += 1
        if k == NO_HIT:
            return madd(color, world.background, weight), rays
        p = madd(o, d, t)
        n = unit((p[0] - sph_f[k, 0], p[1] - sph_f[k, 1], p[2] - sph_f[k, 2]))
        v = neg(d)
        i, shadow_rays = compute_lighting(sph_f, world.light_i, world.light_f, p, n, v,
                                          sph_f[k, 7])
        rays += shadow_rays
        local = (sph_f[k, 4] * i, sph_f[k, 5] * i, sph_f[k, 6] * i)
        r = sph_f[k, 8]
        if depth <= 0 or r <= 0.0:
            return madd(color, local, weight), rays
        color = madd(color, local, weight * (1.0 - r))
        weight *= r
        o = p
        d = reflect_ray(v, n)
        t_min = EPSILON
        t_max = INF
        depth -= 1


@jit_step
def canvas_to_viewport(x, y, cw, ch, vw, vh, d):
    """CanvasToViewport: the point of the viewport (at distance d) under canvas (x, y)."""
    return (x * vw / cw, y * vh / ch, d)


@jit_step
def rotate(m, v):
    """m . v for a 3x3 matrix m (the camera rotation)."""
    return (m[0, 0] * v[0] + m[0, 1] * v[1] + m[0, 2] * v[2],
            m[1, 0] * v[0] + m[1, 1] * v[1] + m[1, 2] * v[2],
            m[2, 0] * v[0] + m[2, 1] * v[1] + m[2, 2] * v[2])


@jit_step
def to_byte(c):
    """What a Uint8ClampedArray stores for c: round half to even, clamp, NaN -> 0."""
    if c >= 255.0:
        return 255
    if c > 0.0:
        return int(np.rint(c))
    return 0


class World(NamedTuple):
    """What rays meet: the arrays of classic_arrays and the background colour
    (3 floats, 0..255) of rays that hit nothing."""
    sph_f: np.ndarray
    light_i: np.ndarray
    light_f: np.ndarray
    background: tuple


class View(NamedTuple):
    """The book's camera: position (3 floats), rotation (float64 [3, 3]), and
    the viewport's width, height and distance d."""
    position: tuple
    rotation: np.ndarray
    vw: float
    vh: float
    d: float


@jit_step
def trace_row(out, row, world, view, depth):
    """Row `row` of the canvas out: each pixel's colour; returns the rays cast."""
    ch, cw = out.shape[0], out.shape[1]
    y = ch * 0.5 - row - 1.0
    rays = 0
    for col in range(cw):
        x = col - cw * 0.5
        ray_d = rotate(view.rotation, canvas_to_viewport(x, y, cw, ch, view.vw, view.vh, view.d))
        c, n = trace_ray(world, view.position, ray_d, 1.0, INF, depth)
        rays += n
        out[row, col, 0] = to_byte(c[0])
        out[row, col, 1] = to_byte(c[1])
        out[row, col, 2] = to_byte(c[2])
    return rays


@jit_parallel
def render_classic(out, row_rays, rows, world, view, depth):
    """Trace one ray per pixel of out (uint8 [Ch, Cw, 3]) and store its 0..255 colour.

    row_rays[row]: rays cast for that row (primary, shadow, reflected); rows:
    the order rows are handed to threads (rows.interleaved_rows); world: a
    World; view: a View; depth: reflections followed (0: none).  Pixels are
    independent, so any thread count gives the same image.
    """
    # A prange body cannot take a tuple holding arrays from outside (Numba's
    # parallel gufunc wants arrays or scalars): the groups go in as their
    # fields and are put together again per row.
    sph_f, light_i, light_f, background = world
    position, rotation, vw, vh, d = view
    for k in numba.prange(rows.shape[0]):
        row_rays[rows[k]] = trace_row(out, rows[k],
                                      World(sph_f, light_i, light_f, background),
                                      View(position, rotation, vw, vh, d), depth)


def classic_arrays(spheres, lights):
    """(sph_f, light_i, light_f) from plain data (already validated elsewhere).

    spheres: dicts with center, radius, color (0..255), specular, reflective;
    lights: dicts with type ("ambient" | "point" | "directional"), intensity,
    and position (point) or direction (directional).
    """
    sph_f = np.zeros((len(spheres), SPH_FLOATS), dtype=np.float64)
    for k, s in enumerate(spheres):
        sph_f[k] = (*s["center"], s["radius"], *s["color"], s["specular"], s["reflective"])
    light_i = np.zeros(len(lights), dtype=np.int64)
    light_f = np.zeros((len(lights), LIGHT_FLOATS), dtype=np.float64)
    for j, light in enumerate(lights):
        light_i[j] = LIGHT_KINDS[light["type"]]
        light_f[j, 0] = light["intensity"]
        if light["type"] == "point":
            light_f[j, 1:] = light["position"]
        elif light["type"] == "directional":
            light_f[j, 1:] = light["direction"]
    return sph_f, light_i, light_f


def _floats3(v):
    # Always a tuple of 3 floats, so ints from the caller never cause a recompile.
    return tuple(float(c) for c in v)


def render_canvas(sph_f, light_i, light_f, width, height, depth, background=(0, 0, 0),
                  position=(0, 0, 0), rotation=None, viewport=(1, 1), d=1.0, rays=None):
    """Render the scene on a width x height canvas: uint8 [height, width, 3].

    depth: reflections followed (the book's recursion_depth); background: 0..255
    colour of rays that hit nothing; position, rotation (3x3, default identity):
    the camera; viewport: (Vw, Vh) at distance d; rays: an optional int64
    [height] array that receives the rays cast per row.
    """
    out = np.empty((height, width, 3), dtype=np.uint8)
    rot = np.eye(3) if rotation is None else rotation
    row_rays = np.zeros(height, dtype=np.int64) if rays is None else rays
    world = World(np.ascontiguousarray(sph_f, dtype=np.float64).reshape(-1, SPH_FLOATS),
                  np.ascontiguousarray(light_i, dtype=np.int64).reshape(-1),
                  np.ascontiguousarray(light_f, dtype=np.float64).reshape(-1, LIGHT_FLOATS),
                  _floats3(background))
    view = View(_floats3(position), np.ascontiguousarray(rot, dtype=np.float64),
                float(viewport[0]), float(viewport[1]), float(d))
    render_classic(out, row_rays, interleaved_rows(height), world, view, int(depth))
    return out
