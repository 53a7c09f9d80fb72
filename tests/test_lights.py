"""The light layer (path/lights.py): one table -- a row per emissive primitive (a
box's six faces), picked by power, then the books' lights list, picked
uniformly -- one picker for both, and points drawn uniformly over each
emitting row's area."""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.kernel import rng
from rtweekend.kernel.vec3 import dot
from rtweekend.path import lights, shapes
from rtweekend.path.layout import (EMITTED, LIGHT_AREA, LIGHT_CDF, LIGHT_PART, LIGHT_POWER,
                                   LIGHT_PROB, LISTED)
from rtweekend.path.pack import pack_scene

from stats import assert_chi2

GLOW = rt.diffuse_light((4.0, 4.0, 4.0))
DIM = rt.diffuse_light((0.5, 0.2, 0.1))
GREY = rt.lambertian((0.5, 0.5, 0.5))
N_POINTS = 120_000


def _arrays(*objects):
    scene = rt.Scene()
    for o in objects:
        scene.add(o)
    return pack_scene(scene)


LIGHTS = {
    "xz rect": lambda: rt.xz_rect(-1, 2, -0.5, 1, 3, GLOW),
    "turned yz rect": lambda: rt.yz_rect(0, 1, 0, 2, 0.5, GLOW).rotate_y(35),
    "quad": lambda: rt.quad((0, 0, 0), (2, 0.5, 0), (0, 0, 1.5), GLOW),
    "flipped xy rect": lambda: rt.xy_rect(0, 1, 0, 1, 2, GLOW).flip_face(),
    "sphere": lambda: rt.sphere((0.5, 1, -2), 0.7, GLOW),
    "hollow sphere": lambda: rt.sphere((0, 0, 0), -1.3, GLOW),
    "box": lambda: rt.box((0, 0, 0), (1, 2, 3), GLOW).rotate_y(20).translate((1, 0, -1)),
}


def test_one_row_per_primitive_and_six_for_a_box():
    a = _arrays(rt.xz_rect(-1, 1, -1, 1, 2, GLOW), rt.sphere((0, 0, 0), 1, GREY),
                rt.box((0, 0, 0), (1, 2, 3), GLOW))
    assert [tuple(r) for r in a.light_rows] == \
        [(0, -1, EMITTED)] + [(2, f, EMITTED) for f in range(6)]
    assert a.light_ranges.tolist() == [[0, 7], [7, 7]]      # no lights list
    np.testing.assert_allclose(a.light_f[1:, LIGHT_AREA], [6, 6, 3, 3, 2, 2])
    np.testing.assert_allclose(a.light_f[:, LIGHT_AREA].sum(), 4 + 22)
    assert a.light_pick[1] == 0.0                     # the grey sphere emits nothing
    np.testing.assert_allclose(a.light_pick[[0, 2]], [4 / 26, 22 / 26])


def test_rows_are_picked_by_power():
    a = _arrays(rt.xz_rect(0, 1, 0, 1, 2, GLOW), rt.sphere((0, 5, 0), 0.5, DIM))
    luminance = [4.0, 0.2126 * 0.5 + 0.7152 * 0.2 + 0.0722 * 0.1]
    power = np.array([math.pi * luminance[0] * 1.0, math.pi * luminance[1] * math.pi])
    np.testing.assert_allclose(a.light_f[:, LIGHT_POWER], power)
    np.testing.assert_allclose(a.light_f[:, LIGHT_PROB], power / power.sum())
    assert a.light_f[-1, LIGHT_CDF] == 1.0
    # pick: the share of a fine uniform grid of u that lands on each row is its
    # probability, to the grid's resolution.
    u = (np.arange(100_000) + 0.5) / 100_000
    rows = np.array([lights.pick(a, EMITTED, x) for x in u[::97]])
    counts = np.bincount(_picks(a, u), minlength=2) / len(u)
    np.testing.assert_allclose(counts, a.light_f[:, LIGHT_PROB], atol=2e-5)
    assert set(rows) == {0, 1}


