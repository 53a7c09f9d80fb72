"""Constant media (The Next Week): closed forms and stability.

Tolerances as in test_accuracy.py: |mean - exact| < 4 standard errors from
the samples' own variance (+1e-6 where the estimator has none)."""
import math

import numpy as np
import pytest

import rtweekend as rt
from test_accuracy import STRATEGIES, assert_expected, furnace
from test_render import _block_stderr, _blocks


def slab_scene(density, albedo=0.0, thickness=2.0):
    """A camera looking down -z at a light (radiance 1) through a box of medium
    `thickness` deep that fills the view."""
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 5), lookat=(0, 0, 0), vfov=10,
                                      width=6, height=6), background=(0, 0, 0))
    scene.add(rt.xy_rect(-20, 20, -20, 20, -10, rt.diffuse_light((1, 1, 1))), light=True)
    boundary = rt.box((-5, -5, -thickness), (5, 5, 0), rt.lambertian((0.5, 0.5, 0.5)))
    scene.add(rt.constant_medium(boundary, density, (albedo,) * 3))
    return scene


@pytest.mark.parametrize("sampling", STRATEGIES)
def test_beer_lambert_through_an_absorbing_slab(sampling):
    # Every camera ray crosses 2 units of medium at near-normal incidence
    # (vfov 10: at most 7 degrees off, so the path length is 2/cos <= 2.016);
    # exact: the mean of exp(-d L) over the pixels' rays, integrated below.
    density = 0.5
    r = rt.render(slab_scene(density), spp=256, sampling=sampling, seed=3)
    exact = _slab_transmittance(r.image.shape[:2], 10.0, density, 2.0)
    assert_expected(r.image, r.stderr, exact, f"slab ({sampling})")
    assert 0.36 < exact < 0.37          # ~ exp(-1)
    assert r.stats.nan_dropped == 0


def _slab_transmittance(shape, vfov, density, thickness, n=64):
    """Mean over the image of exp(-density x path length), each pixel's rays
    integrated by a midpoint rule over its square (the camera looks down -z)."""
    h, w = shape
    half = math.tan(math.radians(vfov) / 2)
    j = (np.arange(n * h) + 0.5) / (n * h)
    i = (np.arange(n * w) + 0.5) / (n * w)
    x, y = np.meshgrid((2 * i - 1) * half * w / h, (1 - 2 * j) * half)
    cos = 1 / np.sqrt(1 + x * x + y * y)
    return float(np.exp(-density * thickness / cos).mean())


@pytest.mark.parametrize("sampling", STRATEGIES)
def test_white_medium_in_a_furnace_gives_one(sampling):
    # Albedo 1 loses nothing: every path ends on the furnace's radiance 1.
    # Optical radius 1.5: paths scatter a few times, far from the depth cap.
    ball = rt.sphere((0, 0, 0), 1, rt.lambertian((0.5, 0.5, 0.5)))
    scene = furnace(rt.constant_medium(ball, 1.5, (1, 1, 1)), vfov=40, size=10)
    r = rt.render(scene, spp=64, sampling=sampling, seed=4)
    assert_expected(r.image, r.stderr, 1.0, f"white medium furnace ({sampling})")
    assert r.stats.nan_dropped == 0


@pytest.mark.parametrize("sampling", ["mixture", "nee+sobol"])
def test_black_medium_in_a_furnace_gives_its_transmittance(sampling):
    # A 1x1 image of the ball's centre: exp(-density x chord), averaged over
    # the pixel's rays (the camera is 4 away; the pixel spans 0.07 there).
    density, radius, dist, vfov = 0.7, 1.0, 4.0, 1.0
    ball = rt.sphere((0, 0, 0), radius, rt.lambertian((0.5, 0.5, 0.5)))
    scene = furnace(rt.constant_medium(ball, density, (0, 0, 0)), vfov=vfov, size=1)
    r = rt.render(scene, spp=4096, sampling=sampling, seed=5)
    n = 400
    half = math.tan(math.radians(vfov) / 2)
    g = ((np.arange(n) + 0.5) / n * 2 - 1) * half
    x, y = np.meshgrid(g, g)
    d = np.stack([x, y, -np.ones_like(x)], axis=-1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    # Ray from (0, 0, dist): closest approach b, chord 2 sqrt(r^2 - b^2).
    o = np.array([0.0, 0.0, dist])
    along = -(d @ o)
    b2 = dist * dist - along * along
    exact = float(np.exp(-density * 2 * np.sqrt(np.maximum(radius ** 2 - b2, 0))).mean())
    assert_expected(r.image, r.stderr, exact, f"black medium furnace ({sampling})")


@pytest.mark.parametrize("sampling", ["mixture", "nee"])
def test_a_camera_inside_fog(sampling):
    # The camera at the centre of a black fog ball of radius R inside the
    # furnace: every ray crosses R of fog, whatever its direction.
    density, radius = 0.3, 2.0
    fog = rt.constant_medium(rt.sphere((0, 0, 0), radius, rt.lambertian((1, 1, 1))),
                             density, (0, 0, 0))
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 0), lookat=(1, 0.3, -2), vfov=90,
                                      width=8, height=6))
    scene.add(rt.sphere((0, 0, 0), 100, rt.diffuse_light((1, 1, 1))).flip_face(), light=True)
    scene.add(fog)
    r = rt.render(scene, spp=128, sampling=sampling, seed=6)
    assert_expected(r.image, r.stderr, math.exp(-density * radius), f"fog ({sampling})")


