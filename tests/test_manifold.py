"""The specular chains of path/manifold.py: solved paths obey Snell's law, the
solid angle per area through a chain matches a finite difference of whole
solves, and a lamp inside a glass ball lights a point outside as a brute-force
trace through the glass says (the estimator's three factors together)."""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.path import manifold
from rtweekend.path.layout import NO_HIT
from rtweekend.path.lights import emitters
from rtweekend.path.pack import pack_scene

from stats import block_z

IOR = 1.5
GLASS = rt.dielectric(IOR)
LAMP = rt.diffuse_light((1.0, 1.0, 1.0))
WORK = manifold.workspace()


@njit
def _chain(a, x0, y, light, work):
    """(count, converged, vertices, objects) of the chain from x0 to y."""
    verts = np.zeros((manifold.MAX_CHAIN, 3))
    objs = np.zeros(manifold.MAX_CHAIN, dtype=np.int64)
    count, ok = manifold.seed_chain(a, x0, np.int64(NO_HIT), y, light, None, verts, objs)
    if ok:
        ok = manifold.solve(a, x0, y, verts, objs, count, None, work)
    return count, ok, verts, objs


@njit
def _measure(a, x0, y, n_y, verts, objs, count, work):
    return (manifold.solid_angle_per_area(a, x0, y, n_y, verts, objs, count, None, work),
            manifold.transmittance(a, x0, y, verts, objs, count, None),
            manifold.first_direction(x0, y, verts, count))


def _snell(a, x0, y, verts, objs, count):
    """For each vertex: (eta_a sin_a - eta_b sin_b, how far the neighbours and
    the normal are from one plane)."""
    out = []
    path = [np.asarray(x0)] + [verts[i] for i in range(count)] + [np.asarray(y)]
    for i in range(count):
        p = path[i + 1]
        k = int(objs[i])
        c, r = a.obj_f[k, :3], a.obj_f[k, 3]
        n = (p - c) / r
        wa = path[i] - p
        wa /= np.linalg.norm(wa)
        wb = path[i + 2] - p
        wb /= np.linalg.norm(wb)
        eta_a = 1.0 if wa @ n > 0 else IOR
        eta_b = 1.0 if wb @ n > 0 else IOR
        sin_a = np.linalg.norm(np.cross(wa, n))
        sin_b = np.linalg.norm(np.cross(wb, n))
        out.append((eta_a * sin_a - eta_b * sin_b, np.linalg.det(np.array([wa, wb, n]))))
    return np.array(out)


def _scene(*shapes):
    """The packed scene, and the index of its one emitter."""
    scene = rt.Scene()
    for s in shapes:
        scene.add(s)
    a = pack_scene(scene)
    return a, np.int64(emitters(a)[0])


def test_into_a_ball_and_through_one():
    # One crossing: a point outside a glass ball, a point inside it.
    a, light = _scene(rt.sphere((0, 0, 0), 1.0, GLASS), rt.sphere((0.2, 0.3, -0.1), 0.05, LAMP))
    x0, y = (3.0, 1.0, 0.5), (0.2, 0.3, -0.05)
    count, ok, verts, objs = _chain(a, x0, y, light, WORK)
    assert ok and count == 1
    np.testing.assert_allclose(_snell(a, x0, y, verts, objs, count), 0.0, atol=1e-9)
    # Two crossings: in and out of the ball, x0 and y on either side.
    a, light = _scene(rt.sphere((0, 0, 0), 1.0, GLASS), rt.sphere((-4, -0.5, 0.3), 0.1, LAMP))
    x0, y = (3.0, 0.6, -0.4), (-3.9, -0.5, 0.3)
    count, ok, verts, objs = _chain(a, x0, y, light, WORK)
    assert ok and count == 2
    np.testing.assert_allclose(_snell(a, x0, y, verts, objs, count), 0.0, atol=1e-9)
    # The seed's crossings were moved: the solved path is not the straight line.
    assert np.linalg.norm(np.cross(verts[0] - x0, np.asarray(y) - x0)) > 1e-3


