"""Manifold next-event estimation (the `mnee` strategy, integrators/path.py):
light that reaches a smooth hit only through smooth glass, which every shadow
ray misses (Hanika, Droske and Fascione 2015).

  connect        at every smooth hit: one point of an emitter, picked as a
                 shadow ray's is (lights.py), the chain of crossings to it
                 solved (manifold.py), its emission side, visibility of every
                 segment, and its weight beta f |cos| L_e T J / p(y)
  renders        the partition: a camera path that reaches an emitter through
                 1 .. MAX_CHAIN refractions after a smooth vertex (counted by
                 through_glass) leaves its emission out only if the walk
                 seeded on the segment to that point solves to its own first
                 crossing -- those are connect's to render, every other path
                 the camera's, so the image is unbiased wherever the walk
                 misses a solution (two paths through a ball lens near its
                 caustic)

connect and renders are called, not inlined (each holds its own searches),
and keep their scratch arrays on the stack.
"""
import math

import numpy as np

from ..kernel.jit import jit_step
from ..kernel.stack import stack_array
from ..kernel.vec3 import dot, scale, sub
from . import lights, manifold, materials, shapes
from . import textures as texturing
from .layout import EMITTED, LIGHT_PROB, NO_HIT, OBJ_MAT
# Imported by name, so that stack_array sees literals when compiling.
from .manifold import MAX_CHAIN, RHS_FLOATS, SYSTEM_FLOATS, VERT_FLOATS

K = MAX_CHAIN
NONE = (0.0, 0.0, 0.0)
SAME = 1e-6               # two solved vertices this fraction of the chain's size apart are one


@jit_step
def _visible(scene, x0, from_obj, y, light, verts, objs, count, time):
    """(visible, rays traced): does each segment of the solved path x0, x1 ..
    xk, y meet nothing before its far end, which it meets there (the right
    object, at its distance)?"""
    a, oa = x0, from_obj
    for i in range(count + 1):
        b = manifold.neighbour(x0, y, verts, count, i + 1)
        ob = objs[i] if i < count else light
        d = sub(b, a)
        dist = math.sqrt(dot(d, d))
        d = scale(d, 1.0 / dist)
        inside = False
        if oa != NO_HIT:
            inside = shapes.enters(scene, oa, shapes.outward_normal(scene, oa, a, time), d)
        k, t = manifold.nearest(scene, a, d, oa, inside, time)
        if k != ob or abs(t - dist) > 1e-6 * dist:
            return False, i + 1
        a, oa = b, ob
    return True, count + 1


@jit_step(inline=False)
def connect(scene, p, k, bsdf, wo, beta, xi, time, textures):
    """Light that reaches the point p of object k (its material: bsdf; the path
    came from wo with throughput beta) from a point of an emitter through
    smooth glass: xi = (u, u1, u2) picks the emitter by power and the point on
    it by area (lights.py), as a shadow ray does; the chain from p to it is
    solved, checked for visibility and weighed:
    beta f |cos| L_e T J / p(y).  Nothing where no glass is in between (the
    shadow ray's light), where the chain does not solve, or where anything
    else blocks it.  Returns (light, rays traced, tried, unsolved): tried 1
    when there was a chain of glass to solve, unsolved 1 when the walk did not
    converge or the solved path meets total internal reflection (the summary
    counts them: film.CONNECTIONS, UNSOLVED).  Called, not inlined: one copy,
    with its own searches."""
    u, u1, u2 = xi
    row = lights.pick(scene, EMITTED, u)
    e, y, n_y, pdf_area = lights.sample_point(scene, row, u1, u2, time)
    verts = stack_array(VERT_FLOATS, np.float64).reshape((K, 3))
    objs = stack_array(K, np.int64)
    count, ok = manifold.seed_chain(scene, p, k, y, e, time, verts, objs)
    rays = count + 1                        # the seed's searches, the last one's miss included
    if not ok or count == 0:
        return NONE, rays, 0, 0
    work = (stack_array(SYSTEM_FLOATS, np.float64).reshape((2 * K, 2 * K)),
            stack_array(RHS_FLOATS, np.float64).reshape((2 * K, 2)),
            stack_array(VERT_FLOATS, np.float64).reshape((K, 3)),
            stack_array(VERT_FLOATS, np.float64).reshape((K, 3)))
    if not manifold.solve(scene, p, y, verts, objs, count, time, work):
        return NONE, rays, 1, 1
    arriving = sub(y, manifold.vertex(verts, count - 1))
    m = scene.obj_i[e, OBJ_MAT]
    color = materials.color(scene, m)
    if textures is not None:
        color = texturing.color_at(scene, textures, m, e, y, color, time)
    emits, radiance = materials.emitted_by(scene, m, dot(arriving, n_y) < 0.0, color)
    if not emits:
        return NONE, rays, 1, 0
    w0 = manifold.first_direction(p, y, verts, count)
    att, f = materials.eval(bsdf, wo, w0, 1.0)
    if f <= 0.0:
        return NONE, rays, 1, 0
    t = manifold.transmittance(scene, p, y, verts, objs, count, time)
    if t <= 0.0:
        return NONE, rays, 1, 1             # total internal reflection on the way
    visible, n = _visible(scene, p, k, y, e, verts, objs, count, time)
    if not visible:
        return NONE, rays + n, 1, 0
    j = manifold.solid_angle_per_area(scene, p, y, n_y, verts, objs, count, time, work)
    c = f * t * j / (pdf_area * scene.light_f[row, LIGHT_PROB])
    return (beta[0] * att[0] * radiance[0] * c, beta[1] * att[1] * radiance[1] * c,
            beta[2] * att[2] * radiance[2] * c), rays + n, 1, 0


@jit_step(inline=False)
def renders(scene, x0, k0, x1, y, light, chain, time):
    """Is the camera's path from the smooth vertex x0 (of object k0) through
    `chain` refractions, the first at x1, to the point y of emitter `light`
    one that connect() finds -- the chain seeded on the segment x0 -> y has
    as many crossings and solves to the same first vertex?  Those paths are
    the connections' to render; the camera's paths render every other (the
    partition is exact, whatever the solutions the walk misses)."""
    verts = stack_array(VERT_FLOATS, np.float64).reshape((K, 3))
    objs = stack_array(K, np.int64)
    count, ok = manifold.seed_chain(scene, x0, k0, y, light, time, verts, objs)
    if not ok or count != chain:
        return False
    work = (stack_array(SYSTEM_FLOATS, np.float64).reshape((2 * K, 2 * K)),
            stack_array(RHS_FLOATS, np.float64).reshape((2 * K, 2)),
            stack_array(VERT_FLOATS, np.float64).reshape((K, 3)),
            stack_array(VERT_FLOATS, np.float64).reshape((K, 3)))
    if not manifold.solve(scene, x0, y, verts, objs, count, time, work):
        return False
    d = sub(manifold.vertex(verts, 0), x1)
    return dot(d, d) <= (SAME * manifold.size(x0, y)) ** 2


@jit_step
def through_glass(chain, kind, d_in, d_out, n):
    """The count of smooth refractions since the path's last smooth vertex
    after a delta bounce from d_in to d_out (normal n) at a material of `kind`:
    one more if the bounce went through a REFRACTS surface, -1 (none to count)
    after anything else or from -1.  A path that reaches an emitter with 1 ..
    MAX_CHAIN of them may be the connections' to render (renders() says)."""
    if chain >= 0 and materials.has(kind, materials.REFRACTS) and \
            (dot(d_in, n) < 0.0) == (dot(d_out, n) < 0.0):
        return chain + 1
    return -1
