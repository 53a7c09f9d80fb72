"""Specular chains: the path from a point to a light through smooth glass
(Hanika, Droske and Fascione 2015, "Manifold Next Event Estimation").

A shadow ray from a diffuse point x0 to a point y on a light is blocked by any
glass between them, though light does reach x0 from y -- bent at each glass
surface it crosses.  The chain x1 .. xk of those crossings is found by a walk
on the surfaces:

  seed      the straight segment x0 -> y: where it crosses smooth glass
            (`seed_chain`), each crossing a vertex on its object's surface
  solve     Newton's method on the vertices' tangent coordinates until every
            vertex obeys Snell's law (`solve`): the constraint at x_i is the
            tangential part of the generalised half vector
            h = eta_a w_a + eta_b w_b (w_a, w_b: the unit directions to the
            neighbours, eta: the index on each one's side), normalised; 0 iff
            eta_a sin(theta_a) = eta_b sin(theta_b) in the plane of incidence
  measure   the solid angle at x0 per unit area at y through the chain
            (`solid_angle_per_area`): the implicit function theorem gives how
            the vertices move with y (dX/dy = -A^-1 B, A and B the constraint's
            derivatives in the vertices' and y's tangent coordinates), hence
            how the first direction w0 = (x1 - x0) / |x1 - x0| turns; with no
            glass it is |cos theta_y| / |x0 - y|^2, the usual geometry term
  transmit  the books' dielectric lets 1 - schlick(cos) through at each
            crossing, the cosine of the ray arriving from x0's side
            (`transmittance`: 0 under total internal reflection)

so that light L_e at y, drawn with area density p(y), gives x0 the estimate
f |cos theta_0| L_e T J / p(y) along w0 (J: solid_angle_per_area).

Derivatives by central differences of the constraints (each vertex's
depends on its neighbours only), in tangent steps scaled to the chain's size:
spheres and flat kinds alike, no per-kind formula.  A vertex on a sphere moves
in its tangent plane and is pushed back radially; on a flat kind it stays on
its plane (leaving the primitive's extent is for the visibility check of the
solved path to find).  Meshes are not casters here.

The `mnee` strategy's steps that use it are in mnee.py.

Chains hold at most MAX_CHAIN vertices, in arrays the caller owns (verts
float64 [MAX_CHAIN, 3], objs int64 [MAX_CHAIN]), and the solver works in the
caller's arrays too (`workspace`, or stack arrays of the sizes below: a
kernel's steps allocate nothing).
"""
import math

import numpy as np

from ..kernel.jit import jit_step
from ..kernel.vec3 import dot, madd, onb, scale, sub
from . import materials, shapes
from .bvh import closest_hit
from .layout import NO_HIT, OBJ_KIND, OBJ_MAT, SPHERE, TRIANGLE
from .shapes import sphere

MAX_CHAIN = 4
# The stack arrays' sizes (literals: stack_array needs them when compiling).
VERT_FLOATS = 12          # 3 MAX_CHAIN
SYSTEM_FLOATS = 64        # (2 MAX_CHAIN)^2
RHS_FLOATS = 16           # 2 MAX_CHAIN x 2
MAX_STEPS = 30            # Newton steps before a solve is given up
TOLERANCE = 1e-10         # |constraint| (a sine) at which Snell's law holds
STEP = 1e-6               # central differences: this fraction of the chain's size


def workspace():
    """The solver's scratch arrays, one set per thread: (A [2K, 2K], the
    right-hand sides [2K, 2], trial vertices [K, 3], reference normals [K, 3])
    for K = MAX_CHAIN."""
    return (np.zeros((2 * MAX_CHAIN, 2 * MAX_CHAIN)), np.zeros((2 * MAX_CHAIN, 2)),
            np.zeros((MAX_CHAIN, 3)), np.zeros((MAX_CHAIN, 3)))


@jit_step
def _unit(v):
    return scale(v, 1.0 / math.sqrt(dot(v, v)))


