"""Next-event estimation with MIS (path/nee.py): the weights of one direction sum
to one, shadow rays are blocked by what is in between, and the estimator is
deterministic; so are the strategies fed Sobol points.  (Their closed-form
radiance values are in test_accuracy.py and their failure modes in
test_stability.py, with every other strategy.)"""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.kernel import rng
from rtweekend.options import RenderOptions
from rtweekend.path import materials, nee
from rtweekend.path.layout import NO_HIT, OBJ_MAT, XZ_RECT
from rtweekend.path.renderer import freeze
from rtweekend.path.lights import emitters, listed
from rtweekend.path.shapes import axis_rect
from rtweekend.path.surface import NO_PRIM, Surface


@njit
def _weights(scene, k, points, n, light_weight, seed):
    """For shadow rays from each point on object k (normal n): the MIS weight the
    shadow ray carries (from its returned value) and the one the integrator would
    give the continuation reaching the same emitter along the same direction."""
    out = np.full((points.shape[0], 2), np.nan)
    state = rng.seed_state(0, 0, seed)
    m = scene.obj_i[k, OBJ_MAT]
    albedo = materials.color(scene, m)
    wo = n                                  # the path came from above
    for i in range(points.shape[0]):
        p = (points[i, 0], points[i, 1], points[i, 2])
        hit = Surface(p, n, n, True, np.int64(k), np.int64(NO_PRIM), m, albedo, (0.0, 0.0))
        bsdf = materials.at(scene, hit)
        u, state = rng.uniform(state)
        u1, state = rng.uniform(state)
        u2, state = rng.uniform(state)
        e, w, inside, t, c = nee.shadow_ray(scene, p, n, k, bsdf, wo, light_weight,
                                            (1.0, 1.0, 1.0), (u, u1, u2), None, None)
        if e == NO_HIT:
            continue
        cosine = n[0] * w[0] + n[1] * w[1] + n[2] * w[2]
        p_e = nee.emitter_pdf(scene, e, p, w, k, inside, None)
        radiance = scene.mat_f[scene.obj_i[e, OBJ_MAT], 0]
        out[i, 0] = c[0] / (albedo[0] * radiance * cosine / math.pi / p_e)
        p_c = nee.continuation_pdf(scene, bsdf, wo, p, light_weight, w, k, inside, None)
        out[i, 1] = nee.power_heuristic(p_c, nee.emitter_pdf(scene, e, p, w, k, inside, None))
    return out


@pytest.mark.parametrize("name", ["cornell_box", "cornell_glass"])
def test_mis_weights_of_one_direction_sum_to_one(name):
    frame = freeze(rt.load_scene(name), RenderOptions("path", sampling="nee"))
    books = freeze(rt.load_scene(name), RenderOptions("path", sampling="mixture"))
    # The books' lights list keeps the light; nee's keeps only what does not emit.
    assert books.features.events is None
    assert list(listed(books.scene)) == sorted([*listed(frame.scene), *emitters(frame.scene)])
    scene, params = frame.scene, frame.params
    assert frame.features.events == 1 and len(emitters(scene)) == 1
    # The light is no target of the mixture any more; cornell_glass keeps its ball.
    assert len(listed(scene)) == (1 if name == "cornell_glass" else 0)
    assert params.light_weight == (0.5 if name == "cornell_glass" else 0.0)
    floor = [k for k in range(len(scene.obj_i)) if scene.obj_i[k, 0] == XZ_RECT
             and scene.obj_f[k, axis_rect.K] == 0.0][0]      # the xz rect at y = 0
    rng_ = np.random.default_rng(3)
    points = np.column_stack([rng_.uniform(20, 530, 400), np.zeros(400),
                              rng_.uniform(20, 530, 400)])
    w = _weights(scene, floor, points, (0.0, 1.0, 0.0), params.light_weight, 11)
    aimed = ~np.isnan(w[:, 0])
    assert aimed.sum() > 300                  # most floor points see the light
    assert np.all((w[aimed] > 0.0) & (w[aimed] < 1.0))
    np.testing.assert_allclose(w[aimed].sum(axis=1), 1.0, rtol=0, atol=1e-12)


def test_power_heuristic():
    a, b = np.meshgrid(np.geomspace(1e-6, 1e6, 25), np.geomspace(1e-6, 1e6, 25))
    wa = np.vectorize(nee.power_heuristic)(a, b)
    wb = np.vectorize(nee.power_heuristic)(b, a)
    np.testing.assert_allclose(wa + wb, 1.0, rtol=0, atol=1e-15)
    assert nee.power_heuristic(3.0, 1.0) == 0.9


def _blocked_scene(blocker):
    """A floor lit by a light above it, with a black plate between them or not;
    the camera looks at the floor from under the plate."""
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0.5, -3), lookat=(0, 0, 0), vfov=8,
                                      width=8, height=8), max_depth=3)
    scene.add(rt.xz_rect(-5, 5, -5, 5, 0, rt.lambertian((0.5, 0.5, 0.5))))
    scene.add(rt.xz_rect(-1, 1, -1, 1, 2, rt.diffuse_light((4, 4, 4))).flip_face(),
              light=True)
    if blocker:
        scene.add(rt.xz_rect(-4, 4, -4, 4, 1, rt.lambertian((0, 0, 0))))
    return scene


