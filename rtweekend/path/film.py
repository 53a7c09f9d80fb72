"""The film: what a render adds up per pixel and per row, and how.

Camera samples.  A sample of pixel (x, y) is added by the thread rendering row
y (add_sample).  Radiance and its square (for the standard error) are summed
per block of BLOCK_SPP samples (partial, partial2) before joining the image's
sums (accum, accum2), so the sums depend only on the sample indices, never on
how passes, threads or machines split the work.  Per row: the ray segments
traced and the samples dropped as NaN/Inf (row_stats), and a histogram of
sample values (hist_n counts, hist_e sums; BINS_PER_OCTAVE bins per factor of 2
from 2**LOG2_LOWEST up) for the firefly count, of each sample but for what its
camera ray saw emitted.

Splats.  An estimator that carries light to the camera (light tracing) adds
to whatever pixel the light lands in, from any thread (add_splat): into
64-bit integers, in units of 2**-SPLAT_BITS (3.7e-9), with one atomic add each
(kernel/atomic.py), so that their sum does not depend on the order of the
adds, nor on threads, passes or machines.  A splat's channels are capped at
the render's clamp and at SPLAT_MAX (1.7e7, far above any sane radiance: a
pixel-block then holds 2048 such splats before its integer could overflow);
NaN/Inf ones are dropped and counted, as samples are.  `splat` holds the block
in progress; at its end (fold_splats) it joins `splat_total`, and the block's
value per pixel -- its camera samples' sum plus its splats -- is squared into
`block2`, whose spread over blocks gives the standard error (batch means:
splats are not samples of their pixel).  A film of an estimator that does not
splat has these arrays empty.
"""
import math
from typing import NamedTuple

import numpy as np

from ..kernel.atomic import atomic_add
from ..kernel.jit import jit_step
from ..result import FIREFLY_FACTOR

BINS_PER_OCTAVE = 16
LOG2_LOWEST = -24.0
HIST_BINS = 64 * BINS_PER_OCTAVE
BLOCK_SPP = 16
SPLAT_BITS = 28
SPLAT_SCALE = float(2 ** SPLAT_BITS)
SPLAT_MAX = float(2 ** 24)
# Columns of row_stats.
SEGMENTS = 0
DROPPED = 1
CONNECTIONS = 2     # manifold connections tried (a chain of glass to solve: mnee.py)
UNSOLVED = 3        # of those, dropped: the walk did not converge, or met total
#                     internal reflection
ROW_STATS = 4


class Film(NamedTuple):
    """The running sums of an image, or of one block of its samples."""
    accum: np.ndarray      # float64 [H, W, 3]: radiance, whole blocks
    accum2: np.ndarray     # float64 [H, W, 3]: its square
    partial: np.ndarray    # float64 [H, W, 3]: the unfinished block
    partial2: np.ndarray
    valid: np.ndarray      # int64 [H, W]: samples kept
    row_stats: np.ndarray  # int64 [H, ROW_STATS]: SEGMENTS, DROPPED, CONNECTIONS, UNSOLVED
    hist_n: np.ndarray     # int64 [H, HIST_BINS]
    hist_e: np.ndarray     # float64 [H, HIST_BINS]
    splat: np.ndarray      # int64 [H, W, 3]: the block in progress's splats ([0, 0, 3]: none)
    splat_total: np.ndarray  # int64 [H, W, 3]: whole blocks' splats
    block2: np.ndarray     # float64 [H, W, 3]: sum over whole blocks of (block value)^2
    marked: np.ndarray     # float64 [H, W, 3]: the camera samples' sum of the last whole
    #                        block, kept apart for fold_splats (the difference of two
    #                        running sums would round, and differ from a block's own)
    albedo: np.ndarray     # float64 [H, W, 3]: sum of the samples' albedo ([0, 0, 3]: none)
    normal: np.ndarray     # float64 [H, W, 3]: sum of their normals
    emission: np.ndarray   # float64 [H, W, 3]: sum of the light their camera rays saw
    #                        emitted, directly or through mirrors and glass


