"""Rendering on a Dask cluster: the same bits as a local render, through faults.

A LocalCluster of two single-threaded worker processes serves the API tests;
the command's tests start their own (--workers) or a scheduler and a worker as
processes (--scheduler), as a user would.
"""
import json
import os
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

import rtweekend as rt

pytest.importorskip("distributed", reason="needs Dask: pip install 'rtweekend[dask]'")

from rtweekend.distributed import (ClusterError, dask_client, environment,  # noqa: E402
                                   warm_worker)
from rtweekend.options import RenderOptions  # noqa: E402
from rtweekend.path.renderer import freeze  # noqa: E402
from watch import Watched  # noqa: E402

CMD = [sys.executable, "-m", "rtweekend"]
SMALL = dict(width=32, height=32, seed=7)


@pytest.fixture(scope="module")
def cornell_box():
    scene = rt.load_scene("cornell_box")
    rt.render(scene, spp=1, width=4, height=4)   # compiled here first: workers load the cache
    return scene


@pytest.fixture(scope="module")
def client(cornell_box):
    with dask_client(workers=2) as c:
        c.wait_for_workers(2, timeout=60)
        yield c


def assert_same(a, b):
    # A render that stopped early says why (a lost cluster, Ctrl-C).
    assert np.array_equal(a.image, b.image), f"stopped by: {a.stats.stopped_by}"
    assert np.array_equal(a.stderr, b.stderr)
    for name in ("width", "height", "spp", "samples", "rays", "nan_dropped", "fireflies"):
        assert getattr(a.stats, name) == getattr(b.stats, name), name


def test_same_bits_as_a_local_render(cornell_box, client):
    # 40 spp: blocks of 16, 16 and a partial 8, merged in order.
    local = rt.render(cornell_box, spp=40, **SMALL)
    far = rt.render(cornell_box, spp=40, client=client, **SMALL)
    assert_same(far, local)
    assert far.stats.spp == 40 and not far.stats.interrupted and far.stats.threads == 2


def test_a_mesh_scene_is_the_same_bits_as_a_local_render(client):
    # The mesh tables travel with the scene's arrays to the workers.
    pytest.importorskip("trimesh", reason="needs the meshes extra")
    scene = rt.load_scene("cornell_mesh")
    assert_same(rt.render(scene, spp=40, client=client, **SMALL),
                rt.render(scene, spp=40, **SMALL))


def test_caustic_photon_maps_are_the_same_bits_as_a_local_render(client):
    # Each worker traces the maps of the samples it renders itself, from the
    # same keys: the same photons in the same order as here.
    scene = rt.load_scene("caustic")
    options = dict(SMALL, sampling="bdpt+photons")
    assert_same(rt.render(scene, spp=40, client=client, **options),
                rt.render(scene, spp=40, **options))


def test_connections_through_glass_are_the_same_bits_as_a_local_render(client):
    # bdpt+mnee: each worker's connections draw from the samples' own keys; the
    # counts of connections tried and dropped travel with the blocks' films.
    scene = rt.load_scene("glass_lamp")
    options = dict(SMALL, sampling="bdpt+mnee")
    far = rt.render(scene, spp=40, client=client, **options)
    local = rt.render(scene, spp=40, **options)
    assert_same(far, local)
    assert far.stats.connections == local.stats.connections > 0
    assert far.stats.unsolved == local.stats.unsolved


@pytest.mark.parametrize("sampling", ["lightpath", "bdpt"])
def test_light_carried_to_the_camera_is_the_same_bits_as_a_local_render(cornell_box, client,
                                                                       sampling):
    # Light tracing (and bdpt's t = 1) splats into any pixel: the blocks'
    # integer sums and their squares merged in order give the local image and
    # standard error.
    local = rt.render(cornell_box, spp=40, sampling=sampling, **SMALL)
    far = rt.render(cornell_box, spp=40, sampling=sampling, client=client, **SMALL)
    assert_same(far, local)
    assert local.image.mean() > 0.05


def test_the_local_cluster_runs_one_numba_thread_per_worker(cornell_box, client):
    [frame] = client.scatter([freeze(cornell_box, RenderOptions(width=4, height=4))],
                              broadcast=True)
    infos = [client.submit(warm_worker, frame, workers=[w], pure=False).result()
             for w in client.nthreads()]
    assert [i["numba_threads"] for i in infos] == [1, 1]
    assert {i["digest"] for i in infos} == {environment()["digest"]}


def test_a_time_budget_renders_whole_blocks(cornell_box, client):
    far = rt.render(cornell_box, time=0.3, client=client, width=16, height=16, seed=2)
    spp = far.stats.spp
    assert spp >= 16 and spp % 16 == 0 and not far.stats.interrupted
    assert_same(far, rt.render(cornell_box, spp=spp, width=16, height=16, seed=2))


