"""Smooth meshes: vertex normals read from files (or made from the faces), the
shading normal they interpolate, the sphere they approach, and the same
surface seen by light and camera subpaths (the shading normal's adjoint)."""
import math

import numpy as np
import pytest
from numba import njit

import rtweekend as rt
from rtweekend.path.layout import NO_HIT
from rtweekend.path.pack import pack_scene
from rtweekend.path.surface import surface_at
from rtweekend.scene import meshes

from rays import nearest_hits, uniform_directions
from stats import block_z
from test_meshes import GREY, sphere_mesh


def _radial(v, center=(0.0, 0.0, 0.0)):
    r = v - np.asarray(center)
    return r / np.linalg.norm(r, axis=1, keepdims=True)


# -- where vertex normals come from ---------------------------------------------------

SQUARE_OBJ = """v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vn 0 0 2
vn 0.5 0 1
vn 0 0 1
vn 0 -0.5 1
f 1//1 2//2 3//3
f 1//1 3//3 4//4
"""


def test_an_obj_files_vertex_normals_are_read_and_made_unit(tmp_path):
    (tmp_path / "square.obj").write_text(SQUARE_OBJ)
    shape = rt.mesh(tmp_path / "square.obj", GREY)
    v, f, _, n = shape.geometry
    file_n = np.array([[0, 0, 2], [0.5, 0, 1], [0, 0, 1], [0, -0.5, 1]], float)
    file_v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    # Each vertex keeps its own normal, whatever order trimesh gives them in.
    for vertex, normal in zip(v, n):
        i = int(np.flatnonzero((file_v == vertex).all(axis=1))[0])
        np.testing.assert_allclose(normal, file_n[i] / np.linalg.norm(file_n[i]), atol=1e-7)
    assert rt.mesh(tmp_path / "square.obj", GREY, smooth=False).geometry[3] is None
    # Scaled per axis, normals go by the inverse scale.
    v2, _, _, n2 = rt.mesh(tmp_path / "square.obj", GREY, scale=(2, 1, 1)).geometry
    for vertex, normal in zip(v2, n2):
        i = int(np.flatnonzero((file_v * [2, 1, 1] == vertex).all(axis=1))[0])
        expect = file_n[i] / [2, 1, 1]
        np.testing.assert_allclose(normal, expect / np.linalg.norm(expect), atol=1e-7)


def test_ply_and_gltf_normals_are_read_and_a_file_without_them_is_flat(tmp_path):
    trimesh = pytest.importorskip("trimesh", reason="needs the meshes extra")
    v, f = sphere_mesh(6, 12)
    normals = _radial(v)
    part = trimesh.Trimesh(vertices=v, faces=f, vertex_normals=normals, process=False)
    for name in ("ball.ply", "ball.glb"):
        part.export(tmp_path / name)
        got_v, _, _, got_n = rt.mesh(tmp_path / name, GREY).geometry
        # float32 in the file: the normal of each vertex, to its precision.
        np.testing.assert_allclose(got_n, _radial(got_v), atol=1e-6)
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    assert rt.mesh(tmp_path / "flat.obj", GREY).geometry[3] is None


def test_smooth_true_makes_normals_from_the_faces():
    v, f = sphere_mesh(24, 48)
    assert rt.mesh((v, f), GREY).geometry[3] is None            # flat unless asked
    n = rt.mesh((v, f), GREY, smooth=True).geometry[3]
    # Area-weighted face normals about a vertex of a fine sphere mesh (its
    # facets 7.5 degrees apart) point within 2 degrees of the radius (measured
    # 1.27 next to the poles, whose fans are lopsided); the poles exactly.
    cos = (n * _radial(v)).sum(axis=1)
    assert cos.min() > math.cos(math.radians(2.0)), math.degrees(math.acos(cos.min()))
    np.testing.assert_allclose(n[:2], [[0, 0, 1], [0, 0, -1]], atol=1e-12)
    # smooth_normals on a hand-checked case: two faces meeting at a crease.
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    f = np.array([[0, 1, 2], [0, 3, 1]])        # normals +z (area 1/2) and +y (1/2)
    n = meshes.smooth_normals(v, f)
    np.testing.assert_allclose(n[0], [0, math.sqrt(0.5), math.sqrt(0.5)], atol=1e-15)
    np.testing.assert_allclose(n[2], [0, 0, 1], atol=1e-15)


