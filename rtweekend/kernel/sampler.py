"""The sampler of one camera sample: where an estimator's random numbers come from.

    smp = start(pixel, index, seed, pairs)
    u1, u2, smp = next_2d(smp)        # a 2-D point for a decision that stratifies
    u, smp = uniform(smp)             # one number of the independent stream

A Sampler is plain data (no allocation, nothing shared): the sample's key, a
dimension counter, and the state of its independent stream (rng.py).  next_2d
hands out the pairs of low-discrepancy points in order -- pair `dim` of
sobol.sample_2d, then the counter moves on -- while the counter is below
`pairs`; past it (and always when pairs = 0) it returns two numbers of the
stream.  So an estimator asks for points in the order of its decisions, and
the strategy says how many get Sobol points (Sampling.sobol_pairs: the +sobol
strategies cover the position in the pixel and the first bounce's decisions,
its light samples included).
Draws where stratification gains nothing (a glass's choice, Russian roulette,
the emitter picked for a shadow ray) take the stream with uniform().

Determinism: every number is a pure function of (pixel, index, seed) and the
order of the requests, so which thread or machine draws it changes nothing.
"""
from typing import NamedTuple

import numpy as np

from . import rng, sobol
from .jit import jit_step


class Sampler(NamedTuple):
    pixel: np.int64        # the key of the sample: pixel, sample index, seed
    index: np.int64
    seed: np.int64
    dim: np.int64          # the next pair of low-discrepancy points
    pairs: np.int64        # how many pairs are low-discrepancy (the rest: the stream)
    state: np.uint64       # the independent stream (rng.py)


@jit_step
def start(pixel, index, seed, pairs):
    """The sampler of sample `index` of `pixel`."""
    return Sampler(np.int64(pixel), np.int64(index), np.int64(seed), np.int64(0),
                   np.int64(pairs), rng.seed_state(pixel, index, seed))


@jit_step
def resume(smp, state):
    """smp with its stream at `state` (after a helper that draws from the stream
    itself, such as a shape's light sampling)."""
    return Sampler(smp.pixel, smp.index, smp.seed, smp.dim, smp.pairs, state)


@jit_step
def uniform(smp):
    """(u in [0, 1), sampler): the next number of the independent stream."""
    u, state = rng.uniform(smp.state)
    return u, resume(smp, state)


@jit_step
def low_discrepancy(smp):
    """Is the next 2-D point a Sobol pair?"""
    return smp.dim < smp.pairs


@jit_step
def next_2d(smp):
    """(u1, u2, sampler): the next 2-D point."""
    if smp.dim < smp.pairs:
        u1, u2 = sobol.sample_2d(smp.pixel, smp.index, smp.dim, smp.seed)
        return u1, u2, Sampler(smp.pixel, smp.index, smp.seed, smp.dim + 1, smp.pairs,
                               smp.state)
    u1, state = rng.uniform(smp.state)
    u2, state = rng.uniform(state)
    return u1, u2, Sampler(smp.pixel, smp.index, smp.seed, smp.dim + 1, smp.pairs, state)


@jit_step
def next_1d(smp):
    """(u, sampler): the next 1-D point (a Sobol dimension of its own while the
    counter is below `pairs`, else the stream)."""
    if smp.dim < smp.pairs:
        u = sobol.sample_1d(smp.pixel, smp.index, smp.dim, smp.seed)
        return u, Sampler(smp.pixel, smp.index, smp.seed, smp.dim + 1, smp.pairs, smp.state)
    u, state = rng.uniform(smp.state)
    return u, Sampler(smp.pixel, smp.index, smp.seed, smp.dim + 1, smp.pairs, state)
