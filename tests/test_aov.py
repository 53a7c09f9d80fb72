"""Feature images (aov): the albedo and normal of what each pixel's paths first
see through mirrors and glass, for denoisers -- exact where the scene says what
they must be, and free of any effect on the image."""
import numpy as np
import pytest

import rtweekend as rt
from rtweekend.errors import SceneError
from rtweekend.path.renderer import Renderer

BOTH = ("albedo", "normal")


def test_asking_for_features_changes_nothing_in_the_image():
    scene = rt.load_scene("cornell_glass")
    plain = rt.render(scene, spp=8, width=24, height=24, seed=2)
    asked = rt.render(scene, spp=8, width=24, height=24, seed=2, aov=BOTH)
    assert np.array_equal(plain.image, asked.image)
    assert np.array_equal(plain.stderr, asked.stderr)
    assert plain.aov == {} and set(asked.aov) == set(BOTH)
    assert asked.aov["albedo"].shape == (24, 24, 3) and asked.aov["albedo"].dtype == np.float32
    only = rt.render(scene, spp=8, width=24, height=24, seed=2, aov="normal")
    assert list(only.aov) == ["normal"]
    assert np.array_equal(only.aov["normal"], asked.aov["normal"])


def test_features_are_the_same_for_any_thread_count_and_pass_split():
    scene = rt.load_scene("cornell_smoke")
    one = rt.render(scene, spp=6, width=20, height=16, seed=4, threads=1, aov=BOTH)
    r = Renderer(scene, width=20, height=16, seed=4, threads=2, aov=BOTH)
    r.add_samples(2)
    for _ in range(2):
        r.add_rows(1, 7)
        r.add_rows(1, 9)
    r.add_samples(2)
    split = r.result()
    for name in BOTH:
        assert np.array_equal(one.aov[name], split.aov[name])
    partial = Renderer(scene, width=20, height=16, seed=4, aov=BOTH)
    partial.add_samples(2)
    partial.add_rows(1, 5)             # five rows have 3 samples, the others 2: each its own
    features = partial.result().aov["albedo"]
    assert np.isfinite(features).all() and features.max() <= 1.0


def _wall_scene(mirror):
    """A camera looking at a lambertian wall (albedo 0.5, facing it), or at a
    mirror (albedo 0.8) that shows it the wall behind the camera."""
    white = rt.lambertian((0.5, 0.5, 0.5))
    light = rt.diffuse_light((2, 2, 2))
    if not mirror:
        scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 0), lookat=(0, 0, -1), vfov=30,
                                          width=8, height=8))
        scene.add(rt.xy_rect(-50, 50, -50, 50, -5, white))
    else:
        scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 0), lookat=(0, 0, -1), vfov=30,
                                          width=8, height=8))
        scene.add(rt.xy_rect(-50, 50, -50, 50, -5, rt.metal((0.8, 0.8, 0.8), 0.0)))
        scene.add(rt.xy_rect(-50, 50, -50, 50, 5, white).flip_face())
    scene.add(rt.xz_rect(-50, 50, -50, 50, 20, light).flip_face(), light=True)
    return scene


@pytest.mark.parametrize("mirror", [False, True], ids=["wall", "through a mirror"])
def test_the_albedo_and_normal_of_what_is_seen(mirror):
    r = rt.render(_wall_scene(mirror), spp=4, seed=1, aov=BOTH)
    expected = 0.8 * 0.5 if mirror else 0.5
    np.testing.assert_allclose(r.aov["albedo"], expected, rtol=1e-6)
    normal = (0, 0, -1) if mirror else (0, 0, 1)       # the seen wall's, facing the ray
    np.testing.assert_allclose(r.aov["normal"], np.broadcast_to(normal, (8, 8, 3)), atol=1e-6)