def test_bad_normals_name_what_is_wrong():
    v, f = sphere_mesh(4, 8)
    n = _radial(v)
    bad_nan, bad_zero = n.copy(), n.copy()
    bad_nan[3, 1] = np.nan
    bad_zero[5] = 0.0
    cases = [((v, f, None, bad_nan), "normals[3] is not a direction: ["),
             ((v, f, None, bad_zero), "normals[5] is not a direction: [0.0, 0.0, 0.0] (the "
              "normal of vertices[5] must be finite and not zero)"),
             ((v, f, None, n[:4]), "normals: expected one per vertex"),
             ((v, f, None, n, 1), "expected at most 4 arrays")]
    for arrays, message in cases:
        with pytest.raises(rt.SceneError, match="^mesh: ") as e:
            rt.mesh(arrays, GREY)
        assert message in str(e.value) and "\n" not in str(e.value), str(e.value)
    with pytest.raises(rt.SceneError, match="smooth: expected true or false"):
        rt.mesh((v, f), GREY, smooth="yes")
    # A vertex only of faces with no area (left out) has no normal to read.
    v2 = np.concatenate([v, [[5.0, 0, 0], [6.0, 0, 0], [7.0, 0, 0]]])
    f2 = np.concatenate([f, [[len(v), len(v) + 1, len(v) + 2]]])
    n2 = np.concatenate([n, np.zeros((3, 3))])
    _, kept, _, got = rt.mesh((v2, f2, None, n2), GREY).geometry
    assert len(kept) == len(f) and np.isfinite(got).all()
    np.testing.assert_allclose(got[:len(v)], n)


# A crease: face 1 (+z, area 1/2) names the zero normal 1 at the origin,
# face 2 (+y, area 1/2) names normal 3 there; face 3 has no area, and its
# corners (normal 1) are used by no other face.
ZERO_NORMAL_OBJ = """v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
v 2 0 0
v 3 0 0
vn 0 0 0
vn 0 0 1
vn 0 1 0
f 1//1 2//2 3//2
f 1//3 4//3 2//3
f 2//1 5//1 6//1
"""


@pytest.mark.parametrize("smooth", [None, True])
def test_a_files_zero_normal_is_made_from_the_faces_around_it(tmp_path, smooth):
    # Exporters write 'vn 0 0 0' where they have no normal: that vertex gets
    # the normal the faces at its position make (as Blender reads a zero
    # custom normal), the other vertices keep the file's.
    (tmp_path / "zero.obj").write_text(ZERO_NORMAL_OBJ)
    v, f, _, n = rt.mesh(tmp_path / "zero.obj", GREY, smooth=smooth).geometry
    assert len(f) == 2 and np.isfinite(n).all()
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    used = np.unique(f)
    at_origin = sorted(n[i].tolist() for i in used if not v[i].any())
    np.testing.assert_allclose(at_origin, [[0, math.sqrt(0.5), math.sqrt(0.5)], [0, 1, 0]],
                               atol=1e-15)
    np.testing.assert_allclose(n[f[0]][1:], [[0, 0, 1], [0, 0, 1]])
    # Scaled per axis: still unit normals, no NaN from the unused vertices.
    n2 = rt.mesh(tmp_path / "zero.obj", GREY, scale=(2, 1, 1)).geometry[3]
    assert np.isfinite(n2).all()
    np.testing.assert_allclose(np.linalg.norm(n2, axis=1), 1.0)


# -- the shading normal ----------------------------------------------------------------