def test_black_emitters_are_picked_by_area():
    black = rt.diffuse_light((0.0, 0.0, 0.0))
    a = _arrays(rt.xz_rect(0, 1, 0, 3, 2, black), rt.xz_rect(0, 1, 0, 1, 4, black))
    np.testing.assert_allclose(a.light_f[:, LIGHT_PROB], [0.75, 0.25])


@njit
def _picks(a, u):
    out = np.empty(len(u), dtype=np.int64)
    for i in range(len(u)):
        out[i] = lights.pick(a, EMITTED, u[i])
    return out


def _listed_scene(n_attractors):
    """An emitting rect and a grey ball, both in the lights list, then
    n_attractors glass balls in it too, and an emitting sphere not in it."""
    scene = rt.Scene()
    scene.add(rt.xz_rect(-1, 1, -1, 1, 2, GLOW), light=True)
    scene.add(rt.sphere((0, 0, 0), 0.5, GREY), light=True)
    for i in range(n_attractors):
        scene.add(rt.sphere((2 + i, 0, 0), 0.3, rt.dielectric(1.5)), light=True)
    scene.add(rt.sphere((0, 5, 0), 0.5, DIM))
    return pack_scene(scene)


def test_the_lights_list_follows_the_emitters_in_one_table():
    a = _listed_scene(2)
    e = 2                                   # the rect and the dim sphere emit
    assert a.light_ranges.tolist() == [[0, e], [e, e + 4]]
    assert [tuple(r) for r in a.light_rows] == [
        (0, -1, EMITTED), (4, -1, EMITTED),
        (0, -1, LISTED), (1, -1, LISTED), (2, -1, LISTED), (3, -1, LISTED)]
    assert lights.listed(a).tolist() == [0, 1, 2, 3]
    assert lights.emitters(a).tolist() == [0, 4]
    np.testing.assert_allclose(a.light_f[e:, LIGHT_PROB], 0.25)
    assert a.light_f[e:, LIGHT_CDF].tolist() == [0.25, 0.5, 0.75, 1.0]
    # the emitters' distribution is their own: the list changes nothing of it
    alone = _arrays(rt.xz_rect(-1, 1, -1, 1, 2, GLOW), rt.sphere((0, 5, 0), 0.5, DIM))
    np.testing.assert_array_equal(a.light_f[:e], alone.light_f)
    assert a.light_pick[[0, 4]].tolist() == alone.light_pick.tolist()
    # next events leave the emitters out of the list: the attractors stay, sorted
    from rtweekend.path.integrators.needs import emitters_left_out
    b = emitters_left_out(a)
    assert lights.listed(b).tolist() == [1, 2, 3]
    assert b.light_ranges.tolist() == [[0, e], [e, e + 3]]
    np.testing.assert_array_equal(b.light_f[:e], a.light_f[:e])


@njit
def _listed_picks(a, u):
    out = np.empty((len(u), 2))
    for i in range(len(u)):
        row = lights.pick(a, LISTED, u[i])
        out[i, 0], out[i, 1] = row, lights.stretched(a, LISTED, row, u[i])
    return out


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
def test_the_listed_pick_is_the_books_uniform_pick(n):
    """pick over the list's rows is the books' int(u n), and u stretched within
    the entry is u n - j, bit for bit (the mixture's draws keep their bits),
    at the entries' boundaries too."""
    a = _listed_scene(n - 2) if n >= 2 else lights.relisted(_listed_scene(0), [1])
    first = a.light_ranges[LISTED, 0]
    u = np.random.default_rng(n).random(200_000)
    edges = np.arange(n + 1) / n
    u = np.concatenate([u, edges[:-1], np.nextafter(edges[1:], 0)])
    got = _listed_picks(a, u)
    j = np.minimum((u * n).astype(np.int64), n - 1)
    np.testing.assert_array_equal(got[:, 0] - first, j)
    np.testing.assert_array_equal(got[:, 1], np.minimum(u * n - j, 1.0))
    # the table says the same: each entry 1 / n of the picks
    np.testing.assert_allclose(np.bincount(j, minlength=n)[:n] / len(u),
                               a.light_f[first:, LIGHT_PROB], atol=0.01)
    assert (got[:, 1] >= 0).all() and (got[:, 1] <= 1).all()


