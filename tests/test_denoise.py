"""Denoising with Open Image Denoise (rtweekend/denoise.py): the unbiased image
untouched beside the denoised one, a real gain against an independent
reference, the light seen directly kept out of the filter, the features saved
as layers, and one line when the extra is missing."""
import os
import subprocess
import sys

import numpy as np
import pytest

import rtweekend as rt
from rtweekend.errors import SceneError
from watch import Watched

pytest.importorskip("pyoidn", reason="the denoise extra is not installed")

CMD = [sys.executable, "-m", "rtweekend"]


def _rmse(a, b):
    return float(np.sqrt(np.mean((a.astype(np.float64) - b) ** 2)))


def test_the_unbiased_image_is_the_same_bits_with_and_without_denoising():
    scene = rt.load_scene("cornell_glass")
    plain = rt.render(scene, spp=8, width=32, height=32, seed=5)
    both = rt.render(scene, spp=8, width=32, height=32, seed=5, denoise=True)
    assert np.array_equal(plain.image, both.image)
    assert np.array_equal(plain.stderr, both.stderr)
    assert plain.denoised is None and both.denoised.shape == (32, 32, 3)
    assert both.denoised.dtype == np.float32 and np.isfinite(both.denoised).all()
    assert both.denoised.min() >= 0.0
    assert both.aov == {}                      # features made for it, not asked for
    assert both.stats.denoise_seconds > 0 and "denoised in" in both.stats.summary()


def test_denoising_cuts_the_error_against_mitsuba(cornell_reference):
    # cornell_box at 16 spp against Mitsuba's 8192-spp render: OIDN with the
    # albedo and normal removes most of the noise (measured 0.2-0.3x).
    reference, _ = cornell_reference
    r = rt.render(rt.load_scene("cornell_box"), spp=16, width=300, height=300, seed=6,
                  denoise=True)
    raw, denoised = _rmse(r.image, reference), _rmse(r.denoised, reference)
    assert denoised < 0.5 * raw, f"denoised RMSE {denoised:.4f} vs raw {raw:.4f}"


def test_the_light_seen_directly_is_kept_out_of_the_filter():
    # The Cornell light (radiance 15) seen directly is added back after the
    # filter: where every sample saw it, the denoised pixel is 15 plus what
    # the filter makes of nothing (a trace of its neighbours' light), not a
    # blur of 15 with the ceiling around it.
    r = rt.render(rt.load_scene("cornell_box"), spp=16, width=60, height=60, seed=7,
                  denoise=True, aov="emission")
    lit = r.aov["emission"].min(axis=2) >= 15.0
    assert lit.sum() >= 8
    np.testing.assert_array_equal(r.image[lit], 15.0)
    np.testing.assert_allclose(r.denoised[lit], 15.0, rtol=0.005)


def test_denoising_is_repeatable_and_the_same_for_any_thread_count():
    # The renderer's image is the same bits for any thread count; OIDN on one
    # machine gives the same output for the same input (it makes no promise
    # across CPUs or versions, so neither do we).
    scene = rt.load_scene("cornell_box")
    one = rt.render(scene, spp=4, width=40, height=40, seed=8, threads=1, denoise=True)
    two = rt.render(scene, spp=4, width=40, height=40, seed=8, threads=2, denoise=True)
    assert np.array_equal(one.image, two.image)
    assert np.array_equal(one.denoised, two.denoised)


def test_a_renderer_denoises_what_it_has_so_far():
    r = rt.Renderer(rt.load_scene("cornell_box"), width=24, height=24, seed=1, denoise=True)
    r.add_samples(2)
    first = r.result()
    r.add_samples(2)
    assert first.denoised is not None and r.result().stats.spp == 4
    plain = rt.Renderer(rt.load_scene("cornell_box"), width=24, height=24, seed=1)
    plain.add_samples(1)
    assert plain.result().denoised is None
    with pytest.raises(SceneError, match="keeps no feature images"):
        plain.result(denoise=True)


def test_light_tracing_cannot_be_denoised():
    with pytest.raises(SceneError, match="no feature images to denoise"):
        rt.render(rt.load_scene("cornell_box"), spp=1, width=4, height=4,
                  sampling="lightpath", denoise=True)


def test_the_command_writes_the_denoised_image_with_the_unbiased_one_and_features(tmp_path):
    OpenEXR = pytest.importorskip("OpenEXR", reason="the exr extra is not installed")
    out = tmp_path / "box.exr"
    r = subprocess.run(CMD + ["render", "cornell_box", "-o", str(out), "--spp", "4", "--width",
                              "20", "--height", "16", "--seed", "2", "--denoise", "--aov",
                              "albedo,normal", "-q"], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    assert "denoised in" in r.stdout
    with OpenEXR.File(str(out), separate_channels=True) as f:
        names = set(f.channels())
    assert {"R", "G", "B", "unbiased.R", "albedo.G", "normal.B"} <= names
    same = rt.render(rt.load_scene("cornell_box"), spp=4, width=20, height=16, seed=2)
    with OpenEXR.File(str(out)) as f:
        header = dict(f.header())
        unbiased = f.channels()["unbiased"].pixels
    assert header["rtweekend.spp"] == "4" and header["rtweekend.denoised"] == "True"
    assert header["rtweekend.sampling"] == "mixture+sobol"
    assert np.array_equal(unbiased, same.image)


def test_npy_layers_go_beside_the_image(tmp_path):
    out = tmp_path / "box.npy"
    r = subprocess.run(CMD + ["render", "cornell_box", "-o", str(out), "--spp", "2", "--width",
                              "12", "--height", "10", "--aov", "albedo", "-q"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    albedo = np.load(tmp_path / "box.albedo.npy")
    assert albedo.shape == (10, 12, 3) and 0 < albedo.max() <= 1.0
    r = subprocess.run(CMD + ["render", "cornell_box", "-o", str(tmp_path / "x.png"), "--aov",
                              "albedo", "--spp", "1"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 2 and "only .npy and .exr" in r.stderr
    assert not (tmp_path / "x.png").exists()


def test_without_the_extra_one_line_and_exit_2_before_rendering(tmp_path):
    # A pyoidn that cannot be imported, first on the path.
    (tmp_path / "fake").mkdir()
    (tmp_path / "fake" / "pyoidn.py").write_text("raise ImportError('No module named pyoidn')\n")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(tmp_path / "fake")] + os.environ.get("PYTHONPATH", "").split(os.pathsep)))
    out = tmp_path / "box.png"
    r = subprocess.run(CMD + ["render", "cornell_box", "-o", str(out), "--denoise"],
                       capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode == 2
    assert r.stderr.strip() == ("rtweekend: error: render: denoise: needs Open Image Denoise: "
                                "pip install 'rtweekend[denoise]'")
    assert not out.exists()


def test_ctrl_c_denoises_what_was_rendered(tmp_path):
    out = tmp_path / "partial.npy"
    run = Watched(CMD + ["render", "cornell_box", "-o", str(out), "--spp", "100000",
                         "--width", "48", "--height", "48", "--denoise"])
    run.wait_for(b" 2/100000 spp")
    run.interrupt()
    status, stdout, _ = run.finish(timeout=120)
    summary = stdout.strip().splitlines()[-1]
    assert status == 130
    assert "interrupted" in summary and "denoised in" in summary
    denoised, unbiased = np.load(out), np.load(tmp_path / "partial.unbiased.npy")
    assert denoised.shape == unbiased.shape == (48, 48, 3)
    assert np.isfinite(denoised).all() and not np.array_equal(denoised, unbiased)
