"""Throughput, compile time, memory and scaling of the renderer.

    pip install '.[bench]' && python benchmarks/throughput.py

For every bundled scene at its own size: samples/s and rays/s (path segments/s)
with 1 thread and with all threads (median of 3 runs after a warm-up pass), the
scaling ratio, the mean path length and the peak memory (RSS) of a process that
renders only that scene.  cornell_glass is measured three times, each time beside
the yardstick (../shared/yardsticks/numba_probe.py, the books' estimator in a small
scalar tracer of that one scene) at the same size, spp and threads, with the books'
mixture sampling: its row is the median, and `vs yardstick` the median of the
three ratios (the other scenes have no yardstick).  Separate processes see a
machine that moves under them, so the ratio is also measured pass by pass in
one process (paired.py; `yardstick_paired`), the figure the target is checked
on.  Then cold compile (fresh process, empty Numba cache; median of 3) and
cached start (fresh process, cache present: import to a first tiny image), and
two scaling curves (median of 3 per point): time against pixels x spp
(cornell_box) and against the number of spheres
(10 .. 10,000 random spheres, with and without the BVH).

Writes benchmark-results/throughput.json and benchmark-results/throughput.png; prints a table.
--quick runs a tiny version (seconds) to check that the script works.
"""
import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

import rtweekend as rt

sys.path.insert(0, str(Path(__file__).resolve().parent))
import paired  # noqa: E402
import yardstick  # noqa: E402
from common import machine, save_json  # noqa: E402
from common import parser as bench_parser  # noqa: E402

# (scene, spp per timed run); sizes are the scenes' own.
FULL = dict(scenes={"cornell_glass": 4, "cornell_box": 4, "metals": 16, "weekend": 2,
                    "cgfs": None},
            runs=3, pixels_spp=[(150, 150, s) for s in (4, 8, 16, 32, 64)],
            spheres=[10, 30, 100, 300, 1000, 3000, 10000], sphere_image=(96, 54, 2),
            flat_limit=10000, weekend=((240, 135), 4))
YARDSTICK_ROUNDS = 3     # cornell_glass and the yardstick, alternated
PAIRED_SECONDS = 60      # per thread count, cornell_glass and the yardstick in one process
QUICK = dict(scenes={"cornell_glass": 1, "cgfs": None}, runs=1, size=(48, 48),
             pixels_spp=[(24, 24, 1), (24, 24, 2)], spheres=[10, 100],
             sphere_image=(24, 16, 1), flat_limit=100, weekend=((24, 16), 1))
TARGETS = {"cornell_glass_samples_per_s_all_threads": 4e6,
           "cornell_glass_samples_per_s_per_thread": 2e6,
           "two_thread_scaling": 1.8, "cold_compile_s": 15.0, "cached_start_s": 1.0,
           "cornell_glass_vs_yardstick_all_threads": 1.0,
           "weekend_bvh_speedup": 5.0}


def _median_seconds(renderer, spp, runs=3):
    """Median wall time of `runs` passes of spp samples per pixel."""
    return float(np.median([renderer.add_samples(spp) for _ in range(runs)]))


def _median_rate(renderer, spp, runs):
    """Samples per second of the median pass (odd runs: the median rate)."""
    return renderer.width * renderer.height * spp / _median_seconds(renderer, spp, runs)


