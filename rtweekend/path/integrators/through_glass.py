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

bdpt's needs (needs.py) for it: the kernel compiled with `caustics` = the
longest chain solved (an integer, where the photon maps' strategy has its
maps: caustics.py tells them apart); the scene as bdpt+sobol renders it
otherwise, bit for bit, where no glass refracts or media scatter.
"""
import numpy as np

from ...kernel import sampler
from ...kernel.jit import jit_step
from ...kernel.vec3 import dot, neg
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


def features(strategy, scene, arrays):
    return {"caustics": mnee.MAX_CHAIN} if strategy.manifold and skipped(scene) is None else {}


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


@jit_step
def connected(scene, cf, ci, nc, textures, time, smp):
    """(z, light, smp): the camera vertex z (seen_through; -1: none) and the
    light a manifold connection brings it from an emitter through glass,
    times the camera subpath's throughput there."""
    z = seen_through(ci, nc)
    if z < 0:
        return z, ZERO, smp
    u, smp = sampler.uniform(smp)
    u1, u2, smp = sampler.next_2d(smp)
    wo = col(cf, z, WO)
    light = mnee.connect(scene, col(cf, z, P), ci[z, OBJ], bsdf_facing(scene.glossy, cf, ci, z, wo),
                         wo, col(cf, z, BETA), (u, u1, u2), time, textures)
    return z, light, smp


@jit_step
def covered(scene, chain_max, cf, ci, z, t, time):
    """Is the path of camera vertices 0 .. t - 1 (vertex t - 1 on an emitter)
    one the connections at vertex z render?  Only refractions through smooth
    glass between z and the emitter, 1 .. chain_max of them, and the walk
    seeded from z finds this very path (mnee.renders)."""
    pt = t - 1
    chain = pt - 1 - z
    if z < 0 or chain < 1 or chain > chain_max:
        return False
    for i in range(z + 1, pt):
        if ci[i, DELTA] == 0 or ci[i, TYPE] != SURFACE or \
                not materials.has(ci[i, MKIND], REFRACTS):
            return False
        n = col(cf, i, NG)
        d_out, _ = toward(col(cf, i, P), col(cf, i + 1, P))
        if (dot(neg(col(cf, i, WO)), n) < 0.0) != (dot(d_out, n) < 0.0):
            return False                    # reflected: not a refraction
    return mnee.renders(scene, col(cf, z, P), ci[z, OBJ], col(cf, z + 1, P), col(cf, pt, P),
                        ci[pt, OBJ], np.int64(chain), time)