def test_nothing_in_between_is_the_geometry_term():
    a, light = _scene(rt.sphere((5, 0, 0), 1.0, GLASS), rt.sphere((0, 2, 0), 0.5, LAMP))
    x0, y, n_y = (0.0, 0.0, 0.0), (0.3, 1.6, 0.1), np.array([0.3, -0.4, 0.1]) / 0.5
    count, ok, verts, objs = _chain(a, x0, y, light, WORK)
    assert ok and count == 0
    j, t, w0 = _measure(a, x0, y, tuple(n_y), verts, objs, count, WORK)
    d = np.asarray(y) - x0
    assert j == pytest.approx(abs(d @ n_y) / np.linalg.norm(d) ** 3, rel=1e-12)
    assert t == 1.0
    np.testing.assert_allclose(w0, d / np.linalg.norm(d), rtol=1e-12)


@pytest.mark.parametrize("y", [(0.2, 0.3, -0.05), (-3.9, -0.5, 0.3)], ids=["one", "two"])
def test_the_solid_angle_per_area_is_that_of_whole_solves(y):
    # Move y along two tangents of its surface, solve again from scratch each
    # time, and measure the solid angle w0 sweeps: a different computation of
    # the same derivative (whole solves, not the implicit function theorem).
    lamp = (0.2, 0.3, -0.1) if y[0] > -1 else (-4, -0.5, 0.3)
    a, light = _scene(rt.sphere((0, 0, 0), 1.0, GLASS), rt.sphere(lamp, 0.05 if y[0] > -1 else 0.1,
                                                            LAMP))
    x0 = (3.0, 1.0, 0.5) if y[0] > -1 else (3.0, 0.6, -0.4)
    n_y = np.asarray(y) - lamp
    n_y /= np.linalg.norm(n_y)
    count, ok, verts, objs = _chain(a, x0, y, light, WORK)
    assert ok
    j, t, w0 = _measure(a, x0, y, tuple(n_y), verts, objs, count, WORK)
    assert 0.0 < t < 1.0
    e1 = np.cross(n_y, [1.0, 0.0, 0.0] if abs(n_y[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n_y, e1)
    h = 1e-5
    turns = []
    for e in (e1, e2):
        ws = []
        for s in (h, -h):
            c2, ok2, v2, o2 = _chain(a, x0, tuple(np.asarray(y) + s * e), light, WORK)
            assert ok2 and c2 == count
            ws.append(np.asarray(_measure(a, x0, y, tuple(n_y), v2, o2, c2, WORK)[2]))
        turns.append((ws[0] - ws[1]) / (2 * h))
    # The area of the parallelogram the two turns span (both are across w0).
    assert j == pytest.approx(np.linalg.norm(np.cross(turns[0], turns[1])), rel=1e-4)


def _schlick(cos, ratio):
    r0 = ((1 - ratio) / (1 + ratio)) ** 2
    return r0 + (1 - r0) * (1 - cos) ** 5


def _brute_force(x0, n0, centre, radius, lamp, rho, count, seed):
    """Irradiance at x0 (normal n0) from a lamp of radiance 1 and radius rho
    inside a glass ball, by cosine-sampled directions refracted into the
    ball (Snell's law and the books' 1 - schlick, written here in NumPy):
    pi x the mean of what each brings.  (mean, standard error)"""
    rng = np.random.default_rng(seed)
    u1, u2 = rng.random(count), rng.random(count)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    local = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)], 1)
    t1 = np.cross(n0, [0.0, 1.0, 0.0] if abs(n0[1]) < 0.9 else [1.0, 0.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n0, t1)
    d = local[:, :1] * t1 + local[:, 1:2] * t2 + local[:, 2:] * n0
    oc = x0 - centre
    b = d @ oc
    disc = b * b - (oc @ oc - radius * radius)
    hit = disc > 0
    t = -b - np.sqrt(np.where(hit, disc, 0))
    hit &= t > 0
    p = x0 + t[:, None] * d
    n = (p - centre) / radius
    cos_i = -(d * n).sum(1)
    eta = 1 / IOR
    k = 1 - eta * eta * (1 - cos_i ** 2)
    refr = eta * d + (eta * cos_i - np.sqrt(np.maximum(k, 0)))[:, None] * n
    trans = 1 - _schlick(cos_i, eta)
    pc = p - lamp
    b2 = (refr * pc).sum(1)
    disc2 = b2 * b2 - ((pc * pc).sum(1) - rho * rho)
    reaches = hit & (disc2 > 0) & (-b2 - np.sqrt(np.maximum(disc2, 0)) > 0)
    value = np.pi * np.where(reaches, trans, 0.0)
    return value.mean(), value.std() / math.sqrt(count)


@njit
def _mnee(a, light, x0, n0, lamp, rho, count, seed, work):
    """The same irradiance by chains to points drawn uniformly on the lamp."""
    np.random.seed(seed)
    out = np.zeros(count)
    area = 4 * np.pi * rho * rho
    for i in range(count):
        z = 1 - 2 * np.random.random()
        phi = 2 * np.pi * np.random.random()
        s = math.sqrt(max(0.0, 1 - z * z))
        n_y = (s * math.cos(phi), s * math.sin(phi), z)
        y = (lamp[0] + rho * n_y[0], lamp[1] + rho * n_y[1], lamp[2] + rho * n_y[2])
        verts = np.zeros((manifold.MAX_CHAIN, 3))
        objs = np.zeros(manifold.MAX_CHAIN, dtype=np.int64)
        c, ok = manifold.seed_chain(a, x0, np.int64(NO_HIT), y, light, None, verts, objs)
        if not ok or c == 0 or not manifold.solve(a, x0, y, verts, objs, c, None, work):
            continue
        last = (verts[c - 1, 0], verts[c - 1, 1], verts[c - 1, 2])
        towards = (y[0] - last[0], y[1] - last[1], y[2] - last[2])
        if towards[0] * n_y[0] + towards[1] * n_y[1] + towards[2] * n_y[2] >= 0:
            continue                     # the lamp's back: hidden by the lamp itself
        j = manifold.solid_angle_per_area(a, x0, y, n_y, verts, objs, c, None, work)
        t = manifold.transmittance(a, x0, y, verts, objs, c, None)
        w0 = manifold.first_direction(x0, y, verts, c)
        cos0 = w0[0] * n0[0] + w0[1] * n0[1] + w0[2] * n0[2]
        if cos0 > 0:
            out[i] = t * j * cos0 * area
    return out


def test_a_lamp_inside_a_glass_ball_lights_a_point_as_the_glass_bends_it():
    centre, radius, lamp, rho = np.zeros(3), 1.0, np.array([0.25, 0.15, -0.1]), 0.2
    a, light = _scene(rt.sphere(tuple(centre), radius, GLASS), rt.sphere(tuple(lamp), rho, LAMP))
    x0 = np.array([2.5, 0.8, 0.6])
    n0 = -x0 / np.linalg.norm(x0)
    want, want_se = _brute_force(x0, n0, centre, radius, lamp, rho, 4_000_000, 1)
    got = _mnee(a, light, tuple(x0), tuple(n0), tuple(lamp), rho, 80_000, 2, WORK)
    se = math.hypot(want_se, got.std() / math.sqrt(len(got)))
    assert abs(got.mean() - want) < 4 * se, (got.mean(), want, se)
    # Not an agreement of two zeros: the lamp lights x0 through the glass.
    assert want > 20 * want_se


def _lamp_in_a_ball(x0, width=1, height=1, vfov=0.01, max_depth=2):
    """A lambertian floor (albedo 0.5), and above it a lamp (radiance 4)
    inside a glass ball: a camera looking at the floor point x0."""
    scene = rt.Scene(camera=rt.Camera(lookfrom=(x0[0] + 0.3, 0.4, x0[2] - 0.3),
                                      lookat=tuple(x0), vfov=vfov, width=width, height=height),
                     max_depth=max_depth)
    scene.add(rt.xz_rect(-50, 50, -50, 50, 0, rt.lambertian((0.5,) * 3)))
    scene.add(rt.sphere((0.3, 1.6, 0.2), 0.6, GLASS))
    scene.add(rt.sphere((0.35, 1.5, 0.15), 0.15, rt.diffuse_light((4.0,) * 3)), light=True)
    return scene


def test_the_mnee_strategy_renders_what_the_glass_lets_through():
    # One bounce (max_depth 2): the floor point's light can come only through
    # the glass, which blocks every shadow ray -- next-event estimation sees
    # nothing -- and which the connections cross: albedo / pi x the
    # irradiance the brute-force trace through the glass finds.
    x0 = np.array([0.1, 0.0, 0.0])
    scene = _lamp_in_a_ball(x0)
    want, want_se = _brute_force(x0, np.array([0.0, 1.0, 0.0]), np.array([0.3, 1.6, 0.2]), 0.6,
                                 np.array([0.35, 1.5, 0.15]), 0.15, 4_000_000, 3)
    want, want_se = 0.5 / math.pi * 4.0 * want, 0.5 / math.pi * 4.0 * want_se
    r = rt.render(scene, spp=20_000, sampling="mnee", seed=4)
    got, got_se = float(r.image[0, 0, 0]), float(r.stderr[0, 0, 0])
    assert abs(got - want) < 4 * math.hypot(got_se, want_se), (got, want, got_se, want_se)
    assert want > 20 * want_se
    assert rt.render(scene, spp=64, sampling="nee+sobol", seed=4).image.max() == 0.0


def test_the_connections_and_the_camera_paths_share_the_light_once():
    # Every bounce: the connections render a smooth vertex's light through
    # 1 .. MAX_CHAIN refractions, the camera paths all the rest (and leave
    # those out).  Against the books' mixture, which finds the lamp only by
    # refracting onto it: the same image within the noise, block by block.
    scene = _lamp_in_a_ball(np.zeros(3), width=12, height=12, vfov=60.0, max_depth=8)
    a = rt.render(scene, spp=256, sampling="mnee", seed=5)
    b = rt.render(scene, spp=4096, sampling="mixture", seed=6)
    z = block_z(a.image, a.stderr, b.image, b.stderr, 4)
    assert np.all(np.abs(z) < 4.5), z
    whole = (a.image.mean() - b.image.mean()) / math.hypot(
        np.sqrt((a.stderr.astype(float) ** 2).sum()) / a.stderr.size,
        np.sqrt((b.stderr.astype(float) ** 2).sum()) / b.stderr.size)
    assert abs(whole) < 4, whole
    # The same bits whatever the thread count.
    one = rt.render(scene, spp=16, sampling="mnee", seed=5, threads=1).image
    two = rt.render(scene, spp=16, sampling="mnee", seed=5, threads=2).image
    assert np.array_equal(one, two)


def test_through_a_ball_lens_the_camera_paths_keep_what_the_walk_misses():
    # Light above a glass ball focuses on the floor: two crossings, and near
    # the caustic more than one path from a floor point to a point of the
    # light -- the walk from the straight segment finds one.  The camera's
    # paths keep every path the walk would not give (mnee.renders):
    # the same image as the books' mixture, block by block.
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0.0, 2.5, -2.0), lookat=(0.0, 0.0, 0.0),
                                      vfov=50.0, width=12, height=12), max_depth=6)
    scene.add(rt.xz_rect(-50, 50, -50, 50, 0, rt.lambertian((0.5,) * 3)))
    scene.add(rt.sphere((0.0, 0.9, 0.0), 0.5, GLASS))
    scene.add(rt.xz_rect(-1.0, 1.0, -1.0, 1.0, 3.0, rt.diffuse_light((3.0,) * 3)).flip_face(),
              light=True)
    a = rt.render(scene, spp=512, sampling="mnee", seed=7)
    b = rt.render(scene, spp=4096, sampling="mixture", seed=8)
    z = block_z(a.image, a.stderr, b.image, b.stderr, 4)
    assert np.all(np.abs(z) < 4.5), z


