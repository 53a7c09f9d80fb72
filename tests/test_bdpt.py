"""Bidirectional path tracing (path/integrators/bdpt.py): MIS weights that sum
to one over the strategies that can make a path, the same image as an
independent renderer and as the path tracer on every kind of scene, and the
same bits for any thread count and pass split."""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.path.integrators import mis
from rtweekend.path.integrators.vertices import DELTA, FWD, NF, NI, REV
from rtweekend.path.renderer import Renderer
from splits import assert_same_bits_for_threads_and_splits
from stats import block_z


SMALL = dict(width=24, height=20, seed=3, sampling="bdpt")



@njit
def _weights(pc, pl, delta, s_max):
    """The weights of every strategy (s, t), s + t = n, of one path of n
    vertices x_0 (camera) .. x_n-1 (light): pc[i] is x_i's density drawn from
    x_i-1, pl[i] from x_i+1, as each strategy's subpaths would store them."""
    n = pc.shape[0]
    out = np.zeros(n + 1)
    for s in range(0, s_max + 1):
        t = n - s
        cf, ci = np.zeros((n, NF)), np.zeros((n, NI), dtype=np.int64)
        lf, li = np.zeros((n, NF)), np.zeros((n, NI), dtype=np.int64)
        for i in range(t):
            cf[i, FWD], cf[i, REV], ci[i, DELTA] = pc[i], pl[i], delta[i]
        for j in range(s):
            x = n - 1 - j
            lf[j, FWD], lf[j, REV], li[j, DELTA] = pl[x], pc[x], delta[x]
        pt_rev = pl[t - 1] if t >= 1 else 0.0
        ptm_rev = pl[t - 2] if t >= 2 else 0.0
        qs_fwd = pl[t] if s >= 1 else 0.0
        qs_rev = pc[t] if s >= 1 else 0.0
        qsm_rev = pc[t + 1] if s >= 2 else 0.0
        mis.accumulate(cf, ci, 1, t)        # as render_row does once per subpath
        mis.accumulate(lf, li, 0, s)
        out[s] = mis.weight(cf, ci, lf, li, s, t, pt_rev, ptm_rev, qs_fwd, qs_rev, qsm_rev)
    return out


@pytest.mark.parametrize("n", [3, 4, 7])
def test_the_weights_of_the_strategies_that_can_make_a_path_sum_to_one(n):
    rng = np.random.default_rng(n)
    for _ in range(20):
        pc, pl = rng.lognormal(0, 2, n), rng.lognormal(0, 2, n)
        w = _weights(pc, pl, np.zeros(n, dtype=np.int64), n - 1)
        assert w[:n].sum() == pytest.approx(1.0, rel=1e-12)
        assert np.all(w[:n] > 0)


def test_strategies_that_would_join_at_a_delta_vertex_get_no_weight_and_the_rest_sum_to_one():
    # x_2 is a mirror: no strategy may join at it, so (s, t) with t - 1 = 2 or
    # s - 1 = n - 1 - 2 is never evaluated; the others must share the whole
    # weight.  The densities drawn from it are 0, as the walks leave them.
    n = 6
    rng = np.random.default_rng(1)
    delta = np.zeros(n, dtype=np.int64)
    delta[2] = 1
    for _ in range(20):
        pc, pl = rng.lognormal(0, 2, n), rng.lognormal(0, 2, n)
        pc[3] = pl[1] = 0.0    # drawn from the mirror, either way
        w = _weights(pc, pl, delta, n - 1)
        possible = [s for s in range(n) if n - s - 1 != 2 and s - 1 != n - 1 - 2]
        assert sum(w[s] for s in possible) == pytest.approx(1.0, rel=1e-12)


def _alone(scene, s, t, spp, seed):
    """Strategy (s, t) alone, unweighted, with paths of at most s + t - 1 segments."""
    r = Renderer(scene, sampling="bdpt", seed=seed, max_depth=s + t - 1, width=40, height=40,
                 threads=2)
    r.frame = r.frame._replace(params=r.frame.params._replace(only_s=s, only_t=t))
    r.add_samples(spp)
    return r.result()


@pytest.mark.parametrize("segments", [2, 3])
def test_each_strategy_alone_renders_the_path_tracers_paths_of_its_length(segments):
    # pbrt's per-strategy images: on cornell_box (all lambertian, an area
    # light) every strategy (s, t) with s + t - 1 = k segments can draw every
    # such path, so each alone, unweighted, must render what the path tracer
    # adds from max_depth k - 1 to k.  That difference is taken with the same
    # seed (the directly seen light cancels to the bit), its standard error
    # from 16 such pairs.
    scene = rt.load_scene("cornell_box")
    pairs = []
    for seed in range(16):
        a, b = (rt.render(scene, spp=128, sampling="mixture", seed=40 + seed, max_depth=d,
                          width=40, height=40, threads=2) for d in (segments, segments - 1))
        pairs.append((a.image.astype(float) - b.image).mean())
    want, want_se = np.mean(pairs), np.std(pairs, ddof=1) / math.sqrt(len(pairs))
    for s in range(segments + 1):
        t = segments + 1 - s
        r = _alone(scene, s, t, 512, 7 + s)
        assert r.stats.nan_dropped == 0
        got = r.image.astype(float).mean()
        se = math.sqrt((r.stderr.astype(float) ** 2).sum()) / r.image.size
        z = (got - want) / math.hypot(se, want_se)
        assert abs(z) < 5, f"({s}, {t}): {got:.5f} vs {want:.5f}, z = {z:.2f}"
    assert want > 0.01


