"""The order in which a prange kernel visits image rows."""
import math

import numpy as np


def interleaved_rows(height):
    """A permutation of the rows such that any contiguous chunk of it (what a
    thread gets from prange) samples the whole image, so threads get equal
    work: in the Cornell box the rows through the boxes cost more, in the
    classic demo the floor's reflections make the bottom rows dearest
    (benchmarks/results/measurements.md)."""
    step = max(1, int(height * 0.6180339887))
    while math.gcd(step, height) != 1:
        step += 1
    return (np.arange(height, dtype=np.int64) * step) % height
