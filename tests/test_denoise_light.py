"""The light seen emitted, estimated again for the denoiser (path/seen_light.py):
glass followed both ways as the render picks one way, the part of a pixel a
light covers to within the Sobol points' stratification, the render's own
estimate kept where the light does not vary, the same expectation as the
render's samples, and the same bits for any thread count."""
import math

import numpy as np
import pytest

import rtweekend as rt
from rtweekend import memory
from rtweekend.path import film as films
from rtweekend.path import pack, seen_light
from rtweekend.path.materials import dielectric

from stats import block_se, blocks

GLASS_CASES = [((0.3, -0.2, -1.0), (0.0, 0.0, 1.0), True, 1.5),
               ((0.8, 0.1, -0.3), (0.0, 0.0, 1.0), True, 1.5),
               ((0.2, 0.3, -1.0), (0.0, 0.0, 1.0), False, 1.5),
               ((0.9, 0.0, -0.2), (0.0, 0.0, 1.0), False, 1.5),     # total internal reflection
               ((0.5, -0.5, -0.7), (0.0, 0.6, 0.8), True, 2.4)]


@pytest.mark.parametrize("d, n, front, ior", GLASS_CASES)
def test_glass_branches_are_what_scatter_at_picks_between(d, n, front, ior):
    # The render reflects when u < the reflectance, else refracts: the two
    # branches are its two directions to the bit, and the reflectance the
    # chance of the first.
    d = tuple(np.asarray(d) / np.linalg.norm(d))
    reflected, refracted, reflectance = dielectric.branches(d, n, front, ior)
    assert 0.0 < reflectance <= 1.0
    below, above = math.nextafter(reflectance, 0.0), math.nextafter(reflectance, 1.0)
    assert dielectric.scatter_at(d, n, front, ior, below) == reflected
    if reflectance < 1.0:
        assert dielectric.scatter_at(d, n, front, ior, above) == refracted
        assert dielectric.scatter_at(d, n, front, ior, 0.999999) == refracted
    else:
        assert refracted == reflected


def _edge_scene(edge=4.3, size=8):
    """A camera facing the plane z = -5 (vfov 30, size x size pixels) and a
    light of radiance 15 on it from the image column `edge` rightwards (the
    map from columns to x on the plane is linear)."""
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 0), lookat=(0, 0, -1), vfov=30,
                                      width=size, height=size))
    x0 = 5.0 * 2.0 * math.tan(math.radians(15.0)) * (edge / size - 0.5)
    scene.add(rt.xy_rect(x0, 50, -50, 50, -5, rt.diffuse_light((15, 15, 15))), light=True)
    return scene


def test_a_lights_edge_is_found_to_within_the_sobol_points_stratification():
    # Column 4 is 70% covered: its n = 2^k points' x take one value in each
    # 1/n of the pixel, so their share past the edge is 0.7 to within 1/n (and
    # one more for a point the edge's rounding moves).  The columns beside
    # it are marked too (8 neighbours) and estimated again, exactly 0 or 15;
    # the others keep the render's own estimate, bit for bit.
    r = rt.Renderer(_edge_scene(), spp=4, seed=3, aov=("emission",))
    r.add_samples(4)
    emission = r.result().aov["emission"]
    light, done = seen_light.estimate(r.frame, emission, 32, 10**12, 1)
    n = done.rays
    assert n == seen_light.N_PER_SPP * 32 and done.pixels == 3 * 8
    assert np.all(np.abs(light[:, 4] - 0.7 * 15.0) <= 2 * 15.0 / n)
    assert np.all(light[:, 5:] == 15.0) and np.all(light[:, :4] == 0.0)
    assert np.array_equal(light[:, [0, 1, 2, 6, 7]], emission[:, [0, 1, 2, 6, 7]])
    # The render's own estimate there: 4 samples, a quarter-pixel's grain.
    assert np.abs(emission[:, 4] - 10.5).max() > 2 * 15.0 / n


def test_a_light_behind_a_glass_pane_at_normal_incidence():
    # Head on (vfov 1 degree: Schlick's reflectance is r0 = 0.04 to 1e-20 on
    # both faces), the light (15) behind a glass pane is seen through both
    # faces, once more after each pair of reflections inside:
    # 15 x 0.96^2 / (1 - 0.04^2).  Both faces are split; what comes back to
    # the first face inside is picked as the render picks, 4% of the 4% then
    # going on to the light: each ray's value is the split part plus 0 or
    # 15 x 0.96^2 x 0.04^2 / (1 - 0.04^2) / 0.0384 (about 0.58) with chance
    # 0.04 x 0.96, whose spread sets the tolerance.
    size = 4
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 0), lookat=(0, 0, -1), vfov=1,
                                      width=size, height=size))
    scene.add(rt.box((-40, -40, -3), (40, 40, -2), rt.dielectric(1.5)))
    scene.add(rt.xy_rect(-50, 50, -50, 50, -5, rt.diffuse_light((15, 15, 15))), light=True)
    frame = rt.Renderer(scene, seed=0, aov=("emission",)).frame
    f = frame.features
    out = np.zeros((size, size, 3))
    n = 1024
    seen_light.refine_pass(out, np.ones((size, size), np.bool_), frame.scene, frame.params,
                           frame.rows, n, 9, f.textures, f.media, f.motion)
    expected = 15 * 0.96 ** 2 / (1 - 0.04 ** 2)
    p = 0.04 * 0.96
    jump = 15 * 0.96 ** 2 * 0.04 ** 2 / (1 - 0.04 ** 2) / p
    sigma = jump * math.sqrt(p * (1 - p) / n)
    np.testing.assert_allclose(out, expected, atol=5 * sigma)
    assert 5 * sigma < 0.005 * expected


