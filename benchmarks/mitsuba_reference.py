"""An independent reference image of a bundled scene, rendered by Mitsuba 3.

    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
    /work/mitsuba-venv/bin/python benchmarks/mitsuba_reference.py caustic --size 100 \\
        --spp 65536 --pass-spp 1024 --threads 2 --out ../shared/references/caustic_100

The scene is translated by mitsuba_peer (its conventions: pixel squares, box
filter, row 0 at the top; Mitsuba's `path` integrator with next-event
estimation, MIS and Russian roulette from depth 5, the scene's max_depth):
rtweekend renders nothing here.  `cornell_smoke` has its own script
(mitsuba_smoke.py: media need `volpath` and stencil boxes), built on the pass
loop below.

Renders in passes of --pass-spp (pass i uses Mitsuba seed --seed * 100003 + i)
and writes, for --out NAME:
  NAME.npy         float32 H x W x 3 linear radiance (the mean of the passes)
  NAME_stderr.npy  float32 per-pixel standard error: std over passes / sqrt(passes)
  NAME.json        settings, seconds, spp_done, mean, RMS stderr, Mitsuba version
  NAME.png         preview, the books' tone map (sqrt, clamp [0, .999], x256)
They are rewritten after every pass, so an interrupted run leaves a valid (if
noisier) result; --time-limit stops after the pass that crosses it.
"""
import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))
os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")

import mitsuba_peer as peer  # noqa: E402  (imports drjit and mitsuba)

dr, mi = peer.dr, peer.mi


def tonemap(image):
    """The books' write_color: sqrt, clamp to [0, 0.999], x256 (as rtweekend.io.image)."""
    c = np.sqrt(np.nan_to_num(np.maximum(image, 0.0), nan=0.0, posinf=1.0))
    return (256.0 * np.clip(c, 0.0, 0.999)).astype(np.uint8)


def write_png(path, image):
    import imageio.v3 as iio
    iio.imwrite(path, tonemap(image))


def render_passes(mscene, width, height, spp, pass_spp, seed=0, time_limit=None,
                  out=None, info=None, log=print):
    """Render spp samples per pixel of a loaded Mitsuba scene in passes.

    Returns (mean float32 H x W x 3, stderr, info): stderr is the std over passes
    (ddof 1) / sqrt(passes), NaN with one pass.  With `out`, writes the four
    files after every pass."""
    info = dict(info or {})
    info.update(width=width, height=height, spp=spp, pass_spp=pass_spp, seed=seed,
                variant=peer._variant, threads=dr.thread_count(), mitsuba=mi.__version__)
    n_passes = -(-spp // pass_spp)
    s1 = np.zeros((height, width, 3))
    s2 = np.zeros((height, width, 3))
    done = passes = 0
    seconds = 0.0
    for i in range(n_passes):
        n = min(pass_spp, spp - done)
        t0 = time.perf_counter()
        img = np.array(mi.render(mscene, spp=n, seed=(seed * 100_003 + i) % 2**32),
                       dtype=np.float64)[..., :3]
        seconds += time.perf_counter() - t0
        # Passes of unequal size (only the last one can be) are weighted by spp;
        # the spread uses the equal-size passes' formula, which is close enough.
        s1 += n * img
        s2 += n * img * img
        done += n
        passes += 1
        mean = s1 / done
        if passes > 1:
            var = np.maximum(s2 / done - mean * mean, 0.0) * passes / (passes - 1)
            stderr = np.sqrt(var / passes)
        else:
            stderr = np.full_like(mean, np.nan)
        info.update(spp_done=done, passes_done=passes, seconds=seconds,
                    mean_linear=float(mean.mean()),
                    rms_stderr_linear=float(np.sqrt(np.mean(stderr ** 2))))
        log(f"pass {passes}/{n_passes}: {done} spp, {seconds:.0f} s, mean {mean.mean():.5f}, "
            f"rms stderr {info['rms_stderr_linear']:.5f}")
        if out is not None:
            save(out, mean, stderr, info)
        if time_limit is not None and seconds >= time_limit:
            log(f"time limit {time_limit} s reached")
            break
    return mean.astype(np.float32), stderr.astype(np.float32), info


def save(out, mean, stderr, info):
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    np.save(f"{out}.npy", mean.astype(np.float32))
    np.save(f"{out}_stderr.npy", stderr.astype(np.float32))
    Path(f"{out}.json").write_text(json.dumps(info, indent=1))
    write_png(f"{out}.png", mean)


def main(argv=None):
    import rtweekend as rt
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scene", help="a bundled scene's name or a .toml file")
    p.add_argument("--size", type=int, default=100, help="width (the height keeps the aspect)")
    p.add_argument("--spp", type=int, default=4096)
    p.add_argument("--pass-spp", type=int, default=256)
    p.add_argument("--threads", type=int, default=1, help="Dr.Jit worker threads")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--time-limit", type=float, help="stop after the pass that crosses it (s)")
    p.add_argument("--out", type=Path, help="NAME (default: SCENE_SIZE): writes NAME.npy, "
                   "NAME_stderr.npy, NAME.json, NAME.png")
    p.add_argument("--quick", action="store_true",
                   help="a 16-pixel-wide image of 64 spp in passes of 16 (tests)")
    a = p.parse_args(argv)
    if a.quick:
        a.size, a.spp, a.pass_spp = 16, 64, 16
    peer._setup(a.threads)
    if hasattr(mi, "set_log_level"):
        mi.set_log_level(mi.LogLevel.Warn)
    scene = rt.load_scene(a.scene)
    c = scene.camera
    scene = peer._resized(scene, a.size, max(1, round(a.size * c.height / c.width)))
    w, h = scene.camera.width, scene.camera.height
    pass_spp = max(1, min(a.pass_spp, a.spp))
    mscene = mi.load_dict(peer.mitsuba_dict(scene, pass_spp, a.seed))
    out = a.out or Path(f"{Path(a.scene).stem}_{a.size}")
    settings = dict(scene=a.scene, out=out.name, integrator="path",
                    max_depth=int(scene.resolved_max_depth()), rr_depth=5,
                    convention="mitsuba_peer (pixel squares, box filter, row 0 top)")
    _, _, info = render_passes(mscene, w, h, a.spp, pass_spp, a.seed, a.time_limit, out,
                               settings)
    print(json.dumps(info))


if __name__ == "__main__":
    main()
