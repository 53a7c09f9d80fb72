"""Scene files: the bundled scenes, the TOML <-> builder equivalence, defaults."""
import numpy as np
import pytest

import rtweekend as rt
from rtweekend.path.camera import pack_camera
from rtweekend.path.layout import BG_SKY, SPHERE, XZ_RECT
from rtweekend.path.lights import listed
from rtweekend.path.pack import pack_scene


def cornell_glass_in_python():
    """The Rest of Your Life's final scene, built the way its main.cc builds it."""
    red = rt.lambertian((.65, .05, .05))
    white = rt.lambertian((.73, .73, .73))
    green = rt.lambertian((.12, .45, .15))
    light = rt.diffuse_light((15, 15, 15))
    aluminium = rt.metal((0.8, 0.85, 0.88), 0.0)
    glass = rt.dielectric(1.5)
    scene = rt.Scene(camera=rt.Camera(lookfrom=(278, 278, -800), lookat=(278, 278, 0),
                                      vup=(0, 1, 0), vfov=40, aperture=0, focus_dist=10,
                                      width=600, height=600),
                     background=(0, 0, 0), spp=100, max_depth=50)
    scene.add(rt.yz_rect(0, 555, 0, 555, 555, green))
    scene.add(rt.yz_rect(0, 555, 0, 555, 0, red))
    scene.add(rt.xz_rect(213, 343, 227, 332, 554, light).flip_face(), light=True)
    scene.add(rt.xz_rect(0, 555, 0, 555, 0, white))
    scene.add(rt.xz_rect(0, 555, 0, 555, 555, white))
    scene.add(rt.xy_rect(0, 555, 0, 555, 555, white))
    box1 = rt.box((0, 0, 0), (165, 330, 165), aluminium).rotate_y(15).translate((265, 0, 295))
    scene.add(box1)
    scene.add(rt.sphere((190, 90, 190), 90, glass), light=True)
    return scene


def _sorted_rows(a):
    rows = np.hstack([a.obj_i, a.obj_f, a.mat_f[a.obj_i[:, 1]]])
    return rows[np.lexsort(rows.T[::-1])]


def test_toml_and_builder_give_the_same_arrays():
    from_file = rt.load_scene("cornell_glass")
    built = cornell_glass_in_python()
    a, b = pack_scene(from_file), pack_scene(built)
    # The file lists floor/ceiling in another order: compare as sets of rows.
    assert np.allclose(_sorted_rows(a), _sorted_rows(b))
    assert np.allclose(pack_camera(from_file.camera), pack_camera(built.camera))
    assert (from_file.spp, from_file.max_depth) == (built.spp, built.max_depth)
    # lights: the flipped light rect and the glass sphere, in both
    for arr in (a, b):
        kinds = arr.obj_i[listed(arr), 0]
        assert sorted(kinds) == [SPHERE, XZ_RECT]


@pytest.mark.parametrize("name, objects, lights, size", [
    ("cornell_glass", 8, 2, (600, 600)),
    ("cornell_box", 8, 1, (600, 600)),
    ("metals", 4, 0, (400, 225)),
    ("weekend", 487, 0, (1200, 675)),
])
def test_bundled_scenes(name, objects, lights, size):
    scene = rt.load_scene(name)
    a = pack_scene(scene)
    assert len(a.obj_i) == objects and len(listed(a)) == lights
    assert (scene.camera.width, scene.camera.height) == size
    assert scene.description
    assert name in rt.bundled_scenes()


def test_weekend_follows_the_book():
    scene = rt.load_scene("weekend")
    a = pack_scene(scene)
    assert a.bg_kind == BG_SKY
    assert scene.camera.vfov == 20 and scene.camera.aperture == 0.1
    small = np.isclose(a.obj_f[:, 3], 0.2)
    assert small.sum() == 483
    kinds = a.mat_i[a.obj_i[small, 1]]
    # the book's mix: 80% diffuse, 15% metal, 5% glass (binomial, n = 483)
    frac = np.bincount(kinds, minlength=4)[:3] / small.sum()
    assert abs(frac[0] - 0.80) < 0.06 and abs(frac[1] - 0.15) < 0.05
    assert abs(frac[2] - 0.05) < 0.03
    c = a.obj_f[small, :3]
    assert (np.hypot(c[:, 0] - 4, c[:, 2]) > 0.9).all()


def test_a_scene_declares_only_what_it_uses(tmp_path):
    f = tmp_path / "tiny.toml"
    f.write_text('[[objects]]\ntype = "sphere"\ncenter = [0, 0, -1]\nradius = 0.5\n'
                 'material = { type = "lambertian", albedo = [0.5, 0.5, 0.5] }\n')
    scene = rt.load_scene(f)
    cam = scene.camera
    assert (cam.lookfrom, cam.lookat, cam.vup, cam.vfov) == ((0, 0, 0), (0, 0, -1),
                                                            (0, 1, 0), 90)
    assert cam.focus_dist == 1.0 and cam.aperture == 0.0
    assert (scene.spp, scene.resolved_max_depth(), scene.resolved_background()) == \
        (100, 50, (0.0, 0.0, 0.0))
    assert scene.name == "tiny" and scene.lights == []


def test_metal_fuzz_is_clamped_to_one_as_in_the_book():
    assert rt.metal((1, 1, 1), 3.0).param == 1.0


def test_unknown_scene_names_the_bundled_ones():
    with pytest.raises(rt.SceneError, match="cornell_glass"):
        rt.load_scene("cornel_glass")