@njit
def _shading(a, o, d, k, t):
    out = np.empty((o.shape[0], 7))
    for i in range(o.shape[0]):
        oi, di = (o[i, 0], o[i, 1], o[i, 2]), (d[i, 0], d[i, 1], d[i, 2])
        hit = surface_at(a, None, k[i], oi, di, t[i], None)
        out[i, 0:3] = hit.n
        out[i, 3:6] = hit.n_out
        out[i, 6] = hit.front
    return out


def _expected_shading(a, o, d, k, t, normals):
    """NumPy: the barycentric blend of the hit triangle's vertex normals, made
    unit, on the outward normal's side, then turned towards the ray."""
    p = o + d * t[:, None]
    rows = a.obj_f[k]
    p0, p1, p2 = rows[:, 0:3], rows[:, 3:6], rows[:, 6:9]
    e1, e2, q = p1 - p0, p2 - p0, p - p0
    nn = np.cross(e1, e2)
    inv = 1.0 / (nn * nn).sum(axis=1)
    b1 = (np.cross(q, e2) * nn).sum(axis=1) * inv
    b2 = (np.cross(e1, q) * nn).sum(axis=1) * inv
    b0 = 1.0 - b1 - b2
    tri = normals[np.int64(rows[:, 13])]
    n = b0[:, None] * tri[:, 0:3] + b1[:, None] * tri[:, 3:6] + b2[:, None] * tri[:, 6:9]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    n_out = rows[:, 9:12]
    n *= np.where((n * n_out).sum(axis=1) < 0, -1.0, 1.0)[:, None]
    return n * np.where((d * n_out).sum(axis=1) < 0, 1.0, -1.0)[:, None]


def test_the_shading_normal_blends_the_vertex_normals_where_the_ray_hits():
    v, f = sphere_mesh(8, 16, radius=1.5, center=(0.3, 0.1, -0.2))
    # Vertex normals pointing inwards for half the vertices: turned to the
    # outward side, as a file's may need.
    n = _radial(v, (0.3, 0.1, -0.2)) * np.where(np.arange(len(v)) % 2, -1.0, 1.0)[:, None]
    scene = rt.Scene()
    scene.add(rt.mesh((v, f, None, n), GREY))
    a = pack_scene(scene)
    rng = np.random.default_rng(4)
    o = rng.uniform(-4, 4, (4000, 3))
    o[:1000] *= 0.1                                    # some from inside
    d = uniform_directions(4000, 7)
    k, t = nearest_hits(a, o, d)
    hit = k != NO_HIT
    o, d, k, t = o[hit], d[hit], k[hit], t[hit]
    got = _shading(a, o, d, k, t)
    np.testing.assert_allclose(got[:, 0:3], _expected_shading(a, o, d, k, t, a.tris.normals),
                               atol=1e-12)
    assert (got[:, 6] == 0).any() and (got[:, 6] == 1).any()
    # A flat mesh in the same scene shades with its faces' normals.
    scene.add(rt.mesh(sphere_mesh(4, 8, radius=0.5, center=(5, 0, 0)), GREY))
    a = pack_scene(scene)
    o, d = np.tile([[5.0, 0, 3]], (200, 1)), np.tile([[0, 0, -1.0]], (200, 1))
    o[:, :2] += rng.uniform(-0.3, 0.3, (200, 2))
    k, t = nearest_hits(a, o, d)
    got = _shading(a, o, d, k, t)
    assert (k != NO_HIT).all()
    np.testing.assert_array_equal(got[:, 0:3], got[:, 3:6])   # front: n is n_out itself


def _normal_feature(shape, size=48, spp=16):
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 4), lookat=(0, 0, 0), vfov=36,
                                      width=size, height=size), background=(0.5, 0.5, 0.5))
    scene.add(shape)
    return rt.render(scene, spp=spp, seed=1, aov="normal").aov["normal"]