def one_scene(name, spp, runs, size=None):
    """Measure one scene in this process (run in a subprocess for its RSS)."""
    scene = rt.load_scene(name)
    width, height = size or (None, None)
    out = dict(scene=name)
    if scene.resolved_integrator() == "classic":
        rt.render(scene, width=width, height=height)             # warm-up
        for label, threads in (("1_thread", 1), ("all_threads", None)):
            times = [rt.render(scene, width=width, height=height, threads=threads).stats
                     for _ in range(runs)]
            st = sorted(times, key=lambda s: s.seconds)[len(times) // 2]
            out[label] = dict(seconds=st.seconds, rays_per_s=st.rays_per_s,
                              samples_per_s=st.samples_per_s, threads=st.threads)
        out.update(width=st.width, height=st.height, spp=1, integrator="classic")
    else:
        r = rt.Renderer(scene, seed=1, width=width, height=height, sampling="mixture")
        r.compile()
        r.add_samples(1)                                        # warm-up
        for label, threads in (("1_thread", 1), ("all_threads", numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            rays0, samples0 = int(r.film.row_stats[:, 0].sum()), r.spp
            rate = _median_rate(r, spp, runs)
            rays = int(r.film.row_stats[:, 0].sum()) - rays0
            path = rays / ((r.spp - samples0) * r.width * r.height)
            out[label] = dict(samples_per_s=rate, rays_per_s=rate * path, threads=threads)
        out.update(width=r.width, height=r.height, spp=spp, integrator="path",
                   mean_path_length=path, objects=int(len(r.frame.scene.obj_i)),
                   bvh=r.frame.scene.wide is not None)
    out["scaling"] = out["all_threads"]["samples_per_s"] / out["1_thread"]["samples_per_s"]
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return out


def _run_child(args):
    """This script in a fresh process (--one SCENE ...), for one scene's own RSS."""
    r = subprocess.run([sys.executable, __file__, *args], capture_output=True, text=True,
                       timeout=1800)
    if r.returncode:
        raise RuntimeError(f"child {args} failed:\n{r.stderr}")
    return json.loads(r.stdout.strip().splitlines()[-1])


FIRST_IMAGE = """
import json, sys, time
t0 = time.perf_counter()
import rtweekend
t1 = time.perf_counter()
scene = rtweekend.load_scene(sys.argv[1])
budget = {} if scene.resolved_integrator() == "classic" else {"spp": 1}
r = rtweekend.render(scene, width=8, height=8, **budget)
t2 = time.perf_counter()
print(json.dumps(dict(import_s=t1 - t0, first_image_s=t2 - t1, total_s=t2 - t0,
                      compile_s=r.stats.compile_seconds)))
"""


def beside_yardstick(child, spp, runs):
    """cornell_glass (a child process each time) alternated with the yardstick at
    the same size, spp and threads: the medians, and the median of the ratios."""
    if not yardstick.available():
        print(f"  yardstick not found at {yardstick.PATH}: cornell_glass measured alone",
              flush=True)
        return _run_child(child)
    ours, theirs = [], []
    for _ in range(YARDSTICK_ROUNDS):
        d = _run_child(child)
        ours.append(d)
        theirs.append({"1_thread": yardstick.samples_per_s(d["width"], spp, runs, threads=1),
                       "all_threads": yardstick.samples_per_s(d["width"], spp, runs)})
    out = dict(ours[0], runs_beside_yardstick=ours, yardstick=theirs)
    out["vs_yardstick"] = {}
    for key in ("1_thread", "all_threads"):
        rates = [o[key]["samples_per_s"] for o in ours]
        out[key] = dict(ours[0][key], samples_per_s=float(np.median(rates)),
                        rays_per_s=float(np.median([o[key]["rays_per_s"] for o in ours])))
        out["yardstick_" + key] = float(np.median([t[key] for t in theirs]))
        out["vs_yardstick"][key] = float(np.median([o / t[key] for o, t in
                                                    zip(rates, theirs)]))
    out["scaling"] = out["all_threads"]["samples_per_s"] / out["1_thread"]["samples_per_s"]
    return out


def first_image(scene, env=None):
    """A fresh interpreter: import rtweekend, render a tiny image; the times."""
    r = subprocess.run([sys.executable, "-c", FIRST_IMAGE, scene], capture_output=True,
                       text=True, env={**os.environ, **(env or {})}, timeout=1800)
    if r.returncode:
        raise RuntimeError(f"first image of {scene} failed:\n{r.stderr}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def compile_times(cold=True):
    """Cold compile (empty cache) and cached start, each in a fresh process.

    cold=False (--quick) measures the cached start only, in the user's cache.
    """
    if not cold:
        return dict(cold=None, cached=first_image("cornell_glass"))
    # One cold compile varies by +-2 s on this machine: the median of three,
    # each from an emptied cache; the last one's cache serves the cached starts.
    colds = []
    with tempfile.TemporaryDirectory() as cache:
        env = {"NUMBA_CACHE_DIR": cache}
        for _ in range(3):
            shutil.rmtree(cache)
            os.mkdir(cache)
            colds.append(first_image("cornell_glass", env))
        cached = first_image("cornell_glass", env)
        cached_threads = first_image("cornell_glass", {**env, "NUMBA_NUM_THREADS": "1"})
        classic_cold = first_image("cgfs", env)
    cold = sorted(colds, key=lambda c: c["total_s"])[1]
    return dict(cold=cold, cold_runs=colds, cached=cached,
                cached_other_thread_count=cached_threads, classic_cold=classic_cold)


def random_spheres(n, seed=0):
    """n small spheres on a ground sphere, spread so that the view stays busy."""
    rng = np.random.default_rng(seed)
    side = max(4.0, np.sqrt(n) * 0.6)
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, side * 0.4, side * 1.2), lookat=(0, 0, 0),
                                      vfov=50), background="sky")
    scene.add(rt.sphere((0, -1e4, 0), 1e4, rt.lambertian((0.5, 0.5, 0.5))))
    for _ in range(n - 1):
        x, z = rng.uniform(-side, side, 2)
        scene.add(rt.sphere((x, 0.2, z), 0.2, rt.lambertian(rng.uniform(0.1, 0.9, 3))))
    return scene


def scaling(cfg):
    out = dict(pixels_spp=[], spheres=[])
    scene = rt.load_scene("cornell_box")
    for w, h, spp in cfg["pixels_spp"]:
        r = rt.Renderer(scene, seed=2, width=w, height=h)
        r.compile()
        seconds = _median_seconds(r, spp)
        out["pixels_spp"].append(dict(width=w, height=h, spp=spp, work=w * h * spp,
                                      seconds=seconds))
    w, h, spp = cfg["sphere_image"]
    for n in cfg["spheres"]:
        row = dict(spheres=n)
        for bvh in (True, False):
            if not bvh and n > cfg["flat_limit"]:
                continue
            r = rt.Renderer(random_spheres(n), seed=3, width=w, height=h, bvh=bvh)
            r.compile()
            r.add_samples(1)
            seconds = _median_seconds(r, spp)
            row["bvh" if bvh else "flat"] = seconds / (w * h * spp) * 1e6
        out["spheres"].append(row)                # microseconds per sample
        print(f"  {n:6d} spheres: " + ", ".join(
            f"{k} {v:.2f} us/sample" for k, v in row.items() if k != "spheres"), flush=True)
    return out


def weekend_bvh(size, spp):
    """weekend (487 spheres) with the BVH and with every object tested."""
    scene = rt.load_scene("weekend")
    out = {}
    for bvh in (True, False):
        r = rt.Renderer(scene, seed=4, width=size[0], height=size[1], bvh=bvh)
        r.compile()
        r.add_samples(1)
        out["bvh" if bvh else "flat"] = r.width * r.height * spp / r.add_samples(spp)
    out["speedup"] = out["bvh"] / out["flat"]
    return out


def chart(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.4))
    ps = data["scaling"]["pixels_spp"]
    a.plot([p["work"] / 1e6 for p in ps], [p["seconds"] for p in ps], "o-")
    a.set_xlabel("pixels x spp (millions)")
    a.set_ylabel("seconds")
    a.set_title("cornell_box: time is linear in the work", fontsize=9)
    a.grid(alpha=0.3)
    sp = data["scaling"]["spheres"]
    for key, label in (("bvh", "BVH"), ("flat", "every object tested")):
        pts = [(r["spheres"], r[key]) for r in sp if key in r]
        b.loglog(*zip(*pts), "o-", label=label)
    b.set_xlabel("spheres")
    b.set_ylabel("microseconds per sample")
    b.set_title("random spheres: time against scene size", fontsize=9)
    b.legend()
    b.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = bench_parser(__doc__)
    parser.add_argument("--one", nargs=3, metavar=("SCENE", "SPP", "RUNS"),
                        help=argparse.SUPPRESS)
    parser.add_argument("--size", nargs=2, type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.one:
        name, spp, runs = args.one
        print(json.dumps(one_scene(name, None if spp == "None" else int(spp), int(runs),
                                   args.size)))
        return
    cfg = QUICK if args.quick else FULL
    start = time.perf_counter()
    data = dict(machine=machine(), quick=args.quick, targets=TARGETS, scenes={})
    print(f"{'scene':14s} {'size':>10s} {'1 thread':>16s} {'all threads':>16s} "
          f"{'scaling':>7s} {'path':>5s} {'RSS MB':>7s}")
    for name, spp in cfg["scenes"].items():
        extra = ["--size", *map(str, cfg["size"])] if "size" in cfg else []
        child = ["--one", name, str(spp), str(cfg["runs"]), *extra]
        if name == "cornell_glass" and not args.quick:
            d = beside_yardstick(child, spp, cfg["runs"])
        else:
            d = _run_child(child)
        data["scenes"][name] = d
        unit = "rays" if d["integrator"] == "classic" else "samples"
        one, all_ = d["1_thread"][f"{unit}_per_s"], d["all_threads"][f"{unit}_per_s"]
        ratio = d.get("vs_yardstick", {}).get("all_threads")
        print(f"{name:14s} {d['width']:>5d}x{d['height']:<4d} {one / 1e6:9.3f} M {unit[0]}/s "
              f"{all_ / 1e6:9.3f} M {unit[0]}/s {d['scaling']:7.2f} "
              f"{d.get('mean_path_length', float('nan')):5.2f} {d['peak_rss_mb']:7.0f}"
              + (f"   {ratio:.2f}x the yardstick" if ratio else ""), flush=True)
    if not args.quick and yardstick.available():
        print("cornell_glass beside the yardstick, pass by pass in one process (paired.py):",
              flush=True)
        threads = sorted({1, numba.config.NUMBA_NUM_THREADS})
        data["yardstick_paired"] = paired.beside_yardstick(PAIRED_SECONDS, threads)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    print("compile times (fresh processes) ...", flush=True)
    data["compile"] = compile_times(cold=not args.quick)
    if data["compile"]["cold"]:
        print("  cold: {total_s:.1f} s to the first image (compile {compile_s:.1f} s)".format(
            **data["compile"]["cold"]), flush=True)
    print("  cached: {total_s:.2f} s to the first image".format(**data["compile"]["cached"]),
          flush=True)
    print("scaling ...", flush=True)
    data["scaling"] = scaling(cfg)
    data["weekend_bvh"] = weekend_bvh(*cfg["weekend"])
    print("  weekend: BVH {bvh:.0f} vs flat {flat:.0f} samples/s: {speedup:.1f}x".format(
        **data["weekend_bvh"]), flush=True)
    data["verdict"] = verdict(data)
    data["total_seconds"] = time.perf_counter() - start
    args.out.mkdir(parents=True, exist_ok=True)
    save_json("throughput.json", data, args.out)
    chart(data, args.out / "throughput.png")
    print(json.dumps(data["verdict"], indent=1))
    print(f"total {data['total_seconds']:.0f} s")


def verdict(data):
    """Each target with the measured value; None where this run did not measure it."""
    glass = data["scenes"].get("cornell_glass", {})
    measured = {
        "cornell_glass_samples_per_s_all_threads": glass.get("all_threads", {}).get(
            "samples_per_s"),
        "cornell_glass_samples_per_s_per_thread": glass.get("1_thread", {}).get(
            "samples_per_s"),
        "two_thread_scaling": glass.get("scaling"),
        "cornell_glass_vs_yardstick_all_threads": data.get("yardstick_paired", {}).get(
            str(numba.config.NUMBA_NUM_THREADS), {}).get("ratio", {}).get("median"),
        "cold_compile_s": (data["compile"]["cold"] or {}).get("total_s"),
        "cached_start_s": data["compile"]["cached"]["total_s"],
        "weekend_bvh_speedup": data["weekend_bvh"]["speedup"],
    }
    lower_is_better = {"cold_compile_s", "cached_start_s"}
    return {k: dict(target=TARGETS[k], measured=v,
                    met=None if v is None else (v <= TARGETS[k] if k in lower_is_better
                                                else v >= TARGETS[k]))
            for k, v in measured.items()}


if __name__ == "__main__":
    main()