def new_film(height, width, splats=False, aov=False):
    """A film of zeros; with the splat arrays if the estimator splats, and the
    feature images if asked for."""
    size = (height, width, 3) if splats else (0, 0, 3)
    features = (height, width, 3) if aov else (0, 0, 3)
    return Film(np.zeros((height, width, 3)), np.zeros((height, width, 3)),
                np.zeros((height, width, 3)), np.zeros((height, width, 3)),
                np.zeros((height, width), dtype=np.int64),
                np.zeros((height, ROW_STATS), dtype=np.int64),
                np.zeros((height, HIST_BINS), dtype=np.int64),
                np.zeros((height, HIST_BINS)),
                np.zeros(size, dtype=np.int64), np.zeros(size, dtype=np.int64),
                np.zeros(size), np.zeros(size), np.zeros(features), np.zeros(features),
                np.zeros(features))


def film_bytes(height, width, splats=False, aov=False):
    """The bytes new_film(height, width, splats, aov) allocates."""
    per_pixel = 4 * 3 * 8 + 8 + (4 * 3 * 8 if splats else 0) + (3 * 3 * 8 if aov else 0)
    return height * width * per_pixel + height * (ROW_STATS * 8 + HIST_BINS * (8 + 8))


# What a render needs beyond its film: from the sums to an image
# (mean_and_stderr's float64 temporaries and its two float32 results; measured
# with tracemalloc, 160 bytes per pixel at the peak), with a margin.  The
# kernels hold no per-thread buffers (a path is scalars); writing the file
# (about 80 bytes per pixel) comes after the film is freed.
RESULT_BYTES_PER_PIXEL = 200
# Denoising, from the sums to the denoised image: the light seen estimated
# again (seen_light.py: 160 bytes per pixel at its peak, freed before the
# filter but for its result), then Open Image Denoise's inputs, buffers and
# output.  Measured as the growth of the process's peak resident memory over
# Renderer.result at 1500x1500: 734 bytes per pixel (718 before the light seen
# was estimated again), with a margin.
DENOISE_BYTES_PER_PIXEL = 900


def render_bytes(height, width, splats=False, aov=False, denoise=False):
    """About the most memory a render of this size holds at once."""
    result = RESULT_BYTES_PER_PIXEL * (4 if aov else 1)
    if denoise:
        result = max(result, DENOISE_BYTES_PER_PIXEL)
    return film_bytes(height, width, splats, aov) + result * height * width


def merge(film, other):
    """Add the sums of the next block(s): with the blocks merged in order the
    image is bit-identical to rendering them here, in one process."""
    for mine, theirs in zip(film, other):
        mine += theirs


@jit_step
def count_value(film, y, v):
    """Row y's histogram of sample values gets v (nothing for v <= 0)."""
    if v > 0.0:
        i = int((math.log2(v) - LOG2_LOWEST) * BINS_PER_OCTAVE)
        i = min(max(i, 0), HIST_BINS - 1)
        film.hist_n[y, i] += 1
        film.hist_e[y, i] += v


@jit_step
def add_splat(film, x, y, light, clamp, source):
    """Add light (r, g, b) to pixel (x, y) from the sample of row `source`, whose
    thread alone writes that row's statistics (its histogram, what it drops)."""
    if not math.isfinite(light[0] + light[1] + light[2]):
        film.row_stats[source, DROPPED] += 1
        return
    cap = min(clamp, SPLAT_MAX)
    r, g, b = (min(max(light[0], 0.0), cap), min(max(light[1], 0.0), cap),
               min(max(light[2], 0.0), cap))
    atomic_add(film.splat, (y, x, 0), np.int64(r * SPLAT_SCALE + 0.5))
    atomic_add(film.splat, (y, x, 1), np.int64(g * SPLAT_SCALE + 0.5))
    atomic_add(film.splat, (y, x, 2), np.int64(b * SPLAT_SCALE + 0.5))
    count_value(film, source, (r + g + b) / 3.0)


@jit_step
def add_features(film, y, x, albedo, normal):
    """Add a sample's feature images to pixel (x, y) (every sample drawn: they
    are divided by the samples drawn, not by those kept)."""
    for c in range(3):
        film.albedo[y, x, c] += albedo[c]
        film.normal[y, x, c] += normal[c]


@jit_step
def add_emission(film, y, x, light):
    """Add to pixel (x, y)'s emission feature the light a sample's camera ray saw
    emitted, directly or through mirrors and glass: what a denoiser should not
    blur (the denoiser adds it back to its output)."""
    for c in range(3):
        film.emission[y, x, c] += light[c]


