"""Triangle meshes: the watertight test, exact answers (a furnace, Lambert's
polygon formula), a mesh box against the box primitive, the light sampling of
a triangle, loading from files and scene files, and bad input."""
import math
import subprocess
import sys

import numpy as np
import pytest

import rtweekend as rt
from rtweekend.path.layout import NO_HIT, TRIANGLE
from rtweekend.path.pack import pack_scene

from rays import light_densities, light_directions, nearest_hits, uniform_directions
from stats import assert_chi2

GREY = rt.lambertian((0.5, 0.5, 0.5))


def sphere_mesh(n_lat=12, n_lon=24, radius=1.0, center=(0.0, 0.0, 0.0)):
    """A closed latitude-longitude sphere: (vertices, faces), faces turning
    counter-clockwise seen from outside."""
    verts = [(0.0, 0.0, radius), (0.0, 0.0, -radius)]
    for i in range(1, n_lat):
        theta = math.pi * i / n_lat
        for j in range(n_lon):
            phi = 2 * math.pi * j / n_lon
            verts.append((radius * math.sin(theta) * math.cos(phi),
                          radius * math.sin(theta) * math.sin(phi), radius * math.cos(theta)))

    def ring(i, j):
        return 2 + (i - 1) * n_lon + j % n_lon
    faces = []
    for j in range(n_lon):
        faces.append((0, ring(1, j), ring(1, j + 1)))
        faces.append((1, ring(n_lat - 1, j + 1), ring(n_lat - 1, j)))
        for i in range(1, n_lat - 1):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces += [(a, c, d), (a, d, b)]
    v = np.array(verts) + np.asarray(center)
    f = np.array(faces)
    # Turn every face to face outward (the construction above mostly does).
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    out = ((n * (v[f].mean(axis=1) - center)).sum(axis=1) < 0)
    f[out] = f[out][:, ::-1]
    return v, f


