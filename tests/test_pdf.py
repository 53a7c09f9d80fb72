"""Each direction pdf integrates to 1 and its samples follow its value().

Integral: Monte Carlo over uniform directions, |estimate - 1| < 5 standard
errors.  Distribution: 200k samples binned on an equal-area (cos theta, phi)
grid; expected counts from the pdf's own value() integrated over each bin
(32x32 stratified points); chi-square at z = 5.
"""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.kernel import sampler
from rtweekend.path import pdf
from rtweekend.path.layout import NO_HIT
from rtweekend.path.materials import LAMBERTIAN
from rtweekend.path.materials import Bsdf
from rtweekend.path.pack import pack_scene

from rays import uniform_directions
from stats import assert_chi2

MAT = rt.lambertian((0.5, 0.5, 0.5))
N_SAMPLES = 200_000
COS_BINS, PHI_BINS, SUB = 24, 48, 32


# The shading point is on a lambertian, whose sampling is the mixture's other
# component; the path came from wo = n.
@njit
def _generate(a, p, n, w, count, seed):
    out = np.empty((count, 3))
    bsdf = Bsdf(np.int64(LAMBERTIAN), (0.5, 0.5, 0.5), (0.0, 0.0), n, True, n, None)
    for i in range(count):
        d, _, _ = pdf.mixture_sample(a, bsdf, n, p, np.int64(NO_HIT), w, True,
                                     sampler.start(i, 0, seed, 0), None)
        out[i, 0], out[i, 1], out[i, 2] = d
    return out


@njit
def _value(a, p, n, w, dirs):
    out = np.empty(dirs.shape[0])
    bsdf = Bsdf(np.int64(LAMBERTIAN), (0.5, 0.5, 0.5), (0.0, 0.0), n, True, n, None)
    for i in range(dirs.shape[0]):
        d = (dirs[i, 0], dirs[i, 1], dirs[i, 2])
        out[i] = pdf.mixture_value(a, bsdf, n, p, w, d, NO_HIT, False, None)
    return out


def _case(shapes, w, p=(0.0, 0.0, 0.0), n=(0.0, 0.0, 1.0)):
    scene = rt.Scene()
    for s in shapes:
        scene.add(s, light=True)
    a = pack_scene(scene)
    n = tuple(np.asarray(n, float) / np.linalg.norm(n))
    return a, tuple(map(float, p)), n, float(w)


CASES = {
    "cosine": lambda: _case([rt.sphere((0, 0, 50), 1, MAT)], 0.0),
    "cosine, tilted normal": lambda: _case([rt.sphere((0, 0, 50), 1, MAT)], 0.0,
                                           n=(1.0, -2.0, 0.5)),
    "rect light": lambda: _case([rt.xy_rect(-1, 1.5, -1, 1, 1, MAT)], 1.0),
    "rotated rect light": lambda: _case(
        [rt.xy_rect(-1, 1, -0.5, 1, 0, MAT).rotate_y(30).translate((0.2, 0, 1))], 1.0),
    "sphere light": lambda: _case([rt.sphere((0.3, 0, 2), 1, MAT)], 1.0),
    "sphere light, point inside": lambda: _case([rt.sphere((0, 0, 0.5), 1, MAT)], 1.0),
    "two lights": lambda: _case([rt.xz_rect(-1, 1, -1, 1, 1, MAT),
                                 rt.sphere((0, 0, 2), 0.8, MAT)], 1.0),
    "mixture 0.5": lambda: _case([rt.xz_rect(-1, 1, -1, 1, 1, MAT),
                                  rt.sphere((0, 0, 2), 0.8, MAT)], 0.5),
    "yz rect light": lambda: _case([rt.yz_rect(-1, 1, -0.5, 2, 1.5, MAT)], 1.0),
    "xy rect light below": lambda: _case([rt.xy_rect(-1, 1, -0.5, 2, -0.7, MAT)], 1.0),
    "box light": lambda: _case([rt.box((-1, -0.5, 1), (1, 0.5, 2), MAT).rotate_y(25)
                                .translate((0.3, 0, 0))], 1.0),
    "box light around the point": lambda: _case([rt.box((-1, -2, -0.5), (1.5, 1, 1), MAT)
                                                 .rotate_y(-40)], 1.0),
}


