"""The film: what a render adds up per pixel and per row, and how.

Radiance and its square (for the standard error) are summed per block of
BLOCK_SPP samples (partial, partial2) before joining the image's sums (accum,
accum2), so the sums depend only on the sample indices, never on how passes,
threads or machines split the work.  Per row: the ray segments traced and the
samples dropped as NaN/Inf (row_stats), and a histogram of sample values
(hist_n counts, hist_e sums; BINS_PER_OCTAVE bins per factor of 2 from
2**LOG2_LOWEST up) for the firefly count, of each sample but for what its
camera ray saw emitted.
"""
import math
from typing import NamedTuple

import numpy as np

from ..kernel.jit import jit_step
from ..result import FIREFLY_FACTOR

BINS_PER_OCTAVE = 16
LOG2_LOWEST = -24.0
HIST_BINS = 64 * BINS_PER_OCTAVE
BLOCK_SPP = 16
# Columns of row_stats.
SEGMENTS = 0
DROPPED = 1


class Film(NamedTuple):
    """The running sums of an image, or of one block of its samples."""
    accum: np.ndarray      # float64 [H, W, 3]: radiance, whole blocks
    accum2: np.ndarray     # float64 [H, W, 3]: its square
    partial: np.ndarray    # float64 [H, W, 3]: the unfinished block
    partial2: np.ndarray
    valid: np.ndarray      # int64 [H, W]: samples kept
    row_stats: np.ndarray  # int64 [H, 2]: SEGMENTS, DROPPED
    hist_n: np.ndarray     # int64 [H, HIST_BINS]
    hist_e: np.ndarray     # float64 [H, HIST_BINS]


def new_film(height, width):
    return Film(np.zeros((height, width, 3)), np.zeros((height, width, 3)),
                np.zeros((height, width, 3)), np.zeros((height, width, 3)),
                np.zeros((height, width), dtype=np.int64),
                np.zeros((height, 2), dtype=np.int64),
                np.zeros((height, HIST_BINS), dtype=np.int64),
                np.zeros((height, HIST_BINS)))


def film_bytes(height, width):
    """The bytes new_film(height, width) allocates."""
    return height * width * (4 * 3 * 8 + 8) + height * (2 * 8 + HIST_BINS * (8 + 8))


# What a render needs beyond its film: from the sums to an image
# (mean_and_stderr's float64 temporaries and its two float32 results; measured
# with tracemalloc, 160 bytes per pixel at the peak), with a margin.  The
# kernels hold no per-thread buffers (a path is scalars); writing the file
# (about 80 bytes per pixel) comes after the film is freed.
RESULT_BYTES_PER_PIXEL = 200


def render_bytes(height, width):
    """About the most memory a render of this size holds at once."""
    return film_bytes(height, width) + RESULT_BYTES_PER_PIXEL * height * width


def merge(film, other):
    """Add the sums of the next block(s): with the blocks merged in order the
    image is bit-identical to rendering them here, in one process."""
    for mine, theirs in zip(film, other):
        mine += theirs


@jit_step
def add_sample(film, y, x, s, lr, lg, lb, clamp, er, eg, eb):
    """Add sample s of pixel (x, y), radiance (lr, lg, lb), capped at clamp.

    A NaN or Inf sample is counted and dropped, never summed.  The sample that
    completes a block moves the block's sums into the image's.  (er, eg, eb):
    the part of it that its camera ray saw emitted, left out of the histogram
    (a light seen directly is no firefly).
    """
    if math.isfinite(lr + lg + lb):
        r, g, b = min(lr, clamp), min(lg, clamp), min(lb, clamp)
        film.partial[y, x, 0] += r
        film.partial[y, x, 1] += g
        film.partial[y, x, 2] += b
        film.partial2[y, x, 0] += r * r
        film.partial2[y, x, 1] += g * g
        film.partial2[y, x, 2] += b * b
        film.valid[y, x] += 1
        v = ((r - min(er, clamp)) + (g - min(eg, clamp)) + (b - min(eb, clamp))) / 3.0
        if v > 0.0:
            i = int((math.log2(v) - LOG2_LOWEST) * BINS_PER_OCTAVE)
            i = min(max(i, 0), HIST_BINS - 1)
            film.hist_n[y, i] += 1
            film.hist_e[y, i] += v
    else:
        film.row_stats[y, DROPPED] += 1
    if (s + 1) % BLOCK_SPP == 0:
        for ch in range(3):
            film.accum[y, x, ch] += film.partial[y, x, ch]
            film.accum2[y, x, ch] += film.partial2[y, x, ch]
            film.partial[y, x, ch] = 0.0
            film.partial2[y, x, ch] = 0.0


# -- from the sums to an image ------------------------------------------------------

def mean_and_stderr(film):
    """Per-pixel mean of the kept samples and its standard error (float32)."""
    accum, accum2 = film.accum + film.partial, film.accum2 + film.partial2
    n = film.valid[..., None].astype(np.float64)
    mean = np.divide(accum, n, out=np.zeros_like(accum), where=n > 0)
    # Unbiased sample variance / n; pixels with < 2 samples get no estimate (inf).
    var = np.divide(accum2 - n * mean * mean, n - 1, out=np.full_like(accum, np.inf),
                    where=n > 1)
    stderr = np.sqrt(np.maximum(var, 0.0) / np.maximum(n, 1))
    return mean.astype(np.float32), stderr.astype(np.float32)


def firefly_stats(film, image_mean):
    """(samples above FIREFLY_FACTOR x image_mean, their share of all energy).

    A sample's value here leaves out what its camera ray saw emitted (a light
    in view is no firefly: add_sample); the share is of the whole image's
    energy, the lights seen directly included.

    From the histogram of sample values: the bin holding the threshold is split
    in proportion to where the threshold falls in it (log scale), so the count
    is exact whenever no sample lies within 1/BINS_PER_OCTAVE octave of it.
    """
    counts, energy = film.hist_n.sum(axis=0), film.hist_e.sum(axis=0)
    total = (float(film.accum.sum()) + float(film.partial.sum())) / 3.0
    if image_mean <= 0.0 or total <= 0.0:
        return 0, 0.0
    x = (math.log2(FIREFLY_FACTOR * image_mean) - LOG2_LOWEST) * BINS_PER_OCTAVE
    i = int(math.floor(x))
    if i < 0:
        return int(counts.sum()), 1.0
    if i >= len(counts):
        return 0, 0.0
    above = 1.0 - (x - i)        # part of bin i above the threshold
    n = counts[i + 1:].sum() + above * counts[i]
    e = energy[i + 1:].sum() + above * energy[i]
    return int(round(n)), float(e / total)
