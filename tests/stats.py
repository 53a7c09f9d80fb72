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
