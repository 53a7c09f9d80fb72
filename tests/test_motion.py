"""Motion blur (The Next Week): moving spheres against closed forms."""
import math

import numpy as np
import pytest

import rtweekend as rt
from test_accuracy import assert_expected

GLOW = rt.diffuse_light((1, 1, 1))


def moving_scene(c0, c1, radius=1.0, width=1, vfov=0.2):
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 50), lookat=(0, 0, 0), vfov=vfov,
                                      width=width, height=1))
    scene.add(rt.sphere(c0, radius, GLOW, center1=c1))
    return scene


@pytest.mark.parametrize("c0, c1, fraction", [((-0.5, 0, 0), (3.5, 0, 0), 0.375),
                                              ((-3, 0, 0), (3, 0, 0), 1 / 3),
                                              ((0, 0, 0), (0, 0, -10), 1.0)])
def test_a_moving_sphere_covers_a_pixel_for_its_share_of_the_shutter(c0, c1, fraction):
    # The pixel's ray runs down the z axis; the sphere (radius 1, emitting 1)
    # covers it while its centre is within 1 of the axis: the pixel's value is
    # the fraction of the shutter when that holds (the pixel spans 0.17 at
    # the sphere: its rays differ by little, see the pixel-by-pixel test).
    r = rt.render(moving_scene(c0, c1), spp=4096, seed=1, sampling="mixture")
    assert_expected(r.image, r.stderr, fraction, f"coverage {c0} -> {c1}")


def test_time_averaged_coverage_pixel_by_pixel():
    # 16 pixels across the sweep of a sphere moving 6 along x: each pixel's
    # value is the time-and-area average of "its ray hits the sphere", which
    # for a ray at (x, y) is the share of t in [0, 1] with
    # |x - (x0 + 6 t)| < sqrt(r^2 - y^2): integrated here on a fine grid.
    width, vfov = 16, 0.5
    scene = moving_scene((-3, 0, 0), (3, 0, 0), radius=0.4, width=width, vfov=vfov)
    r = rt.render(scene, spp=1024, seed=2)
    half = math.tan(math.radians(vfov) / 2) * 50          # the view at z = 0
    n = 200
    xs = ((np.arange(width * n) + 0.5) / (width * n) * 2 - 1) * half * width
    ys = ((np.arange(n) + 0.5) / n * 2 - 1) * half
    X, Y = np.meshgrid(xs, ys)
    chord = np.sqrt(np.maximum(0.4 ** 2 - Y ** 2, 0))
    # Time in which x0 + 6 t lies within chord of X, for t in [0, 1].
    lo = np.clip((X - chord + 3) / 6, 0, 1)
    hi = np.clip((X + chord + 3) / 6, 0, 1)
    exact = (hi - lo).reshape(n, width, n).mean(axis=(0, 2))
    z = (r.image[0, :, 0] - exact) / np.maximum(r.stderr[0, :, 0], 1e-9)
    assert np.abs(z).max() < 5, f"worst pixel z = {np.abs(z).max():.2f}"
    assert (exact > 0.05).sum() >= 12                         # the test sees the sphere


def test_scattered_rays_keep_the_time():
    # A black sphere moves across the camera's line of sight; behind it a
    # mirror sends the ray back along the same line to a light behind the
    # camera.  The ray passes the sphere's path twice at one time: it gets
    # through with probability P(miss) = 1 - 0.375, not P(miss)^2 (a time
    # drawn anew per segment).
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 10), lookat=(0, 0, 0), vfov=0.2,
                                      width=1, height=1), max_depth=5)
    scene.add(rt.sphere((-0.5, 0, 0), 1, rt.lambertian((0, 0, 0)), center1=(3.5, 0, 0)))
    scene.add(rt.xy_rect(-50, 50, -50, 50, -5, rt.metal((1, 1, 1), 0.0)))
    scene.add(rt.xy_rect(-50, 50, -50, 50, 20, rt.diffuse_light((1, 1, 1))).flip_face())
    r = rt.render(scene, spp=4096, seed=3)
    assert_expected(r.image, r.stderr, 1 - 0.375, "one time per path")


def test_zero_length_motion_is_no_motion():
    # center1 == center: the sphere does not move, and the scene renders the
    # bits of the static one (no motion kernel at all).
    still = moving_scene((0, 0, 0), (0, 0, 0), width=4, vfov=5)
    static = rt.Scene(camera=still.camera)
    static.add(rt.sphere((0, 0, 0), 1, GLOW))
    a, b = rt.render(still, spp=8, seed=4), rt.render(static, spp=8, seed=4)
    assert np.array_equal(a.image, b.image)
    # ... and a motion of 1e-300 goes through the motion kernel harmlessly.
    tiny = moving_scene((0, 0, 0), (1e-300, 0, 0), width=4, vfov=5)
    c = rt.render(tiny, spp=8, seed=4)
    assert c.stats.nan_dropped == 0 and np.allclose(c.image, b.image)


def test_moving_spheres_in_a_bvh_are_bounded_by_their_sweep():
    # Twelve spheres moving across each other: a BVH built on bounds that
    # missed the sweep would lose hits; with and without one, the same bits.
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 2, 12), lookat=(0, 0, 0), vfov=40,
                                      width=24, height=16), background="sky")
    rng = np.random.default_rng(5)
    for _ in range(12):
        c = tuple(rng.uniform(-3, 3, 3))
        scene.add(rt.sphere(c, 0.6, rt.lambertian((0.6, 0.4, 0.3)),
                            center1=tuple(np.add(c, rng.uniform(-2, 2, 3)))))
    with_bvh = rt.render(scene, spp=8, seed=6, bvh=True)
    flat = rt.render(scene, spp=8, seed=6, bvh=False)
    assert np.array_equal(with_bvh.image, flat.image)
    one = rt.render(scene, spp=8, seed=6, threads=1)
    assert np.array_equal(one.image, with_bvh.image)