def _seen_through_a_pane(max_depth=8):
    """_lamp_in_a_ball with a glass pane between the camera and the floor: the
    floor is seen only through glass, where bdpt cannot join the camera."""
    scene = _lamp_in_a_ball(np.zeros(3), width=12, height=12, vfov=60.0, max_depth=max_depth)
    scene.add(rt.box((-0.6, 0.05, -0.6), (1.0, 0.15, 0.4), GLASS))
    return scene


def test_bdpt_joins_the_connections_where_the_camera_sees_through_glass():
    # bdpt+mnee: at the first smooth vertex the camera sees through the pane,
    # a connection through the ball to the lamp; the camera subpath's own
    # hits on the lamp through 1 .. MAX_CHAIN refractions from there are left
    # out (through_glass.covered), every other path is bdpt's.  Against the
    # books' mixture, block by block: counting those paths twice or not at
    # all moves the floor's blocks by many standard errors.
    scene = _seen_through_a_pane()
    a = rt.render(scene, spp=256, sampling="bdpt+mnee", seed=5)
    b = rt.render(scene, spp=4096, sampling="mixture", seed=6)
    z = block_z(a.image, a.stderr, b.image, b.stderr, 4)
    assert np.all(np.abs(z) < 4.5), z
    # The connections carry the floor's light there: far less noise than
    # bdpt's camera paths finding the lamp by chance, at the same samples.
    c = rt.render(scene, spp=256, sampling="bdpt+sobol", seed=5)
    assert a.stderr.mean() < 0.5 * c.stderr.mean(), (a.stderr.mean(), c.stderr.mean())


