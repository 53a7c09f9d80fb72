"""The classic ray tracer from the scene file, the command and the API."""
import imageio.v3 as iio
import numpy as np
import pytest

import rtweekend as rt
from rtweekend.classic.kernel import classic_arrays, render_canvas
from rtweekend.cli import main
from rtweekend.io.image import tonemap

from test_classic import DEMO_LIGHTS, DEMO_SPHERES, twin_render


def _demo_canvas(width, height, depth=3):
    return render_canvas(*classic_arrays(DEMO_SPHERES, DEMO_LIGHTS), width, height, depth)


def test_cgfs_is_a_classic_scene():
    scene = rt.load_scene("cgfs")
    assert scene.resolved_integrator() == "classic"
    assert isinstance(scene.resolved_camera(), rt.ClassicCamera)
    assert scene.resolved_max_depth() == 3
    assert [lt.kind for lt in scene.lights] == ["ambient", "point", "directional"]
    assert rt.load_scene("cornell_box").resolved_integrator() == "path"


def test_the_command_writes_the_books_figure(tmp_path, capsys):
    out = tmp_path / "cgfs.png"
    assert main(["render", "cgfs", "-o", str(out), "-q"]) == 0
    png = iio.imread(out)
    assert png.shape == (600, 600, 3)
    # The kernel's own test compares it with an independent NumPy twin of the
    # book's algorithm; here the file must be exactly the kernel's canvas.
    assert np.array_equal(png, _demo_canvas(600, 600))
    assert "classic ray tracer" in capsys.readouterr().out


def test_file_matches_the_numpy_twin_of_the_book(tmp_path):
    # End to end against the independent twin, on a smaller canvas.
    out = tmp_path / "small.png"
    assert main(["render", "cgfs", "-o", str(out), "-q", "--width", "64",
                 "--height", "48"]) == 0
    twin = twin_render(DEMO_SPHERES, DEMO_LIGHTS, 64, 48, 3)
    diff = np.abs(iio.imread(out).astype(int) - twin.astype(int))
    assert diff.max() <= 1 and (diff > 0).sum() <= 3


def test_depth_and_size_overrides(tmp_path):
    r = rt.render(rt.load_scene("cgfs"), width=40, height=30, max_depth=0)
    canvas = _demo_canvas(40, 30, 0)
    assert r.image.shape == (30, 40, 3)
    # Linear radiance, as for every scene: the canvas colour c is (c / 255)**2.
    assert np.array_equal(r.image, ((canvas / 255.0) ** 2).astype(np.float32))
    rt.save_image(r, tmp_path / "c.png")
    assert np.array_equal(iio.imread(tmp_path / "c.png"), canvas)
    assert r.stats.rays > 40 * 30                  # primary + shadow rays


def test_every_documented_way_of_saving_writes_the_canvas(tmp_path):
    # The README shows both: saving the result, and saving the unpacked image.
    scene = rt.load_scene("cgfs")
    result = rt.render(scene, width=40, height=30)
    image, stats = rt.render(scene, width=40, height=30)
    rt.save_image(result, tmp_path / "result.png")
    rt.save_image(image, tmp_path / "image.png")
    rt.save_image(result.image, tmp_path / "result_image.png")
    canvas = _demo_canvas(40, 30)
    for name in ("result.png", "image.png", "result_image.png"):
        assert np.array_equal(iio.imread(tmp_path / name), canvas), name
    assert (tmp_path / "result.png").read_bytes() == (tmp_path / "image.png").read_bytes()
    # The command writes the same file too.
    assert main(["render", "cgfs", "-o", str(tmp_path / "cli.png"), "-q", "--width", "40",
                 "--height", "30"]) == 0
    assert (tmp_path / "cli.png").read_bytes() == (tmp_path / "image.png").read_bytes()


def test_the_tone_map_gives_back_every_canvas_colour():
    from rtweekend.classic.render import canvas_radiance
    from rtweekend.io.image import tonemap
    c = np.arange(256, dtype=np.uint8).reshape(16, 16, 1).repeat(3, axis=2)
    assert np.array_equal(tonemap(canvas_radiance(c)), c)


