"""The counter-based generator: uniform, keyed, and independent across keys."""
import numpy as np
from numba import njit

from rtweekend.kernel.rng import seed_state, uniform

from stats import assert_chi2


@njit
def _draws(pixels, samples, seed, per_stream):
    out = np.empty((pixels * samples, per_stream))
    for p in range(pixels):
        for s in range(samples):
            state = seed_state(p, s, seed)
            for j in range(per_stream):
                out[p * samples + s, j], state = uniform(state)
    return out


def test_uniform_in_unit_interval_and_flat():
    u = _draws(1000, 100, 0, 4)
    assert u.min() >= 0.0 and u.max() < 1.0
    for j in range(4):  # each draw position within a stream is uniform
        assert_chi2(np.histogram(u[:, j], bins=100, range=(0, 1))[0], np.full(100, 1000.0))


def test_pairs_are_independent():
    # Successive draws fill the unit square evenly (20x20 grid).
    u = _draws(500, 100, 3, 2)
    h = np.histogram2d(u[:, 0], u[:, 1], bins=20, range=[[0, 1], [0, 1]])[0]
    assert_chi2(h, np.full(h.shape, len(u) / 400))


def test_neighbouring_keys_are_uncorrelated():
    a = _draws(2000, 1, 0, 1)[:, 0]
    b = _draws(2000, 1, 1, 1)[:, 0]                 # next seed
    c = _draws(2000, 2, 0, 1).reshape(2000, 2)[:, 1]  # next sample index
    for x, y in [(a, b), (a, c), (a[:-1], a[1:])]:   # ... and next pixel
        r = np.corrcoef(x, y)[0, 1]
        assert abs(r) < 5 / np.sqrt(len(x)), r


def test_stream_is_a_pure_function_of_its_key():
    assert np.array_equal(_draws(10, 10, 42, 8), _draws(10, 10, 42, 8))
    assert not np.array_equal(_draws(10, 10, 42, 8), _draws(10, 10, 43, 8))