def test_bdpt_with_connections_is_the_same_bits_for_any_thread_count_and_pass_split():
    from splits import assert_same_bits_for_threads_and_splits
    assert_same_bits_for_threads_and_splits(rt.load_scene("glass_lamp"), width=24, height=20,
                                            seed=3, sampling="bdpt+mnee")


@pytest.mark.parametrize("name,why", [("cornell_box", "no smooth glass to connect through"),
                                      ("cornell_smoke", "no manifold connections with media")])
def test_bdpt_mnee_renders_a_scene_without_glass_as_bdpt_sobol(name, why):
    scene = rt.load_scene(name)
    if name == "cornell_smoke":              # glass, and media
        scene.add(rt.sphere((190, 90, 190), 90, GLASS))
    size = dict(width=20, height=16, spp=8, seed=2, progress=False)
    a = rt.render(scene, sampling="bdpt+mnee", **size)
    b = rt.render(scene, sampling="bdpt+sobol", **size)
    assert np.array_equal(a.image, b.image)
    assert (a.stats.sampling, a.stats.sampling_note) == ("bdpt+sobol", why)


@pytest.mark.parametrize("sampling", ["mnee", "bdpt+mnee"])
def test_the_summary_counts_the_connections_and_their_rays(sampling):
    # Each connection tried (a chain of glass to solve) is counted, and those
    # dropped unsolved (no convergence, total internal reflection) among them;
    # the rays a connection traces (its seed's searches, the solved path's
    # visibility) count in the rays/s figure.
    scene = rt.load_scene("glass_lamp")
    size = dict(width=24, height=20, spp=16, seed=3, progress=False)
    stats = rt.render(scene, sampling=sampling, **size).stats
    assert 0 < stats.connections and 0 <= stats.unsolved < stats.connections
    assert f"{stats.unsolved} of {stats.connections} connections through glass" in \
        stats.summary()
    other = {"mnee": "nee+sobol", "bdpt+mnee": "bdpt+sobol"}[sampling]
    without = rt.render(scene, sampling=other, **size).stats
    assert without.connections == 0 and "connections" not in without.summary()
    # At least the seed's two searches (to the globe, then to the lamp) per
    # connection tried, beside paths much like the other strategy's.
    assert stats.rays >= 0.8 * without.rays + 2 * stats.connections