def test_builder_api_makes_the_same_scene():
    scene = rt.Scene(camera=rt.ClassicCamera(width=32, height=32), max_depth=3)
    for s in DEMO_SPHERES:
        scene.add(rt.sphere(s["center"], s["radius"],
                            rt.phong(s["color"], s["specular"], s["reflective"])))
    scene.lights += [rt.ambient(0.2), rt.point(0.6, (2, 1, 0)),
                     rt.directional(0.2, (1, 4, 4))]
    r = rt.render(scene)
    assert np.array_equal(tonemap(r.image), _demo_canvas(32, 32))


@pytest.mark.parametrize("args, words", [
    (["--spp", "4"], ["spp does not apply to the classic ray tracer"]),
    (["--time", "1"], ["time does not apply"]),
    (["--sampling", "cosine"], ["sampling does not apply"]),
    (["--clamp", "3"], ["clamp does not apply"]),
])
def test_path_options_are_errors_for_a_classic_scene(tmp_path, capsys, args, words):
    out = tmp_path / "x.png"
    assert main(["render", "cgfs", "-o", str(out), "-q", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and all(w in err[0] for w in words)
    assert not out.exists()


MIXED = """
[[lights]]
type = "ambient"
intensity = 0.5

[[objects]]
type = "sphere"
center = [0, 0, 3]
radius = 1
material = {{ type = "{material}", {fields} }}
{extra}
"""


@pytest.mark.parametrize("material, fields, extra, words", [
    ("lambertian", "albedo = [0.5, 0.5, 0.5]", "",
     ["mixes the classic ray tracer and the path tracer", "ambient light",
      "lambertian material"]),
    ("phong", "color = [255, 0, 0]", 'integrator = "path"',
     ["integrator: path, but", "phong material"]),
    ("phong", "color = [255, 0, 0]", "[camera]\nlookfrom = [0, 0, -5]",
     ["mixes", "camera is the path tracer's"]),
    ("phong", "color = [255, 0, 0]", "[render]\nspp = 10",
     ["render: spp: does not apply to the classic ray tracer"]),
    ("phong", "color = [255, 0, 300]", "", ["color: components must be <= 255"]),
    ("phong", "color = [255, 0, 0], specular = -3", "", ["specular: must be -1 (matte)"]),
    ("phong", "color = [255, 0, 0], reflective = 2", "", ["reflective: must be <= 1"]),
])
def test_scenes_that_cannot_be_rendered(tmp_path, material, fields, extra, words):
    text = MIXED.format(material=material, fields=fields, extra=extra)
    if extra.startswith("integrator"):
        text = extra + "\n" + MIXED.format(material=material, fields=fields, extra="")
    path = tmp_path / "mixed.toml"
    path.write_text(text)
    with pytest.raises(rt.SceneError) as info:
        rt.load_scene(path)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message
    for w in words:
        assert w in message, (w, message)


def test_a_rect_in_a_classic_scene_is_an_error():
    scene = rt.Scene(integrator="classic")
    scene.add(rt.xy_rect(0, 1, 0, 1, 0, rt.phong((255, 255, 255))))
    with pytest.raises(rt.SceneError, match="spheres only"):
        rt.render(scene)


@pytest.mark.parametrize("light, field", [
    ({"type": "point", "intensity": 0.5}, "position: missing"),
    ({"type": "directional", "intensity": 0.5, "direction": [0, 0, 0]}, "must not be"),
    ({"type": "ambient", "intensity": -1}, "intensity: must be >= 0"),
    ({"type": "spot", "intensity": 1}, "'spot' is not a light type"),
])
def test_bad_classic_lights(light, field):
    from rtweekend.scene.loader import scene_from_dict
    doc = {"lights": [light], "objects": [{"type": "sphere", "center": [0, 0, 3], "radius": 1,
                                           "material": {"type": "phong",
                                                        "color": [1, 2, 3]}}]}
    with pytest.raises(rt.SceneError, match=field):
        scene_from_dict(doc)
