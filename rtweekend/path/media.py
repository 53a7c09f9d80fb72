"""Constant media (The Next Week, "Volumes"): a convex boundary (a sphere or a
box) filled with a medium of constant density that scatters isotropically.

The boundary is invisible: media are not in the nearest-hit search at all.
After the search has found the nearest surface at distance t along a ray, each
medium the line passes through draws a free-flight distance -ln(1 - u) /
density from where the ray is inside it (from 0 if it starts inside); the
nearest flight that ends before t, and before the medium's far side, is where
the ray scatters instead.  This is the book's constant_medium, except that a
ray is never stopped at the boundary itself, so a ray starting inside (a
camera in fog, a path inside a glass sphere holding a medium) needs nothing
special.  Overlapping media add their densities (the minimum of independent
exponential flights is one flight at the summed density).

At a scattering point the new direction comes from the phase function
(uniform over the sphere, 1 / 4 pi), mixed with the light pdf as the books mix
it with the cosine lobe at a surface; the throughput is multiplied by
albedo x phase / pdf.  A shadow ray (next-event estimation from a surface)
through media carries their transmittance exp(-density x length inside).

The kernel takes the media's object indices only when the scene has media;
otherwise the argument is None and Numba compiles none of this.
"""
import math

import numpy as np

from ..kernel import rng
from ..kernel.jit import jit_inline
from . import pdf, shapes
from .layout import MAT_PARAM, NO_HIT, OBJ_MAT

INV_4PI = 1.0 / (4.0 * math.pi)


@jit_inline
def density(scene, k):
    return scene.mat_f[scene.obj_i[k, OBJ_MAT], MAT_PARAM]


@jit_inline
def free_flight(scene, media, o, d, t_surface, time, state):
    """(medium, t, state): the medium object in which the ray o + t d scatters
    first and where, before t_surface; (NO_HIT, t_surface) if none."""
    best = np.int64(NO_HIT)
    t_best = t_surface
    for j in range(media.shape[0]):
        k = media[j]
        t0, t1 = shapes.interval(scene, k, o, d, time)
        t0 = max(t0, 0.0)
        t1 = min(t1, t_best)
        if t0 < t1:
            sigma = density(scene, k)
            u, state = rng.uniform(state)
            if sigma > 0.0:
                t = t0 - math.log(1.0 - u) / sigma
                if t < t1:
                    best, t_best = k, t
    return best, t_best, state


@jit_inline
def transmittance(scene, media, o, d, t_max, time):
    """The fraction of light that crosses every medium between o and o + t_max d."""
    tau = 0.0
    for j in range(media.shape[0]):
        k = media[j]
        t0, t1 = shapes.interval(scene, k, o, d, time)
        t0 = max(t0, 0.0)
        t1 = min(t1, t_max)
        if t0 < t1:
            tau += density(scene, k) * (t1 - t0)
    return math.exp(-tau)


@jit_inline
def phase_scatter(scene, p, light_weight, use_lights, time, state):
    """(direction, phase / pdf, state) at a scattering point p: uniform over the
    sphere, or mixed with the light pdf (weight light_weight)."""
    if not use_lights:
        d, state = rng.unit_vector(state)
        return d, 1.0, state
    u, state = rng.uniform(state)
    if u < light_weight:
        d, state = pdf.lights_generate(scene, p, state, time)
    else:
        d, state = rng.unit_vector(state)
    mixed = (1.0 - light_weight) * INV_4PI + \
        light_weight * pdf.lights_value(scene, p, d, NO_HIT, False, time)
    return d, INV_4PI / mixed, state
