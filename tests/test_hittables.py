"""Intersections of every primitive and placement: t, hit point, normal, face."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rtweekend as rt
from rtweekend.path import shapes
from rtweekend.path.bvh import INF, closest_hit
from rtweekend.path.surface import face_normal
from rtweekend.path.layout import NO_HIT
from rtweekend.path.pack import pack_scene

from rays import nearest_hits

MAT = rt.lambertian((0.5, 0.5, 0.5))


@pytest.fixture(params=[False, True], ids=["linear", "bvh"])
def bvh(request):
    """Every intersection test runs with and without the hierarchy."""
    return request.param


def arrays(*shapes, bvh=False):
    scene = rt.Scene()
    for s in shapes:
        scene.add(s)
    return pack_scene(scene, bvh=bvh)


def hit(a, o, d, t_max=INF, from_obj=NO_HIT, from_inside=False):
    d = tuple(np.asarray(d, dtype=float) / np.linalg.norm(d))
    o = tuple(float(c) for c in o)
    k, t = closest_hit(a, o, d, t_max, from_obj, from_inside, None)
    if k == NO_HIT:
        return None
    p = tuple(np.add(o, np.multiply(t, d)))
    n_out = shapes.outward_normal(a, k, p, None)
    front, n = face_normal(d, n_out)
    return dict(k=k, t=t, p=np.array(p), n_out=np.array(n_out), front=front, n=np.array(n))


def test_sphere_from_outside(bvh):
    a = arrays(rt.sphere((0, 0, -5), 2, MAT), bvh=bvh)
    h = hit(a, (0, 0, 0), (0, 0, -1))
    assert h["t"] == pytest.approx(3.0)
    assert np.allclose(h["p"], (0, 0, -3))
    assert np.allclose(h["n_out"], (0, 0, 1)) and h["front"]
    # off-axis: closed-form t for a ray at height b: t = 5 - sqrt(4 - b^2) (unit d)
    d = np.array([0.1, 0.0, -1.0])
    h = hit(a, (0, 0, 0), d)
    assert np.linalg.norm(h["p"] - (0, 0, -5)) == pytest.approx(2.0, rel=1e-12)
    assert np.linalg.norm(h["n_out"]) == pytest.approx(1.0, rel=1e-12)


def test_sphere_from_inside_is_back_face(bvh):
    a = arrays(rt.sphere((0, 0, 0), 2, MAT), bvh=bvh)
    h = hit(a, (0.5, 0, 0), (1, 0, 0))
    assert h["t"] == pytest.approx(1.5)
    assert not h["front"] and np.allclose(h["n"], (-1, 0, 0))


def test_negative_radius_turns_the_normal_inward(bvh):
    a = arrays(rt.sphere((0, 0, -5), -2, MAT), bvh=bvh)
    h = hit(a, (0, 0, 0), (0, 0, -1))
    assert h["t"] == pytest.approx(3.0)              # same surface
    assert np.allclose(h["n_out"], (0, 0, -1)) and not h["front"]


def test_t_max_and_behind_the_origin(bvh):
    a = arrays(rt.sphere((0, 0, -5), 1, MAT), bvh=bvh)
    assert hit(a, (0, 0, 0), (0, 0, -1), t_max=3.9) is None
    assert hit(a, (0, 0, 0), (0, 0, 1)) is None      # sphere behind the ray


@pytest.mark.parametrize("make, o, d, t, normal", [
    (lambda: rt.xy_rect(-1, 1, -1, 1, -3, MAT), (0.3, 0.2, 0), (0, 0, -1), 3.0, (0, 0, 1)),
    (lambda: rt.xz_rect(-1, 1, -1, 1, -2, MAT), (0.3, 0, 0.2), (0, -1, 0), 2.0, (0, 1, 0)),
    (lambda: rt.yz_rect(-1, 1, -1, 1, 4, MAT), (0, 0.3, 0.2), (1, 0, 0), 4.0, (1, 0, 0)),
])
def test_axis_rects(make, o, d, t, normal, bvh):
    a = arrays(make(), bvh=bvh)
    h = hit(a, o, d)
    assert h["t"] == pytest.approx(t)
    assert np.allclose(h["n_out"], normal)          # the book's +axis normal
    assert h["front"] == (np.dot(d, normal) < 0)
    assert np.allclose(h["n"], -np.sign(np.dot(d, normal)) * np.array(normal))
    # flip_face turns the front side around, not the surface
    hf = hit(arrays(make().flip_face(), bvh=bvh), o, d)
    assert hf["t"] == pytest.approx(t) and hf["front"] != h["front"]
    assert np.allclose(hf["n"], h["n"])
    # just outside the bounds: a miss
    shifted = np.add(o, (1.01, 1.01, 1.01) * (1 - np.abs(normal)))
    assert hit(a, shifted, d) is None


def test_rect_edge_is_inclusive_and_parallel_ray_misses(bvh):
    a = arrays(rt.xy_rect(0, 1, 0, 1, 0, MAT), bvh=bvh)
    assert hit(a, (1.0, 1.0, 1.0), (0, 0, -1)) is not None
    assert hit(a, (0.5, 0.5, 0.0), (1, 0, 0)) is None   # in the plane
    assert hit(a, (0.5, 0.5, 1.0), (1, 0, 0)) is None   # parallel above it


def test_box_faces_point_outward(bvh):
    a = arrays(rt.box((0, 0, 0), (1, 2, 3), MAT), bvh=bvh)
    center = np.array([0.5, 1.0, 1.5])
    for axis in range(3):
        for sign in (-1, 1):
            o = center.copy()
            o[axis] += sign * 10
            h = hit(a, o, -sign * np.eye(3)[axis])
            expected_n = sign * np.eye(3)[axis]
            assert np.allclose(h["n_out"], expected_n) and h["front"]
            assert h["p"][axis] == pytest.approx(center[axis] + sign * (0.5, 1.0, 1.5)[axis])


def _slab(o, d, lo, hi):
    """Reference ray/box intersection in object space: entry t and axis."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t0, t1 = (lo - o) / d, (hi - o) / d
    tn, tf = np.minimum(t0, t1), np.maximum(t0, t1)
    t_enter, t_exit = tn.max(), tf.min()
    return (t_enter if 0 < t_enter <= t_exit else None), int(tn.argmax())


