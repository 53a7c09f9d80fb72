"""Low-discrepancy samples: hashed Owen-scrambled Sobol points, padded in pairs.

    u, v = sample_2d(pixel, index, dim, seed)     # pair `dim` of sample `index`
    u = sample_1d(pixel, index, dim, seed)        # a 1-D decision (light, lobe)

Burley, "Practical Hash-based Owen Scrambling" (JCGT 2020), as pbrt-v4 and Cycles
use it.  Everything is 32-bit integers held in uint64 and masked.

The sequence.  The first two dimensions of Sobol's sequence form a (0,2)-sequence
in base 2: x = the index's bits reversed (van der Corput), y = the Pascal matrix
mod 2 applied to the index, then reversed.  By Lucas's theorem C(j, i) is odd iff
the bits of i are a subset of those of j, so the Pascal product is the GF(2)
"superset sum" of the index's bits: five shift-and-xor steps (`_pascal`), not a
loop over 32 direction numbers.  "(0,2)-sequence" means: every aligned block of
2^k consecutive indices, [m 2^k, (m+1) 2^k), puts exactly one point in each
elementary interval [a/2^i, (a+1)/2^i) x [b/2^(k-i), (b+1)/2^(k-i)), for every i.

Owen scrambling.  A nested uniform scramble flips bit j (counting from the most
significant) of a coordinate by a random function of the bits above it.  It maps
every elementary interval onto one of the same shape, so the net property
survives exactly, while each point alone becomes uniformly random and the RMS
error falls like N^-1.5 (up to log factors) on smooth integrands, like N^-0.75
on integrands with edges, instead of N^-0.5.  Burley's hash form: reverse the
bits, apply a hash in which every output bit depends only on the same and lower
input bits (adding a seed, multiplying by a constant, x ^= x * even: carries only
travel up), reverse back.  The hash is Vegdahl's improved Laine-Karras
permutation (pbrt-v4's FastOwenScrambler).

Shuffling and padding.  The index itself is Owen-scrambled too (seeded
separately): bits above k of an index below 2^k are zero, so they map to the
same constant m, and the low k bits are permuted: the first 2^k samples of a
pixel are all of one aligned block of the sequence, a (0,2)-net, in a random
order.  Each dimension pair `dim` gets its own index shuffle and its own
coordinate scrambles, seeded by a hash of (pixel, dim, seed): pairs are
decorrelated from each other (no Sobol dimension beyond the second is used, so
projections across pairs are those of random padding, as in Burley's padded
construction and pbrt-v4's PaddedSobolSampler) and every pixel is an
independent randomisation.  A nested shuffle is not a uniformly random
permutation (it reorders samples in pairs, then pairs of pairs, ...), so two
pairs' coordinates correlate a little within a pixel: (N - 1) E[r^2] is about
1.6, against 1 for a random matching; without the shuffle it would grow like
N / 2.
`sample_1d` uses the van der Corput dimension alone, with seeds of its own
(dimension `dim` of sample_1d and of sample_2d are unrelated).

Determinism.  Each point is a pure function of (pixel, index, dim, seed): no
state, no table filled at run time, nothing shared.  Which thread draws it, how
the samples are split into passes or machines, and which other pixels exist
change nothing, bit for bit.

Exactness.  A 32-bit integer times 2^-32 is exact in float64, so a point is
k / 2^32 with k < 2^32: in [0, 1) strictly, and floor(u 2^i) is the integer's
top i bits.  Indices are taken modulo 2^32.
"""
import numpy as np

from .jit import jit_step
from .rng import mix64

_M32 = np.uint64(0xFFFFFFFF)
_GAMMA = np.uint64(0x9E3779B97F4A7C15)
_DIM_KEY = np.uint64(0xC2B2AE3D27D4EB4F)   # odd, not one of rng.py's constants
_DOMAIN_2D = np.uint64(0x165667B19E3779F9)
_DOMAIN_1D = np.uint64(0x27D4EB2F165667C5)
_DOMAIN_FORK = np.uint64(0x85EBCA77C2B2AE63)
_TO_UNIT = 1.0 / 4294967296.0              # 2**-32

# Bit reversal and the Pascal product: masks of bit positions.
_B1 = np.uint64(0x55555555)
_B2 = np.uint64(0x33333333)
_B4 = np.uint64(0x0F0F0F0F)
_B8 = np.uint64(0x00FF00FF)
_B16 = np.uint64(0x0000FFFF)
_S1 = np.uint64(1)
_S2 = np.uint64(2)
_S4 = np.uint64(4)
_S8 = np.uint64(8)
_S16 = np.uint64(16)
_S32 = np.uint64(32)