def test_a_worker_killed_mid_render_changes_nothing(cornell_box, client):
    """Kill a worker that is rendering a block as soon as a block is merged
    while one is busy (nearly always at the first): the scheduler reruns its
    blocks on the other worker.  A block takes about 0.3 s here, so the other
    worker is usually still busy when the first returns (at 48x48, 30 ms a
    block, both workers were often idle by then)."""
    opts = dict(width=128, height=128, seed=11)
    spp = 12 * 16
    killed = []

    def kill_a_busy_worker(done, total, rate):
        if killed:
            return
        busy = [w for w, keys in client.processing().items()
                if any(str(k).startswith("rtweekend-block-") for k in keys)]
        if not busy:
            return          # both idle at this block's return: try at the next one
        pids = client.run(os.getpid, workers=busy[:1])
        for pid in pids.values():
            os.kill(pid, signal.SIGKILL)
        killed.append((busy[:1], done))

    far = rt.render(cornell_box, spp=spp, client=client, progress=kill_a_busy_worker, **opts)
    assert killed, "no worker was ever rendering when a block came back"
    [(busy, done)] = killed
    assert busy and done < spp
    assert_same(far, rt.render(cornell_box, spp=spp, **opts))
    client.wait_for_workers(2, timeout=60)      # the nanny restarts it, for the next tests


def test_every_worker_killed_at_once_changes_nothing(cornell_box, client):
    """Both workers die: the nannies restart them, the scene (lost with them) is
    scattered again and the lost blocks are rendered again."""
    opts = dict(width=32, height=32, seed=12)
    spp = 8 * 16
    killed = []

    def kill_every_worker(done, total, rate):
        if not killed:
            for pid in client.run(os.getpid).values():
                os.kill(pid, signal.SIGKILL)
            killed.append(done)

    far = rt.render(cornell_box, spp=spp, client=client, progress=kill_every_worker, **opts)
    assert killed and killed[0] < spp
    assert_same(far, rt.render(cornell_box, spp=spp, **opts))
    client.wait_for_workers(2, timeout=60)


def test_api_errors(cornell_box, client):
    with pytest.raises(ClusterError, match="threads does not apply"):
        rt.render(cornell_box, spp=1, threads=1, client=client)
    with pytest.raises(ClusterError, match="classic scene"):
        rt.render(rt.load_scene("cgfs"), client=client)
    with pytest.raises(rt.SceneError, match="spp: must be"):
        rt.render(cornell_box, spp=0, client=client)


def test_import_rtweekend_does_not_import_dask():
    code = ("import sys, rtweekend, rtweekend.cli, rtweekend.distributed; "
            "rtweekend.render(rtweekend.load_scene('cornell_box'), spp=1, width=4, height=4); "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


def run(*args, cwd=None, timeout=120):
    t0 = time.monotonic()
    r = subprocess.run(CMD + list(args), capture_output=True, text=True, cwd=cwd,
                       timeout=timeout)
    return r, time.monotonic() - t0


def test_a_scheduler_that_does_not_answer_is_one_line_and_exit_2(tmp_path):
    with socket.socket() as s:                  # a port that is ours, and not listening
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        r, seconds = run("render", "cornell_box", "-o", str(tmp_path / "x.png"), "--spp", "1",
                         "--scheduler", f"tcp://127.0.0.1:{port}", cwd=tmp_path)
    assert r.returncode == 2
    assert r.stderr.splitlines() == [
        f"rtweekend: error: render: cannot reach the Dask scheduler at tcp://127.0.0.1:{port}: "
        f"Timed out trying to connect to tcp://127.0.0.1:{port} after 5 s"]
    assert seconds < 20
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, message", [
    (["cornell_box", "--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"],
     "not allowed with"),
    (["cornell_box", "--workers", "0"], "must be >= 1"),
    (["cgfs", "--workers", "2"], "classic scene is ray traced once per pixel"),
    (["cornell_box", "--workers", "2", "--threads", "1"], "threads does not apply"),
    (["cornell_box", "--scheduler", "localhost"], "bad Dask scheduler address 'localhost': "
     "missing port number in address 'localhost' (expected tcp://HOST:PORT)"),
    (["cornell_box", "--scheduler", "udp://x:1"], "unknown address scheme 'udp'"),
])
def test_bad_cluster_options_are_one_line_and_exit_2(tmp_path, capfd, args, message):
    from rtweekend.cli import main
    try:
        code = main(["render", *args, "-o", str(tmp_path / "x.png")])
    except SystemExit as e:             # argparse's errors
        code = e.code
    assert code == 2
    err = capfd.readouterr().err
    assert len(err.strip().splitlines()) == 1 and message in err, err
    assert list(tmp_path.iterdir()) == []


