"""Textures (The Next Week): values at fixed points against hand-computed ones,
texel lookups, and rendering through them; quads."""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.path import textures as tx
from test_accuracy import STRATEGIES, _floor_point_scene, assert_expected


def arrays(*textures):
    """TextureArrays with one material per texture."""
    return tx.pack_textures([rt.lambertian(t) for t in textures])


@njit
def value(a, t, u, v, p):
    """Texture t's value at (u, v, p), as the kernel looks it up."""
    return tx.value(a, t, u, v, p)


def test_checker_is_the_sign_of_three_sines():
    even, odd = (0.2, 0.3, 0.1), (0.9, 0.9, 0.9)
    a = arrays(rt.checker_texture(even, odd, scale=10))
    # sin(10 x) at x = 0.05: sin(0.5) > 0; at x = 0.4: sin(4) < 0.
    assert value(a, 0, 0.0, 0.0, (0.05, 0.05, 0.05)) == even
    assert value(a, 0, 0.0, 0.0, (0.4, 0.05, 0.05)) == odd
    assert value(a, 0, 0.0, 0.0, (0.4, 0.4, 0.05)) == even
    assert value(a, 0, 0.0, 0.0, (0.4, 0.4, 0.4)) == odd
    assert value(a, 0, 0.0, 0.0, (0.0, 0.4, 0.4)) == even     # sines == 0: even


def test_checker_of_checkers_is_walked():
    inner = rt.checker_texture((1, 0, 0), (0, 1, 0), scale=100)
    a = arrays(rt.checker_texture(inner, (0, 0, 1), scale=1))
    p = (0.5, 0.5, 0.5)                      # outer: sin(.5)^3 > 0 -> inner
    s = math.sin(50) ** 3                    # inner at scale 100
    assert value(a, 0, 0.0, 0.0, p) == ((1, 0, 0) if s >= 0 else (0, 1, 0))
    assert value(a, 0, 0.0, 0.0, (4, 0.5, 0.5)) == (0, 0, 1)


def perlin_twin(g, perm, p):
    """The book's perlin::noise, written out in Python."""
    fx, fy, fz = (math.floor(c) for c in p)
    u, v, w = p[0] - fx, p[1] - fy, p[2] - fz
    uu, vv, ww = (t * t * (3 - 2 * t) for t in (u, v, w))
    total = 0.0
    for i in range(2):
        for j in range(2):
            for k in range(2):
                c = g[perm[0][(fx + i) & 255] ^ perm[1][(fy + j) & 255] ^ perm[2][(fz + k) & 255]]
                weight = np.array([u - i, v - j, w - k])
                total += ((i * uu + (1 - i) * (1 - uu)) * (j * vv + (1 - j) * (1 - vv))
                          * (k * ww + (1 - k) * (1 - ww)) * float(c @ weight))
    return total


@pytest.mark.parametrize("p", [(0.5, 0.25, 0.75), (-3.2, 7.9, 12.01), (100.5, -0.5, 3.3)])
def test_perlin_noise_equals_the_books_formula(p):
    a = arrays(rt.noise_texture(1.0, "noise", seed=3))
    g, perm = tx.perlin_tables(3)
    exact = 0.5 * (1 + perlin_twin(g, perm, p))
    assert value(a, 0, 0.0, 0.0, p) == pytest.approx((exact,) * 3, abs=1e-12)
    # Turbulence: |sum of 7 octaves|; marble: 0.5 (1 + sin(s z + 10 turb(p))).
    turb = abs(sum(0.5 ** i * perlin_twin(g, perm, tuple(2 ** i * c for c in p))
                   for i in range(7)))
    t = arrays(rt.noise_texture(1.0, "turbulence", seed=3))
    assert value(t, 0, 0.0, 0.0, p)[0] == pytest.approx(turb, abs=1e-12)
    m = arrays(rt.noise_texture(4.0, "marble", seed=3))
    assert value(m, 0, 0.0, 0.0, p)[0] == pytest.approx(
        0.5 * (1 + math.sin(4.0 * p[2] + 10 * turb)), abs=1e-12)


def test_perlin_noise_is_zero_on_the_lattice_and_seeded():
    a = arrays(rt.noise_texture(1.0, "noise", seed=1))
    for p in [(0, 0, 0), (3, -2, 7), (255, 256, -1000)]:
        assert value(a, 0, 0.0, 0.0, p) == (0.5, 0.5, 0.5)
    b = arrays(rt.noise_texture(1.0, "noise", seed=2))
    p = (0.3, 0.6, 0.1)
    assert value(a, 0, 0.0, 0.0, p) != value(b, 0, 0.0, 0.0, p)
    assert value(a, 0, 0.0, 0.0, p) == value(arrays(rt.noise_texture(1.0, "noise", seed=1)),
                                             0, 0.0, 0.0, p)


