"""Passes sized by time, Ctrl-C (real signals, in subprocesses), the memory
check, and what the summary says about compiling (issue #16)."""
import os
import subprocess
import sys
import time
import tomllib
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import REPO
from watch import Watched

import rtweekend as rt
from rtweekend import local, memory
from rtweekend.path import film as films
from rtweekend.result import RenderStats

CMD = [sys.executable, "-m", "rtweekend"]

# A closed box of perfect mirrors with the camera inside: every path bounces
# max_depth times, so a sample costs what max_depth says, at any image size.
MIRROR_BOX = """
[camera]
lookfrom = [0, 0, 0]
lookat = [0, 0, -1]
width = {width}
height = {height}

[render]
max_depth = {depth}

[materials]
mirror = {{ type = "metal", albedo = [1, 1, 1], fuzz = 0 }}

[[objects]]
type = "box"
p0 = [-1, -1, -1]
p1 = [1, 1, 1]
material = "mirror"
"""


def mirror_box(tmp_path, width, height, depth):
    path = tmp_path / "mirrors.toml"
    path.write_text(MIRROR_BOX.format(width=width, height=height, depth=depth))
    return path


class Run(Watched):
    """`rtweekend ...` in a subprocess; finish() gives stderr's lines without the bar."""

    def __init__(self, *args, env=None, cwd=None):
        super().__init__(CMD + list(args), env=env, cwd=cwd)

    def finish(self, timeout):
        """Wait at most `timeout` s; (status, stdout, stderr lines without the bar)."""
        status, out, err = super().finish(timeout)
        # The bar rewrites its line with \r: keep what follows the last one.
        lines = [line.rsplit("\r", 1)[-1].strip() for line in err.split("\n")]
        return status, out, [line for line in lines if line]


# -- passes sized by time ------------------------------------------------------

def fake(spp=0, seconds=0.0, width=100, height=1000, band=0, rows_done=0):
    return SimpleNamespace(spp=spp, seconds=seconds, width=width, height=height, band=band,
                           rows_done=rows_done)


def test_first_pass_is_one_row_per_thread():
    assert local.next_pass(fake(), 10, None, 0, threads=2) == (1, 2)
    assert local.next_pass(fake(height=1), 10, None, 0, threads=2) == (1, 1)


def test_a_long_full_pass_becomes_passes_over_part_of_the_rows():
    # 4 rows took 0.02 s: a whole pass (1000 rows) would take 5 s, 10x too long.
    r = fake(band=1, rows_done=4, seconds=0.02)
    n, rows = local.next_pass(r, 10, None, last=4, threads=2)
    assert (n, rows) == (1, 16)                          # growth capped at 4x
    n, rows = local.next_pass(r, 10, None, last=1000, threads=2)
    assert (n, rows) == (1, 100)                         # 0.5 s of rows
    # A whole pass of 0.05 s: whole passes of ~10 spp.
    assert local.next_pass(fake(spp=1, seconds=0.05), 100, None, 1000) == (4, 1000)
    assert local.next_pass(fake(spp=1, seconds=0.05), 100, None, 10**6) == (10, 1000)
    assert local.next_pass(fake(spp=10, seconds=0.5), 10, None, 10**6) is None


def test_a_time_budget_finishes_the_pass_it_started():
    # 1 s per whole pass, 2.2 s spent of a 2 s budget, mid-pass: finish it.
    r = fake(spp=2, seconds=2.2, band=1, rows_done=500)
    assert local.next_pass(r, None, 2.0, last=500) == (1, 500)
    # Not mid-pass: stop.
    assert local.next_pass(fake(spp=2, seconds=1.9), None, 2.0, last=1000) is None
    # An image whose one spp does not fit at all: the rows the budget allows.
    r = fake(spp=0, seconds=1.0, band=1, rows_done=100)     # 10 s per whole pass
    assert local.next_pass(r, None, 2.0, last=100) == (1, 50)
    assert local.next_pass(fake(spp=0, seconds=2.0, band=1, rows_done=200), None, 2.0,
                           last=100) is None


@pytest.fixture(scope="module")
def cornell_box():
    return rt.load_scene("cornell_box")


def test_passes_over_part_of_the_rows_give_the_bits_of_one_pass(cornell_box):
    whole = rt.Renderer(cornell_box, seed=7, width=24, height=20)
    whole.add_samples(19)                 # crosses a block of 16
    split = rt.Renderer(cornell_box, seed=7, width=24, height=20, threads=1)
    for n, parts in [(3, [1, 5, 14]), (10, [20]), (6, [7, 6, 7])]:
        for count in parts:
            split.add_rows(n, count)
        assert split.band == 0
    assert split.spp == 19
    for name in ("accum", "accum2", "partial", "partial2", "valid", "row_stats", "hist_n"):
        assert np.array_equal(getattr(whole.film, name), getattr(split.film, name)), name
    assert np.array_equal(whole.result().image, split.result().image)