@pytest.mark.parametrize("name", CASES)
def test_pdf_integrates_to_one(name):
    a, p, n, w = CASES[name]()
    dirs = uniform_directions(400_000, 7)
    v = _value(a, p, n, w, dirs) * 4 * math.pi
    se = v.std() / math.sqrt(len(v))
    assert abs(v.mean() - 1.0) < 5 * se + 1e-12, (v.mean(), se)


def _bin_index(dirs):
    cos_t = np.clip(dirs[:, 2], -1, 1 - 1e-15)
    phi = np.mod(np.arctan2(dirs[:, 1], dirs[:, 0]), 2 * math.pi)
    i = ((cos_t + 1) / 2 * COS_BINS).astype(int)
    j = np.minimum((phi / (2 * math.pi) * PHI_BINS).astype(int), PHI_BINS - 1)
    return i * PHI_BINS + j


def _expected_per_bin(a, p, n, w):
    """N x integral of value() over each equal-area bin.

    One jittered point per sub-cell (stratified Monte Carlo): unlike the
    midpoint rule it has no bias at the light's edge, where a bin may be
    covered by a sliver thinner than a sub-cell.
    """
    jitter = np.random.default_rng(5).random((2, COS_BINS * SUB, PHI_BINS * SUB))
    ci = np.arange(COS_BINS * SUB)[:, None] + jitter[0]
    pj = np.arange(PHI_BINS * SUB)[None, :] + jitter[1]
    cos_t = ci / (COS_BINS * SUB) * 2 - 1
    phi = pj / (PHI_BINS * SUB) * 2 * math.pi
    sin_t = np.sqrt(1 - cos_t ** 2)
    dirs = np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], -1).reshape(-1, 3)
    v = _value(a, p, n, w, np.ascontiguousarray(dirs))
    d_omega = 4 * math.pi / (COS_BINS * SUB * PHI_BINS * SUB)
    per_bin = v.reshape(COS_BINS, SUB, PHI_BINS, SUB).sum(axis=(1, 3)) * d_omega
    return N_SAMPLES * per_bin.ravel()


def _expected_in_bin(a, p, n, w, b, sub=512):
    """N x integral of value() over bin b alone, from sub x sub jittered points."""
    i, j = divmod(int(b), PHI_BINS)
    jitter = np.random.default_rng(b).random((2, sub, sub))
    cos_t = (i + (np.arange(sub)[:, None] + jitter[0]) / sub) / COS_BINS * 2 - 1
    phi = (j + (np.arange(sub)[None, :] + jitter[1]) / sub) / PHI_BINS * 2 * math.pi
    sin_t = np.sqrt(1 - cos_t ** 2)
    dirs = np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], -1).reshape(-1, 3)
    v = _value(a, p, n, w, np.ascontiguousarray(dirs))
    return N_SAMPLES * v.sum() * 4 * math.pi / (COS_BINS * PHI_BINS * sub * sub)


@pytest.mark.parametrize("name", CASES)
def test_samples_follow_value(name):
    a, p, n, w = CASES[name]()
    dirs = _generate(a, p, n, w, N_SAMPLES, 11)
    assert np.allclose(np.linalg.norm(dirs, axis=1), 1.0)
    # Every sample is a direction its own pdf gives a positive density.
    assert (_value(a, p, n, w, dirs) > 0).all()
    observed = np.bincount(_bin_index(dirs), minlength=COS_BINS * PHI_BINS)
    expected = _expected_per_bin(a, p, n, w)
    # A light's edge may cross a bin in a sliver that no sub-cell's point
    # met: where a sample fell in a bin integrated to 0, integrate it finer.
    for b in np.flatnonzero((expected == 0) & (observed > 0)):
        expected[b] = _expected_in_bin(a, p, n, w, b)
    # Pool the bins with few expected samples (the chi-square needs ~20+).
    keep = expected > 20
    observed = np.append(observed[keep], observed[~keep].sum())
    expected = np.append(expected[keep], expected[~keep].sum())
    assert_chi2(observed, expected)


