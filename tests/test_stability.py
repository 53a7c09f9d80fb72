"""Where sampling methods break down: each failure mode, on purpose."""
import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rtweekend as rt
from rtweekend.path.materials.dielectric import scatter_at

from test_accuracy import assert_expected, furnace


# 1. Sphere-light pdf from inside or on the sphere (cornell_glass's glass ball
#    is in `lights`): the books' sqrt(1 - r^2/d^2) is NaN for d < r.

@pytest.mark.parametrize("sampling", ["light", "mixture", "nee"])
def test_shading_points_inside_a_sphere_light(sampling):
    # A lambertian ball inside a glass ball that is in `lights`: every shading
    # point is inside the light sphere.
    scene = furnace(rt.sphere((0, 0, 0), 0.5, rt.lambertian((0.6,) * 3)), vfov=10)
    glass = scene.add(rt.sphere((0, 0, 0), 1.0, rt.dielectric(1.5)), light=True)
    assert glass in scene.lights
    r = rt.render(scene, spp=32, sampling=sampling, seed=1)
    assert r.stats.nan_dropped == 0 and np.isfinite(r.image).all()
    assert_expected(r.image, r.stderr, 0.6, "lambertian inside a sphere light")


def test_light_sphere_touching_the_floor():
    # cornell_glass's ball touches the floor: shading points at d = r.
    scene = rt.load_scene("cornell_glass")
    r = rt.render(scene, spp=4, width=48, height=48, seed=2)
    assert r.stats.nan_dropped == 0


# 2. A mixture density of 0, and scattering below the surface.

@pytest.mark.parametrize("sampling", ["light", "mixture", "nee"])
def test_light_behind_the_surface_contributes_nothing(sampling):
    # The light is under the floor: every light sample goes below the surface.
    floor = rt.xz_rect(-5, 5, -5, 5, 0, rt.lambertian((0.5,) * 3))
    below = rt.xz_rect(-1, 1, -1, 1, -1, rt.diffuse_light((10,) * 3))
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 2, 2), lookat=(0, 0, 0), vfov=20,
                                      width=8, height=8), max_depth=3)
    scene.add(floor)
    scene.add(below, light=True)
    r = rt.render(scene, spp=16, sampling=sampling, seed=3)
    assert r.stats.nan_dropped == 0
    assert (r.image == 0).all()


# 3. Degenerate geometry is rejected when built (file or API).

@pytest.mark.parametrize("build, field", [
    (lambda m: rt.xy_rect(0, 0, 0, 1, 0, m), "x1"),
    (lambda m: rt.xz_rect(0, 1, 2, 2, 0, m), "z1"),
    (lambda m: rt.yz_rect(1, 0, 0, 1, 0, m), "y1"),
    (lambda m: rt.sphere((0, 0, 0), 0, m), "radius"),
    (lambda m: rt.box((1, 2, 3), (1, 2, 3), m), "p1"),
    (lambda m: rt.box((0, 0, 0), (1, 0, 1), m), "p1"),
])
def test_degenerate_geometry_is_rejected(build, field):
    with pytest.raises(rt.SceneError, match=rf": {field}: "):
        build(rt.lambertian((0.5, 0.5, 0.5)))


# 4. Self-intersection across scales: no epsilon to tune.

def _scaled(scene, s):
    def shape(o):
        g = o.geometry
        if o.kind == "sphere":
            g = (tuple(s * c for c in g[0]), s * g[1])
        elif o.kind == "box":
            g = tuple(tuple(s * c for c in p) for p in g)
        else:
            g = tuple(s * c for c in g)
        return dataclasses.replace(o, geometry=g, offset=tuple(s * c for c in o.offset))
    objects = [shape(o) for o in scene.objects]
    lights = [objects[scene.objects.index(light)] for light in scene.lights]
    cam = scene.camera
    camera = dataclasses.replace(cam, lookfrom=tuple(s * c for c in cam.lookfrom),
                                 lookat=tuple(s * c for c in cam.lookat),
                                 focus_dist=s * cam.focus_dist)
    return dataclasses.replace(scene, objects=objects, lights=lights, camera=camera)