def box_mesh(lo, hi):
    """The 12 triangles of an axis-aligned box, facing outward."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                  [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], float)
    f = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                  [3, 7, 6], [3, 6, 2], [0, 4, 7], [0, 7, 3], [1, 2, 6], [1, 6, 5]])
    return v, f


# -- the watertight test ---------------------------------------------------------------

def test_no_ray_slips_through_the_edges_and_vertices_of_a_closed_mesh():
    # 10^6 rays aimed at the vertices and edges of a closed sphere mesh, within
    # rounding of them (in double precision a test that is not watertight
    # rarely fails here: the exact test below is the sharper one).
    v, f = sphere_mesh(16, 32, radius=1.3, center=(0.2, -0.1, 0.4))
    scene = rt.Scene()
    scene.add(rt.mesh((v, f), GREY))
    a = pack_scene(scene, bvh=True)
    rng = np.random.default_rng(3)
    n = 1_000_000
    # Targets: the vertices, and points on the edges (t in [0, 1] between two
    # vertices of a face), where a test that is not watertight lets rays through.
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    pick = rng.integers(0, len(edges), n)
    t = rng.random(n)[:, None]
    t[: n // 4] = 0.0                                 # a quarter aimed at vertices exactly
    targets = v[edges[pick, 0]] * (1 - t) + v[edges[pick, 1]] * t
    # From outside, within 60 degrees of the outward normal there: every ray
    # goes into the mesh through its target (a ray that only grazes a vertex
    # of the outline could pass it either way).
    outward = targets - np.array((0.2, -0.1, 0.4))
    outward /= np.linalg.norm(outward, axis=1, keepdims=True)
    away = rng.normal(size=(n, 3))
    away -= (away * outward).sum(axis=1, keepdims=True) * outward          # tangent
    away /= np.linalg.norm(away, axis=1, keepdims=True)
    angle = np.arccos(1 - rng.random((n, 1)) * (1 - math.cos(math.radians(60))))
    directions = outward * np.cos(angle) + away * np.sin(angle)
    origins = targets + directions * rng.uniform(0.5, 50, (n, 1))
    assert (nearest_hits(a, origins, targets - origins)[0] != NO_HIT).all()


def test_rays_exactly_through_edges_and_vertices_meet_the_mesh():
    # An octahedron with integer vertices, rays from integer points to integer
    # points of its edges (vertices included): each ray passes exactly through
    # an edge or a vertex, where two or four faces meet and a test whose
    # edge functions disagree, or that rejects a zero, lets it through (a
    # strict "> 0" here lets 679 of these 38,594 through).  Only rays that go
    # into every face they touch are kept: a grazing one may pass either way.
    r = 12
    v = np.array([[r, 0, 0], [-r, 0, 0], [0, r, 0], [0, -r, 0], [0, 0, r], [0, 0, -r]], float)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5],
                  [0, 3, 5]])
    scene = rt.Scene()
    scene.add(rt.mesh((v, f), GREY))
    a = pack_scene(scene, bvh=False)
    rng = np.random.default_rng(1)
    n = 200_000
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    pick = rng.integers(0, len(edges), n)
    k = rng.integers(0, r + 1, n)[:, None]
    targets = (v[edges[pick, 0]] * (r - k) + v[edges[pick, 1]] * k) / r
    origins = rng.integers(-60, 61, (n, 3)).astype(float)
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    touches = ((targets[:, None, :] - v[f[:, 0]][None]) * normals[None]).sum(-1) == 0
    inward = ((targets - origins)[:, None, :] * normals[None]).sum(-1) < 0
    keep = np.where(touches, inward, True).all(axis=1) & touches.any(axis=1)
    assert keep.sum() > 30_000
    # Directions target - origin, not normalised: exact for integers.
    assert (nearest_hits(a, origins[keep], targets[keep] - origins[keep])[0] != NO_HIT).all()


# -- exact answers --------------------------------------------------------------------

def test_a_convex_mesh_in_a_furnace_is_exactly_its_albedo():
    # A convex grey mesh under a uniform sky of radiance 1: a ray that meets it
    # scatters once and leaves (no face sees another), so every sample of a
    # pixel inside its outline is 0.5 exactly.  A false self-hit (0.25) or a
    # leak into the inside would show.
    v, f = sphere_mesh(10, 20, radius=1.0)
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0, 4), lookat=(0, 0, 0), vfov=40,
                                      width=24, height=24), background=(1, 1, 1))
    scene.add(rt.mesh((v, f), GREY))
    for sampling in ("mixture+sobol", "nee", "bdpt+sobol"):
        r = rt.render(scene, spp=32, seed=2, sampling=sampling)
        inside = r.image[8:16, 8:16]
        assert np.abs(inside - 0.5).max() < 1e-6, sampling
        assert r.stderr[8:16, 8:16].max() < 1e-6


def _lambert_polygon(x, n, polygon):
    """Irradiance at x (normal n) from a polygon of unit radiance: Lambert's
    formula, E = 1/2 sum over edges of angle(a_i, b_i) n . unit(a_i x b_i)."""
    e = 0.0
    for i in range(len(polygon)):
        a = polygon[i] - x
        b = polygon[(i + 1) % len(polygon)] - x
        a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
        c = np.cross(a, b)
        e += math.acos(np.clip(a @ b, -1, 1)) * (n @ c) / np.linalg.norm(c)
    return 0.5 * abs(e)


@pytest.mark.parametrize("sampling", ["nee", "bdpt+sobol", "mixture+sobol"])
def test_a_triangle_light_gives_lambert_polygon_irradiance(sampling):
    # A floor point under a one-sided triangle light of radiance 4 facing down:
    # the floor's radiance is albedo / pi x E (nothing else lights it).
    tri = np.array([[-1.0, 2.0, -0.5], [1.5, 2.2, 0.3], [-0.3, 1.6, 1.4]])
    faces = np.array([[0, 1, 2]])
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    if n[1] > 0:
        faces = faces[:, ::-1]                        # face down, towards the floor
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0.1, 1.0, 0.2), lookat=(0.1, 0, 0.2),
                                      vup=(0, 0, 1), vfov=0.01, width=1, height=1))
    scene.add(rt.xz_rect(-50, 50, -50, 50, 0, GREY))
    scene.add(rt.mesh((tri, faces), rt.diffuse_light((4, 4, 4))))
    r = rt.render(scene, spp=8192, seed=5, sampling=sampling)
    expected = 0.5 / math.pi * 4 * _lambert_polygon(np.array([0.1, 0, 0.2]),
                                                   np.array([0, 1.0, 0]), tri)
    got, se = float(r.image[0, 0, 0]), float(r.stderr[0, 0, 0])
    assert abs(got - expected) < 5 * se + 1e-9, (got, expected, se)


# -- a mesh box is the box --------------------------------------------------------------

@pytest.mark.parametrize("sampling", ["mixture+sobol", "bdpt+sobol"])
def test_a_box_of_12_triangles_renders_as_the_box_primitive(sampling):
    def cornell(boxes_as_meshes):
        s = rt.load_scene("cornell_box")
        out = rt.Scene(camera=s.camera)
        for o in s.objects:
            if o.kind == "box" and boxes_as_meshes:
                m = rt.mesh(box_mesh(*o.geometry), o.material)
                m = m.rotate_y(dict(o.turns)[1]).translate(o.offset)
                out.add(m)
            else:
                out.add(o, light=any(o is light for light in s.lights))
        return out
    a = rt.render(cornell(False), spp=8, width=40, height=40, seed=3, sampling=sampling)
    b = rt.render(cornell(True), spp=8, width=40, height=40, seed=3, sampling=sampling)
    # The same surfaces hit at the same places up to rounding: the same image
    # to float32's precision (measured: bit-identical).
    np.testing.assert_allclose(b.image, a.image, rtol=1e-5, atol=1e-6)


# -- a triangle as a light: its direction sampling and density ----------------------------


def test_a_triangles_light_density_integrates_to_one_and_its_samples_follow_it():
    scene = rt.Scene()
    scene.add(rt.mesh((np.array([[-1.0, -0.5, 1.0], [1.2, 0.1, 1.5], [0.0, 1.0, 0.8]]),
                       np.array([[0, 1, 2]])), rt.diffuse_light((1, 1, 1))))
    a = pack_scene(scene)
    assert a.obj_i[0, 0] == TRIANGLE
    p = (0.1, 0.0, 0.0)
    v = light_densities(a, 0, p, uniform_directions(400_000, 7)) * 4 * math.pi
    assert abs(v.mean() - 1.0) < 5 * v.std() / math.sqrt(len(v))
    dirs = light_directions(a, 0, p, 200_000, 11)
    assert (light_densities(a, 0, p, dirs) > 0).all()
    # Binned on a grid of the triangle's own barycentric coordinates: where each
    # sampled direction meets it, which must be uniform in area.
    hits = []
    q0, q1, q2 = a.obj_f[0, 0:3], a.obj_f[0, 3:6], a.obj_f[0, 6:9]
    n = np.cross(q1 - q0, q2 - q0)
    t = ((q0 - p) @ n) / (dirs @ n)
    x = np.asarray(p) + dirs * t[:, None]
    m = np.stack([q1 - q0, q2 - q0], axis=1)
    b = np.linalg.lstsq(m, (x - q0).T, rcond=None)[0].T          # (b1, b2)
    hits = np.minimum((b[:, 0] * 10).astype(int), 9) * 10 + np.minimum((b[:, 1] * 10)
                                                                     .astype(int), 9)
    observed = np.bincount(hits, minlength=100)
    # Cells of the 10x10 grid inside b1 + b2 <= 1: 45 whole, 10 halves on the edge.
    i, j = np.divmod(np.arange(100), 10)
    share = np.where(i + j < 9, 1.0, np.where(i + j == 9, 0.5, 0.0)) / 50.0
    keep = share > 0
    assert observed[~keep].sum() == 0
    assert_chi2(observed[keep], 200_000 * share[keep])


# -- files and scene files ------------------------------------------------------------------

OBJ = """# a unit square in the xz plane, facing up, as two triangles with uvs
v 0 0 0
v 1 0 0
v 1 0 1
v 0 0 1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
f 1/1 3/3 2/2
f 1/1 4/4 3/3
"""


def box_quads(lo, hi):
    """The six faces of an axis-aligned box as quads (Q, u, v), u x v outward."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    size = hi - lo
    out = []
    for axis in range(3):
        a, b = (axis + 1) % 3, (axis + 2) % 3
        u, v = np.eye(3)[a] * size[a], np.eye(3)[b] * size[b]        # u x v along +axis
        high = lo + np.eye(3)[axis] * size[axis]
        out += [(high, u, v), (lo, v, u)]
    return out