@jit_step(inline=False)
def nearest(scene, o, d, from_obj, inside, time):
    """closest_hit with no limit, called: the one copy of the search that the
    connections hold (seed_chain, mnee's visibility), seconds less of compile."""
    return closest_hit(scene, o, d, math.inf, from_obj, inside, time)


@jit_step(inline=False)
def seed_chain(scene, x0, from_obj, y, light, time, verts, objs):
    """The smooth-glass crossings of the segment from x0 (a point of object
    from_obj) to y (a point of object `light`), in order, into verts and objs:
    (count, ok); ok False if anything else blocks the segment first, a
    crossing is a mesh's, or the crossings are more than MAX_CHAIN."""
    d = sub(y, x0)
    dist = math.sqrt(dot(d, d))
    d = scale(d, 1.0 / dist)
    o, last, inside, travelled = x0, from_obj, False, 0.0
    count = 0
    while True:
        k, t = nearest(scene, o, d, last, inside, time)
        if k == light or k == NO_HIT or travelled + t >= dist * (1.0 - 1e-9):
            return count, True                  # y reached (a miss: by a rounding)
        if materials.smooth_ior(scene, scene.obj_i[k, OBJ_MAT]) <= 0.0 or count == MAX_CHAIN or \
                scene.obj_i[k, OBJ_KIND] == TRIANGLE:
            return count, False     # a mesh refracts by its shading normals: not a caster
        p = madd(o, d, t)
        verts[count, 0], verts[count, 1], verts[count, 2] = p
        objs[count] = k
        count += 1
        inside = shapes.enters(scene, k, shapes.outward_normal(scene, k, p, time), d)
        o, last, travelled = p, k, travelled + t


@jit_step
def vertex(verts, i):
    return (verts[i, 0], verts[i, 1], verts[i, 2])


@jit_step
def neighbour(x0, y, verts, count, i):
    """Vertex i of the whole path x0, x1 .. xk, y (0: x0, count + 1: y)."""
    if i == 0:
        return x0
    if i == count + 1:
        return y
    return vertex(verts, i - 1)


@jit_step
def constraint(scene, x0, y, verts, objs, count, i, ref, time):
    """Snell's law at vertex i (0-based) as two numbers, 0 when it holds: the
    normalised half vector's part across the surface's normal, along the two
    tangents of the frame onb(ref) (ref: a normal near the vertex's, held
    fixed while the vertex moves, so that the frame does not jump)."""
    p = vertex(verts, i)
    n = shapes.outward_normal(scene, objs[i], p, time)
    wa = _unit(sub(neighbour(x0, y, verts, count, i), p))
    wb = _unit(sub(neighbour(x0, y, verts, count, i + 2), p))
    ior = materials.smooth_ior(scene, scene.obj_i[objs[i], OBJ_MAT])
    eta_a = 1.0 if dot(wa, n) > 0.0 else ior
    eta_b = 1.0 if dot(wb, n) > 0.0 else ior
    h = _unit((eta_a * wa[0] + eta_b * wb[0], eta_a * wa[1] + eta_b * wb[1],
               eta_a * wa[2] + eta_b * wb[2]))
    across = madd(h, n, -dot(h, n))
    s, t = onb(ref)
    return dot(across, s), dot(across, t)


@jit_step
def _normal(scene, verts, objs, i, time):
    return shapes.outward_normal(scene, objs[i], vertex(verts, i), time)


@jit_step
def _residual(scene, x0, y, verts, objs, count, time):
    """The largest constraint (in each vertex's own frame)."""
    worst = 0.0
    for i in range(count):
        c0, c1 = constraint(scene, x0, y, verts, objs, count, i,
                            _normal(scene, verts, objs, i, time), time)
        worst = max(worst, math.sqrt(c0 * c0 + c1 * c1))
    return worst


@jit_step
def _moved(scene, k, p, n, da, db, time):
    """p moved by (da, db) in the tangent frame onb(n), back on object k's
    surface (a sphere: radially; a flat kind stays in its plane)."""
    s, t = onb(n)
    q = (p[0] + da * s[0] + db * t[0], p[1] + da * s[1] + db * t[1],
         p[2] + da * s[2] + db * t[2])
    if scene.obj_i[k, OBJ_KIND] == SPHERE:
        c = sphere.center(scene.obj_f, k, time)
        r = abs(scene.obj_f[k, sphere.RADIUS])
        return madd(c, _unit(sub(q, c)), r)
    return q