def test_cornell_box_is_the_same_at_every_scale():
    scene = rt.load_scene("cornell_box")
    images = {s: rt.render(_scaled(scene, s), spp=16, width=40, height=40, seed=4)
              for s in (1e-3, 1.0, 1e3)}
    base = images[1.0]
    for s in (1e-3, 1e3):
        # Same seed, same decisions: equal up to rounding in the last bits,
        # far inside the noise (checked with the standard error all the same).
        diff = np.abs(images[s].image - base.image)
        assert (diff <= 4 * base.stderr + 1e-5).mean() > 0.999
        assert abs(images[s].image.mean() - base.image.mean()) < 1e-3 * base.image.mean()
        assert images[s].stats.nan_dropped == 0


def test_scales_down_to_the_bound_render_the_same_bits():
    # A power of two scales every length exactly: while no square underflows
    # (lengths >= 1e-100), the image is the same to the bit.  Below, the scene
    # is refused, naming the length.
    scene = rt.load_scene("cornell_box")
    base, _ = rt.render(scene, spp=4, width=24, height=24, seed=4)
    for s in (2.0**-330, 2.0**300):         # 5.7e-100 .. 2e90: all lengths in bounds
        image, stats = rt.render(_scaled(scene, s), spp=4, width=24, height=24, seed=4)
        assert np.array_equal(image, base), s
    with pytest.raises(rt.SceneError, match="too small|only .* from"):
        _scaled(scene, 1e-160)


# 5. Total internal reflection and grazing angles in the dielectric.

unit_vectors = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)).filter(
    lambda v: 1e-3 < math.hypot(*v))


@settings(max_examples=500)
@given(d=unit_vectors, ior=st.floats(1.0001, 4.0), front=st.booleans(),
       grazing=st.floats(0.0, 1e-6), u=st.floats(0.0, 1.0, exclude_max=True))
def test_dielectric_scatter_is_finite_and_unit(d, ior, front, grazing, u):
    n = (0.0, 0.0, 1.0)
    d = np.array(d) / np.linalg.norm(d)
    d[2] = -abs(d[2]) - grazing               # arriving against the normal
    d = tuple(d / np.linalg.norm(d))
    out = scatter_at(d, n, front, ior, u)
    assert all(math.isfinite(c) for c in out)
    assert math.isclose(math.hypot(*out), 1.0, rel_tol=1e-9)


# 6. Fireflies are counted, with their share of the energy; clamp is explicit.

def _direct_firefly_scene():
    """A wall of radiance 1 with a tiny patch of radiance 1e6 in front of it,
    both seen directly by the camera."""
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 5), lookat=(0, 0, 0), vfov=10,
                                      width=8, height=8), max_depth=1)
    scene.add(rt.xy_rect(-5, 5, -5, 5, 0, rt.diffuse_light((1, 1, 1))))
    scene.add(rt.xy_rect(0.01, 0.04, 0.01, 0.05, 0.1, rt.diffuse_light((1e6,) * 3)))
    return scene


def _firefly_scene():
    """The same wall and patch behind the camera, seen in a perfect mirror: camera
    samples whose reflection hits the patch are the fireflies, nothing else is."""
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 5), lookat=(0, 0, 0), vfov=10,
                                      width=8, height=8), max_depth=2)
    scene.add(rt.xy_rect(-5, 5, -5, 5, 0, rt.metal((1, 1, 1), 0.0)))
    scene.add(rt.xy_rect(-15, 15, -15, 15, 10, rt.diffuse_light((1, 1, 1))).flip_face())
    scene.add(rt.xy_rect(0.03, 0.12, 0.03, 0.15, 9.9,
                         rt.diffuse_light((1e6,) * 3)).flip_face())
    return scene


