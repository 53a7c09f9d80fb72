"""The camera's way back (path/camera.py): a world point to its raster
position, the importance W_e normalised over the film, the density of camera
ray directions, and points of the lens seen from the scene."""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.kernel import rng
from rtweekend.path import camera
from rtweekend.path.camera import (FORWARD, LENS, LENS_AREA, LENS_U, LENS_V, ORIGIN,
                                   get_ray_at, pack_camera)

from stats import assert_chi2

CAMERAS = {
    "pinhole": rt.Camera(lookfrom=(278, 278, -800), lookat=(278, 278, 0), vfov=40,
                         width=40, height=30),
    "thin lens": rt.Camera(lookfrom=(13, 2, 3), lookat=(0, 0, 0), vfov=20, aperture=0.6,
                           focus_dist=10.0, width=32, height=18),
    "wide and tilted": rt.Camera(lookfrom=(1, 5, -2), lookat=(0, 0, 1), vup=(0.3, 1, 0),
                                 vfov=100, aperture=0.2, width=24, height=40),
}


def _cam(name):
    c = CAMERAS[name]               # validated (focus_dist filled in) when made
    return pack_camera(c), c.width, c.height


@njit
def _round_trip(cam, w, h, n, seed):
    """(x + jx, y + jy) of n camera rays, and the raster position of a point
    along each, seen from the ray's own lens point."""
    out = np.empty((n, 5))
    state = rng.seed_state(0, 0, seed)
    for i in range(n):
        u, state = rng.uniform(state)
        x = int(u * w)
        u, state = rng.uniform(state)
        y = int(u * h)
        jx, state = rng.uniform(state)
        jy, state = rng.uniform(state)
        o, d, state = get_ray_at(cam, x, y, w, h, jx, jy, state)
        t, state = rng.uniform(state)
        p = (o[0] + (0.1 + 50 * t) * d[0], o[1] + (0.1 + 50 * t) * d[1],
             o[2] + (0.1 + 50 * t) * d[2])
        rx, ry, on = camera.raster(cam, w, h, o, p)
        out[i] = x + jx, y + jy, rx, ry, 1.0 if on else 0.0
    return out


@pytest.mark.parametrize("name", CAMERAS)
def test_a_point_on_a_camera_ray_projects_back_to_where_the_ray_left_the_film(name):
    cam, w, h = _cam(name)
    out = _round_trip(cam, w, h, 5000, 3)
    np.testing.assert_allclose(out[:, 2:4], out[:, :2], rtol=0, atol=1e-7 * max(w, h))
    assert out[:, 4].all()
    # behind the camera: not on the film
    o = tuple(cam[ORIGIN:ORIGIN + 3])
    behind = tuple(np.asarray(o) - 3 * cam[FORWARD:FORWARD + 3])
    assert not camera.raster(cam, w, h, o, behind)[2]


@njit
def _film_integrals(cam, w, h, n, seed):
    """Monte Carlo, directions uniform over the sphere and lens points uniform
    over the lens: the integral of W_e cos theta over the lens and the film's
    directions (1), and of the direction density over the film's directions
    from the lens's centre (1)."""
    state = rng.seed_state(1, 0, seed)
    f = (cam[FORWARD], cam[FORWARD + 1], cam[FORWARD + 2])
    total_w, total_p, sq_w, sq_p = 0.0, 0.0, 0.0, 0.0
    scale = 4.0 * math.pi
    for i in range(n):
        d, state = rng.unit_vector(state)
        disk, state = rng.in_unit_disk(state)
        o = (cam[ORIGIN], cam[ORIGIN + 1], cam[ORIGIN + 2])
        a, b = cam[LENS] * disk[0], cam[LENS] * disk[1]
        lens = (o[0] + a * cam[LENS_U] + b * cam[LENS_V], o[1] + a * cam[LENS_U + 1]
                + b * cam[LENS_V + 1], o[2] + a * cam[LENS_U + 2] + b * cam[LENS_V + 2])
        c = d[0] * f[0] + d[1] * f[1] + d[2] * f[2]
        if camera.raster(cam, w, h, lens, (lens[0] + d[0], lens[1] + d[1], lens[2] + d[2]))[2]:
            x = camera.importance(cam, d) * c * scale * cam[LENS_AREA]
            total_w += x
            sq_w += x * x
        if camera.raster(cam, w, h, o, (o[0] + d[0], o[1] + d[1], o[2] + d[2]))[2]:
            x = camera.pdf_direction(cam, d) * scale
            total_p += x
            sq_p += x * x
    mw, mp = total_w / n, total_p / n
    return mw, math.sqrt((sq_w / n - mw * mw) / n), mp, math.sqrt((sq_p / n - mp * mp) / n)