@njit
def _sobol_mixture(a, p, n, w, count, seed):
    """Directions of samples 0..count-1 of one pixel whose first 2-D point is a
    Sobol pair, and whether the light drew each (its weight is NO_COLOR)."""
    out = np.empty((count, 4))
    bsdf = Bsdf(np.int64(LAMBERTIAN), (0.5, 0.5, 0.5), (0.0, 0.0), n, True, n, None)
    for i in range(count):
        d, weight, _ = pdf.mixture_sample(a, bsdf, n, p, np.int64(NO_HIT), w, True,
                                          sampler.start(3, i, seed, 1), None)
        out[i, 0], out[i, 1], out[i, 2] = d
        out[i, 3] = weight[0] == 0.0
    return out


def test_a_sobol_point_stratifies_the_lights_surface():
    # With a low-discrepancy point, u1 < w picks the light and (u1 / w, u2)
    # places the point on it: 2^k samples of a (0,2)-net put 2^(k-1) points on
    # the light, one in each of its elementary cells of area 2^-(k-1) (all
    # shapes: 1 x 2^-(k-1), ..., 2^-(k-1) x 1), which the stream would not.
    x0, x1, y0, y1, h, k = -1.0, 1.0, -0.5, 2.0, 1.5, 8
    a, p, n, w = _case([rt.xy_rect(x0, x1, y0, y1, h, MAT)], 0.5)
    out = _sobol_mixture(a, p, n, w, 2 ** k, 4)
    d = out[out[:, 3] == 1.0, :3]
    assert len(d) == 2 ** (k - 1)
    t = h / d[:, 2]
    v1, v2 = (t * d[:, 0] - x0) / (x1 - x0), (t * d[:, 1] - y0) / (y1 - y0)
    for bits in range(k):
        cells = np.floor(v1 * 2 ** bits) * 2 ** (k - 1 - bits) + np.floor(v2 * 2 ** (k - 1 - bits))
        assert len(np.unique(cells)) == 2 ** (k - 1), bits


def test_light_pdf_closed_forms():
    # Sphere of radius r at distance d: uniform over the cone, 1 / (2 pi (1 - cos)).
    a, p, n, w = _case([rt.sphere((0, 0, 3), 1.5, MAT)], 1.0)
    cos_max = math.sqrt(1 - 1.5 ** 2 / 3 ** 2)
    for d in [(0.0, 0.0, 1.0), (0.3, 0.1, 1.0)]:
        d = tuple(np.asarray(d) / np.linalg.norm(d))
        assert pdf.lights_value(a, p, d, NO_HIT, False, None) == \
            pytest.approx(1 / (2 * math.pi * (1 - cos_max)), rel=1e-12)
    # Far away the same formula, without cancellation: ~ 1 / (pi (r/d)^2).
    a, p, n, w = _case([rt.sphere((0, 0, 1e6), 1.0, MAT)], 1.0)
    assert pdf.lights_value(a, p, (0.0, 0.0, 1.0), NO_HIT, False, None) == \
        pytest.approx(1e12 / math.pi, rel=1e-6)
    # Rect of area A at distance h, straight above: h^2 / (cos A); at 45 degrees
    # the distance is h sqrt 2 and the cosine 1/sqrt 2.
    a, p, n, w = _case([rt.xz_rect(-2, 2, -1, 1, 1.5, MAT)], 1.0)
    assert pdf.lights_value(a, p, (0.0, 1.0, 0.0), NO_HIT, False, None) == \
        pytest.approx(1.5 ** 2 / 8, rel=1e-12)
    d = (math.sqrt(0.5), math.sqrt(0.5), 0.0)
    assert pdf.lights_value(a, p, d, NO_HIT, False, None) == \
        pytest.approx((1.5 * math.sqrt(2)) ** 2 / (math.sqrt(0.5) * 8), rel=1e-12)
    # Inside a sphere light every direction hits it: uniform, 1 / (4 pi).
    a, p, n, w = _case([rt.sphere((0.2, 0, 0), 1.0, MAT)], 1.0)
    assert pdf.lights_value(a, p, (0.0, 1.0, 0.0), NO_HIT, False, None) == \
        pytest.approx(1 / (4 * math.pi))


def test_light_pdf_is_zero_off_the_light_and_from_the_light_itself():
    a, p, n, w = CASES["rect light"]()
    miss = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
    assert (_value(a, p, n, 1.0, miss) == 0).all()
    # From a point on the light rect, no direction reaches it: density 0.
    assert pdf.lights_value(a, (0.0, 0.0, 1.0), (0.0, 0.0, 1.0),
                            0, False, None) == 0.0