def test_lights_seen_directly_are_no_fireflies():
    r = rt.render(_direct_firefly_scene(), spp=200, seed=5)
    # The patch is in the image, its samples (1e6) above 100x the image's mean ...
    assert r.image.max() > 1000 and 1e6 > 100 * r.image.mean()
    # ... but what a camera ray sees emitted is no firefly.
    assert r.stats.fireflies == 0 and r.stats.firefly_energy == 0.0


def test_fireflies_are_counted_exactly():
    r = rt.render(_firefly_scene(), spp=200, seed=5)
    # Each pixel mean is (k * 1e6 + (spp - k) * 1) / spp: recover k per pixel.
    k = np.rint((r.image[..., 0].astype(np.float64) * 200 - 200) / (1e6 - 1))
    n = int(k.sum())
    assert 0 < n < 200 * 64
    assert r.stats.fireflies == n
    total = float(r.image.astype(np.float64).mean()) * 64 * 200
    assert r.stats.firefly_energy == pytest.approx(n * 1e6 / total, rel=1e-4)
    assert f"{n} fireflies" in r.stats.summary()


def test_clamp_is_explicit_and_biased():
    plain = rt.render(_firefly_scene(), spp=50, seed=6)
    clamped = rt.render(_firefly_scene(), spp=50, seed=6, clamp=10.0)
    assert clamped.image.max() <= 10.0 and clamped.stats.clamp == 10.0
    assert clamped.image.mean() < plain.image.mean()        # energy is lost
    assert "biased" in clamped.stats.summary() and "biased" not in plain.stats.summary()
    assert plain.stats.fireflies > 0 and clamped.stats.fireflies == 0


# 7. The camera: inside an object is legal; impossible set-ups are errors.

def test_camera_inside_a_glass_ball_sees_the_furnace():
    scene = furnace(rt.sphere((0, 0, 0), 1, rt.dielectric(1.5)))
    scene.camera = rt.Camera(lookfrom=(0, 0, 0.5), lookat=(0, 0, 0), vfov=90,
                             width=12, height=12)
    r = rt.render(scene, spp=32, seed=7)
    assert_expected(r.image, r.stderr, 1.0, "camera inside glass")


@pytest.mark.parametrize("kwargs, message", [
    (dict(lookfrom=(1, 2, 3), lookat=(1, 2, 3)), "lookat: equals lookfrom"),
    (dict(lookfrom=(0, 0, 0), lookat=(0, 5, 0)), "vup: .* parallel"),
    (dict(vfov=0), "vfov: must be > 0"),
    (dict(vfov=180), "vfov: must be < 180"),
    (dict(vfov=-5), "vfov"),
    (dict(width=0), "width: must be >= 1"),
    (dict(focus_dist=0), "focus_dist: must not be 0"),
    (dict(focus_dist=-1), "focus_dist: must be >= 0"),
    (dict(lookfrom=(0, 0, 3e-170), lookat=(0, 0, 0)),
     "lookat: is only 3e-170 from lookfrom: the renderer squares distances"),
])
def test_impossible_cameras_are_errors(kwargs, message):
    with pytest.raises(rt.SceneError, match=f"camera: {message}"):
        rt.Camera(**kwargs)


@pytest.mark.parametrize("vfov", [1e-4, 179.9])
def test_extreme_legal_fields_of_view_render(vfov):
    scene = rt.load_scene("metals")
    scene.camera = dataclasses.replace(scene.camera, vfov=vfov, width=8, height=8)
    r = rt.render(scene, spp=2, seed=8)
    assert r.stats.nan_dropped == 0 and np.isfinite(r.image).all()


@pytest.mark.parametrize("sampling", [None, "bdpt"])
@pytest.mark.parametrize("name", sorted(rt.bundled_scenes()))
def test_bundled_scenes_drop_no_samples(name, sampling):
    scene = rt.load_scene(name)
    classic = scene.resolved_integrator() == "classic"
    if classic and sampling:
        pytest.skip("the classic ray tracer does not sample")
    budget = {} if classic else dict(spp=4, seed=9, sampling=sampling)
    r = rt.render(scene, width=40, height=24, **budget)
    assert r.stats.nan_dropped == 0 and np.isfinite(r.image).all()