# Vegdahl's permutation constants (even ones: x ^= x * c keeps bit 0).
_H1 = np.uint64(0x3D20ADEA)
_H2 = np.uint64(0x05526C56)
_H3 = np.uint64(0x53A22864)


@jit_step
def reverse32(x):
    """The low 32 bits of x in reverse order."""
    x = ((x >> _S1) & _B1) | ((x & _B1) << _S1)
    x = ((x >> _S2) & _B2) | ((x & _B2) << _S2)
    x = ((x >> _S4) & _B4) | ((x & _B4) << _S4)
    x = ((x >> _S8) & _B8) | ((x & _B8) << _S8)
    return ((x >> _S16) & _B16) | ((x & _B16) << _S16)


@jit_step
def _permute(x, seed):
    """A seeded bijection of 32 bits whose output bit i depends on input bits <= i."""
    x = x ^ (x * _H1)
    x = x + seed
    x = x * ((seed >> _S16) | _S1)
    x = x ^ (x * _H2)
    x = x ^ (x * _H3)
    return x & _M32


@jit_step
def owen_scramble(x, seed):
    """A nested uniform (Owen) scramble of the 32-bit x: bit j from the top is
    flipped by a hash of the bits above it and the seed."""
    return reverse32(_permute(reverse32(x), seed))


@jit_step
def _pascal(i):
    """The Pascal matrix mod 2 times the bits of i: bit t = xor of the bits j of i
    with t a subset of j (Lucas's theorem), one bit of t per step."""
    i = i ^ ((i >> _S1) & _B1)
    i = i ^ ((i >> _S2) & _B2)
    i = i ^ ((i >> _S4) & _B4)
    i = i ^ ((i >> _S8) & _B8)
    return i ^ ((i >> _S16) & _B16)


@jit_step
def sobol_2d(index):
    """The unscrambled (0,2)-sequence: Sobol's first two dimensions of `index`
    (mod 2^32), as 32-bit integers."""
    i = np.uint64(index) & _M32
    return reverse32(i), reverse32(_pascal(i))


@jit_step
def to_unit(x):
    """The 32-bit integer x as a float in [0, 1): x / 2^32, exact in float64."""
    return float(x) * _TO_UNIT


@jit_step
def _key(pixel, dim, seed, domain):
    """64 hashed bits of (pixel, dim, seed) for the sampler `domain`."""
    k = mix64(np.uint64(seed) * _GAMMA + np.uint64(pixel))
    return mix64(k ^ (np.uint64(dim) * _DIM_KEY + domain))


@jit_step
def sample_2d(pixel, index, dim, seed):
    """(u, v) in [0, 1)^2: point `index` of pixel `pixel`'s randomisation of the
    Owen-scrambled, shuffled (0,2)-sequence of dimension pair `dim`."""
    k = _key(pixel, dim, seed, _DOMAIN_2D)
    k2 = mix64(k + _GAMMA)
    # The shuffled index, reversed: owen_scramble(index) without its last reversal.
    r = _permute(reverse32(np.uint64(index) & _M32), k & _M32)
    i = reverse32(r)
    # x = owen(reverse(i)) = reverse(permute(i)); y = owen(reverse(pascal(i))).
    x = reverse32(_permute(i, k >> _S32))
    y = reverse32(_permute(_pascal(i), k2 & _M32))
    return to_unit(x), to_unit(y)


@jit_step
def sample_1d(pixel, index, dim, seed):
    """u in [0, 1): point `index` of pixel `pixel`'s randomisation of the
    Owen-scrambled, shuffled van der Corput sequence of dimension `dim`."""
    return _van_der_corput(_key(pixel, dim, seed, _DOMAIN_1D), index)


@jit_step
def sample_fork(pixel, index, fork, seed):
    """u in [0, 1): sample_1d for the path's fork number `fork` (a glass's
    choice between reflection and refraction), in a domain of its own: the
    forks' points are unrelated to every dimension of sample_1d and sample_2d."""
    return _van_der_corput(_key(pixel, fork, seed, _DOMAIN_FORK), index)


@jit_step
def _van_der_corput(k, index):
    """Point `index` of the van der Corput sequence, shuffled and scrambled by
    the key k."""
    i = reverse32(_permute(reverse32(np.uint64(index) & _M32), k & _M32))
    return to_unit(reverse32(_permute(i, k >> _S32)))
