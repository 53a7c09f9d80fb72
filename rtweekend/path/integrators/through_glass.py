"""bdpt's manifold connections (the `bdpt+mnee` strategy): light that reaches a
smooth surface through smooth glass, where the camera too sees that surface
only through glass or in a mirror.

Why: such a path -- lamp, glass globe, wall, glass globe, camera: the wall seen
through the globe that holds the lamp -- has one strategy in bdpt only, the
camera subpath reaching the emitter through the glass by chance (s = 0):
light tracing cannot join the camera through glass, nor a shadow ray cross
it (photons.py says the same of caustics).  On `glass_lamp` those pixels held
most of bdpt's error once the glass choices were stratified.  A manifold
connection (path/mnee.py) solves for the path from that surface point through
the glass to a point drawn on an emitter: the light arriving there, directly.

The paths it takes over, exactly: camera, one or more delta vertices, a
smooth surface point z -- the first smooth vertex of the camera path --,
1 .. MAX_CHAIN refractions through smooth glass, an emitter, when the walk
seeded on the segment from z to that emitter point solves to the path's own
first crossing (mnee.renders; a path the walk does not find stays the
camera's).  The camera subpath's s = 0 strategy skips these paths (covered),
and no other strategy can make them (each would join at a delta vertex), so
the two estimates never count a path twice.

bdpt's needs (needs.py) for it: the kernel compiled with `manifold` = the
longest chain solved (layout.Features); the scene as bdpt+sobol renders it,
bit for bit, where no glass refracts or media scatter.
"""
import itertools

import numpy as np

from ...kernel import sampler
from ...kernel.jit import jit_step
from ...kernel.vec3 import neg
from .. import materials, mnee
from ..materials import EMITS, REFRACTS
from .vertices import (BETA, DELTA, MKIND, NG, OBJ, P, SURFACE, TYPE, WO, bsdf_facing, col,
                       connectible, toward)

ZERO = (0.0, 0.0, 0.0)


def skipped(scene):
    """Why bdpt+mnee renders `scene` as bdpt+sobol, in a few words, or None."""
    if not any(materials.kind_has(shape.material.kind, REFRACTS) for shape in scene.objects):
        return "no smooth glass to connect through"
    if any(shape.medium for shape in scene.objects):
        return "no manifold connections with media"
    return None


def encloses_an_emitter(scene):
    """Does a smooth glass ball or box hold a whole emitter (a lamp in a glass
    globe)?  Then every light path leaves through the glass and every shadow
    ray meets it: what the connections are for (integrators.default_sampling)."""
    glass = [g for g in scene.objects
             if g.kind in ("sphere", "box") and materials.kind_has(g.material.kind, REFRACTS)]
    return any(_holds(g, e) for e in scene.objects
               if materials.kind_has(e.material.kind, EMITS) for g in glass)


def _holds(glass, shape):
    """Is the whole of `shape` inside the glass sphere or box?  A sphere by its
    centre and radius, any other kind by the corners of its box in its own
    frame (a mesh: never)."""
    rot, offset = glass.placement()
    if shape.kind == "sphere":
        r = abs(shape.geometry[1])
        points = [_world(shape, shape.geometry[0])]
    elif shape.kind == "mesh":
        return False
    else:
        r = 0.0
        points = [_world(shape, p) for p in itertools.product(*zip(*_box(shape)))]
    for p in points:
        q = rot.T @ (p - offset)                 # in the glass's own frame
        if glass.kind == "sphere":
            if np.linalg.norm(q - np.asarray(glass.geometry[0])) + r >= abs(glass.geometry[1]):
                return False
        elif np.any(q - r <= np.asarray(glass.geometry[0])) or \
                np.any(q + r >= np.asarray(glass.geometry[1])):
            return False
    return True


def _box(shape):
    """(lo, hi): the box of a rect, quad or box in its own frame."""
    g, k = shape.geometry, shape.kind
    if k == "box":
        return np.asarray(g[0]), np.asarray(g[1])
    if k == "quad":
        q, u, v = (np.asarray(x) for x in g)
        corners = [q, q + u, q + v, q + u + v]
        return np.min(corners, axis=0), np.max(corners, axis=0)
    a0, a1, b0, b1, c = g                           # xy_rect, xz_rect, yz_rect
    axes = list({"xy_rect": (0, 1, 2), "xz_rect": (0, 2, 1), "yz_rect": (1, 2, 0)}[k])
    lo, hi = np.zeros(3), np.zeros(3)
    lo[axes], hi[axes] = (a0, b0, c), (a1, b1, c)
    return lo, hi


def _world(shape, p):
    rot, offset = shape.placement()
    return rot @ np.asarray(p, dtype=np.float64) + offset


def features(strategy, scene, arrays):
    return {"manifold": mnee.MAX_CHAIN} if strategy.manifold and skipped(scene) is None else {}


def runs_as(strategy, scene):
    why = skipped(scene) if strategy.manifold else None
    return None if why is None else ("bdpt+sobol", why)


@jit_step
def seen_through(ci, nc):
    """The camera vertex where connections are made: the first smooth vertex of
    the camera subpath (nc vertices), if one or more delta vertices lie before
    it and it is a surface that does not emit; else -1."""
    for i in range(1, nc):
        if ci[i, DELTA] == 0:
            if i >= 2 and ci[i, TYPE] == SURFACE and connectible(ci, i) and \
                    not materials.has(ci[i, MKIND], EMITS):
                return i
            return -1
    return -1


@jit_step(inline=False)
def connected(scene, cf, ci, nc, textures, time, smp):
    """(z, light, (rays, tried, unsolved), smp): the camera vertex z
    (seen_through; -1: none) and the light a manifold connection brings it
    from an emitter through glass, times the camera subpath's throughput
    there; what the connection traced and whether it was tried and dropped
    unsolved (mnee.connect)."""
    z = seen_through(ci, nc)
    if z < 0:
        return z, ZERO, (0, 0, 0), smp
    u, smp = sampler.uniform(smp)
    u1, u2, smp = sampler.reserved_2d(smp, 0)   # the point on the emitter: stratified
    wo = col(cf, z, WO)
    light, rays, tried, unsolved = mnee.connect(
        scene, col(cf, z, P), ci[z, OBJ], bsdf_facing(scene.glossy, cf, ci, z, wo), wo,
        col(cf, z, BETA), (u, u1, u2), time, textures)
    return z, light, (rays, tried, unsolved), smp


@jit_step(inline=False)
def covered(scene, chain_max, cf, ci, z, t, time):
    """Is the path of camera vertices 0 .. t - 1 (vertex t - 1 on an emitter)
    one the connections at vertex z render?  Only refractions through smooth
    glass between z and the emitter, 1 .. chain_max of them, and the walk
    seeded from z finds this very path (mnee.renders)."""
    pt = t - 1
    chain = pt - 1 - z
    if z < 0 or chain < 1 or chain > chain_max:
        return False
    refractions = 0
    for i in range(z + 1, pt):
        if ci[i, DELTA] == 0 or ci[i, TYPE] != SURFACE:
            return False
        d_out, _ = toward(col(cf, i, P), col(cf, i + 1, P))
        refractions = mnee.through_glass(refractions, ci[i, MKIND], neg(col(cf, i, WO)), d_out,
                                         col(cf, i, NG))
        if refractions < 0:
            return False                    # not a refraction through smooth glass
    return mnee.renders(scene, col(cf, z, P), ci[z, OBJ], col(cf, z + 1, P), col(cf, pt, P),
                        ci[pt, OBJ], np.int64(chain), time)
