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
(materials/isotropic.py: uniform over the sphere, 1 / 4 pi), mixed with the
light pdf as the books mix it with the cosine lobe at a surface; the
throughput is multiplied by albedo x phase / pdf.  A shadow ray (next-event
estimation from a surface) through media carries their transmittance
exp(-density x length inside).

The kernel takes the media's object indices only when the scene has media;
otherwise the argument is None and Numba compiles none of this.
"""
import math

import numpy as np

from ..kernel import sampler
from ..kernel.jit import jit_step
from . import pdf, shapes
from .layout import MAT_PARAMS, NO_HIT, OBJ_MAT
from .materials import isotropic


@jit_step
def density(scene, k):
    return scene.mat_f[scene.obj_i[k, OBJ_MAT], MAT_PARAMS + isotropic.DENSITY]


@jit_step
def free_flight(scene, media, o, d, t_surface, time, smp):
    """(medium, t, smp): the medium object in which the ray o + t d scatters
    first and where, before t_surface; (NO_HIT, t_surface) if none.  One number
    of the stream per medium the ray crosses."""
    best = np.int64(NO_HIT)
    t_best = t_surface
    for j in range(media.shape[0]):
        k = media[j]
        t0, t1 = shapes.interval(scene, k, o, d, time)
        t0 = max(t0, 0.0)
        t1 = min(t1, t_best)
        if t0 < t1:
            sigma = density(scene, k)
            u, smp = sampler.uniform(smp)
            if sigma > 0.0:
                t = t0 - math.log(1.0 - u) / sigma
                if t < t1:
                    best, t_best = k, t
    return best, t_best, smp


@jit_step
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


@jit_step
def phase_scatter(scene, p, light_weight, use_lights, time, smp):
    """(direction, phase / pdf, smp) at a scattering point p: the phase
    function's own sampling (isotropic: uniform over the sphere), or mixed with
    the light pdf (weight light_weight)."""
    if not use_lights:
        d, state = isotropic.sample(smp.state)
        return d, 1.0, sampler.resume(smp, state)
    u, smp = sampler.uniform(smp)
    if u < light_weight:
        d, smp = pdf.lights_generate(scene, p, NO_HIT, smp, time)
    else:
        d, state = isotropic.sample(smp.state)
        smp = sampler.resume(smp, state)
    mixed = (1.0 - light_weight) * isotropic.pdf() + \
        light_weight * pdf.lights_value(scene, p, d, NO_HIT, False, time)
    return d, isotropic.pdf() / mixed, smp
