"""The triangle: one face of a mesh, placed in the world.

Row of obj_f: its vertices P0 (0:3), P1 (3:6), P2 (6:9) as the mesh file gives
them (placed), the unit normal N (9:12) of (P1 - P0) x (P2 - P0) -- its front
side, counter-clockwise winding as in OBJ, PLY and glTF --, AREA (12) and
INDEX (13), the triangle's row in the mesh tables (layout.Triangles: texture
coordinates).  The vertices are stored, not an edge and a corner: two
triangles that share an edge then test bit-identical end points, which is what
makes the test below watertight.

The ray-triangle test is Woop, Benthin and Wald's watertight one (JCGT 2013):
the ray is turned into a frame where it runs along +z from the origin, the
vertices are sheared into that frame, and the hit is decided by the signs of
three 2-D edge functions.  Each edge function of a shared edge is computed from
the same two points in the same order by both triangles, with opposite signs,
so a ray through an edge or a vertex meets at least one of them: no ray slips
between the faces of a closed mesh (tests/test_meshes.py aims 10^6 at them).

Shading.  A mesh with vertex normals (layout.Triangles.normals) shades with
them, interpolated across each triangle by the hit's barycentric weights
(Phong's normal interpolation); a flat one with the triangle's own normal.
The geometric normal still decides which side a ray is on, where it goes and
the densities of points; the materials see the shading normal.  Transport
that carries light (light tracing, bdpt's light subpaths, photons) is not
symmetric under it and takes materials.shading_adjoint's factor (Veach's
thesis 5.3; pbrt-v4's CorrectShadingNormal).

Self-intersection keeps the analytic kinds' rule: a ray leaving a triangle
never meets that triangle again (a plane).  Its neighbours it may meet -- a
crease is seen from the triangle beside it -- and only a leaving point within
rounding (about 1e-16 of the coordinates) of a shared edge could meet one at
t ~ 0 by mistake, which no render draws often enough to see.

Every kernel here takes the scene's mesh tables first: None in a scene without
meshes, where Numba prunes the rest of each function, so such a scene compiles
none of the triangle's code (practice 5 of the design notes).
"""
import math

import numpy as np

from ...kernel.jit import jit_host, jit_step, like
from ...kernel.vec3 import cross, dot, sub

INF = math.inf
NAN = math.nan
P0 = 0
P1 = 3
P2 = 6
N = 9
AREA = 12
INDEX = 13
FLOATS = 14


# Meshes up to this many triangles are packed by NumPy (pack_rows): a first
# run then compiles no packing (benchmarks/results/measurements.md).
NUMPY_PACK_MAX = 100_000


def pack_rows(vertices, faces, first_index, block):
    """pack's rows, by NumPy: the same operations in the same order, so the
    same bits (tests/test_meshes.py), and nothing to compile."""
    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    block[:, P0:P0 + 3], block[:, P1:P1 + 3], block[:, P2:P2 + 3] = a, b, c
    u, v = b - a, c - a
    nx = u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1]
    ny = u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2]
    nz = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    double_area = np.sqrt(nx * nx + ny * ny + nz * nz)
    block[:, N], block[:, N + 1], block[:, N + 2] = (nx / double_area, ny / double_area,
                                                     nz / double_area)
    block[:, AREA] = 0.5 * double_area
    block[:, INDEX] = first_index + np.arange(len(faces))