def test_the_background_gives_its_colour_and_no_normal():
    scene = rt.Scene(camera=rt.Camera(width=4, height=4), background=(0.2, 0.4, 3.0))
    scene.add(rt.sphere((0, 0, -50), 1, rt.lambertian((0.5, 0.5, 0.5))))
    r = rt.render(scene, spp=2, seed=1, width=4, height=4, aov=BOTH)
    np.testing.assert_allclose(r.aov["albedo"][0, 0], (0.2, 0.4, 1.0), rtol=1e-6)
    assert (r.aov["normal"][0, 0] == 0).all()


@pytest.mark.parametrize("aov, message", [
    (("albedo", "normals"), "did you mean 'normal'"),
    ("depth", "unknown feature 'depth'"),
    (5, "expected names among albedo, normal"),
])
def test_bad_feature_names_are_one_line(aov, message):
    with pytest.raises(SceneError, match=message) as e:
        rt.render(rt.load_scene("cornell_box"), spp=1, width=4, height=4, aov=aov)
    assert "\n" not in str(e.value)


def test_light_tracing_has_no_features():
    with pytest.raises(SceneError, match="no feature images"):
        rt.render(rt.load_scene("cornell_box"), spp=1, width=4, height=4,
                  sampling="lightpath", aov=BOTH)


@pytest.mark.parametrize("sampling", ["mixture+sobol", "bdpt"])
def test_features_through_a_glass_pane_are_those_of_what_lies_behind(sampling):
    # A glass box in front of the wall: the camera ray goes in and out of it
    # (weight 1: both faces refract, or Schlick reflects it back at the
    # camera, where nothing is), so the features are the wall's.
    scene = _wall_scene(False)
    scene.add(rt.box((-40, -40, -3), (40, 40, -2), rt.dielectric(1.5)))
    r = rt.render(scene, spp=64, seed=1, aov=BOTH + ("emission",), sampling=sampling)
    # Schlick sends about 4% back at each face, into the dark (albedo 0, no
    # normal): each pixel's features are the wall's times the share of its
    # rays that got through, the same share in both.
    through = r.aov["normal"][..., 2]
    assert 0.85 < through.mean() < 1.0 and through.max() <= 1.0
    np.testing.assert_allclose(r.aov["normal"][..., :2], 0.0, atol=1e-12)
    np.testing.assert_allclose(r.aov["albedo"], 0.5 * through[..., None] * np.ones(3),
                               rtol=1e-6)
    assert r.aov["emission"].max() == 0.0


@pytest.mark.parametrize("sampling", ["mixture", "nee+sobol", "bdpt"])
def test_the_emission_feature_is_the_light_seen_directly_or_in_a_mirror(sampling):
    # A camera facing a light (radiance 3) that fills its view, seen directly
    # and in a mirror of albedo 0.5: the feature is the radiance seen, exactly,
    # and the image is the same with the feature asked for.
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 0), lookat=(0, 0, -1), vfov=30,
                                      width=8, height=8))
    scene.add(rt.xy_rect(-50, 50, -50, 50, -5, rt.diffuse_light((3, 3, 3))), light=True)
    r = rt.render(scene, spp=4, seed=1, aov=("emission",), sampling=sampling)
    np.testing.assert_allclose(r.aov["emission"], 3.0, rtol=1e-6)
    mirror = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 0), lookat=(0, 0, -1), vfov=30,
                                       width=8, height=8))
    mirror.add(rt.xy_rect(-50, 50, -50, 50, -5, rt.metal((0.5, 0.5, 0.5), 0.0)))
    mirror.add(rt.xy_rect(-50, 50, -50, 50, 5, rt.diffuse_light((3, 3, 3))).flip_face(),
               light=True)
    r = rt.render(mirror, spp=4, seed=1, aov=("emission",), sampling=sampling)
    np.testing.assert_allclose(r.aov["emission"], r.image, rtol=1e-6)
    if sampling != "nee+sobol":     # with no Russian roulette after the mirror: exactly
        np.testing.assert_allclose(r.image, 1.5, rtol=1e-6)
    else:                           # roulette: 1.5 in the mean
        se = np.sqrt((r.stderr.astype(float) ** 2).sum()) / r.stderr.size
        assert abs(r.image.mean() - 1.5) < 5 * se
    plain = rt.render(mirror, spp=4, seed=1, sampling=sampling)
    assert np.array_equal(plain.image, r.image)


