"""The glossy materials (path/materials/rough_conductor.py, rough_dielectric.py)
in renders: against an independent renderer, and compiled only into the
kernels of a scene that has one."""
import os
import subprocess
import sys

import numpy as np
import pytest
from conftest import DATA, REPO
from stats import block_z

import rtweekend as rt
from numba import njit
from rtweekend.kernel import sampler
from rtweekend.path import materials
from rtweekend.path.bvh import closest_hit
from rtweekend.path.integrators.path import smooth_bounce
from rtweekend.path.layout import NO_HIT
from rtweekend.path.pack import pack_scene
from rtweekend.path.surface import surface_at

# The Cornell room with a rough gold box (alpha 0.25) and a rough steel ball
# (alpha 0.06), and Mitsuba 3's render of it (roughconductor, GGX, material
# "none": tests/data/reference/README.md).
ROUGH_BOX = DATA / "rough_box.toml"


# bdpt+sobol: camera and light subpaths bounce off the glossy surfaces, join
# there both ways and connect to the camera.  (Every sampling matched Mitsuba
# on this scene at 100x100 when the material was added; each one's kernel for
# a glossy scene is a compile of its own, so the suite checks one.)
@pytest.mark.parametrize("sampling", ["bdpt+sobol"])
def test_a_rough_conductor_renders_as_mitsuba_does(sampling):
    with np.load(DATA / "reference" / "rough_box_40.npz") as f:
        reference, ref_se = f["radiance"], f["stderr"]
    result = rt.render(rt.load_scene(ROUGH_BOX), width=40, height=40, spp=512,
                       sampling=sampling, seed=5, threads=2)
    assert result.stats.nan_dropped == 0
    z = block_z(result.image, result.stderr, reference, ref_se, 10)
    assert z.size == 48
    assert np.mean(np.abs(z) < 3) >= 0.95 and np.abs(z).max() < 5, np.round(z, 1)


# The bundled cornell_rough: a rough gold box (alpha 0.2) and a frosted glass
# ball (ior 1.5, alpha 0.12), against Mitsuba 3's roughconductor and
# roughdielectric (tests/data/reference/README.md).  bdpt+sobol: light
# subpaths refract through the rough glass (the adjoint's eta^2, the reverse
# densities from the other side) and join the camera's at either side.
def test_a_frosted_glass_ball_renders_as_mitsuba_does():
    with np.load(DATA / "reference" / "cornell_rough_40.npz") as f:
        reference, ref_se = f["radiance"], f["stderr"]
    result = rt.render(rt.load_scene("cornell_rough"), width=40, height=40, spp=512,
                       sampling="bdpt+sobol", seed=5, threads=2)
    assert result.stats.nan_dropped == 0
    z = block_z(result.image, result.stderr, reference, ref_se, 10)
    assert z.size == 48
    assert np.mean(np.abs(z) < 3) >= 0.95 and np.abs(z).max() < 5, np.round(z, 1)


# In a process of its own, with an empty cache (a step loaded from the cache
# compiles none of its callees): a lambertian's record from a scene without
# glossy materials (glossy None) through eval, pdf and sample_at.
UNGLOSSY = """
import numpy as np
from rtweekend.kernel import sampler
from rtweekend.path import materials
from rtweekend.path.materials import Bsdf, rough_conductor
n = (0.0, 0.0, 1.0)
for glossy in (None, True):
    bsdf = Bsdf(np.int64(materials.LAMBERTIAN), (0.5, 0.5, 0.5), (0.0, 0.0), n, True, n, glossy)
    assert materials.eval(bsdf, n, n, 1.0)[1] > 0 and materials.pdf(bsdf, n, n) > 0
    assert materials.sample_at(bsdf, n, 0.3, 0.6, sampler.start(0, 0, 1, 0))[2] > 0
    print(sum(len(step.signatures) for step in
              (rough_conductor.eval, rough_conductor.pdf, rough_conductor.sample)))
"""


def test_a_scene_without_a_glossy_material_compiles_none_of_their_code(tmp_path):
    assert pack_scene(rt.load_scene("cornell_box")).glossy is None
    assert pack_scene(rt.load_scene(ROUGH_BOX)).glossy is True
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), RTWEEKEND_COMPILE_HELPERS="0")
    run = subprocess.run([sys.executable, "-c", UNGLOSSY], env=env, capture_output=True,
                         text=True, timeout=300, cwd=REPO)
    assert run.returncode == 0, run.stderr[-2000:]
    # None: the glossy kinds' code was pruned before typing; True: compiled.
    assert run.stdout.split() == ["0", "3"]


@njit
def _bounce_energies(scene, params, events, o, d, count):
    """The energy each of count continuations from the hit of ray (o, d)
    carries (weight, times eta^2 where it went through): what it multiplies
    the path's throughput by, in energy."""
    k, t = closest_hit(scene, o, d, np.inf, np.int64(NO_HIT), np.bool_(False), None)
    hit = surface_at(scene, None, k, o, d, t, None)
    bsdf = materials.at(scene, hit)
    out = np.empty(count)
    for i in range(count):
        smp = sampler.start(i, 0, 7, 0)
        _, w, _, weight, _, ok, _ = smooth_bounce(scene, params, hit, bsdf, (-d[0], -d[1], -d[2]),
                                                  (1.0, 1.0, 1.0), True, events, None, None, smp)
        through = w[0] * hit.n[0] + w[1] * hit.n[1] + w[2] * hit.n[2] < 0.0
        eta = materials.rough_dielectric.relative_ior(bsdf)
        out[i] = weight[0] * (eta * eta if through else 1.0) if ok else 0.0
    return out


@pytest.mark.parametrize("sampling", ["nee+sobol", "mixture"])
@pytest.mark.parametrize("inside", [False, True])
def test_a_bounce_off_frosted_glass_makes_no_energy(sampling, inside):
    # The ball is in the lights list (the books' attractor): mixing its share
    # into a glossy lobe's draws would weigh each by up to 2 G1, and a path
    # reflected inside the ball grew without bound (a sample of 25,000 on
    # cornell_rough).  A glossy hit draws from its own lobe.
    frame = rt.Renderer(rt.load_scene("cornell_rough"), width=8, height=8,
                        sampling=sampling).frame
    centre = np.array([190.0, 90.0, 190.0])
    if inside:
        o, d = centre, np.array([0.3, -0.5, 0.81])
    else:
        o = np.array([278.0, 278.0, -800.0])
        d = centre - o
    d = tuple(d / np.linalg.norm(d))
    energy = _bounce_energies(frame.scene, frame.params, frame.features.events, tuple(o), d,
                              20_000)
    assert energy.max() <= 1.0 + 1e-9 and energy.mean() > 0.5