@njit
def _points(a, row, count, seed):
    """count points of row `row`: (points, normals, densities, outward normals
    the shape gives at each point, objects)."""
    state = rng.seed_state(row, 0, seed)
    pts, nrm, out = np.empty((count, 3)), np.empty((count, 3)), np.empty((count, 3))
    pdf = np.empty(count)
    for i in range(count):
        u1, state = rng.uniform(state)
        u2, state = rng.uniform(state)
        k, p, n, d = lights.sample_point(a, row, u1, u2, None)
        o = shapes.outward_normal(a, k, p, None)
        for c in range(3):
            pts[i, c], nrm[i, c], out[i, c] = p[c], n[c], o[c]
        pdf[i] = d
    return pts, nrm, pdf, out


# Each light's area in closed form (the table's AREA, which the kernels' densities
# divide by, comes from the kind's light_parts alone).
AREAS = {"xz rect": 3 * 1.5, "turned yz rect": 2.0,
         "quad": float(np.linalg.norm(np.cross((2, 0.5, 0), (0, 0, 1.5)))),
         "flipped xy rect": 1.0, "sphere": 4 * math.pi * 0.49,
         "hollow sphere": 4 * math.pi * 1.69, "box": 2 * (2 + 3 + 6)}


@pytest.mark.parametrize("name", LIGHTS)
def test_the_tables_area_is_the_lights_area(name):
    a = _arrays(LIGHTS[name]())
    assert math.isclose(a.light_f[:, LIGHT_AREA].sum(), AREAS[name], rel_tol=1e-12)


@pytest.mark.parametrize("name", LIGHTS)
def test_points_lie_on_the_light_with_its_outward_normal(name):
    a = _arrays(LIGHTS[name]())
    total = 0.0
    for row in range(len(a.light_rows)):
        pts, nrm, pdf, outward = _points(a, row, 2000, row)
        area = a.light_f[row, LIGHT_AREA]
        np.testing.assert_allclose(pdf, 1.0 / area, rtol=1e-12)
        np.testing.assert_allclose(nrm, outward, atol=1e-9)
        np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, rtol=1e-12)
        # On the surface: a ray from just outside, back along the normal, meets
        # the object at that small distance.
        for p, n in zip(pts[:50], nrm[:50]):
            eps = 1e-6
            o = tuple(p + eps * n)
            t = shapes.distance(a, 0, o, tuple(-n), np.inf, -1, False, None)
            assert abs(t - eps) < 1e-9
        total += area
    assert math.isclose(total, a.light_f[:, LIGHT_AREA].sum())


def _uniform_chi2(coords, bins):
    """Chi-square of 2-D coordinates in [0, 1)^2 against the uniform density."""
    h, _, _ = np.histogram2d(coords[:, 0], coords[:, 1], bins=bins, range=[[0, 1], [0, 1]])
    assert_chi2(h.ravel(), np.full(bins * bins, len(coords) / bins ** 2))


@pytest.mark.parametrize("name", ["xz rect", "turned yz rect", "quad", "flipped xy rect"])
def test_points_are_uniform_over_a_rect(name):
    a = _arrays(LIGHTS[name]())
    pts, _, _, _ = _points(a, 0, N_POINTS, 3)
    uv = np.array([shapes.uv(a, 0, tuple(p), None) for p in pts])
    _uniform_chi2(uv, 20)


@pytest.mark.parametrize("name", ["sphere", "hollow sphere"])
def test_points_are_uniform_over_a_sphere(name):
    a = _arrays(LIGHTS[name]())
    pts, _, _, _ = _points(a, 0, N_POINTS, 4)
    c = a.obj_f[0, :3]
    d = (pts - c) / np.linalg.norm(pts - c, axis=1)[:, None]
    # (z + 1) / 2 and phi / 2 pi are uniform for directions uniform on the sphere
    coords = np.column_stack([(d[:, 2] + 1) / 2,
                              np.mod(np.arctan2(d[:, 1], d[:, 0]), 2 * math.pi) / (2 * math.pi)])
    _uniform_chi2(np.clip(coords, 0, 1 - 1e-15), 20)


