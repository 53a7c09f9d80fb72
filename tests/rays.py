"""Rays for the tests: many at once through the renderer's own search,
directions uniform over the sphere, and directions towards a light of the
lights list with their density."""
import math

import numpy as np
from numba import njit

from rtweekend.kernel.rng import seed_state, uniform, unit_vector
from rtweekend.path import pdf
from rtweekend.path.bvh import closest_hit
from rtweekend.path.layout import NO_HIT


@njit
def nearest_hits(arrays, origins, directions):
    """(object int64 [N], t float64 [N]) of each ray's nearest hit by
    bvh.closest_hit (NO_HIT and inf for a miss); directions need not be unit."""
    k = np.empty(origins.shape[0], dtype=np.int64)
    t = np.empty(origins.shape[0])
    for i in range(origins.shape[0]):
        k[i], t[i] = closest_hit(arrays, (origins[i, 0], origins[i, 1], origins[i, 2]),
                                 (directions[i, 0], directions[i, 1], directions[i, 2]),
                                 math.inf, np.int64(NO_HIT), False, None)
    return k, t


@njit
def uniform_directions(count, seed):
    """float64 [count, 3] unit vectors, uniform over the sphere."""
    out = np.empty((count, 3))
    for i in range(count):
        d, _ = unit_vector(seed_state(i, 1, seed))
        out[i, 0], out[i, 1], out[i, 2] = d
    return out


@njit
def light_directions(arrays, k, p, count, seed):
    """float64 [count, 3]: directions from p drawn towards object k as the
    lights list draws them (pdf.toward_light: a mesh's first triangle stands
    for the mesh)."""
    out = np.empty((count, 3))
    for i in range(count):
        u1, state = uniform(seed_state(i, 0, seed))
        u2, _ = uniform(state)
        d = pdf.toward_light(arrays, k, p, np.int64(NO_HIT), u1, u2, None)
        out[i, 0], out[i, 1], out[i, 2] = d
    return out


@njit
def light_densities(arrays, k, p, dirs):
    """float64 [N]: the solid-angle density at p of each direction under
    light_directions (pdf.density_toward)."""
    out = np.empty(dirs.shape[0])
    for i in range(dirs.shape[0]):
        d = (dirs[i, 0], dirs[i, 1], dirs[i, 2])
        out[i] = pdf.density_toward(arrays, k, p, d, np.int64(NO_HIT), False, None)
    return out