@pytest.mark.parametrize("name", CAMERAS)
def test_importance_and_direction_density_integrate_to_one_over_the_film(name):
    cam, w, h = _cam(name)
    n = 4_000_000
    iw, se_w, ip, se_p = _film_integrals(cam, w, h, n, 5)
    assert abs(iw - 1.0) < 5 * se_w and abs(ip - 1.0) < 5 * se_p, (iw, se_w, ip, se_p)
    assert se_w < 0.02 and se_p < 0.02


@njit
def _lens_samples(cam, w, h, p, n, seed):
    state = rng.seed_state(2, 0, seed)
    out = np.empty((n, 8))
    for i in range(n):
        u1, state = rng.uniform(state)
        u2, state = rng.uniform(state)
        wi, dist, pdf, we, x, y, on = camera.sample_lens(cam, w, h, p, u1, u2)
        q = (p[0] + dist * wi[0], p[1] + dist * wi[1], p[2] + dist * wi[2])
        out[i] = q[0], q[1], q[2], pdf, we, x, y, 1.0 if on else 0.0
    return out


@pytest.mark.parametrize("name", ["thin lens", "wide and tilted"])
def test_lens_points_seen_from_the_scene_are_uniform_over_the_lens(name):
    cam, w, h = _cam(name)
    o, f = cam[ORIGIN:ORIGIN + 3], cam[FORWARD:FORWARD + 3]
    p = tuple(o + 7.0 * f + 0.2 * cam[LENS_U:LENS_U + 3])     # near the image's centre
    s = _lens_samples(cam, w, h, p, 100_000, 4)
    rel = s[:, :3] - o
    assert np.abs(rel @ f).max() < 1e-9                          # on the lens's plane
    a, b = rel @ cam[LENS_U:LENS_U + 3], rel @ cam[LENS_V:LENS_V + 3]
    r2 = (a * a + b * b) / cam[LENS] ** 2
    assert r2.max() <= 1 + 1e-9
    phi = np.mod(np.arctan2(b, a), 2 * math.pi) / (2 * math.pi)
    h2, _, _ = np.histogram2d(np.minimum(r2, 1 - 1e-15), phi, bins=16, range=[[0, 1], [0, 1]])
    assert_chi2(h2.ravel(), np.full(256, len(s) / 256))
    # density at p: distance^2 / (cos a); W_e and the raster position agree with
    # the forward functions
    d = np.asarray(p) - s[:, :3]
    dist = np.linalg.norm(d, axis=1)
    cos = (d / dist[:, None]) @ f
    on = s[:, 7] > 0
    assert on.mean() > 0.99
    np.testing.assert_allclose(s[on, 3], dist[on] ** 2 / (cos[on] * cam[LENS_AREA]),
                               rtol=1e-9)
    we = 1 / (cam[camera.FILM_AREA] * cam[LENS_AREA] * cos[on] ** 4)
    np.testing.assert_allclose(s[on, 4], we, rtol=1e-9)


def test_a_pinhole_is_seen_at_its_one_point():
    cam, w, h = _cam("pinhole")
    p = (300.0, 250.0, 100.0)
    s = _lens_samples(cam, w, h, p, 10, 1)
    np.testing.assert_allclose(s[:, :3], np.broadcast_to(cam[ORIGIN:ORIGIN + 3], (10, 3)),
                               atol=1e-9)
    x, y, on = camera.raster(cam, w, h, tuple(cam[ORIGIN:ORIGIN + 3]), p)
    assert on and np.allclose(s[:, 5:7], (x, y))