@pytest.mark.parametrize("threads", [1, 2])
def test_the_local_driver_in_row_passes_is_bit_identical(cornell_box, monkeypatch, threads):
    whole, _ = rt.render(cornell_box, spp=18, seed=2, width=32, height=24)
    monkeypatch.setattr(local, "PASS_SECONDS", 1e-9)         # one row per pass
    calls = []
    real = rt.Renderer.add_rows
    monkeypatch.setattr(rt.Renderer, "add_rows",
                        lambda self, n, count: calls.append(count) or real(self, n, count))
    split, stats = rt.render(cornell_box, spp=18, seed=2, width=32, height=24,
                             threads=threads)
    assert calls and max(calls) < 24                        # passes over part of the rows
    assert stats.spp == 18 and stats.partial_rows == 0 and stats.threads == threads
    assert np.array_equal(whole, split)


def test_an_interrupted_row_pass_is_said(cornell_box):
    r = rt.Renderer(cornell_box, width=8, height=10)
    r.add_samples(2)
    r.add_rows(1, 4)
    with pytest.raises(rt.SceneError, match="add_samples: a pass over part of the rows"):
        r.add_samples(1)
    with pytest.raises(rt.SceneError, match="add_rows: n: the pass in progress adds 1"):
        r.add_rows(2, 1)
    with pytest.raises(rt.SceneError, match="add_rows: count: must be <= 6"):
        r.add_rows(1, 7)
    stats = r.result(interrupted=True).stats
    assert (stats.spp, stats.partial_rows, stats.partial_spp) == (2, 4, 1)
    assert stats.samples == 8 * (10 * 2 + 4)
    assert "2 spp (3 in 4 of 10 rows)" in stats.summary()


# -- Ctrl-C, with real signals --------------------------------------------------

def test_first_ctrl_c_is_answered_within_a_pass_on_a_long_image(tmp_path):
    # One sample per pixel of this image takes tens of seconds; a row, ~0.1 s.
    scene = mirror_box(tmp_path, 128, 128, 20000)
    out = tmp_path / "partial.npy"
    run = Run("render", str(scene), "-o", str(out), "--spp", "4", "--threads", "2")
    run.wait_for(b"pass 2")
    t0 = time.monotonic()
    run.interrupt()
    status, stdout, err = run.finish(timeout=60)
    assert time.monotonic() - t0 < 5.0, "Ctrl-C waited for a whole-image pass"
    assert status == 130
    assert "interrupted" in stdout.strip().splitlines()[-1]
    assert "holds the 0 spp rendered (1 in " in err[-1] and " of 128 rows)" in err[-1]
    assert "Traceback" not in "\n".join(err)
    assert np.load(out).shape == (128, 128, 3)
    assert [f.name for f in tmp_path.iterdir() if f.suffix != ".toml"] == ["partial.npy"]


def test_second_ctrl_c_stops_at_once_without_writing(tmp_path):
    # A row here takes seconds: both signals land inside the first pass.
    scene = mirror_box(tmp_path, 64, 4, 10**6)
    out = tmp_path / "never.png"
    run = Run("render", str(scene), "-o", str(out), "--spp", "1", "--threads", "2")
    run.wait_for(b"render")                 # compiled: the first pass is running
    run.interrupt()
    time.sleep(0.3)
    t0 = time.monotonic()
    run.interrupt()
    status, stdout, err = run.finish(timeout=60)
    assert time.monotonic() - t0 < 5.0
    assert status == 130
    assert err == ["rtweekend: interrupted; nothing written"], err
    assert stdout == ""
    assert [f.name for f in tmp_path.iterdir()] == ["mirrors.toml"]