@jit_host
def pack(vertices, faces, first_index, block):
    """Fill block [F, >= FLOATS] with the triangles faces[f] of vertices (V x 3,
    placed in the world); their table rows start at first_index.  (NumPy's
    cross product and norm, operation for operation.)  Compiled, for meshes
    larger than NUMPY_PACK_MAX."""
    for f in range(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        for k in range(3):
            block[f, P0 + k] = vertices[a, k]
            block[f, P1 + k] = vertices[b, k]
            block[f, P2 + k] = vertices[c, k]
        ux, uy, uz = vertices[b, 0] - vertices[a, 0], vertices[b, 1] - vertices[a, 1], \
            vertices[b, 2] - vertices[a, 2]
        vx, vy, vz = vertices[c, 0] - vertices[a, 0], vertices[c, 1] - vertices[a, 1], \
            vertices[c, 2] - vertices[a, 2]
        nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        double_area = math.sqrt(nx * nx + ny * ny + nz * nz)
        block[f, N], block[f, N + 1], block[f, N + 2] = (nx / double_area, ny / double_area,
                                                         nz / double_area)
        block[f, AREA] = 0.5 * double_area
        block[f, INDEX] = first_index + f


def bounds(row):
    corners = np.array([row[P0:P0 + 3], row[P1:P1 + 3], row[P2:P2 + 3]])
    return corners.min(axis=0), corners.max(axis=0)


def light_parts(row):
    """[(part, area)] of the triangle as a light (lights.pack_lights): one part."""
    return [(-1, row[AREA])]


@jit_step
def _vertex(obj_f, k, c):
    return (obj_f[k, c], obj_f[k, c + 1], obj_f[k, c + 2])


@jit_step
def _axis(v, i):
    if i == 0:
        return v[0]
    if i == 1:
        return v[1]
    return v[2]


@jit_step
def ray_frame(d):
    """(kx, ky, kz, sx, sy, sz): the watertight test's frame for direction d,
    the same for every triangle a ray meets (a BVH walk makes it once).  z is
    along d's largest component, x and y the next two (swapped if z points
    backwards, which keeps the winding); s shears d onto +z."""
    ad = (abs(d[0]), abs(d[1]), abs(d[2]))
    kz = 0 if ad[0] >= ad[1] and ad[0] >= ad[2] else (1 if ad[1] >= ad[2] else 2)
    kx = (kz + 1) % 3
    ky = (kx + 1) % 3
    dz = _axis(d, kz)
    if dz < 0.0:
        kx, ky = ky, kx
    return kx, ky, kz, _axis(d, kx) / dz, _axis(d, ky) / dz, 1.0 / dz


@jit_step
def hit(obj_f, k, o, d, t_max):
    """(t, b0, b1, b2): the watertight test's distance in (0, t_max) and the
    barycentric weights of P0, P1, P2 there; t = inf on a miss."""
    return hit_in_frame(obj_f, k, o, ray_frame(d), t_max)


@jit_step
def hit_in_frame(rows, k, o, frame, t_max):
    """hit, for the triangle whose vertices are rows[k, 0:9] (obj_f's row, or
    a copy of it), with the ray's frame already made (ray_frame)."""
    miss = (like(t_max, INF), 0.0, 0.0, 0.0)
    kx, ky, kz, sx, sy, sz = frame
    a = sub(_vertex(rows, k, P0), o)
    b = sub(_vertex(rows, k, P1), o)
    c = sub(_vertex(rows, k, P2), o)
    ax = _axis(a, kx) - sx * _axis(a, kz)
    ay = _axis(a, ky) - sy * _axis(a, kz)
    bx = _axis(b, kx) - sx * _axis(b, kz)
    by = _axis(b, ky) - sy * _axis(b, kz)
    cx = _axis(c, kx) - sx * _axis(c, kz)
    cy = _axis(c, ky) - sy * _axis(c, kz)
    # Edge functions: u of the edge P1 P2 (P0's weight), v of P2 P0, w of P0 P1.
    u = cx * by - cy * bx
    v = ax * cy - ay * cx
    w = bx * ay - by * ax
    if (u < 0.0 or v < 0.0 or w < 0.0) and (u > 0.0 or v > 0.0 or w > 0.0):
        return miss
    det = u + v + w
    t_scaled = u * sz * _axis(a, kz) + v * sz * _axis(b, kz) + w * sz * _axis(c, kz)
    if not within(det, t_scaled, t_max):
        return miss
    inv = 1.0 / det
    return t_scaled * inv, u * inv, v * inv, w * inv


@jit_step
def within(det, t_scaled, t_max):
    """Is the hit of determinant det (0: seen edge-on, or outside the edges)
    and scaled distance t_scaled in (0, t_max)?  (Its distance is then
    t_scaled x (1 / det), which the caller makes.)"""
    if det > 0.0:
        return t_scaled > 0.0 and t_scaled < t_max * det
    if det < 0.0:
        return t_scaled < 0.0 and t_scaled > t_max * det
    return False


@jit_step
def solid_angle_term(obj_f, k, p, d):
    """distance^2 / |cos| where the ray from p along d meets triangle k, wherever
    (0 if it misses): its part of a mesh's light density (mesh_light.py)."""
    t = hit(obj_f, k, p, d, INF)[0]
    if t == INF:
        return 0.0
    cosine = abs(dot(_vertex(obj_f, k, N), d))
    return t * t / cosine if cosine > 0.0 else 0.0


@jit_step
def distance(tris, obj_f, k, o, d, t_max, from_self):
    """Distance to the triangle along d; a ray leaving it never meets it again."""
    if tris is None:
        return like(t_max, NAN)
    if from_self:
        return like(t_max, INF)
    return hit(obj_f, k, o, d, t_max)[0]


@jit_step
def outward_normal(tris, obj_f, k):
    if tris is None:
        return (NAN, NAN, NAN)
    return _vertex(obj_f, k, N)


@jit_step
def shading_normal(tris, obj_f, k, p, n_out):
    """The normal a smooth mesh shades with at p: its vertex normals weighted
    by p's barycentric weights, made unit and turned to n_out's side (a
    file's normals may point either way); n_out for a flat triangle."""
    if tris is None:
        return n_out
    t = tris.normals
    if t.shape[0] == 0:
        return n_out
    i = np.int64(obj_f[k, INDEX])
    if not t[i, 0] == t[i, 0]:          # NaN: a flat mesh's triangle
        return n_out
    b0, b1, b2 = weights(obj_f, k, p)
    n = (b0 * t[i, 0] + b1 * t[i, 3] + b2 * t[i, 6], b0 * t[i, 1] + b1 * t[i, 4] + b2 * t[i, 7],
         b0 * t[i, 2] + b1 * t[i, 5] + b2 * t[i, 8])
    length = math.sqrt(dot(n, n))
    if not length > 0.0:                # opposite vertex normals cancel here
        return n_out
    if dot(n, n_out) < 0.0:
        length = -length
    return (n[0] / length, n[1] / length, n[2] / length)


@jit_step
def surface(tris, obj_f, k):
    """The surface triangle k is part of: its mesh's first triangle."""
    return tris.mesh[np.int64(obj_f[k, INDEX])]


@jit_step
def enters(tris, obj_f, k, n, d):
    """A triangle has no inside of its own: a ray leaving it never goes into it."""
    return False


@jit_step
def weights(obj_f, k, p):
    """The barycentric weights (b0, b1, b2) of a point p on the triangle."""
    p0 = _vertex(obj_f, k, P0)
    e1 = sub(_vertex(obj_f, k, P1), p0)
    e2 = sub(_vertex(obj_f, k, P2), p0)
    n = cross(e1, e2)
    q = sub(p, p0)
    inv = 1.0 / dot(n, n)
    b1 = dot(cross(q, e2), n) * inv
    b2 = dot(cross(e1, q), n) * inv
    return 1.0 - b1 - b2, b1, b2


@jit_step
def uv(tris, obj_f, k, p):
    """Texture coordinates: the mesh's, interpolated, where it has them; else
    the barycentric (b1, b2)."""
    if tris is None:
        return (NAN, NAN)
    b0, b1, b2 = weights(obj_f, k, p)
    i = np.int64(obj_f[k, INDEX])
    if tris.uvs.shape[0] == 0:
        return (b1, b2)
    t = tris.uvs
    return (b0 * t[i, 0] + b1 * t[i, 2] + b2 * t[i, 4], b0 * t[i, 1] + b1 * t[i, 3] + b2 * t[i, 5])


@jit_step
def point(obj_f, k, u1, u2):
    """The point of the unit square's (u1, u2) under the area-preserving map onto
    the triangle (b0 = 1 - sqrt(u1), b1 = u2 sqrt(u1))."""
    s = math.sqrt(u1)
    b0 = 1.0 - s
    b1 = u2 * s
    b2 = 1.0 - b0 - b1
    p0, p1, p2 = _vertex(obj_f, k, P0), _vertex(obj_f, k, P1), _vertex(obj_f, k, P2)
    return (b0 * p0[0] + b1 * p1[0] + b2 * p2[0], b0 * p0[1] + b1 * p1[1] + b2 * p2[1],
            b0 * p0[2] + b1 * p1[2] + b2 * p2[2])


@jit_step
def sample_area(tris, obj_f, k, u1, u2):
    """(point, outward normal): a point uniform over the triangle."""
    if tris is None:
        return (NAN, NAN, NAN), (NAN, NAN, NAN)
    return point(obj_f, k, u1, u2), _vertex(obj_f, k, N)


@jit_step
def sample_toward(tris, obj_f, k, p, u1, u2):
    """The unit direction from p to the triangle's point for the unit square's
    (u1, u2) (uniform in its area for a uniform point)."""
    if tris is None:
        return (NAN, NAN, NAN)
    q = sub(point(obj_f, k, u1, u2), p)
    inv = 1.0 / math.sqrt(dot(q, q))
    return (q[0] * inv, q[1] * inv, q[2] * inv)


@jit_step
def pdf_toward(tris, obj_f, k, p, d, from_self):
    """Solid-angle density at p of direction d under sample_toward:
    distance^2 / (|cos| area) where d meets the triangle, else 0."""
    if tris is None:
        return NAN
    if from_self:
        return 0.0
    t = hit(obj_f, k, p, d, INF)[0]
    if t == INF:
        return 0.0
    cosine = abs(dot(_vertex(obj_f, k, N), d))
    return t * t / (cosine * obj_f[k, AREA])