def test_the_standard_error_as_a_layer_is_the_results_and_costs_no_feature_images():
    scene = rt.load_scene("cornell_box")
    plain = rt.render(scene, spp=4, width=12, height=10, seed=3)
    r = Renderer(scene, spp=4, width=12, height=10, seed=3, aov="stderr")
    assert r.film.albedo.shape[0] == 0          # the kernel keeps no feature images
    r.add_samples(4)
    asked = r.result()
    assert list(asked.aov) == ["stderr"]
    assert np.array_equal(asked.aov["stderr"], plain.stderr)
    assert np.array_equal(asked.image, plain.image)


def test_the_command_saves_the_standard_error_beside_the_image(tmp_path):
    import subprocess
    import sys
    out = tmp_path / "box.npy"
    r = subprocess.run([sys.executable, "-m", "rtweekend", "render", "cornell_box", "-o",
                        str(out), "--spp", "4", "--width", "12", "--height", "10", "--seed", "3",
                        "--aov", "stderr,albedo", "-q"], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    same = rt.render(rt.load_scene("cornell_box"), spp=4, width=12, height=10, seed=3)
    assert np.array_equal(np.load(tmp_path / "box.stderr.npy"), same.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.albedo.npy", "box.npy",
                                                          "box.stderr.npy"]


def _sphere_normals_over_pixels(scene, sub=16):
    """The mean over each pixel's area (a sub x sub grid of points) of the
    analytic normal where the camera ray meets the scene's one sphere, and
    whether every point of the pixel meets it; from the camera's own mapping
    (pack_camera: pixel (i, j) covers [i, i+1) x [j, j+1) of the viewport)."""
    from rtweekend.path.camera import pack_camera
    c = scene.camera
    cam = pack_camera(c)
    origin, corner, horizontal, vertical = cam[0:3], cam[3:6], cam[6:9], cam[9:12]
    center, radius = (np.asarray(v, dtype=np.float64) for v in scene.objects[0].geometry)
    offsets = (np.arange(sub) + 0.5) / sub
    x = (np.arange(c.width)[:, None] + offsets[None, :]).ravel() / c.width
    y = (np.arange(c.height)[:, None] + offsets[None, :]).ravel() / c.height
    s, t = np.meshgrid(x, y)                           # [H*sub, W*sub]
    d = corner + s[..., None] * horizontal - t[..., None] * vertical - origin
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    oc = origin - center
    b = (d * oc).sum(-1)
    disc = b * b - (oc @ oc - radius * radius)
    hit = disc > 0
    dist = -b - np.sqrt(np.where(hit, disc, 0.0))
    n = (origin + dist[..., None] * d - center) / radius
    shape = (c.height, sub, c.width, sub)
    mean = n.reshape(*shape, 3).mean(axis=(1, 3))
    return mean, hit.reshape(shape).all(axis=(1, 3))


@pytest.mark.parametrize("sampling", ["mixture+sobol", "bdpt+sobol"])
def test_a_spheres_normal_feature_is_its_analytic_normal_over_each_pixel(sampling):
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0.3, -0.2, 0), lookat=(0, 0, -10), vfov=30,
                                      width=16, height=16))
    scene.add(rt.sphere((0, 0, -10), 2.4, rt.lambertian((0.5, 0.5, 0.5))))
    scene.add(rt.xz_rect(-50, 50, -50, 50, 20, rt.diffuse_light((2, 2, 2))).flip_face(),
              light=True)
    r = rt.render(scene, spp=256, seed=1, sampling=sampling, aov="normal")
    expected, inside = _sphere_normals_over_pixels(scene)
    assert inside.sum() > 100                        # most of the image is sphere
    # Sobol pixel positions: 256 stratified points per pixel, whose mean normal
    # is within 1e-4 of the area's (a shift of half a pixel would be ~3e-2).
    np.testing.assert_allclose(r.aov["normal"][inside], expected[inside], atol=1e-3)