def test_a_box_lights_six_faces_are_all_picked_and_sampled_uniformly():
    a = _arrays(LIGHTS["box"]())
    u = np.random.default_rng(2).random(N_POINTS)
    rows = _picks(a, u)
    assert_chi2(np.bincount(rows, minlength=6), N_POINTS * a.light_f[:, LIGHT_PROB])
    for row in range(6):
        assert a.light_rows[row, LIGHT_PART] == row
        pts, _, _, _ = _points(a, row, 20_000, 10 + row)
        uv = np.array([shapes.uv(a, 0, tuple(p), None) for p in pts])
        _uniform_chi2(np.clip(uv, 0, 1 - 1e-15), 10)


@njit
def _solid_angle_pair(a, row, p, count, seed):
    """For points drawn on row `row` seen from p: the density area_to_solid_angle
    gives their directions, and the shape's own pdf_toward (area sampling for
    rects: the same density)."""
    state = rng.seed_state(row, 0, seed)
    out = np.empty((count, 2))
    for i in range(count):
        u1, state = rng.uniform(state)
        u2, state = rng.uniform(state)
        k, q, n, pdf = lights.sample_point(a, row, u1, u2, None)
        d = (q[0] - p[0], q[1] - p[1], q[2] - p[2])
        inv = 1.0 / math.sqrt(dot(d, d))
        d = (d[0] * inv, d[1] * inv, d[2] * inv)
        out[i, 0] = lights.area_to_solid_angle(pdf, p, q, n)
        out[i, 1] = shapes.pdf_toward(a, k, p, d, -1, False, None)
    return out


@pytest.mark.parametrize("name", ["xz rect", "turned yz rect", "quad"])
def test_the_solid_angle_density_of_an_area_sample_is_the_rects_pdf_toward(name):
    a = _arrays(LIGHTS[name]())
    out = _solid_angle_pair(a, 0, (0.3, -1.0, 0.2), 500, 5)
    np.testing.assert_allclose(out[:, 0], out[:, 1], rtol=1e-9)


@njit
def _from_its_surface(a, k, count, seed):
    """Directions sample_toward draws towards sphere k from points of its own
    surface, and the density pdf_toward gives each leaving from it."""
    state = rng.seed_state(k, 1, seed)
    c, r = (a.obj_f[k, 0], a.obj_f[k, 1], a.obj_f[k, 2]), abs(a.obj_f[k, 3])
    out = np.empty((count, 5))
    for i in range(count):
        n, state = rng.unit_vector(state)
        p = (c[0] + r * n[0], c[1] + r * n[1], c[2] + r * n[2])
        u1, state = rng.uniform(state)
        u2, state = rng.uniform(state)
        d = shapes.sample_toward(a, k, p, k, u1, u2, None)
        inside = shapes.enters(a, k, n, d)
        out[i, 0] = shapes.pdf_toward(a, k, p, d, k, inside, None)
        out[i, 1] = -dot(d, n)                          # cosine with the inward normal
        out[i, 2], out[i, 3], out[i, 4] = d
    return out


def test_a_sphere_seen_from_its_own_surface_is_the_inward_hemisphere():
    # An attractor that scatters (a frosted glass ball in the lights list) is
    # sampled from points of itself: every direction drawn goes in, uniform
    # over the hemisphere (cosine uniform in (0, 1)), and pdf_toward leaving
    # from it gives that density, 1 / 2 pi -- else the books' mixture weighs
    # its draws wrongly.
    a = _arrays(rt.sphere((0.3, -0.2, 1.0), 90.0, GREY))
    out = _from_its_surface(a, 0, 40_000, 3)
    assert (out[:, 1] > 0).all()
    np.testing.assert_allclose(out[:, 0], 1 / (2 * math.pi), rtol=1e-12)
    assert_chi2(np.bincount((out[:, 1] * 20).astype(int), minlength=20), np.full(20, 2000.0))
