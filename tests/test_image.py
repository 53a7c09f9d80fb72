"""Output files: the books' tone map, linear floats, atomic writes."""
import os

import imageio.v3 as iio
import numpy as np
import pytest

import rtweekend as rt
from rtweekend.io.image import tonemap


def test_tonemap_is_the_books_write_color():
    # int(256 * clamp(sqrt(c), 0, 0.999))
    c = np.array([[[0.0, 0.25, 1.0], [4.0, -1.0, np.nan], [0.01, 0.5, 0.9]]])
    expected = [[[0, 128, 255], [255, 0, 0], [25, 181, 242]]]
    assert tonemap(c).tolist() == expected


@pytest.fixture
def image():
    rng = np.random.default_rng(0)
    return (rng.random((7, 5, 3)) * 2).astype(np.float32)


def test_png_holds_the_tone_mapped_pixels(tmp_path, image):
    rt.save_image(image, tmp_path / "a.png")
    assert np.array_equal(iio.imread(tmp_path / "a.png"), tonemap(image))


def test_npy_holds_linear_float32(tmp_path, image):
    rt.save_image(image, tmp_path / "a.npy")
    back = np.load(tmp_path / "a.npy")
    assert back.dtype == np.float32 and np.array_equal(back, image)


def test_exr_holds_linear_float32(tmp_path, image):
    OpenEXR = pytest.importorskip("OpenEXR", reason="the exr extra is not installed")
    rt.save_image(image, tmp_path / "a.exr")
    with OpenEXR.File(str(tmp_path / "a.exr")) as f:
        back = f.channels()["RGB"].pixels
    assert back.dtype == np.float32 and np.array_equal(back, image)


def test_a_failed_write_leaves_the_old_file_and_no_debris(tmp_path, image, monkeypatch):
    target = tmp_path / "a.png"
    target.write_bytes(b"old")

    def broken_replace(src, dst):
        raise OSError("disk full")
    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError):
        rt.save_image(image, target)
    assert target.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["a.png"]


@pytest.mark.parametrize("name, message", [
    ("a.gif2", "unknown output extension"),
    ("missing/a.png", "does not exist"),
])
def test_bad_output_paths(tmp_path, image, name, message):
    with pytest.raises(rt.SceneError, match=message):
        rt.save_image(image, tmp_path / name)
    assert not (tmp_path / name).exists()


def test_wrong_shape_writes_nothing(tmp_path):
    with pytest.raises(rt.SceneError, match="HxWx3"):
        rt.save_image(np.zeros((4, 4)), tmp_path / "a.png")
    assert os.listdir(tmp_path) == []


def test_a_result_shows_itself_as_its_tone_mapped_png():
    r = rt.render(rt.load_scene("cornell_box"), spp=2, width=20, height=12, seed=1)
    shown = iio.imread(r._repr_png_())
    assert np.array_equal(shown, rt.tonemap(r.image))
    html = r._repr_html_()
    assert html.startswith("<figure") and "data:image/png;base64," in html
    assert "20x12, 2 spp, mixture+sobol" in html and "standard error" in html


def test_tonemap_is_the_books_and_exposure_scales_the_radiance_first():
    image = np.array([[[0.0, 0.25, 1.0], [4.0, np.nan, -1.0]]])
    assert rt.tonemap(image).tolist() == [[[0, 128, 255], [255, 0, 0]]]
    assert rt.tonemap(image, exposure=4.0)[0, 0].tolist() == [0, 255, 255]


def test_a_scene_shows_itself_in_one_line():
    text = repr(rt.load_scene("cornell_glass"))
    assert text == ("Scene('cornell_glass', 600x600, 8 objects: 5 lambertian, "
                    "1 diffuse_light, 1 metal, 1 dielectric; 2 in lights)")
    assert "\n" not in repr(rt.load_scene("next_week_final"))