# The command with a slow write: `slow` is "encode" (the image's encoding, one
# long C call that releases the GIL, as a big PNG's or EXR's) or "fsync" (the
# second of two files to disk, the first one already written under its
# temporary name).  Made slow here, not on the machine.
SLOW_WRITE = """
import hashlib, os, sys
import rtweekend.io.image as image
from rtweekend.cli import main

def slowly():
    print("writing slowly", file=sys.stderr, flush=True)
    hashlib.pbkdf2_hmac("sha256", b"slow", b"write", 60_000_000)   # ~10 s in C

encode, fsync, calls = image.encode, os.fsync, []
def slow_encode(*args, **kwargs):
    slowly()
    return encode(*args, **kwargs)
def slow_fsync(fd):
    calls.append(fd)
    if len(calls) == 2:
        slowly()
    return fsync(fd)
if sys.argv[1] == "encode":
    image.encode = slow_encode
else:
    os.fsync = slow_fsync
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.parametrize("slow", ["encode", "fsync"])
def test_second_ctrl_c_during_a_slow_write_stops_at_once_and_leaves_no_file(tmp_path, slow):
    scene = mirror_box(tmp_path, 64, 64, 20000)
    out = tmp_path / "never.npy"               # with a layer: two files to write
    run = Watched([sys.executable, "-c", SLOW_WRITE, slow, "render", str(scene), "-o",
                   str(out), "--aov", "albedo", "--spp", "64", "--threads", "2"])
    run.wait_for(b"pass 2")
    run.interrupt()                            # the first: stop and write
    run.wait_for(b"writing slowly")
    time.sleep(0.3)
    t0 = time.monotonic()
    run.interrupt()                            # the second, during the write
    status, stdout, err = run.finish(timeout=60)
    assert time.monotonic() - t0 < 2.0, "the second Ctrl-C waited for the write"
    assert status == 130, (status, err)
    assert err.strip().splitlines()[-1] == "rtweekend: interrupted; nothing written"
    assert "Traceback" not in err and stdout == ""
    assert [f.name for f in tmp_path.iterdir()] == ["mirrors.toml"]


def test_ctrl_c_while_compiling_stops_at_once(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "empty_cache"))
    out = tmp_path / "never.png"
    run = Run("render", "cornell_box", "-o", str(out), "--spp", "1", "--width", "8",
              "--height", "8", env=env)
    run.wait_for(b"compiling")
    time.sleep(0.5)                          # well inside the compile (~10 s cold)
    t0 = time.monotonic()
    run.interrupt()
    status, stdout, err = run.finish(timeout=60)
    assert time.monotonic() - t0 < 5.0, "Ctrl-C waited for the compile"
    assert status == 130
    assert err == ["rtweekend: Ctrl-C while compiling; nothing written"], err
    assert not out.exists()
    assert not any(p.suffix == ".part" for p in tmp_path.iterdir())


# -- memory -----------------------------------------------------------------------

def test_an_image_too_big_for_memory_fails_at_once_in_one_line(tmp_path):
    out = tmp_path / "huge.png"
    r = subprocess.run(CMD + ["render", "cornell_box", "--width", "65536", "--height",
                              "65536", "--spp", "1", "-o", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("rtweekend: error: render: width x height: 65536x65536 "
                               "(the width/height asked for) needs about ")
    assert " TB of memory and " in lines[0] and " is available (" in lines[0]
    assert list(tmp_path.iterdir()) == []
    scene = tmp_path / "big.toml"
    scene.write_text('[camera]\nwidth = 65536\nheight = 65536\n[[objects]]\ntype = "sphere"\n'
                     'center = [0, 0, -1]\nradius = 0.5\n'
                     'material = { type = "lambertian", albedo = [0.5, 0.5, 0.5] }\n')
    r = subprocess.run(CMD + ["render", str(scene), "-o", str(out)], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 2
    assert "65536x65536 (the camera of scene 'big') needs about " in r.stderr


def test_the_memory_check_comes_before_any_allocation(monkeypatch, cornell_box):
    monkeypatch.setattr(memory, "available", lambda: (8e9, "MemAvailable"))
    allocated = []
    monkeypatch.setattr(films, "new_film", lambda *a: allocated.append(a))
    with pytest.raises(rt.SceneError, match=r"16384x16384 \(the width/height asked for\) "
                       r"needs about [0-9.]+ GB of memory and 8\.0 GB is available "
                       r"\(MemAvailable\)"):
        rt.render(cornell_box, width=16384, height=16384, spp=1)
    with pytest.raises(rt.SceneError, match="needs about"):
        rt.render(rt.load_scene("cgfs"), width=16384, height=16384)
    assert allocated == []


def test_the_memory_check_counts_the_scenes_arrays_before_packing_them(monkeypatch):
    from rtweekend.path import pack, renderer
    scene = rt.Scene(camera=rt.Camera(width=4, height=4))
    for i in range(3000):
        scene.add(rt.sphere((i, 0, -5), 0.4, rt.lambertian((0.5, 0.5, 0.5))))
    scene.add(rt.box((0, 0, 0), (1, 1, 1), rt.diffuse_light((1, 1, 1))), light=True)
    arrays = pack.pack_scene(scene)
    packed = sum(a.nbytes for a in arrays if isinstance(a, np.ndarray))
    assert packed < pack.scene_bytes(scene) < 4 * packed + 10**6
    monkeypatch.setattr(memory, "available", lambda: (pack.scene_bytes(scene), "MemAvailable"))
    packing = []
    monkeypatch.setattr(renderer, "pack_scene", lambda *a, **k: packing.append(a))
    with pytest.raises(rt.SceneError, match=r"the scene's 3001 objects need about [0-9.]+ MB "
                       r"of memory, with its 4x4 image [0-9.]+ MB, and [0-9.]+ MB is "
                       r"available \(MemAvailable\); render a smaller scene"):
        rt.render(scene, spp=1)
    assert packing == []


def test_the_estimate_counts_the_film():
    film = films.new_film(7, 5)
    assert films.film_bytes(7, 5) == sum(a.nbytes for a in film)
    assert films.render_bytes(7, 5) > films.film_bytes(7, 5)
    free, source = memory.available()
    assert free is None or (free > 0 and source)


# -- what the summary says ----------------------------------------------------------

def _stats(**changes):
    fields = dict(width=8, height=8, spp=4, spp_requested=None, seconds=3.03,
                  compile_seconds=16.94, samples=256, rays=512, nan_dropped=0,
                  interrupted=False, threads=2, seed=0)
    return RenderStats(**{**fields, **changes})


def test_the_summary_reports_a_compile_apart():
    assert "3.03 s, plus 16.9 s compiling" in _stats(compiled=True).summary()
    assert "compiling" not in _stats(compiled=False).summary()
    classic = _stats(compiled=True, integrator="classic").summary()
    assert "plus 16.9 s compiling" in classic


def test_a_warm_render_reports_no_compile(cornell_box):
    rt.render(cornell_box, spp=1, width=4, height=4)
    _, stats = rt.render(cornell_box, spp=1, width=4, height=4)
    assert not stats.compiled and "compiling" not in stats.summary()


def test_the_bar_shows_seconds_and_spp_with_a_time_budget(tmp_path):
    r = subprocess.run(CMD + ["render", "metals", "--time", "0.5", "--width", "16",
                              "--height", "16", "-o", str(tmp_path / "m.png")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert ": : " not in r.stderr
    assert " spp, pass " in r.stderr and "M samples/s" in r.stderr


def test_the_bars_time_left_comes_from_the_samples_rate_not_the_first_pass(monkeypatch):
    # A one-minute render: the first pass is a row per thread (2 of 100 rows of
    # the first sample) in 0.05 s.  tqdm's own estimate read hours there.
    import io
    from types import SimpleNamespace
    from rtweekend.io.progress import Progress
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    bar = Progress(True, spp=10)
    bar.started()
    first = SimpleNamespace(width=100, height=100, spp=0, band=1, rows_done=2, seconds=0.05)
    bar.update(first, 1)
    assert "<?," in err.getvalue().split("\r")[-1]            # not known yet
    second = SimpleNamespace(width=100, height=100, spp=2, band=0, rows_done=0, seconds=12.0)
    bar.update(second, 2)
    shown = err.getvalue().split("\r")[-1]
    assert "<00:48," in shown, shown                          # 8 spp left at 6 s each
    bar.close()
    assert Progress(True, spp=None, time=30).time_left(second, 1) == 18.0


# -- version and help ------------------------------------------------------------------

def test_version_is_pyproject_s():
    expected = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["version"]
    assert rt.__version__ == expected
    r = subprocess.run(CMD + ["--version"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and r.stdout.strip() == f"rtweekend {expected}"


def test_help_lists_every_format_written():
    from rtweekend.io.image import FORMATS
    r = subprocess.run(CMD + ["render", "--help"], capture_output=True, text=True, timeout=60)
    text = " ".join(r.stdout.split())
    for ext in FORMATS:
        assert ext in text, ext


def test_docs_state_the_coordinate_bounds():
    text = (REPO / "docs" / "scenes.md").read_text()
    assert "1e100" in text and "1e-100" in text


def test_the_compile_clock_ticks_while_the_kernel_thread_works():
    # A cold compile takes seconds in the kernel thread; the waiting thread
    # calls tick (the bar's redraw) meanwhile, so the clock runs.
    from rtweekend.kernel.calls import POLL, call_awake
    ticks = []
    assert call_awake(lambda: time.sleep(6 * POLL) or 7, tick=lambda: ticks.append(1)) == 7
    assert len(ticks) >= 3


def test_the_command_run_in_process_gives_back_the_ctrl_c_handler(tmp_path):
    # The command ignores Ctrl-C once its file is written; called in-process
    # (a script, these tests) it must not leave it ignored -- the processes a
    # caller starts afterwards would inherit the ignored Ctrl-C.
    import signal
    from rtweekend.cli import main
    before = signal.getsignal(signal.SIGINT)
    assert main(["render", "cgfs", "-o", str(tmp_path / "c.png"), "-q", "--width", "8"]) == 0
    assert signal.getsignal(signal.SIGINT) is before
