"""A mesh in the lights list: the books' mixture draws a point uniformly over
its whole surface, and its density sums every triangle a direction meets."""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.path import mesh_light
from rtweekend.path.lights import listed
from rtweekend.path.pack import pack_scene

from rays import light_densities, light_directions, uniform_directions
from stats import assert_chi2
from test_meshes import GREY, _lambert_polygon

# An octahedron about (0, 2, 0), stretched so that its faces differ in area,
# faces turning counter-clockwise seen from outside.
OCTA_V = np.array([[0.9, 2.0, 0.0], [-0.5, 2.0, 0.0], [0.0, 2.7, 0.0], [0.0, 1.6, 0.0],
                   [0.0, 2.0, 0.6], [0.0, 2.0, -0.4]])
OCTA_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                   [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def _octahedron_scene(light=True):
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0.1, 1.0, 0.2), lookat=(0.1, 0, 0.2),
                                      vup=(0, 0, 1), vfov=0.01, width=1, height=1))
    scene.add(rt.xz_rect(-50, 50, -50, 50, 0, GREY))
    scene.add(rt.mesh((OCTA_V, OCTA_F), rt.diffuse_light((4, 4, 4))), light=light)
    return scene


def test_the_octahedron_faces_outward():
    n = np.cross(OCTA_V[OCTA_F[:, 1]] - OCTA_V[OCTA_F[:, 0]],
                 OCTA_V[OCTA_F[:, 2]] - OCTA_V[OCTA_F[:, 0]])
    assert (((OCTA_V[OCTA_F].mean(axis=1) - [0, 2, 0]) * n).sum(axis=1) > 0).all()


@njit
def _picks(cdf, start, count, u):
    out = np.empty(u.shape[0], dtype=np.int64)
    for i in range(u.shape[0]):
        out[i] = mesh_light.pick(cdf, start, count, u[i])
    return out


def test_a_mesh_lights_triangles_are_picked_by_area():
    a = pack_scene(_octahedron_scene())
    ((first, count, start),) = a.tris.groups
    assert listed(a).tolist() == [first] and count == 8
    area = a.obj_f[first:first + count, 12]
    assert a.tris.group_area[0] == pytest.approx(area.sum())
    u = np.random.default_rng(2).random(400_000)
    observed = np.bincount(_picks(a.tris.group_cdf, start, count, u), minlength=count)
    assert_chi2(observed, len(u) * area / area.sum())
    # The ends: u = 0 takes the first triangle, u just below 1 the last.
    assert _picks(a.tris.group_cdf, start, count, np.array([0.0, 1 - 1e-16])).tolist() == \
        [0, count - 1]


def test_a_mesh_lights_density_integrates_to_one_and_matches_its_samples():
    # From a point outside the closed octahedron most directions that meet it
    # meet it twice (near side and far side): the density counts both.
    a = pack_scene(_octahedron_scene())
    k = int(listed(a)[0])
    p = (0.3, 0.2, -0.4)
    v = light_densities(a, k, p, uniform_directions(400_000, 7)) * 4 * math.pi
    assert abs(v.mean() - 1.0) < 5 * v.std() / math.sqrt(len(v)), v.mean()
    # Its samples: E[h(d) / density(d)] is the integral of h over directions
    # that meet the mesh -- here h = 1 + d.x, against the same integral by
    # uniform directions.  A density that counted only the nearest face would
    # be half of the true one almost everywhere and give twice the integral.
    dirs = light_directions(a, k, p, 200_000, 11)
    dens = light_densities(a, k, p, dirs)
    assert (dens > 0).all()
    g = (1.0 + dirs[:, 0]) / dens
    uni = uniform_directions(400_000, 5)
    meets = light_densities(a, k, p, uni) > 0
    h = np.where(meets, 1.0 + uni[:, 0], 0.0) * 4 * math.pi
    diff = g.mean() - h.mean()
    se = math.hypot(g.std() / math.sqrt(len(g)), h.std() / math.sqrt(len(h)))
    assert abs(diff) < 5 * se, (g.mean(), h.mean(), se)


@pytest.mark.parametrize("sampling", ["mixture+sobol", "light"])
def test_a_mesh_in_the_lights_list_gives_lambert_polygon_irradiance(sampling):
    # A floor point under the emitting octahedron (radiance 4, one-sided,
    # outward): each face turned towards it is seen whole (a convex body), so
    # its irradiance is Lambert's formula summed over those faces.  "light"
    # draws only from the lights list: the density alone.
    x = np.array([0.1, 0.0, 0.2])
    expected = 0.0
    for f in OCTA_F:
        tri = OCTA_V[f]
        n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
        if n @ (x - tri[0]) > 0:
            expected += 0.5 / math.pi * 4 * _lambert_polygon(x, np.array([0, 1.0, 0]), tri)
    r = rt.render(_octahedron_scene(), spp=8192, seed=5, sampling=sampling)
    got, se = float(r.image[0, 0, 0]), float(r.stderr[0, 0, 0])
    assert abs(got - expected) < 5 * se + 1e-9, (got, expected, se)
    assert se < 0.02 * expected


def test_the_density_walks_the_hierarchy_as_the_flat_loop_does():
    # A bumpy (non-convex) ball of 1,520 triangles beside a floor and a sphere:
    # with a hierarchy, the density's all-hits walk (wide_bvh.solid_angle_sum)
    # must sum the same triangles as the loop over every object does without
    # one (the order of the sum may differ: its last bits), and integrate to 1.
    from test_meshes import sphere_mesh
    v, f = sphere_mesh(20, 40, radius=1.0, center=(0, 2, 0))
    v = v + np.random.default_rng(1).normal(scale=0.05, size=v.shape)
    scene = rt.Scene()
    scene.add(rt.xz_rect(-50, 50, -50, 50, 0, GREY))
    scene.add(rt.sphere((3, 1, 0), 1.0, GREY))
    scene.add(rt.mesh((v, f), rt.diffuse_light((4, 4, 4))), light=True)
    tree, flat = pack_scene(scene, bvh=True), pack_scene(scene, bvh=False)
    assert tree.wide is not None and flat.wide is None
    k = int(listed(tree)[0])
    assert k == int(listed(flat)[0])
    dirs = uniform_directions(200_000, 7)
    for p in [(0.1, 0.2, -0.4), (0.0, 2.0, 0.0), (2.5, 2.5, 2.5)]:
        a, b = light_densities(tree, k, p, dirs), light_densities(flat, k, p, dirs)
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=0)
        assert (a > 0).mean() > 0.01
        v4 = a * 4 * math.pi
        assert abs(v4.mean() - 1.0) < 5 * v4.std() / math.sqrt(len(v4)), (p, v4.mean())
