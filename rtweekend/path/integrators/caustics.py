"""How bdpt renders the paths only its s = 0 strategy can make -- light through
glass or off a mirror onto a surface the camera sees through glass or in a
mirror: with caustic photon maps (photons.py, `bdpt+photons`) or manifold
connections (through_glass.py, `bdpt+mnee`).

    z, light, smp = seen(scene, caustics, s, cf, ci, nc, max_depth, textures, time, smp)
    covered(scene, caustics, cf, ci, z, t, time)   # s = 0 leaves the path out

Both take the kernel's `caustics` argument: the photon maps (photons.Caustics)
or the longest glass chain solved (an integer).  Numba picks each one's
version by that type when compiling, so a kernel holds one of the two only
(as `is None` keeps out both).
"""
from numba import types
from numba.extending import overload

from . import photons, through_glass

ZERO = (0.0, 0.0, 0.0)


def seen(scene, caustics, s, cf, ci, nc, max_depth, textures, time, smp):
    """(z, light, smp): the camera vertex z where the caustics are read (-1:
    none) and the light they bring the camera's sample s there."""


def covered(scene, caustics, cf, ci, z, t, time):
    """Does the caustics' estimate at z render the camera path of t vertices
    that ends on an emitter?"""


@overload(seen, inline="always")
def _seen(scene, caustics, s, cf, ci, nc, max_depth, textures, time, smp):
    if isinstance(caustics, types.Integer):
        return lambda scene, caustics, s, cf, ci, nc, max_depth, textures, time, smp: \
            through_glass.connected(scene, cf, ci, nc, textures, time, smp)
    return lambda scene, caustics, s, cf, ci, nc, max_depth, textures, time, smp: \
        photons.seen(scene, caustics, s, cf, ci, nc, max_depth, smp)


@overload(covered, inline="always")
def _covered(scene, caustics, cf, ci, z, t, time):
    if isinstance(caustics, types.Integer):
        return lambda scene, caustics, cf, ci, z, t, time: \
            through_glass.covered(scene, caustics, cf, ci, z, t, time)
    return lambda scene, caustics, cf, ci, z, t, time: photons.covered(scene, cf, ci, z, t)