def test_a_box_turned_off_its_axes_is_the_box_of_six_turned_quads_or_triangles():
    lo, hi, turn = (0, 0, 0), (165, 330, 165), (30, 40, 50)
    for q, u, v in box_quads(lo, hi):            # the quads do face outward
        centre = np.add(q, np.add(u, v) / 2)
        assert np.cross(u, v) @ (centre - np.add(lo, hi) / 2) > 0

    def cornell(tall_box, turn=turn):
        s = rt.load_scene("cornell_box")
        out = rt.Scene(camera=s.camera)
        for o in s.objects:
            if o.kind == "box" and o.geometry == (lo, hi):
                for part in tall_box(o.material):
                    out.add(part.rotate(turn).translate((265, 100, 295)))
            else:
                out.add(o, light=any(o is light for light in s.lights))
        return out
    as_box = cornell(lambda m: [rt.box(lo, hi, m)])
    as_quads = cornell(lambda m: [rt.quad(q, u, v, m) for q, u, v in box_quads(lo, hi)])
    as_mesh = cornell(lambda m: [rt.mesh(box_mesh(lo, hi), m)])
    # Each through the kernels the file's other tests compile: the room without a
    # hierarchy, the mesh with one (which hit is nearest does not depend on it).
    a, b, c = (rt.render(s, spp=8, width=40, height=40, seed=3, sampling="mixture+sobol",
                         bvh=bvh) for s, bvh in ((as_box, False), (as_quads, False),
                                                 (as_mesh, True)))
    # The same surfaces met at the same places, up to rounding: the same
    # image to float32's precision.  A box turned wrong (or only about y)
    # would move whole pixels.
    np.testing.assert_allclose(b.image, a.image, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(c.image, a.image, rtol=1e-5, atol=1e-6)
    # ... and the test can tell: the box turned by [0, 40, 0] alone is another image.
    only_y = cornell(lambda m: [rt.box(lo, hi, m)], turn=(0, 40, 0))
    d = rt.render(only_y, spp=8, width=40, height=40, seed=3, sampling="mixture+sobol",
                  bvh=False)
    assert np.abs(d.image - a.image).max() > 0.1


def test_a_small_mesh_is_packed_by_numpy_into_the_compiled_packings_bits():
    # Meshes up to NUMPY_PACK_MAX triangles are packed by NumPy (nothing to
    # compile), larger ones by the compiled loop: both write the same rows.
    from rtweekend.path.shapes import triangle
    rng = np.random.default_rng(11)
    vertices = rng.normal(size=(500, 3)) * 10.0 ** rng.integers(-3, 4, size=(500, 1))
    faces = rng.integers(0, 500, size=(2000, 3))
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
                  & (faces[:, 0] != faces[:, 2])]
    compiled = np.full((len(faces), 16), 7.0)
    by_numpy = compiled.copy()
    triangle.pack(vertices, faces, 40, compiled)
    triangle.pack_rows(vertices, faces, 40, by_numpy)
    assert compiled.tobytes() == by_numpy.tobytes()
    assert by_numpy[-1, triangle.INDEX] == 40 + len(faces) - 1 and by_numpy[0, 15] == 7.0