@jit_step
def _zero(x):
    for i in range(x.shape[0]):
        for j in range(x.shape[1]):
            x[i, j] = 0.0


@jit_step
def size(x0, y):
    d = sub(y, x0)
    return math.sqrt(dot(d, d))


@jit_step
def _jacobian(scene, x0, y, verts, objs, count, refs, time, a):
    """a[2k, 2k]: the constraints' derivatives in the vertices' tangent
    coordinates (central differences of step STEP x the chain's size), each
    constraint in the frame of refs[i], a vertex moved in that of its normal."""
    h = STEP * size(x0, y)
    for j in range(count):
        p = vertex(verts, j)
        n = shapes.outward_normal(scene, objs[j], p, time)
        for axis in range(2):
            for sign in (1.0, -1.0):
                q = _moved(scene, objs[j], p, n, sign * h if axis == 0 else 0.0,
                           sign * h if axis == 1 else 0.0, time)
                verts[j, 0], verts[j, 1], verts[j, 2] = q
                for i in range(max(0, j - 1), min(count, j + 2)):
                    c0, c1 = constraint(scene, x0, y, verts, objs, count, i,
                                        vertex(refs, i), time)
                    a[2 * i, 2 * j + axis] += sign * c0 / (2.0 * h)
                    a[2 * i + 1, 2 * j + axis] += sign * c1 / (2.0 * h)
            verts[j, 0], verts[j, 1], verts[j, 2] = p


@jit_step
def _solve_linear(a, b, n, m):
    """Solve a[:n, :n] x = b[:n, :m] in place (b becomes x), by Gaussian
    elimination with partial pivoting; False if a is singular."""
    for c in range(n):
        pivot = c
        for r in range(c + 1, n):
            if abs(a[r, c]) > abs(a[pivot, c]):
                pivot = r
        if a[pivot, c] == 0.0 or not math.isfinite(a[pivot, c]):
            return False
        if pivot != c:
            for j in range(n):
                a[c, j], a[pivot, j] = a[pivot, j], a[c, j]
            for j in range(m):
                b[c, j], b[pivot, j] = b[pivot, j], b[c, j]
        for r in range(c + 1, n):
            f = a[r, c] / a[c, c]
            for j in range(c, n):
                a[r, j] -= f * a[c, j]
            for j in range(m):
                b[r, j] -= f * b[c, j]
    for c in range(n - 1, -1, -1):
        for j in range(m):
            s = b[c, j]
            for k in range(c + 1, n):
                s -= a[c, k] * b[k, j]
            b[c, j] = s / a[c, c]
    return True


@jit_step(inline=False)
def solve(scene, x0, y, verts, objs, count, time, work):
    """Move verts[:count] (on objs' surfaces) until Snell's law holds at each,
    by Newton's method with the step halved while it does not lower the
    largest constraint (Hanika et al.'s walk).  True if it converged."""
    a, b, trial, refs = work
    error = _residual(scene, x0, y, verts, objs, count, time)
    for _ in range(MAX_STEPS):
        if error < TOLERANCE:
            return True
        for i in range(count):
            n = _normal(scene, verts, objs, i, time)
            refs[i, 0], refs[i, 1], refs[i, 2] = n
        _zero(a)
        _jacobian(scene, x0, y, verts, objs, count, refs, time, a)
        for i in range(count):
            c0, c1 = constraint(scene, x0, y, verts, objs, count, i, vertex(refs, i), time)
            b[2 * i, 0], b[2 * i + 1, 0] = -c0, -c1
        if not _solve_linear(a, b, 2 * count, 1):
            return False
        step = 1.0
        while True:
            for j in range(count):
                p = vertex(verts, j)
                n = shapes.outward_normal(scene, objs[j], p, time)
                q = _moved(scene, objs[j], p, n, step * b[2 * j, 0], step * b[2 * j + 1, 0],
                           time)
                trial[j, 0], trial[j, 1], trial[j, 2] = q
            e = _residual(scene, x0, y, trial, objs, count, time)
            if e < error:
                for j in range(count):
                    verts[j, 0], verts[j, 1], verts[j, 2] = trial[j, 0], trial[j, 1], trial[j, 2]
                error = e
                break
            step *= 0.5
            if step < 1e-6:
                return False
    return error < TOLERANCE


