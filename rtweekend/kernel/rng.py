"""Counter-based random numbers keyed by (pixel, sample index, seed).

Every camera sample starts its own SplitMix64 stream from a hash of its key, so
a pixel's value never depends on which thread rendered it, on how samples were
split into passes, or on what other pixels did.  The state is one uint64 that
the caller threads through (`u, state = uniform(state)`): plain data, no
allocation, no shared generator.
"""
import math

import numpy as np

from .jit import jit_step

_GAMMA = np.uint64(0x9E3779B97F4A7C15)   # golden-ratio increment of SplitMix64
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_SAMPLE_KEY = np.uint64(0xD1B54A32D192ED03)
_S30 = np.uint64(30)
_S27 = np.uint64(27)
_S31 = np.uint64(31)
_S11 = np.uint64(11)
_TO_UNIT = 1.0 / 9007199254740992.0      # 2**-53: 53 random bits -> [0, 1)
TWO_PI = 2.0 * math.pi


@jit_step
def mix64(z):
    """SplitMix64's finaliser: a bijective avalanche of 64 bits."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@jit_step
def seed_state(pixel, sample, seed):
    """The stream start for one camera sample; pure function of its key."""
    s = mix64(np.uint64(seed) * _GAMMA + np.uint64(pixel))
    return mix64(s ^ (np.uint64(sample) * _SAMPLE_KEY + _GAMMA))


@jit_step
def uniform(state):
    """(u in [0, 1), next state)."""
    state = state + _GAMMA
    return float(mix64(state) >> _S11) * _TO_UNIT, state


@jit_step
def unit_vector(state):
    """A direction uniform on the unit sphere, for two numbers of the stream."""
    u1, state = uniform(state)
    u2, state = uniform(state)
    return sphere_point(u1, u2), state


@jit_step
def sphere_point(u1, u2):
    """The direction uniform on the unit sphere at the unit square's point
    (u1, u2) (Archimedes: z = 1 - 2 u1 is uniform)."""
    z = 1.0 - 2.0 * u1
    r = math.sqrt(max(0.0, 1.0 - z * z))
    phi = TWO_PI * u2
    return (r * math.cos(phi), r * math.sin(phi), z)


@jit_step
def in_unit_sphere(state):
    """A point uniform in the unit ball: a uniform direction at radius cbrt(u).

    Always three draws (no rejection loop), so the stream stays in step.
    """
    d, state = unit_vector(state)
    u, state = uniform(state)
    r = u ** (1.0 / 3.0)
    return (r * d[0], r * d[1], r * d[2]), state


@jit_step
def in_unit_disk(state):
    """A point uniform in the unit disk (for the thin-lens aperture)."""
    u1, state = uniform(state)
    u2, state = uniform(state)
    r = math.sqrt(u1)
    phi = TWO_PI * u2
    return (r * math.cos(phi), r * math.sin(phi)), state