def test_a_mesh_file_is_read_placed_and_scaled(tmp_path):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "square.obj").write_text(OBJ)
    (tmp_path / "s.toml").write_text("""
[camera]
lookfrom = [0, 5, 0]
lookat = [0, 0, 0]
vup = [0, 0, 1]
width = 8
height = 8

[[objects]]
type = "mesh"
file = "models/square.obj"
material = { type = "lambertian", albedo = [0.5, 0.5, 0.5] }
scale = 2
rotate_y = 90
translate = [10, 1, 0]
""")
    scene = rt.load_scene(tmp_path / "s.toml")
    (shape,) = scene.objects
    assert shape.kind == "mesh" and shape.area == pytest.approx(4.0)
    a = pack_scene(scene)
    assert (a.obj_i[:, 0] == TRIANGLE).all() and len(a.obj_i) == 2
    corners = a.obj_f[:, 0:9].reshape(-1, 3)
    # scale 2, then rotate_y 90 (x' = z, z' = -x), then translate.
    assert corners[:, 0].min() == pytest.approx(10) and corners[:, 0].max() == pytest.approx(12)
    assert corners[:, 2].min() == pytest.approx(-2) and corners[:, 2].max() == pytest.approx(0)
    np.testing.assert_allclose(corners[:, 1], 1.0)
    np.testing.assert_allclose(a.obj_f[:, 9:12], [[0, 1, 0]] * 2, atol=1e-12)   # faces up
    assert a.tris.uvs.shape == (2, 6)