def test_without_dask_the_command_says_what_to_install(tmp_path, monkeypatch, capsys):
    from rtweekend.cli import main
    monkeypatch.setitem(sys.modules, "distributed", None)     # import distributed fails
    code = main(["render", "cornell_box", "--workers", "2", "-o", str(tmp_path / "x.png")])
    assert code == 2
    err = capsys.readouterr().err
    assert err == ("rtweekend: error: render: rendering on a Dask cluster needs Dask: "
                   "pip install 'rtweekend[dask]'\n")


def test_the_command_with_workers_writes_the_local_image(tmp_path):
    common = ["render", "cornell_box", "--spp", "20", "--width", "24", "--height", "16",
              "--seed", "3", "-q"]
    far, _ = run(*common, "-o", str(tmp_path / "far.npy"), "--workers", "2")
    assert far.returncode == 0, far.stderr
    assert far.stderr in ("", "rtweekend: warning: --workers 2 on 1 cores: the worker "
                              "processes share them, no faster than 1\n")
    assert far.stdout.strip().splitlines()[-1].startswith(
        f"{tmp_path / 'far.npy'}: 24x16, 20 spp")
    local, _ = run(*common, "-o", str(tmp_path / "local.npy"))
    assert local.returncode == 0, local.stderr
    assert np.array_equal(np.load(tmp_path / "far.npy"), np.load(tmp_path / "local.npy"))


def _spp_kept(stdout):
    summary = stdout.strip().splitlines()[-1]
    assert "interrupted" in summary and "of 100000 spp" in summary, summary
    return int(summary.split("interrupted: ")[1].split(" of")[0])


def _messages(stderr):
    """stderr's lines of text, without the progress bar's redraws."""
    return [line for line in stderr.replace("\r", "\n").splitlines()
            if line.strip() and not line.startswith(("compiling", "render"))]


def test_ctrl_c_keeps_the_blocks_merged(tmp_path, cornell_box):
    out = tmp_path / "partial.npy"
    w = Watched(CMD + ["render", "cornell_box", "-o", str(out), "--spp", "100000",
                       "--width", "32", "--height", "32", "--seed", "5", "--workers", "2"])
    w.wait_for(b"pass 2", timeout=60)
    w.p.send_signal(signal.SIGINT)
    code, stdout, stderr = w.finish()
    assert code == 130
    spp = _spp_kept(stdout)
    assert spp >= 32 and spp % 16 == 0
    assert _messages(stderr) == [f"rtweekend: interrupted; {out} holds the {spp} spp rendered"]
    local = rt.render(cornell_box, spp=spp, width=32, height=32, seed=5)
    assert np.array_equal(np.load(out), local.image)


def test_a_lost_cluster_keeps_the_blocks_merged(tmp_path, cornell_box):
    """The scheduler dies (SIGKILL) mid-render: one line says so, and the file
    holds the blocks merged until then -- the bits of a local render of that spp."""
    info = tmp_path / "scheduler.json"
    scheduler = subprocess.Popen(
        [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
         "--port", "0", "--no-dashboard", "--scheduler-file", str(info)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    worker = render = None
    try:
        deadline = time.monotonic() + 60
        while not info.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        address = json.loads(info.read_text())["address"]
        worker = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file",
             str(info), "--nthreads", "1", "--no-dashboard", "--death-timeout", "20"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            env=dict(os.environ, NUMBA_NUM_THREADS="1"))
        out = tmp_path / "partial.npy"
        render = Watched(CMD + ["render", "cornell_box", "-o", str(out), "--spp", "100000",
                                "--width", "32", "--height", "32", "--seed", "6",
                                "--scheduler", address])
        render.wait_for(b"pass 1", timeout=60)
        scheduler.kill()
        code, stdout, stderr = render.finish()
    finally:
        for p in (render and render.p, worker, scheduler):
            if p is not None and p.poll() is None:
                p.kill()
                p.wait(timeout=30)
    assert code == 130
    spp = _spp_kept(stdout)
    assert spp >= 16 and spp % 16 == 0
    assert _messages(stderr) == [
        f"rtweekend: lost the connection to the Dask scheduler; {out} holds the {spp} spp "
        "rendered"]
    local = rt.render(cornell_box, spp=spp, width=32, height=32, seed=6)
    assert np.array_equal(np.load(out), local.image)


def test_more_workers_than_cores_is_warned_about():
    # The warning comes first (then the classic scene is refused: no cluster starts).
    many = (os.cpu_count() or 1) + 1
    with pytest.warns(rt.SceneWarning, match=f"--workers {many} on .* cores: the worker "
                                              "processes share them"):
        with pytest.raises(ClusterError, match="classic scene"):
            with dask_client(rt.load_scene("cgfs"), workers=many):
                pass