@pytest.mark.parametrize("sampling", ["bdpt", "bdpt+sobol"])
def test_a_caustic_seen_directly_is_as_quiet_as_light_tracing_makes_it(sampling):
    # The floor just in front of where the glass ball of `caustic` touches it:
    # its light comes through the ball (light, glass, glass, floor, camera),
    # which light tracing (t = 1) renders with little noise and the camera
    # subpath (s = 0) only by hitting the small light through the glass.  The
    # MIS weights must give it to light tracing.  Compared in area measure
    # across the glass (1 / distance^2 to the ball, a few units here), they
    # gave it to s = 0: 10x light tracing's standard error there (rows 86-88).
    scene = rt.load_scene("caustic")
    size = dict(width=100, height=100, threads=2, spp=64)
    area = (slice(86, 89), slice(44, 56))
    light = rt.render(scene, sampling="lightpath", seed=1, **size)
    both = rt.render(scene, sampling=sampling, seed=1, **size)
    assert light.image[area].mean() > 0.15         # the caustic is there (0.23)
    ratio = both.stderr[area].mean() / light.stderr[area].mean()
    assert ratio < 1.5, f"bdpt's standard error {ratio:.1f}x light tracing's"


def test_bdpt_renders_cornell_glass_as_mitsuba_does_mirror_glass_and_caustics_included(
        cornell_glass_reference):
    reference, ref_se = cornell_glass_reference
    # Blocks of 25 x 25 pixels: light through glass and off the mirror arrives
    # in rare large samples here (in every estimator), and the standard error
    # of a small block, from the spread of 8 batches of samples, is then
    # often too small (10 x 10 blocks: |z| up to 6 for some seeds; the mean of
    # 16 seeds met the reference within |z| 2.8).
    result = rt.render(rt.load_scene("cornell_glass"), spp=128, width=150, height=150,
                       sampling="bdpt+sobol", seed=2, threads=2)
    assert result.stats.nan_dropped == 0
    z = block_z(result.image, result.stderr, reference, ref_se, 25, quiet_equal=True)
    assert z.size > 100                 # 36 blocks x 3 channels, but the black ones
    assert np.abs(z).max() < 5, f"worst block z = {np.abs(z).max():.2f}"
    assert abs(z.mean()) < 4 / math.sqrt(z.size)


def test_bdpt_renders_smoke_as_mitsuba_does(cornell_smoke_reference):
    reference, ref_se = cornell_smoke_reference
    result = rt.render(rt.load_scene("cornell_smoke"), spp=64, width=150, height=150,
                       sampling="bdpt", seed=2, threads=2)
    z = block_z(result.image, result.stderr, reference, ref_se, 15, quiet_equal=True)
    assert np.abs(z).max() < 5, f"worst block z = {np.abs(z).max():.2f}"
    assert abs(z.mean()) < 4 / math.sqrt(z.size)


@pytest.mark.parametrize("name", ["simple_light", "next_week_final", "weekend"])
def test_bdpt_and_the_path_tracer_agree(name):
    # simple_light: textured surfaces, a sphere light and a rect light;
    # next_week_final: textures, media, motion blur, many lights' worth of
    # geometry; weekend: no emitter at all, the sky (bdpt is then the camera
    # subpath alone).  The path tracer is the default's estimator (mixture),
    # with which test_render.py and the benchmarks render these scenes too: its
    # kernels are compiled once for all (a cold compile is most of this test's
    # time).  At 160 spp its standard error is no larger than nee's at 128 was.
    scene = rt.load_scene(name)
    size = dict(width=40, height=32) if name != "next_week_final" else dict(width=32, height=32)
    a = rt.render(scene, spp=64, sampling="bdpt", seed=4, **size)
    b = rt.render(scene, spp=160, sampling="mixture", seed=5, **size)
    assert a.stats.nan_dropped == 0
    z = block_z(a.image, a.stderr, b.image, b.stderr, 4, quiet_equal=True)
    assert np.abs(z).max() < 5, f"worst block z = {np.abs(z).max():.2f}"
    assert abs(z.mean()) < 4 / math.sqrt(z.size)


def test_bdpt_is_the_same_bits_for_any_thread_count_and_pass_split():
    assert_same_bits_for_threads_and_splits(rt.load_scene("cornell_glass"), **SMALL)


def test_bdpt_feature_images_are_the_path_tracers():
    # The camera ray comes first from the same stream in both: where it meets a
    # smooth surface first (all of cornell_box) the features are the same bits.
    # Through glass the two draw their numbers in another order (bdpt's
    # roulette), so there they agree in the mean.
    box = rt.load_scene("cornell_box")
    a = rt.render(box, spp=4, aov=("albedo", "normal"), **SMALL)
    b = rt.render(box, spp=4, aov=("albedo", "normal"), **{**SMALL, "sampling": "mixture"})
    for name in ("albedo", "normal"):
        assert np.array_equal(a.aov[name], b.aov[name])
    assert a.aov["albedo"].max() > 0.5
    glass = rt.load_scene("cornell_glass")
    a = rt.render(glass, spp=64, aov=("albedo",), **SMALL)
    b = rt.render(glass, spp=64, aov=("albedo",), **{**SMALL, "sampling": "mixture"})
    assert not np.array_equal(a.aov["albedo"], b.aov["albedo"])
    assert a.aov["albedo"].mean() == pytest.approx(b.aov["albedo"].mean(), rel=0.01)