def test_rotate_stands_a_z_up_model_up(tmp_path):
    # A Z-up file (as Blender writes it): a triangle lying in z = 0, facing +z,
    # with vertex normals, stretched along z by scale, then turned about x by
    # -90 degrees (y' = z, z' = -y) and moved.
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\n"
                                      "f 1//1 2//1 3//1\n")
    (tmp_path / "s.toml").write_text("""
[camera]
lookfrom = [0, 0, 5]
lookat = [0, 0, 0]
width = 8
height = 8

[[objects]]
type = "mesh"
file = "tri.obj"
material = { type = "lambertian", albedo = [0.5, 0.5, 0.5] }
scale = [1, 2, 3]
rotate = [-90, 0, 0]
translate = [10, 0, 0]
""")
    a = pack_scene(rt.load_scene(tmp_path / "s.toml"))
    corners = a.obj_f[0, 0:9].reshape(3, 3)
    # (x, y, z) scaled to (x, 2y, 3z), turned to (x, 3z, -2y), moved.
    np.testing.assert_allclose(corners, [[10, 0, 0], [11, 0, 0], [10, 0, -2]], atol=1e-12)
    np.testing.assert_allclose(a.obj_f[0, 9:12], (0, 1, 0), atol=1e-12)     # faces up
    np.testing.assert_allclose(a.tris.normals.reshape(3, 3), [[0, 1, 0]] * 3, atol=1e-12)


def test_flip_face_turns_a_one_sided_mesh_light_around():
    tri = (np.array([[-5.0, 1, -5], [5, 1, -5], [0, 1, 5]]), np.array([[0, 1, 2]]))

    def floor_lit(light):
        scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 0.5, 0), lookat=(0, 0, 0),
                                          vup=(0, 0, 1), vfov=10, width=2, height=2))
        scene.add(rt.xz_rect(-50, 50, -50, 50, 0, GREY))
        scene.add(light)
        return rt.render(scene, spp=16, seed=1, sampling="nee").image.mean()
    up = rt.mesh(tri, rt.diffuse_light((1, 1, 1)))
    n = np.cross(tri[0][1] - tri[0][0], tri[0][2] - tri[0][0])
    facing_up = n[1] > 0
    lit = [floor_lit(up), floor_lit(up.flip_face())]
    assert (lit[0] == 0) == facing_up and (lit[1] == 0) != facing_up