def test_media_inside_glass_and_fog_render_without_bad_samples():
    # The book's subsurface sphere (glass with a medium in the same sphere)
    # and a scene-wide fog, under a light: the light arrives (a non-zero
    # image), no sample is NaN, and one thread gives the bits of two.
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 1, 6), lookat=(0, 0, 0), vfov=40,
                                      width=16, height=12))
    glass = rt.sphere((0, 0, 0), 1, rt.dielectric(1.5))
    scene.add(glass)
    scene.add(rt.constant_medium(rt.sphere((0, 0, 0), 1, rt.dielectric(1.5)), 2.0,
                                 (0.2, 0.4, 0.9)))
    scene.add(rt.constant_medium(rt.sphere((0, 0, 0), 50, rt.dielectric(1.5)), 0.01,
                                 (1, 1, 1)))
    scene.add(rt.xz_rect(-3, 3, -3, 3, 4, rt.diffuse_light((4, 4, 4))).flip_face(),
              light=True)
    scene.add(rt.xz_rect(-10, 10, -10, 10, -1, rt.lambertian((0.5, 0.5, 0.5))))
    for sampling in ("mixture+sobol", "nee"):
        one = rt.render(scene, spp=16, sampling=sampling, seed=7, threads=1)
        two = rt.render(scene, spp=16, sampling=sampling, seed=7, threads=2)
        assert np.array_equal(one.image, two.image)
        assert one.stats.nan_dropped == 0 and one.image.mean() > 0.01


@pytest.mark.parametrize("density", [0.0, 1e6])
def test_extreme_densities(density):
    # Density 0: the slab is not there (every ray reaches the light: exactly
    # 1).  Density 1e6, black: nothing gets through (exactly 0); white: the
    # light is scattered back and forth until the depth cap, never NaN.
    black = rt.render(slab_scene(density, 0.0), spp=16, seed=8)
    assert np.all(black.image == (1.0 if density == 0.0 else 0.0))
    white = rt.render(slab_scene(density, 1.0), spp=16, seed=8, sampling="nee")
    assert white.stats.nan_dropped == 0 and np.isfinite(white.image).all()


def test_grazing_boundaries():
    # A medium ball whose silhouette crosses the pixels (rays tangent to the
    # boundary, chords near 0): a white one in the furnace is still 1 in
    # every pixel's expectation; never a NaN.
    ball = rt.sphere((0, 0, 0), 1, rt.lambertian((0.5, 0.5, 0.5)))
    scene = furnace(rt.constant_medium(ball, 2.0, (1, 1, 1)), vfov=30, size=12)
    r = rt.render(scene, spp=32, sampling="mixture", seed=9)
    assert r.stats.nan_dropped == 0
    assert_expected(r.image, r.stderr, 1.0, "grazing white medium")


@pytest.mark.parametrize("sampling", ["mixture+sobol", "nee"])
def test_cornell_smoke_agrees_with_mitsuba(cornell_smoke_reference, sampling):
    """10x10-pixel block means of a 64-spp render against Mitsuba 3's volpath
    render of the same scene (homogeneous media in cubes with a null BSDF).
    Each block within 5 combined standard errors, the image mean within 4;
    blocks inside the light (no noise in either) equal."""
    ref, ref_se = cornell_smoke_reference
    r = rt.render(rt.load_scene("cornell_smoke"), spp=64, seed=1, width=150, height=150,
                  sampling=sampling)
    assert r.stats.nan_dropped == 0
    diff = _blocks(r.image, 10) - _blocks(ref, 10)
    both = np.hypot(_block_stderr(r.stderr, 10), _block_stderr(ref_se, 10))
    assert np.allclose(diff[both == 0], 0.0, atol=1e-5)
    z = diff[both > 0] / both[both > 0]
    assert np.abs(z).max() < 5.0, f"worst block z = {np.abs(z).max():.2f}"
    mean_se = np.sqrt((r.stderr.astype(np.float64) ** 2).sum() + (ref_se ** 2).sum()) \
        / r.stderr.size
    assert abs(r.image.mean() - ref.mean()) < 4 * mean_se