def test_a_smooth_sphere_mesh_shades_as_the_sphere_does():
    # The normal feature (what the first hit shades with, averaged over each
    # pixel) of a coarse sphere mesh against the analytic sphere's, inside the
    # outline: vertex normals on the sphere make its error a fraction of the
    # flat mesh's facets (measured 0.31x: what is left is mostly that a pixel
    # sees the mesh a little inside the sphere, at another point).
    v, f = sphere_mesh(10, 20)
    sphere = _normal_feature(rt.sphere((0, 0, 0), 1.0, GREY))
    inside = np.linalg.norm(sphere[..., :2], axis=-1) < 0.8
    flat = np.abs(_normal_feature(rt.mesh((v, f), GREY)) - sphere)[inside].mean()
    smooth = np.abs(_normal_feature(rt.mesh((v, f, None, _radial(v)), GREY)) -
                    sphere)[inside].mean()
    assert smooth < 0.4 * flat, (smooth, flat)
    assert smooth < 0.01, smooth


# -- light and camera subpaths see the same surface --------------------------------------

def _lit_bumps(smooth):
    """A coarse grey ball on a floor under a square light: vertex normals that
    lean far from the faces' (a ball of 6 x 12 facets) make the shading
    normal's adjoint matter."""
    v, f = sphere_mesh(6, 12, radius=1.0, center=(0, 1.0, 0))
    normals = _radial(v, (0, 1.0, 0)) if smooth else None
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 2.5, 5), lookat=(0, 0.8, 0), vfov=40,
                                      width=24, height=24))
    scene.add(rt.xz_rect(-4, 4, -4, 4, 0, GREY))
    scene.add(rt.mesh((v, f, None, normals), rt.lambertian((0.7, 0.7, 0.7))))
    scene.add(rt.xz_rect(-1, 1, -1, 1, 3.5, rt.diffuse_light((6, 6, 6))).flip_face(),
              light=True)
    return scene


@pytest.mark.parametrize("sampling", ["lightpath", "bdpt+sobol"])
def test_light_tracing_and_bdpt_render_a_smooth_mesh_as_the_path_tracer(sampling):
    # Light subpaths carry light the other way through the shading normal:
    # without its adjoint factor, light tracing's ball is brighter or darker
    # than the path tracer's where the normals lean (tens of standard errors).
    scene = _lit_bumps(True)
    a = rt.render(scene, spp=512, seed=3, sampling="mixture+sobol", threads=2)
    b = rt.render(scene, spp=512 if sampling != "lightpath" else 2048, seed=4,
                  sampling=sampling, threads=2)
    z = block_z(a.image, a.stderr, b.image, b.stderr, 4)
    assert np.abs(z).max() < 5, np.abs(z).max()


# -- no light through the surface -----------------------------------------------------

def _tilted_quad_lit_from_behind():
    """A lambertian quad at z = 0 facing +z whose vertex normals lean 40 degrees
    towards +x, and a light entirely behind it (z < 0) at x = 4: the shading
    normal's hemisphere reaches the light, the true surface hides it."""
    v = np.array([[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]], float)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    a = math.radians(40)
    ns = np.tile([math.sin(a), 0.0, math.cos(a)], (4, 1))
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 5), lookat=(0, 0, 0), vfov=30,
                                      width=12, height=12), background=(0, 0, 0))
    scene.add(rt.mesh((v, f, None, ns), GREY))
    scene.add(rt.yz_rect(-1, 1, -1, -0.2, 4, rt.diffuse_light((20, 20, 20))).flip_face(),
              light=True)
    return scene


@pytest.mark.parametrize("sampling", ["mixture+sobol", "cosine", "nee", "bdpt+sobol"])
def test_a_light_behind_a_smooth_surface_does_not_light_its_front(sampling):
    # Every strategy that scatters or connects at the quad must stop at its
    # true surface; before, each found ~0.25 on the quad's front (all alike,
    # so comparing strategies could not see it).
    image = rt.render(_tilted_quad_lit_from_behind(), spp=16, seed=1, threads=1,
                      sampling=sampling).image
    assert np.isfinite(image).all()
    # Not exactly 0 for bdpt: it joins points on the quad's two sides along
    # segments in its plane, where rounding leaves cosines of ~1e-17 (a flat
    # quad gives ~1e-29 that way); the leak was ~0.25.
    assert image.max() < 1e-9, (sampling, image.max())
