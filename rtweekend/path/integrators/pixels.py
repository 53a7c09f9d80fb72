"""One camera-sample loop for every estimator that renders into the film.

A pass adds samples s0 .. s1 - 1 of every pixel of its rows.  Each sample
starts the sampler at (pixel, sample index) -- so a pixel's sums depend on
its sample indices alone, whatever the thread, the pass split or the machine
-- and the estimator's `sample` gives what the sample brings to its pixel:
(radiance, what the camera ray saw emitted, ray segments traced).  The film
keeps it (film.add_sample); the segments go to the row's statistics.

`sample(film, scene, params, y, x, s, smp, state)` is the estimator's own
(integrators/<name>.py): `state`, a tuple of whatever it needs beyond the
scene (its features, its scratch arrays).  It is passed as a function: Numba
compiles this loop once for each estimator's, with the call resolved at
compile time, and LLVM inlines both (a step: no indirection at run time; the
same speed as a loop written in each estimator, measured).  The cache keeps
it only inside the kernels (kernel/disk_cache.py, takes_a_function): an entry
of its own could not be keyed by the sample function's sources.

The shutter's time is the estimator's draw (`shutter`), in the order of its
decisions: the path tracer after the camera ray, bdpt and light tracing
before anything else.
"""
from ...kernel import sampler
from ...kernel.jit import jit_step
from ...kernel.rows import claim
from .. import film as films
from ..film import SEGMENTS


@jit_step
def shutter(motion, smp):
    """(time, smp): a time on the shutter for the whole sample where something
    moves (motion: 0), else None."""
    if motion is not None:
        return sampler.uniform(smp)
    return None, smp


@jit_step
def render_rows(sample, queue, film, scene, params, s0, s1, state):
    """Samples s0..s1-1 of every row this thread claims from the queue
    (kernel/rows.py), row by row, by `sample`, into the film."""
    y = claim(queue)
    while y >= 0:
        render_row(sample, y, film, scene, params, s0, s1, state)
        y = claim(queue)


@jit_step
def render_row(sample, y, film, scene, params, s0, s1, state):
    """Samples s0..s1-1 of every pixel of row y, by `sample`, into the film."""
    segments = 0
    width = params.width
    for x in range(width):
        pixel = y * width + x
        for s in range(s0, s1):
            smp = sampler.start(pixel, s, params.seed, params.pairs)
            radiance, seen, n = sample(film, scene, params, y, x, s, smp, state)
            segments += n
            films.add_sample(film, y, x, s, radiance[0], radiance[1], radiance[2],
                             params.clamp, seen[0], seen[1], seen[2])
    film.row_stats[y, SEGMENTS] += segments