def test_shadow_rays_stop_at_what_is_in_between():
    lit = rt.render(_blocked_scene(False), spp=16, sampling="nee", seed=1)
    dark = rt.render(_blocked_scene(True), spp=16, sampling="nee", seed=1)
    assert lit.image.min() > 0.0
    # The plate hides the light from every floor point the camera sees, and
    # reflects nothing: not one shadow ray, nor any path, gets light through.
    assert np.array_equal(dark.image, np.zeros_like(dark.image))


@pytest.mark.parametrize("sampling", ["nee", "mixture+sobol", "nee+sobol"])
def test_renders_are_the_same_for_any_thread_count_and_pass_split(sampling):
    scene = rt.load_scene("cornell_glass")
    a = rt.render(scene, spp=4, seed=3, width=32, height=24, sampling=sampling, threads=1)
    b = rt.render(scene, spp=4, seed=3, width=32, height=24, sampling=sampling, threads=2)
    r = rt.Renderer(scene, seed=3, width=32, height=24, sampling=sampling)
    for n in (1, 2, 1):
        r.add_samples(n)
    c = r.result()
    assert np.array_equal(a.image, b.image) and np.array_equal(a.image, c.image)
    assert a.stats.rays == b.stats.rays == c.stats.rays


def test_the_books_mixture_traces_no_shadow_rays():
    scene = rt.load_scene("cornell_box")
    books = rt.render(scene, spp=2, seed=1, width=24, height=24, sampling="mixture")
    nee_ = rt.render(scene, spp=2, seed=1, width=24, height=24, sampling="nee")
    # Russian roulette ends nee's paths early, shadow rays add rays: they differ.
    assert books.stats.rays != nee_.stats.rays
    assert not np.array_equal(books.image, nee_.image)


def test_sobol_points_change_the_image_not_its_expectation():
    # The same estimator fed stratified points: another image, and (measured
    # against the books' own, 64 spp each) no sign of a different mean.
    scene = rt.load_scene("cornell_box")
    books = rt.render(scene, spp=64, seed=4, width=40, height=40, sampling="mixture")
    qmc = rt.render(scene, spp=64, seed=4, width=40, height=40, sampling="mixture+sobol")
    assert not np.array_equal(books.image, qmc.image)
    diff = books.image.astype(float).mean() - qmc.image.astype(float).mean()
    se = np.sqrt((books.stderr.astype(float) ** 2).sum()
                 + (qmc.stderr.astype(float) ** 2).sum()) / books.image.size
    assert abs(diff) < 4 * se


def _bright_and_dim_scene():
    """A floor under a large bright ceiling light and a tiny dim sphere light."""
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 4, -6), lookat=(0, 0, 0), vfov=40,
                                      width=12, height=12), max_depth=2)
    scene.add(rt.xz_rect(-3, 3, -3, 3, 0, rt.lambertian((0.6, 0.6, 0.6))))
    scene.add(rt.xz_rect(-1, 1, -1, 1, 3, rt.diffuse_light((8, 8, 8))).flip_face(),
              light=True)
    scene.add(rt.sphere((2, 1, 1), 0.05, rt.diffuse_light((0.5, 0.5, 0.5))), light=True)
    return scene


def test_next_events_pick_emitters_by_power_with_less_variance_and_the_same_mean():
    from rtweekend.path.layout import LIGHT_CDF, LIGHT_PROB
    scene = _bright_and_dim_scene()
    by_power = rt.Renderer(scene, seed=5, sampling="nee")
    a = by_power.frame.scene
    prob = a.light_f[:, LIGHT_PROB]
    assert prob[0] > 0.999 and a.light_pick[a.light_rows[0, 0]] == prob[0]
    # The same render with the emitters picked uniformly (as next events did
    # before): the arrays say how often each is picked, the kernel follows them.
    uniform = rt.Renderer(scene, seed=5, sampling="nee")
    f = uniform.frame
    light_f = a.light_f.copy()
    light_f[:, LIGHT_PROB], light_f[:, LIGHT_CDF] = 0.5, [0.5, 1.0]
    pick = np.where(a.light_pick > 0, 0.5, 0.0)
    uniform.frame = f._replace(scene=f.scene._replace(light_f=light_f, light_pick=pick))
    for r in (by_power, uniform):
        r.add_samples(256)
    p, u = by_power.result(), uniform.result()
    var_p, var_u = (np.mean(x.stderr.astype(float) ** 2) for x in (p, u))
    assert var_p < 0.7 * var_u
    se = np.sqrt(p.stderr.astype(float) ** 2 + u.stderr ** 2)
    seen = se > 0                    # the rest sees the black sky: 0 in both
    assert seen.mean() > 0.5 and (p.image[~seen] == u.image[~seen]).all()
    z = (p.image.astype(float) - u.image)[seen] / se[seen]
    assert abs(z.mean()) < 4 / math.sqrt(z.size) and z.std() < 1.3
