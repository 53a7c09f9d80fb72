"""Statistics for tests, without SciPy."""
import math

import numpy as np


def chi2_quantile(k, z):
    """Upper quantile of chi-square with k dof at the normal quantile z
    (Wilson-Hilferty; z = 5 is a false alarm once in ~3.5 million runs)."""
    a = 2.0 / (9.0 * k)
    return k * (1.0 - a + z * math.sqrt(a)) ** 3


def chi2_statistic(observed, expected):
    observed = np.asarray(observed, dtype=np.float64).ravel()
    expected = np.asarray(expected, dtype=np.float64).ravel()
    keep = expected > 0
    assert observed[~keep].sum() == 0, "samples where the pdf says 0"
    return float((((observed - expected) ** 2)[keep] / expected[keep]).sum()), int(keep.sum()) - 1


def assert_chi2(observed, expected, z=5.0):
    stat, dof = chi2_statistic(observed, expected)
    limit = chi2_quantile(dof, z)
    assert stat < limit, f"chi-square {stat:.1f} over {dof} dof exceeds {limit:.1f}"


def blocks(x, n):
    """Means over n x n pixel blocks of an H x W x 3 image (cropped to whole blocks)."""
    h, w = (x.shape[0] // n) * n, (x.shape[1] // n) * n
    return x[:h, :w].astype(np.float64).reshape(h // n, n, w // n, n, -1).mean(axis=(1, 3))


def block_se(se, n):
    """The standard errors of blocks(image, n) from the pixels' own (independent)."""
    h, w = (se.shape[0] // n) * n, (se.shape[1] // n) * n
    return np.sqrt((se[:h, :w].astype(np.float64) ** 2).reshape(h // n, n, w // n, n, -1)
                   .sum(axis=(1, 3))) / (n * n)


def block_z(a, a_se, b, b_se, n, quiet_equal=False):
    """The differences of two images' n x n block means over their combined
    standard errors, blocks with no noise on either side left out (with
    quiet_equal, those must agree exactly: black walls, a light seen directly)."""
    se = np.hypot(block_se(a_se, n), block_se(b_se, n))
    d = blocks(a, n) - blocks(b, n)
    keep = se > 0
    if quiet_equal:
        assert np.all(d[~keep] == 0)
    return d[keep] / se[keep]