@pytest.mark.parametrize("body, message", [
    ('file = "nowhere.obj"', "file: no such mesh file: "),
    ('file = "text.obj"', "holds no triangles"),
    ('file = "nan.obj"', "file: vertex 0 is not finite: [nan, 0.0, 0.0]"),
    ('file = "badidx.obj"', "badidx.obj, line 4: corner '9' names vertex 9, but the file has 3 "
                            "vertices"),
    ('file = "zero.obj"', "zero.obj, line 5: corner '0' names vertex 0 (OBJ indices start at 1"),
    ('file = "flat.obj"', "none of its 1 triangles has an area"),
    ('file = "ok.obj"\nscale = 0', "scale: must not be 0"),
    ('file = "ok.obj"\nscale = "big"', "scale: "),
])
def test_bad_meshes_are_one_line_and_exit_2(tmp_path, body, message):
    if "nan.obj" in body:                   # the OBJ reader leaves 'nan' to trimesh
        pytest.importorskip("trimesh", reason="needs the meshes extra")
    files = {"ok.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
             "text.obj": "hello\nworld\n",
             "nan.obj": "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
             "badidx.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
             "zero.obj": "v 0 0 0\nv 1 0 0\nv 0 1 0\n# from 0\nf 0 1 2\n",
             "flat.obj": "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"}
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    (tmp_path / "s.toml").write_text(f"""
[[objects]]
type = "mesh"
name = "model"
{body}
material = {{ type = "lambertian", albedo = [0.5, 0.5, 0.5] }}
""")
    out = tmp_path / "out.png"
    r = subprocess.run([sys.executable, "-m", "rtweekend", "render", str(tmp_path / "s.toml"),
                        "-o", str(out), "--spp", "1"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rtweekend: error: ")
    assert "s.toml: objects[0] (mesh 'model'): " in lines[0] and message in lines[0], lines[0]
    assert not out.exists()


def test_bad_mesh_arrays_name_what_is_wrong():
    v, f = box_mesh((0, 0, 0), (1, 1, 1))
    cases = [((v[:, :2], f), "vertices: expected an array of shape (V, 3)"),
             ((v, f[:, :2]), "faces: expected triangles"),
             ((v, f[:0]), "has no triangles"),
             ((v, f + 8), "face 0 refers to vertex [8, 10, 9], but the mesh has 8 vertices"),
             ((v, f.astype(float)), "faces: expected integer vertex indices"),
             (5, "expected a file name or the arrays")]
    for arrays, message in cases:
        with pytest.raises(rt.SceneError, match="^mesh: ") as e:
            rt.mesh(arrays, GREY)
        assert message in str(e.value), str(e.value)


def test_a_scene_without_meshes_packs_no_mesh_tables():
    assert pack_scene(rt.load_scene("cornell_box")).tris is None


@pytest.mark.parametrize("sampling", ["bdpt+sobol", "mixture+sobol"])
def test_the_bundled_mesh_scene_renders_as_mitsuba_does(sampling):
    # cornell_mesh (a mirror torus knot of 5,600 triangles in the Cornell box)
    # against Mitsuba 3's converged render of it (its own ply loader and BVH),
    # quarter by quarter as the failure scenes are (test_failures.py).  Its
    # knot.obj is read by the compiled OBJ reader: no trimesh needed.
    from conftest import failure_reference
    from stats import block_se, blocks
    reference, ref_se = failure_reference("cornell_mesh")
    r = rt.render(rt.load_scene("cornell_mesh"), spp=128, width=100, height=100,
                  sampling=sampling, seed=11, threads=2)
    assert r.stats.nan_dropped == 0
    se = np.hypot(block_se(r.stderr, 50), block_se(ref_se, 50))
    z = (blocks(r.image, 50) - blocks(reference, 50)) / se
    assert z.size == 12 and np.abs(z).max() < 5, z


def test_the_memory_check_counts_a_meshs_tables(monkeypatch):
    # What packing a mesh makes -- its rows, the wide BVH, its triangles in
    # blocks, vertex normals and uvs -- is within the estimate the memory
    # check uses before packing, and a mesh that does not fit is refused in
    # one line, before anything is packed.
    from rtweekend import memory
    from rtweekend.path import pack, renderer

    def nbytes(x):
        if isinstance(x, np.ndarray):
            return x.nbytes
        if isinstance(x, tuple):
            return sum(nbytes(y) for y in x)
        return 0
    v, f = sphere_mesh(60, 120)
    uv = np.random.default_rng(1).random((len(v), 2))
    scene = rt.Scene(camera=rt.Camera(width=4, height=4))
    scene.add(rt.mesh((v, f, uv, v), GREY))
    scene.add(rt.xz_rect(-5, 5, -5, 5, 3, rt.diffuse_light((1, 1, 1))), light=True)
    packed = nbytes(pack_scene(scene))
    assert packed < pack.scene_bytes(scene) < 4 * packed
    monkeypatch.setattr(memory, "available", lambda: (pack.scene_bytes(scene), "MemAvailable"))
    packing = []
    monkeypatch.setattr(renderer, "pack_scene", lambda *a, **k: packing.append(a))
    with pytest.raises(rt.SceneError, match=rf"the scene's 2 objects \({len(f) + 1:,} "
                       r"primitives: a mesh's triangles count one each\) need about "):
        rt.render(scene, spp=1)
    assert packing == []