def image_file(tmp_path, pixels):
    import imageio.v3 as iio
    path = tmp_path / "t.png"
    iio.imwrite(path, np.asarray(pixels, dtype=np.uint8))
    return path


def test_image_lookups_at_texel_centres(tmp_path):
    rng = np.random.default_rng(0)
    pixels = rng.integers(0, 256, (5, 7, 3))
    a = arrays(rt.image_texture(str(image_file(tmp_path, pixels))))
    linear = (pixels / 255.0) ** 2.2
    for row in range(5):
        for col in range(7):
            u, v = (col + 0.5) / 7, 1 - (row + 0.5) / 5       # v = 1 is the top row
            assert value(a, 0, u, v, (0, 0, 0)) == pytest.approx(tuple(linear[row, col]),
                                                                 abs=1e-15)
    # Outside [0, 1]: clamped to the edge texels.
    assert value(a, 0, -1.0, 2.0, (0, 0, 0)) == pytest.approx(tuple(linear[0, 0]))
    assert value(a, 0, 1.0, 0.0, (0, 0, 0)) == pytest.approx(tuple(linear[4, 6]))


def test_an_image_on_a_quad_light_is_seen_texel_for_pixel(tmp_path):
    # A 2x2 image emitted by a quad that exactly fills a 2x2 camera: each
    # pixel sees one texel, upright (row 0 at the top, column 0 on the left).
    pixels = [[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 255]]]
    light = rt.diffuse_light(rt.image_texture(str(image_file(tmp_path, pixels))))
    vfov = math.degrees(2 * math.atan(1 / 10))
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 10), lookat=(0, 0, 0), vfov=vfov,
                                      width=2, height=2))
    scene.add(rt.quad((-1, -1, 0), (2, 0, 0), (0, 2, 0), light))
    r = rt.render(scene, spp=8, seed=1)
    assert np.allclose(r.image, np.asarray(pixels) / 255.0, atol=1e-6)


def test_image_texture_on_a_sphere_wraps_by_its_uv(tmp_path):
    # The book's (u, v): u = 0.5 faces -z... a sphere seen from +x (u = 0.5
    # there: phi = atan2(0, 1) + pi) shows the image's middle column.
    pixels = np.zeros((4, 8, 3), dtype=np.uint8)
    pixels[:, 3:5] = 255                      # the columns around u = 0.5
    light = rt.diffuse_light(rt.image_texture(str(image_file(tmp_path, pixels))))
    scene = rt.Scene(camera=rt.Camera(lookfrom=(10, 0, 0), lookat=(0, 0, 0), vfov=1,
                                      width=1, height=1))
    scene.add(rt.sphere((0, 0, 0), 1, light))
    assert rt.render(scene, spp=4, seed=1).image.min() == pytest.approx(1.0)


def test_a_solid_texture_renders_the_bits_of_its_colour():
    def scene(albedo):
        s = rt.load_scene("cornell_box").with_camera(width=12, height=12)
        s.objects[3] = rt.xz_rect(0, 555, 0, 555, 0, rt.lambertian(albedo))
        return s
    plain = rt.render(scene((0.73, 0.73, 0.73)), spp=4, seed=2)
    textured = rt.render(scene(rt.solid_color((0.73, 0.73, 0.73))), spp=4, seed=2)
    assert np.array_equal(plain.image, textured.image)


def polygon_irradiance(p, normal, corners):
    """Lambert's formula: irradiance at p from a polygon of unit radiance,
    (1/2) sum over edges of angle x (normal . unit edge-plane normal)."""
    v = [np.subtract(c, p) / np.linalg.norm(np.subtract(c, p)) for c in corners]
    total = 0.0
    for a, b in zip(v, v[1:] + v[:1]):
        g = np.cross(a, b)
        total += math.acos(np.clip(a @ b, -1, 1)) * (np.asarray(normal) @ (g / np.linalg.norm(g)))
    return abs(total) / 2


@pytest.mark.parametrize("sampling", STRATEGIES)
def test_a_skewed_quad_light(sampling):
    # A parallelogram (edges not perpendicular) facing down over the floor.
    le, q, u, v = 4.0, np.array([-0.6, 1.0, -0.4]), np.array([1.2, 0.0, 0.3]), \
        np.array([0.5, 0.0, 0.9])
    if np.cross(u, v)[1] > 0:
        u, v = v, u                                   # face down (-y)
    light = rt.quad(tuple(q), tuple(u), tuple(v), rt.diffuse_light((le,) * 3))
    scene, albedo = _floor_point_scene((0.1, 0, 0.2), light)
    e = polygon_irradiance((0.1, 0, 0.2), (0, 1, 0), [q, q + u, q + u + v, q + v])
    r = rt.render(scene, spp=40_000, sampling=sampling, seed=5)
    assert_expected(r.image[..., 0], r.stderr[..., 0], albedo / math.pi * le * e,
                    f"skewed quad light ({sampling})")