vec = st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1)


def _turn(axis, degrees):
    """The right-handed rotation about world axis 0, 1 or 2, written out."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return [np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),       # the books' rotate_y
            np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])][axis]


def _check_box_hit(box, lo, hi, rot, offset, target, jitter, far, bvh):
    """A ray from outside aimed at a point strictly inside the box lo..hi
    (turned by rot, then moved by offset) meets it where the object-space slab
    test says, with the outward normal of that face.  The odd offset keeps
    Hypothesis's favourite values (0, 1) from aiming the ray exactly along a
    diagonal, through an edge shared by two faces."""
    a = arrays(box, bvh=bvh)
    inside = lo + (np.array(target) * 0.45 + 0.5 + (0.0123, 0.0271, 0.0314)) * (hi - lo)
    o_obj = inside - far * np.array(jitter) / np.linalg.norm(jitter)
    o = rot @ o_obj + offset
    d = rot @ (inside - o_obj)
    d /= np.linalg.norm(d)
    t_ref, axis = _slab(o_obj, rot.T @ d, lo, hi)
    h = hit(a, o, d)
    assert h is not None and h["t"] == pytest.approx(t_ref, rel=1e-9)
    n_obj = np.zeros(3)
    n_obj[axis] = -np.sign((rot.T @ d)[axis])
    assert np.allclose(h["n_out"], rot @ n_obj, atol=1e-9) and h["front"]


@pytest.mark.parametrize("bvh", [False, True], ids=["linear", "bvh"])
@settings(max_examples=200)
@given(target=vec, jitter=vec, angle=st.floats(-180, 180))
def test_rotated_translated_box_matches_object_space(target, jitter, angle, bvh):
    lo, hi = np.array([0.0, 0, 0]), np.array([165.0, 330, 165])
    offset = np.array([265.0, 0, 295])
    _check_box_hit(rt.box(lo, hi, MAT).rotate_y(angle).translate(offset), lo, hi,
                   _turn(1, angle), offset, target, jitter, 1000, bvh)


@pytest.mark.parametrize("bvh", [False, True], ids=["linear", "bvh"])
@settings(max_examples=200)
@given(target=vec, jitter=vec, angles=st.tuples(*[st.floats(-180, 180)] * 3))
def test_any_rotation_of_a_box_matches_object_space(target, jitter, angles, bvh):
    lo, hi = np.array([-1.0, 0, 2]), np.array([3.0, 0.5, 4])
    offset = np.array([5.0, -2, 1])
    rot = _turn(2, angles[2]) @ _turn(1, angles[1]) @ _turn(0, angles[0])   # x, y, then z
    _check_box_hit(rt.box(lo, hi, MAT).rotate(angles).translate(offset), lo, hi, rot,
                   offset, target, jitter, 100, bvh)


def test_rotate_turns_about_x_then_y_then_z():
    # (0, 1, 0): about x by 90 -> (0, 0, 1); about z it stays.  z first would
    # give (-1, 0, 0), which x keeps.
    s = rt.sphere((0, 1, 0), 0.5, MAT).rotate((90, 0, 90)).translate((0, 2, 0))
    np.testing.assert_allclose(arrays(s).obj_f[0, :3], (0, 2, 1), atol=1e-12)
    # Right-handed, as the books' rotate_y (x' = cos x + sin z = 0, z' = -1).
    s = rt.sphere((1, 0, 0), 0.5, MAT).rotate((0, 90, 0))
    np.testing.assert_allclose(arrays(s).obj_f[0, :3], (0, 0, -1), atol=1e-12)
    rot, _ = rt.quad((0, 0, 0), (1, 0, 0), (0, 1, 0), MAT).rotate((10, 20, 30)).placement()
    np.testing.assert_allclose(rot, _turn(2, 30) @ _turn(1, 20) @ _turn(0, 10), atol=1e-15)
    # What is already placed turns with it: translate then rotate is rotate
    # then translate by the turned offset.
    t1 = rt.box((0, 0, 0), (1, 1, 1), MAT).translate((1, 2, 3)).rotate((10, 20, 30))
    t2 = rt.box((0, 0, 0), (1, 1, 1), MAT).rotate((10, 20, 30)).translate(
        _turn(2, 30) @ _turn(1, 20) @ _turn(0, 10) @ (1, 2, 3))
    np.testing.assert_allclose(arrays(t1).obj_f, arrays(t2).obj_f, atol=1e-12)


@pytest.mark.parametrize("make", [
    lambda: rt.box((0, 0, 0), (1, 2, 3), MAT),
    lambda: rt.quad((0, 0, 0), (1, 0, 0), (0, 1, 1), MAT),
    lambda: rt.xz_rect(0, 1, 0, 2, 0.5, MAT),
    lambda: rt.sphere((1, 2, 3), 0.5, MAT, center1=(2, 2, 3))],
    ids=["box", "quad", "xz_rect", "moving sphere"])
def test_rotate_0_a_0_is_rotate_y_a_bit_for_bit(make):
    for a in (15.0, -18.0, 90.0, 123.4):
        one = arrays(make().translate((1, 2, 3)).rotate_y(a).translate((4, 5, 6)))
        other = arrays(make().translate((1, 2, 3)).rotate((0, a, 0)).translate((4, 5, 6)))
        assert one.obj_f.tobytes() == other.obj_f.tobytes()


def test_rotate_then_translate_sphere_and_chains(bvh):
    s = rt.sphere((1, 0, 0), 0.5, MAT).rotate_y(90).translate((0, 2, 0))
    a = arrays(s, bvh=bvh)
    # rotate_y(90): x' = cos x + sin z = 0, z' = -sin x + cos z = -1
    assert np.allclose(a.obj_f[0, :3], (0, 2, -1))
    # translate then rotate == rotate then translate by the rotated offset
    t1 = rt.box((0, 0, 0), (1, 1, 1), MAT).translate((1, 0, 0)).rotate_y(90)
    t2 = rt.box((0, 0, 0), (1, 1, 1), MAT).rotate_y(90).translate((0, 0, -1))
    assert np.allclose(arrays(t1, bvh=bvh).obj_f, arrays(t2, bvh=bvh).obj_f)


def test_leaving_a_surface_never_hits_it_again(bvh):
    a = arrays(rt.xz_rect(-1, 1, -1, 1, 0, MAT), rt.sphere((0, 5, 0), 1, MAT), bvh=bvh)
    # Leave the rect at its own plane, grazing upward: only the sphere counts.
    h = hit(a, (0, 0, 0), (0, 1, 0), from_obj=0)
    assert h["k"] == 1
    # Leaving the sphere outward, downward: only the rect below counts.
    assert hit(a, (0, 4, 0), (0, -1, 0), from_obj=1)["k"] == 0
    # Entering the sphere at its bottom: the far side at the chord length.
    p = (0.0, 4.0, 0.0)
    d = np.array([0.3, 1.0, 0.0]) / np.linalg.norm([0.3, 1.0, 0.0])
    assert shapes.enters(a, 1, shapes.outward_normal(a, 1, p, None), tuple(d))
    h = hit(a, p, d, from_obj=1, from_inside=True)
    chord = 2 * 1.0 * d[1]                    # 2 r cos(angle to the normal)
    assert h["k"] == 1 and h["t"] == pytest.approx(chord, rel=1e-12)
    assert not h["front"]


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_self_exclusion_is_scale_free(scale, bvh):
    # A ray leaving a sphere at a point computed in floating point, grazing the
    # surface: no acne at any scale, because no epsilon is involved.
    a = arrays(rt.sphere((0, 0, 0), scale, MAT), bvh=bvh)
    rng = np.random.default_rng(1)
    for _ in range(200):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        p = tuple(scale * n)
        t = np.cross(n, rng.normal(size=3))
        d = t / np.linalg.norm(t) + 1e-9 * n      # almost tangent, outward
        d /= np.linalg.norm(d)
        assert hit(a, p, d, from_obj=0, from_inside=False) is None


def test_bvh_finds_the_same_hits_as_testing_every_object():
    scene = rt.load_scene("weekend")
    flat, tree = pack_scene(scene, bvh=False), pack_scene(scene, bvh=True)
    assert tree.wide is not None and len(tree.wide.child) > 1 and flat.wide is None
    assert sorted(tree.bvh_prims) == list(range(len(tree.obj_i)))   # each object once
    rng = np.random.default_rng(3)
    hits = 0
    for _ in range(3000):
        o = rng.uniform([-12, 0.05, -12], [12, 3, 12])
        d = rng.normal(size=3)
        a, b = hit(flat, o, d), hit(tree, o, d)
        assert (a is None) == (b is None)
        if a is not None:
            hits += 1
            assert a["k"] == b["k"] and a["t"] == b["t"]
    assert hits > 1000          # enough of the rays hit something


def test_shapes_become_the_primitive_kinds_they_are():
    from rtweekend.path.layout import BOX, RECT, SPHERE, XY_RECT, XZ_RECT, YZ_RECT
    a = arrays(rt.sphere((0, 0, 0), 1, MAT), rt.xy_rect(0, 1, 0, 1, 0, MAT),
               rt.xz_rect(0, 1, 0, 1, 0, MAT).translate((1, 2, 3)),
               rt.yz_rect(0, 1, 0, 1, 0, MAT).rotate_y(360),
               rt.yz_rect(0, 1, 0, 1, 0, MAT).rotate_y(30), rt.box((0, 0, 0), (1, 1, 1), MAT))
    assert a.obj_i[:, 0].tolist() == [SPHERE, XY_RECT, XZ_RECT, YZ_RECT, RECT, BOX]


@pytest.mark.parametrize("flip", [False, True])
@pytest.mark.parametrize("kind", ["xy_rect", "xz_rect", "yz_rect"])
def test_axis_rect_and_general_rect_agree(kind, flip, bvh):
    # The same rect tested on its axis and as a general rect (rect.py's row).
    from rtweekend.path.layout import RECT
    from rtweekend.path.shapes import rect
    shape = getattr(rt, kind)(-1, 2, -0.5, 1.5, 0.25, MAT).translate((0.1, -0.2, 0.3))
    if flip:
        shape = shape.flip_face()
    axis = arrays(shape, bvh=bvh)
    q, u, v = rect.axis_frame(kind, shape.geometry)
    row = np.zeros_like(axis.obj_f[0])
    rect.pack(np.add(q, shape.offset), *((v, u) if flip else (u, v)), row)
    general = axis._replace(obj_i=np.array([[RECT, 0]]), obj_f=row[None, :])
    if general.kind_first is not None:      # no hierarchy: searched kind by kind
        from rtweekend.path.bvh import sorted_by_kind
        prims, first = sorted_by_kind(general.obj_i, general.bvh_prims)
        general = general._replace(bvh_prims=prims, kind_first=first)
    rng = np.random.default_rng(7)
    lo, hi = shapes.bounds(axis.obj_i[0, 0], axis.obj_f[0])
    hits = 0
    for _ in range(400):
        # Rays aimed at the rect's bounds, grown by 20%: most hit, some miss.
        o = rng.uniform(-3, 3, size=3)
        target = rng.uniform(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo))
        x, y = hit(axis, o, target - o), hit(general, o, target - o)
        assert (x is None) == (y is None)
        if x is not None:
            hits += 1
            assert x["t"] == pytest.approx(y["t"], rel=1e-9)
            assert np.allclose(x["n_out"], y["n_out"], atol=1e-12)
            assert x["front"] == y["front"]
    assert hits > 50


def test_a_box_is_met_again_only_from_inside_at_its_exit(bvh):
    a = arrays(rt.box((0, 0, 0), (2, 2, 2), MAT).rotate_y(30).translate((5, 0, 0)), bvh=bvh)
    o = (0.0, 1.0, 0.3)
    d = np.array([1.0, 0.1, 0.05])
    entry = hit(a, o, d)
    assert entry is not None and entry["front"]
    p, n = tuple(entry["p"]), entry["n_out"]
    u = tuple(d / np.linalg.norm(d))
    # Refracted inward (here: straight on): the next hit is the exit, from inside.
    assert shapes.enters(a, 0, tuple(n), u)
    out = hit(a, p, u, from_obj=0, from_inside=True)
    assert out is not None and not out["front"] and out["t"] > 0.1
    # The exit point lies on the box: its distance to the entry is a chord.
    assert np.linalg.norm(out["p"] - entry["p"]) == pytest.approx(out["t"])
    # Reflected outward: never met again.
    r = tuple(u - 2 * np.dot(u, n) * n)
    assert not shapes.enters(a, 0, tuple(n), r)
    assert hit(a, p, r, from_obj=0, from_inside=False) is None


def test_a_ray_inside_a_box_meets_its_far_side(bvh):
    a = arrays(rt.box((-1, -1, -1), (1, 1, 1), MAT), bvh=bvh)
    h = hit(a, (0.5, 0, 0), (1, 0, 0))
    assert h["t"] == pytest.approx(0.5) and not h["front"]
    assert np.allclose(h["n_out"], (1, 0, 0))
    flipped = arrays(rt.box((-1, -1, -1), (1, 1, 1), MAT).flip_face(), bvh=bvh)
    h = hit(flipped, (0.5, 0, 0), (1, 0, 0))
    assert np.allclose(h["n_out"], (-1, 0, 0)) and h["front"]


def _random_spheres_and_boxes(rng, spheres, boxes, extent):
    """A scene of spheres and turned boxes scattered in [-extent, extent]^3."""
    scene = rt.Scene()
    for _ in range(spheres):
        scene.add(rt.sphere(rng.uniform(-extent, extent, 3), rng.uniform(0.1, 5), MAT))
    for _ in range(boxes):
        lo = rng.uniform(-extent, extent, 3)
        scene.add(rt.box(lo, lo + rng.uniform(0.5, 9, 3), MAT).rotate_y(rng.uniform(0, 90)))
    return scene


def test_the_compiled_bvh_builder_builds_the_numpy_reference_tree():
    # Every bundled scene, and random spheres, boxes and triangles: the same
    # boxes, nodes and object order, bit for bit (so images do not change).
    import bvh_reference
    from rtweekend.path.bvh_build import build_bvh

    def same(arrays, ids=None):
        new = build_bvh(arrays.obj_i, arrays.obj_f, ids)
        old = bvh_reference.build_bvh(arrays.obj_i, arrays.obj_f, ids)
        return all(np.array_equal(a, b) for a, b in zip(new, old))
    for name in rt.bundled_scenes():
        scene = rt.load_scene(name)
        if scene.resolved_integrator() == "path":
            assert same(pack_scene(scene, bvh=False)), name
    rng = np.random.default_rng(4)
    scene = _random_spheres_and_boxes(rng, 300, 40, 50)
    v = rng.uniform(-60, 60, (900, 3))
    scene.add(rt.mesh((v, rng.integers(0, 900, (700, 3))), MAT))
    scene.add(rt.mesh((np.zeros((3, 3)) + [[0, 0, 0], [1, 0, 0], [0, 1, 0]],    # 30 copies:
                       np.zeros((30, 3), dtype=int) + [0, 1, 2]), MAT))           # no split
    arrays = pack_scene(scene, bvh=False)
    assert same(arrays)
    assert same(arrays, np.arange(0, len(arrays.obj_i), 3))
    # Subtrees built on threads (down to 8 objects, so there are many), put
    # back together: the same tree.
    from rtweekend.path.bvh_build import _build, object_bounds
    bounds = object_bounds(arrays.obj_i, arrays.obj_f)
    ids = np.arange(len(arrays.obj_i), dtype=np.int64)
    old = bvh_reference.build_bvh(arrays.obj_i, arrays.obj_f)
    for task in (8, 100, 10**6):
        new = _build(bounds, ids.copy(), task)
        assert all(np.array_equal(a, b) for a, b in zip(new, old)), task


def test_the_wide_walk_finds_what_the_stackless_walk_finds():
    # A scene with a hierarchy walks it 4-wide, nearer children first
    # (wide_bvh.py); the binary tree's walk by its miss links (bvh.py) finds
    # the same hits, bit for bit.
    from rtweekend.path.bvh_build import build_bvh
    rng = np.random.default_rng(8)
    scene = _random_spheres_and_boxes(rng, 400, 30, 20)
    ordered = pack_scene(scene, bvh=True)
    assert ordered.wide is not None and ordered.bvh_node.shape[0] == 0
    box, node, prims = build_bvh(ordered.obj_i, ordered.obj_f, np.sort(ordered.bvh_prims))
    assert np.array_equal(prims, ordered.bvh_prims)
    stackless = ordered._replace(wide=None, bvh_box=box, bvh_node=node)
    o = rng.uniform(-30, 30, (20_000, 3))
    d = rng.normal(size=(20_000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    k1, t1 = nearest_hits(stackless, o, d)
    k2, t2 = nearest_hits(ordered, o, d)
    assert (k1 != NO_HIT).mean() > 0.3
    assert np.array_equal(k1, k2) and np.array_equal(t1, t2)


def test_the_builders_first_extreme_is_numpys_argmin_and_argmax():
    # The builder's own argmin / argmax (bvh_build.py: written out so that a
    # cached builder needs no numba.np.arraymath) pick what NumPy's pick: the
    # first of equal values, the first NaN, infinities in order.
    from rtweekend.path.bvh_build import _first_extreme
    rng = np.random.default_rng(5)
    values = np.array([0.0, 1.0, -1.0, np.inf, -np.inf, np.nan, 2.5])
    for n in (1, 2, 3, 7, 16):
        for _ in range(300):
            a = rng.choice(values, size=n)
            assert _first_extreme(a, False) == np.argmin(a), a
            assert _first_extreme(a, True) == np.argmax(a), a


def test_the_bounds_padding_in_numpy_is_the_compiled_pads_bits():
    # Objects other than triangles are padded by NumPy (a scene without meshes
    # compiles no bounds), triangles by the compiled _pad: the same widening.
    from rtweekend.path.bvh_build import _pad, _pad_rows
    rng = np.random.default_rng(5)
    boxes = rng.normal(size=(300, 6)) * 10.0 ** rng.integers(-12, 6, size=(300, 1))
    by_numpy, compiled = boxes.copy(), boxes.copy()
    rows = np.arange(0, 300, 2)
    _pad_rows(by_numpy, rows)
    for k in rows:
        _pad(compiled, k)
    assert by_numpy.tobytes() == compiled.tobytes()
    assert (by_numpy[1::2] == boxes[1::2]).all() and (by_numpy[::2, :3] < boxes[::2, :3]).all()


def test_the_kind_by_kind_search_finds_what_testing_in_index_order_finds():
    # A small scene (no hierarchy) whose kinds are interleaved in index order:
    # kind_walk tests them sorted by kind; the nearest hit, and the object a
    # ray leaves (self-exclusion), must be those of a walk in index order.
    a = arrays(rt.sphere((0, 1, 0), 1, MAT), rt.xz_rect(-4, 4, -4, 4, 0, MAT),
               rt.box((1.5, 0, -1), (2.5, 1, 0), MAT).rotate_y(20),
               rt.yz_rect(0, 3, -4, 4, -3, MAT), rt.sphere((-1.5, 0.5, 1.5), 0.5, MAT),
               rt.xy_rect(-4, 4, 0, 3, -3.5, MAT).flip_face(),
               rt.quad((-1, 2, 2), (1, 0, 0.5), (0, 1, 0), MAT), rt.sphere((0, 1, 0), 1.5, MAT))
    assert a.wide is None and a.kind_first is not None
    assert list(a.bvh_prims) != sorted(a.bvh_prims)           # the order did change
    rng = np.random.default_rng(11)
    hits = 0
    for i in range(1500):
        from_obj = int(rng.integers(-1, len(a.obj_i)))
        o = rng.uniform([-3.5, 0.01, -3.4], [3.5, 2.9, 3.9])
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        inside = bool(rng.integers(2))
        o, d = tuple(float(c) for c in o), tuple(float(c) for c in d)
        k, t = closest_hit(a, o, d, INF, from_obj, inside, None)
        best, t_best = NO_HIT, INF
        for j in range(len(a.obj_i)):
            tj = shapes.distance(a, j, o, d, t_best, from_obj, inside, None)
            if tj < t_best:
                best, t_best = j, tj
        # t to the last bits: the kernel's inlined division may be a product by
        # a reciprocal (fastmath's arcp), the lone call's a division
        assert k == best and (k == NO_HIT or abs(t - t_best) <= 1e-14 * t_best)
        hits += k != NO_HIT
    assert hits > 600           # enough of the rays hit something
