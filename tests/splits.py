"""One check several estimators' tests share: the same bits for any thread
count and any split of the samples into passes."""
import numpy as np

import rtweekend as rt
from rtweekend.path.renderer import Renderer


def assert_same_bits_for_threads_and_splits(scene, **options):
    """40 spp rendered with 1 thread, with 2, and in passes of 3, 20 (across a
    block's end: splats folded on the way), a sample over part of the rows four
    times, and 16: image, standard error and rays the same bits."""
    one = rt.render(scene, spp=40, threads=1, **options)
    two = rt.render(scene, spp=40, threads=2, **options)
    r = Renderer(scene, **options)
    r.add_samples(3)
    r.add_samples(20)
    for _ in range(4):
        r.add_rows(1, 5)
    r.add_samples(16)
    split = r.result()
    for other in (two, split):
        assert np.array_equal(one.image, other.image)
        assert np.array_equal(one.stderr, other.stderr)
        assert one.stats.rays == other.stats.rays
    assert one.image.mean() > 0.05
