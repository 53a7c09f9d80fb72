"""The rtweekend command, run as users run it: in a subprocess."""
import os
import signal
import subprocess
import sys
import threading
import time

import imageio.v3 as iio
import numpy as np
import pytest

import rtweekend as rt

CMD = [sys.executable, "-m", "rtweekend"]


def run(*args, cwd=None):
    return subprocess.run(CMD + list(args), capture_output=True, text=True, cwd=cwd,
                          timeout=300)


def test_render_writes_the_png_and_a_summary(tmp_path):
    out = tmp_path / "box.png"
    r = run("render", "cornell_box", "-o", str(out), "--spp", "2", "--width", "24",
            "--height", "16", "--seed", "3", "--max-depth", "5", "--threads", "1")
    assert r.returncode == 0, r.stderr
    assert iio.imread(out).shape == (16, 24, 3)
    last = r.stdout.strip().splitlines()[-1]
    assert "24x16, 2 spp" in last and "samples/s" in last and "rays/s" in last
    assert "0 NaN/Inf samples dropped" in last


def test_cli_image_is_the_api_image(tmp_path):
    out = tmp_path / "m.npy"
    r = run("render", "metals", "-o", str(out), "--spp", "3", "--width", "20",
            "--height", "12", "--seed", "4", "-q")
    assert r.returncode == 0, r.stderr
    api, _ = rt.render(rt.load_scene("metals"), spp=3, width=20, height=12, seed=4)
    assert np.array_equal(np.load(out), api)


def test_default_scene_and_output_name(tmp_path):
    r = run("render", "--spp", "1", "--width", "8", "--height", "8", "-q", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "cornell_glass.png").exists()


def test_scenes_lists_every_bundled_scene():
    r = run("scenes")
    assert r.returncode == 0
    lines = r.stdout.strip().splitlines()
    for name, description in rt.bundled_scenes().items():
        assert any(line.startswith(name) and description in line for line in lines)


@pytest.mark.parametrize("args, message", [
    (["render", "no_such_scene"], "bundled scenes (bouncing_spheres, caustic, cgfs, "
                                  "checkered_spheres, cornell_box, cornell_glass"),
    (["render", "metals", "--spp", "4", "--time", "2"], "not allowed with"),
    (["render", "metals", "--spp", "0"], "must be >= 1"),
    (["render", "metals", "-o", "x.gif2"], "unknown output extension"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, args, message):
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and message in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_keeps_the_passes_rendered(tmp_path):
    out = tmp_path / "partial.npy"
    p = subprocess.Popen(CMD + ["render", "cornell_box", "-o", str(out), "--spp", "100000",
                                "--width", "64", "--height", "64"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    seen = bytearray()

    def pump():
        while chunk := p.stderr.read1(256):
            seen.extend(chunk)
    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    deadline = time.monotonic() + 120
    # The bar's "2/100000 spp": two samples in every pixel (early passes may
    # cover part of the rows).
    while b" 2/100000 spp" not in seen and time.monotonic() < deadline and p.poll() is None:
        time.sleep(0.05)
    assert b" 2/100000 spp" in seen, seen.decode(errors="replace")
    p.send_signal(signal.SIGINT)
    p.wait(timeout=120)
    reader.join(timeout=10)             # stderr is read by the pump alone
    stdout = p.stdout.read()
    assert p.returncode == 130
    summary = stdout.decode().strip().splitlines()[-1]
    assert "interrupted" in summary and "of 100000 spp" in summary
    spp = int(summary.split("interrupted: ")[1].split(" of")[0])
    assert 2 <= spp < 100000
    assert f"holds the {spp} spp rendered" in seen.decode()
    image = np.load(out)
    assert image.shape == (64, 64, 3) and np.isfinite(image).all() and image.mean() > 0
    assert [f.name for f in tmp_path.iterdir()] == ["partial.npy"]


def test_render_help_has_examples_ctrl_c_and_exit_status():
    r = run("render", "--help")
    assert r.returncode == 0
    assert "examples:" in r.stdout and "rtweekend render cornell_box --spp 16" in r.stdout
    assert "status 130" in r.stdout and "status 2" in r.stdout
    assert "SCENE.png in the current folder" in r.stdout


def test_option_errors_have_the_prefix_of_every_other_error():
    r = run("render", "--spp", "0")
    assert r.returncode == 2
    assert r.stderr.strip() == ("rtweekend: error: render: --spp: must be >= 1, got 0 "
                                "(see rtweekend render --help)")
    r = run("render", "no_such_scene")
    assert r.stderr.startswith("rtweekend: error: ")


def test_cache_lists_and_clears_what_no_source_matches_any_more(tmp_path):
    # A cache of its own: a kernel of the sources as they are (compiled here),
    # one of an edited version of its module, and an earlier release's folder.
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    compiled = subprocess.run([sys.executable, "-c", "from rtweekend.kernel.vec3 import dot; "
                               "print(dot((1.0, 2.0, 3.0), (4.0, 5.0, 6.0)))"], env=env,
                              capture_output=True, text=True, timeout=300)
    assert compiled.stdout.strip() == "32.0"
    kernels = tmp_path / "kernels"
    current = sorted(p.name for p in kernels.rglob("*") if p.is_file())
    assert any(name.startswith("vec3.dot-") for name in current)
    stale = kernels / "rtweekend" / "kernel" / "vec3.dot-10-0123456789abcdef.py311.nbi"
    stale.write_bytes(b"x" * 1_000_000)
    old = tmp_path / "numba-0123456789abcdef"
    old.mkdir()
    (old / "kernel.nbc").write_bytes(b"x" * 2_000_000)
    listed = subprocess.run(CMD + ["cache"], capture_output=True, text=True, env=env,
                            timeout=120)
    assert listed.returncode == 0
    first, second = listed.stdout.splitlines()
    assert first.startswith(str(kernels)) and "of which 1.0 MB built from sources" in first
    assert second.startswith(str(old)) and "2.0 MB" in second
    cleared = subprocess.run(CMD + ["cache", "clear"], capture_output=True, text=True,
                             env=env, timeout=120)
    assert cleared.returncode == 0 and cleared.stdout.startswith("removed 2 files, 3.0 MB")
    assert not old.exists()
    assert sorted(p.name for p in kernels.rglob("*") if p.is_file()) == current
    everything = subprocess.run(CMD + ["cache", "clear", "--all"], capture_output=True,
                                text=True, env=env, timeout=120)
    assert everything.returncode == 0
    assert [p.name for p in kernels.rglob("*") if p.is_file()] == [".lock"]