def fold_splats(film):
    """At the end of a block of samples (every pixel has them): its splats join
    the total, and its value per pixel (camera samples' sum + splats) is squared
    into block2 for the standard error."""
    block = film.marked + film.splat / SPLAT_SCALE
    film.block2[:] += block * block
    film.splat_total[:] += film.splat
    film.splat[:] = 0


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
        count_value(film, y, ((r - min(er, clamp)) + (g - min(eg, clamp)) +
                              (b - min(eb, clamp))) / 3.0)
    else:
        film.row_stats[y, DROPPED] += 1
    if (s + 1) % BLOCK_SPP == 0:
        splatting = film.marked.shape[0] > 0
        for ch in range(3):
            if splatting:
                film.marked[y, x, ch] = film.partial[y, x, ch]
            film.accum[y, x, ch] += film.partial[y, x, ch]
            film.accum2[y, x, ch] += film.partial2[y, x, ch]
            film.partial[y, x, ch] = 0.0
            film.partial2[y, x, ch] = 0.0


# -- from the sums to an image ------------------------------------------------------

def mean_and_stderr(film, spp=0):
    """Per-pixel mean of the kept samples and its standard error (float32).

    A film with splats adds them divided by spp (the samples per pixel drawn:
    light carried from any pixel's samples), and takes the standard error from
    the spread of its whole blocks (batch means)."""
    accum, accum2 = film.accum + film.partial, film.accum2 + film.partial2
    n = film.valid[..., None].astype(np.float64)
    mean = np.divide(accum, n, out=np.zeros_like(accum), where=n > 0)
    if film.splat.size:
        return _with_splats(film, mean, spp)
    # Unbiased sample variance / n; pixels with < 2 samples get no estimate (inf).
    var = np.divide(accum2 - n * mean * mean, n - 1, out=np.full_like(accum, np.inf),
                    where=n > 1)
    stderr = np.sqrt(np.maximum(var, 0.0) / np.maximum(n, 1))
    return mean.astype(np.float32), stderr.astype(np.float32)


def _with_splats(film, mean, spp):
    """mean_and_stderr of a film with splats: batch means over its whole blocks."""
    splats = (film.splat_total + film.splat) / SPLAT_SCALE
    mean = mean + (splats / spp if spp > 0 else 0.0)
    blocks = spp // BLOCK_SPP
    if blocks < 2:
        return mean.astype(np.float32), np.full(mean.shape, np.inf, dtype=np.float32)
    # The whole blocks' values B: their sum and the sum of their squares.
    total = film.accum + film.splat_total / SPLAT_SCALE
    var = (film.block2 - total * total / blocks) / (blocks - 1)     # of one block's value
    stderr = np.sqrt(np.maximum(var, 0.0) / blocks) / BLOCK_SPP
    return mean.astype(np.float32), stderr.astype(np.float32)


def features(film, samples):
    """{name: HxWx3 float32 mean} of the feature images the film has (none: {});
    samples: the samples drawn in each row ([H])."""
    if not film.albedo.size:
        return {}
    n = np.asarray(samples, dtype=np.float64)[:, None, None]
    return {name: np.divide(total, n, out=np.zeros_like(total), where=n > 0).astype(np.float32)
            for name, total in (("albedo", film.albedo), ("normal", film.normal),
                                ("emission", film.emission))}


def firefly_stats(film, image_mean):
    """(samples above FIREFLY_FACTOR x image_mean, their share of all energy).

    A sample's value here leaves out what its camera ray saw emitted (a light
    in view is no firefly: add_sample); a splat counts as a sample of the pixel
    it lands in; the share is of the whole image's energy, the lights seen
    directly included.

    From the histogram of sample values: the bin holding the threshold is split
    in proportion to where the threshold falls in it (log scale), so the count
    is exact whenever no sample lies within 1/BINS_PER_OCTAVE octave of it.
    """
    counts, energy = film.hist_n.sum(axis=0), film.hist_e.sum(axis=0)
    total = (float(film.accum.sum()) + float(film.partial.sum()) +
             float((film.splat_total + film.splat).sum()) / SPLAT_SCALE) / 3.0
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