@jit_step
def solid_angle_per_area(scene, x0, y, n_y, verts, objs, count, time, work):
    """dw0 / dA(y): how much solid angle at x0 the directions towards x1 sweep
    per unit area of y's surface (normal n_y), through the solved chain."""
    if count == 0:
        d = sub(y, x0)
        dist2 = dot(d, d)
        return abs(dot(d, n_y)) / (dist2 * math.sqrt(dist2))
    n = 2 * count
    a, b, _, refs = work
    _zero(a)
    _zero(b)
    for j in range(count):
        nj = _normal(scene, verts, objs, j, time)
        refs[j, 0], refs[j, 1], refs[j, 2] = nj
    _jacobian(scene, x0, y, verts, objs, count, refs, time, a)
    # B: the last vertex's constraint as y moves along its surface's tangents.
    h = STEP * size(x0, y)
    su, sv = onb(n_y)
    i = count - 1
    for axis in range(2):
        e = su if axis == 0 else sv
        hi = constraint(scene, x0, madd(y, e, h), verts, objs, count, i, vertex(refs, i), time)
        lo = constraint(scene, x0, madd(y, e, -h), verts, objs, count, i, vertex(refs, i), time)
        b[2 * i, axis] = -(hi[0] - lo[0]) / (2.0 * h)        # -B: dX = A^-1 (-B)
        b[2 * i + 1, axis] = -(hi[1] - lo[1]) / (2.0 * h)
    if not _solve_linear(a, b, n, 2):
        return 0.0
    # x1 moves by s1 dX[0] + t1 dX[1]; w0 turns by its part across w0 over |x1 - x0|.
    x1 = vertex(verts, 0)
    s1, t1 = onb(shapes.outward_normal(scene, objs[0], x1, time))
    r = sub(x1, x0)
    dist = math.sqrt(dot(r, r))
    w0 = scale(r, 1.0 / dist)
    e1, e2 = onb(w0)
    du = (s1[0] * b[0, 0] + t1[0] * b[1, 0], s1[1] * b[0, 0] + t1[1] * b[1, 0],
          s1[2] * b[0, 0] + t1[2] * b[1, 0])
    dv = (s1[0] * b[0, 1] + t1[0] * b[1, 1], s1[1] * b[0, 1] + t1[1] * b[1, 1],
          s1[2] * b[0, 1] + t1[2] * b[1, 1])
    return abs(dot(e1, du) * dot(e2, dv) - dot(e1, dv) * dot(e2, du)) / (dist * dist)


@jit_step
def transmittance(scene, x0, y, verts, objs, count, time):
    """The books' dielectric transmittance along the chain, crossed from x0's
    side: the product of 1 - schlick(cos) with the cosine each ray arrives
    with; 0 if a crossing is not a refraction (both neighbours on one side)
    or would reflect totally."""
    total = 1.0
    for i in range(count):
        p = vertex(verts, i)
        n = shapes.outward_normal(scene, objs[i], p, time)
        d = _unit(sub(p, neighbour(x0, y, verts, count, i)))
        out = _unit(sub(neighbour(x0, y, verts, count, i + 2), p))
        if (dot(d, n) < 0.0) != (dot(out, n) < 0.0):
            return 0.0
        ior = materials.smooth_ior(scene, scene.obj_i[objs[i], OBJ_MAT])
        t = materials.smooth_transmittance(d, n, ior)
        if t <= 0.0:
            return 0.0
        total *= t
    return total


@jit_step
def first_direction(x0, y, verts, count):
    """The unit direction from x0 along the chain's first segment."""
    return _unit(sub(neighbour(x0, y, verts, count, 1), x0))
