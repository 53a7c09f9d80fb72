"""The sampler of one camera sample: where an estimator's random numbers come from.

    smp = start(pixel, index, seed, pairs)
    u1, u2, smp = next_2d(smp)        # a 2-D point for a decision that stratifies
    u, smp = uniform(smp)             # one number of the independent stream
    u, smp = fork(smp)                # a glass's choice (reflect or refract)

A Sampler is plain data (no allocation, nothing shared): the sample's key, a
dimension counter, and the state of its independent stream (rng.py).  next_2d
hands out the pairs of low-discrepancy points in order -- pair `dim` of
sobol.sample_2d, then the counter moves on -- while the counter is below
`pairs`; past it (and always when pairs is 0 or None) it returns two numbers
of the stream.  None, a strategy without Sobol pairs, is known when compiling:
its kernel has none of the Sobol code (_below).  So an estimator asks for
points in the order of its decisions, and the strategy says how many get Sobol
points (Sampling.sobol_pairs: the +sobol strategies cover the position in the
pixel and the first bounce's decisions, its light samples included).
Draws where stratification gains nothing (Russian roulette, the emitter
picked for a shadow ray) take the stream with uniform().  A glass's choice
between reflection and refraction is a fork: behind a glass the two branches
see very different radiance (a lamp through a glass globe against the room it
reflects), so the first FORKS choices of a path that has Sobol pairs take
points of their own (sobol.sample_fork, numbered by the fork, so that no other
decision's order moves them) and later ones the stream.

Each Sobol pair is drawn one request ahead (the sampler carries pair `dim`
while the estimator works towards asking for it): a pair is a chain of
dependent hashes and multiplications, some 70 cycles from key to point, and
asked for at the moment a direction needs it, that chain stalled the path
(`nee+sobol` ran 5-6% more samples per second once its pairs were drawn
ahead; benchmarks/results/measurements.md).  The values are the same, drawn
earlier.

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
    forks: np.int64        # the glass choices made so far (fork)
    ahead1: np.float64     # Sobol pair `dim`, drawn one request ahead (0 past `pairs`)
    ahead2: np.float64


FORKS = 4                  # a path's choices at glass that take Sobol points
# A pair of Sobol dimensions no estimator's order reaches (next_2d hands out
# Sobol pairs only below `pairs`, a handful): for a decision made once per
# sample at a place of its own (reserved_2d).
RESERVED = 64


@jit_step
def _below(i, pairs):
    """i < pairs, for a counter i >= 0, compared unsigned so that pairs 0 alone
    decides it (nothing is below 0) at no cost to a strategy with pairs:
    start() makes `pairs` the constant 0 for a strategy without Sobol pairs
    (None), which LLVM carries through the path's loop once every step is
    inlined, so the kernel drops the Sobol code and the values only it reads
    (the key, the counter, the pair drawn ahead) instead of carrying them
    round every bounce (what that was worth: benchmarks/results/measurements.md).
    The Sampler's type stays one: the steps that take it compile once for both
    kinds of strategy."""
    return np.uint64(i) < np.uint64(pairs)


@jit_step
def _count(pairs):
    """pairs as the Sampler holds it: None (no Sobol pairs) is the constant 0."""
    if pairs is None:
        return np.int64(0)
    return np.int64(pairs)


@jit_step
def _ahead(pixel, index, dim, seed, pairs):
    """Sobol pair `dim` if it is one the sample will use, else nothing (zeros)."""
    if _below(dim, pairs):
        return sobol.sample_2d(pixel, index, dim, seed)
    return 0.0, 0.0


@jit_step
def start(pixel, index, seed, pairs):
    """The sampler of sample `index` of `pixel`."""
    n = _count(pairs)
    a1, a2 = _ahead(pixel, index, 0, seed, n)
    return Sampler(np.int64(pixel), np.int64(index), np.int64(seed), np.int64(0),
                   n, rng.seed_state(pixel, index, seed), np.int64(0), a1, a2)


@jit_step
def _moved_on(smp, state):
    """smp with its counter one pair further (that pair drawn ahead) and its
    stream at `state`."""
    a1, a2 = _ahead(smp.pixel, smp.index, smp.dim + 1, smp.seed, smp.pairs)
    return Sampler(smp.pixel, smp.index, smp.seed, smp.dim + 1, smp.pairs, state, smp.forks,
                   a1, a2)


@jit_step
def resume(smp, state):
    """smp with its stream at `state` (after a helper that draws from the stream
    itself, such as a shape's light sampling)."""
    return Sampler(smp.pixel, smp.index, smp.seed, smp.dim, smp.pairs, state, smp.forks,
                   smp.ahead1, smp.ahead2)


@jit_step
def uniform(smp):
    """(u in [0, 1), sampler): the next number of the independent stream."""
    u, state = rng.uniform(smp.state)
    return u, resume(smp, state)


@jit_step
def low_discrepancy(smp):
    """Is the next 2-D point a Sobol pair?"""
    return _below(smp.dim, smp.pairs)


@jit_step
def next_2d(smp):
    """(u1, u2, sampler): the next 2-D point."""
    if _below(smp.dim, smp.pairs):
        return smp.ahead1, smp.ahead2, _moved_on(smp, smp.state)
    u1, state = rng.uniform(smp.state)
    u2, state = rng.uniform(state)
    return u1, u2, _moved_on(smp, state)


@jit_step
def fork(smp):
    """(u, sampler): the number for a glass's choice -- a Sobol point of its own
    for the first FORKS forks of a path with Sobol pairs, else the stream's
    next number."""
    if smp.pairs > 0 and smp.forks < FORKS:
        u = sobol.sample_fork(smp.pixel, smp.index, smp.forks, smp.seed)
        return u, Sampler(smp.pixel, smp.index, smp.seed, smp.dim, smp.pairs, smp.state,
                          smp.forks + 1, smp.ahead1, smp.ahead2)
    u, state = rng.uniform(smp.state)
    return u, Sampler(smp.pixel, smp.index, smp.seed, smp.dim, smp.pairs, state,
                      smp.forks + 1, smp.ahead1, smp.ahead2)


@jit_step
def reserved_2d(smp, k):
    """(u1, u2, sampler): reserved Sobol pair k (RESERVED + k) of a sample with
    Sobol pairs -- outside the counter's order, which it leaves as it is --
    else two numbers of the stream.  For a decision each sample makes at most
    once, wherever it falls in the order: bdpt's manifold connection
    (integrators/through_glass.py)."""
    if smp.pairs > 0:
        u1, u2 = sobol.sample_2d(smp.pixel, smp.index, RESERVED + k, smp.seed)
        return u1, u2, smp
    u1, state = rng.uniform(smp.state)
    u2, state = rng.uniform(state)
    return u1, u2, resume(smp, state)