def test_where_nothing_varies_more_than_the_spread_nothing_is_estimated_again():
    # The books' sky varies inside a pixel by far less than SPREAD: the
    # render's estimate is kept everywhere (the ball is behind the camera).
    scene = rt.Scene(camera=rt.Camera(width=160, height=90), background="sky")
    scene.add(rt.sphere((0, 0, 5), 1, rt.lambertian((0.5, 0.5, 0.5))))
    r = rt.Renderer(scene, spp=1, seed=1, aov=("emission",))
    r.add_samples(1)
    emission = r.result().aov["emission"]
    assert emission.max() > 0.5
    light, done = seen_light.estimate(r.frame, emission, 16, 10**12, 1)
    assert done.pixels == 0 and np.array_equal(light, emission)


def test_the_rays_per_pixel_follow_the_samples_within_the_share_of_the_render():
    n = seen_light.rays_per_pixel
    assert n(10, 1.0, 100, 10**12) == 512                  # 8 x 100, down to a power of 2
    assert n(10, 1.0, 10**6, 10**12) == seen_light.N_MAX
    assert n(10, 1.0, 0, 10**12) == 0                      # no sample yet
    assert n(10, 1.0, 1, 10**12) == seen_light.N_MIN       # 8 x 1, but N_MIN at least
    share = seen_light.SHARE * 10**7
    assert n(1000, 2.0, 100, 10**7) == 64 and 1000 * 64 * 2.0 <= share < 1000 * 128 * 2.0
    assert n(10**6, 1.0, 100, 10**7) == 0                  # below N_MIN: none


def test_the_same_bits_for_any_thread_count():
    r = rt.Renderer(rt.load_scene("cornell_glass"), spp=1, width=40, height=40, seed=2,
                    sampling="mixture+sobol", aov=("emission",))
    r.add_samples(1)
    emission = r.result().aov["emission"]
    one, a = seen_light.estimate(r.frame, emission, 16, 10**12, 1)
    two, b = seen_light.estimate(r.frame, emission, 16, 10**12, 2)
    assert a == b and a.pixels > 0 and np.array_equal(one, two)


def test_the_estimate_has_the_expectation_of_the_renders_samples():
    # cornell_glass seen close up where the glass ball reflects the light
    # (Schlick's 5%: the render reflects one sample in 20) and shows it
    # through itself.  Every pixel estimated again (4 independent keys of 256
    # rays each) against the emission feature of the default strategy's
    # samples (8 seeds of 64), each side's standard error from the spread of
    # its own runs: 2x2 blocks where the render's samples vary, and the whole
    # window (which also holds the pixels whose rarer paths no sample took).
    size = 32
    scene = rt.load_scene("cornell_glass").with_camera(lookat=(202.3, 159.1, 190.0), vfov=2.5,
                                                       width=size, height=size)
    runs = [rt.render(scene, spp=64, seed=seed, aov=("emission",)).aov["emission"]
            for seed in range(8)]
    frame = rt.Renderer(scene, seed=0, aov=("emission",)).frame
    f = frame.features
    marks = np.ones((size, size), dtype=np.bool_)
    again = []
    for key in range(4):
        out = np.zeros((size, size, 3))
        seen_light.refine_pass(out, marks, frame.scene, frame.params, frame.rows, 256, key,
                               f.textures, f.media, f.motion)
        again.append(out)

    def mean_se(xs):
        xs = np.array(xs, dtype=np.float64)
        return xs.mean(axis=0), xs.std(axis=0, ddof=1) / math.sqrt(len(xs))

    (a, a_se), (b, b_se) = mean_se(runs), mean_se(again)
    assert 0.5 < b.max() < 1.0 and (b[..., 0] > 0.5).sum() > 50        # the reflection
    varying = block_se(a_se, 2) > 0
    se = np.hypot(block_se(a_se, 2), block_se(b_se, 2))[varying]
    z = (blocks(a, 2) - blocks(b, 2))[varying] / se
    assert z.size > 100 and np.abs(z).max() < 5.0, np.abs(z).max()
    total = (a - b).sum() / np.sqrt((a_se ** 2 + b_se ** 2).sum())
    assert abs(total) < 5.0, total


def test_the_memory_check_counts_what_denoising_holds(monkeypatch):
    # With just the memory for the feature images, a render with them goes
    # ahead; denoised (the light seen estimated again, then the filter's
    # buffers: film.DENOISE_BYTES_PER_PIXEL), it is refused before anything
    # is allocated.
    pytest.importorskip("pyoidn", reason="the denoise extra is not installed")
    scene = rt.load_scene("cornell_box")
    size = 48
    features = films.render_bytes(size, size, False, True) + pack.scene_bytes(scene)
    denoising = films.render_bytes(size, size, False, True, True) + pack.scene_bytes(scene)
    assert denoising > features
    monkeypatch.setattr(memory, "available", lambda: (features / memory.SHARE, "MemAvailable"))
    assert rt.render(scene, width=size, height=size, spp=1, aov="emission").aov
    allocated = []
    monkeypatch.setattr(films, "new_film", lambda *a: allocated.append(a))
    with pytest.raises(rt.SceneError, match="needs about"):
        rt.render(scene, width=size, height=size, spp=1, denoise=True)
    assert allocated == []

