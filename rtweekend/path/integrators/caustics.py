"""How bdpt renders the paths only its s = 0 strategy can make -- light through
glass or off a mirror onto a surface the camera sees through glass or in a
mirror: with caustic photon maps (photons.py, `bdpt+photons`), manifold
connections (through_glass.py, `bdpt+mnee`), or not at all (s = 0 alone).

    z, light, counts, smp = seen(scene, maps, chain, s, cf, ci, nc, max_depth, textures,
                                 time, smp)
    covered(scene, maps, chain, cf, ci, z, t, time)   # s = 0 leaves the path out

maps and chain are the kernel's `caustics` and `manifold` (layout.Features),
at most one of them not None.  Each is an argument here, so Numba prunes the
`is None` tests: a kernel holds the code of the one it renders with, or none.
"""
from ...kernel.jit import jit_step
from . import photons, through_glass

ZERO = (0.0, 0.0, 0.0)
NO_COUNTS = (0, 0, 0)


@jit_step
def seen(scene, maps, chain, s, cf, ci, nc, max_depth, textures, time, smp):
    """(z, light, counts, smp): the camera vertex z where the caustics are read
    (-1: none), the light they bring camera sample s there, and the
    connections' (rays traced, tried, unsolved): through_glass.connected."""
    if maps is not None:
        z, light, smp = photons.seen(scene, maps, s, cf, ci, nc, max_depth, smp)
        return z, light, NO_COUNTS, smp
    if chain is not None:
        return through_glass.connected(scene, cf, ci, nc, textures, time, smp)
    return -1, ZERO, NO_COUNTS, smp


@jit_step
def covered(scene, maps, chain, cf, ci, z, t, time):
    """Does the estimate at camera vertex z render the camera path of t
    vertices that ends on an emitter (so that s = 0 leaves it out)?"""
    if maps is not None:
        return photons.covered(scene, cf, ci, z, t)
    if chain is not None:
        return through_glass.covered(scene, chain, cf, ci, z, t, time)
    return False
