"""What compiling costs, per bundled scene: the first render's compile with an
empty Numba cache, the other strategies' kernels after it, and the start when
everything is cached.

    python benchmarks/compile.py [--runs 3] [--quick]

(--quick: two scenes, tiny, in the user's cache: only checks that it runs.)

For each bundled scene, in a fresh process with an empty cache (median of
--runs): the compile of its default strategy's kernel (what `rtweekend render
SCENE` waits for the first time) and samples/s after it (100x100, 8 spp, all
threads); then, in the same process, the extra compile of next-event
estimation (`nee`) and of light tracing (`lightpath`, where the scene allows
it) -- the kernels share their steps, compiled once; then a second fresh
process with that cache: its start, import to the first image (the default
strategy's kernel loaded from the cache).  A scene pays
only for The Next Week's features it uses (textures, media, motion: each
compiled in only where a scene has it), which the features column says.
Writes benchmark-results/compile.json and prints a table.
"""
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, save_json  # noqa: E402
from common import parser as bench_parser  # noqa: E402

CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
import rtweekend as rt
from rtweekend.errors import SceneError
name, size, spp = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
scene = rt.load_scene(name)
out = dict(import_s=time.perf_counter() - t0)
if scene.resolved_integrator() == "classic":
    r = rt.render(scene, width=size, height=size)
    out.update(features=["classic"], compile_s=r.stats.compile_seconds,
               samples_per_s=size * size / r.stats.seconds,
               first_image_s=time.perf_counter() - t0)
else:
    r = rt.Renderer(scene, seed=1, width=size, height=size)
    out["sampling"] = r.options.sampling            # the scene's default
    f = r.frame.features
    out["features"] = [n for n, v in (("textures", f.textures), ("media", f.media),
                                      ("motion", f.motion)) if v is not None] or ["none"]
    out["compile_s"] = r.compile()
    r.add_samples(1)
    out["first_image_s"] = time.perf_counter() - t0
    out["samples_per_s"] = size * size * spp / r.add_samples(spp)
    for sampling in ("nee", "lightpath"):
        try:
            other = rt.Renderer(scene, seed=1, width=size, height=size, sampling=sampling)
        except SceneError:
            out[sampling + "_s"] = None
            continue
        out[sampling + "_s"] = other.compile()
print(json.dumps(out))
"""


def _listed():
    p = subprocess.run([sys.executable, "-m", "rtweekend", "scenes"], capture_output=True,
                       text=True, check=True)
    return [line.split()[0] for line in p.stdout.splitlines() if line.strip()]


def child(name, size, spp, cache):
    env = dict(os.environ, **({"NUMBA_CACHE_DIR": cache} if cache else {}))
    p = subprocess.run([sys.executable, "-c", CHILD, name, str(size), str(spp)], env=env,
                       capture_output=True, text=True, timeout=1800)
    if p.returncode:
        raise RuntimeError(f"{name}: {p.stderr[-2000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def measure(name, size, spp, runs, quick=False):
    colds, cached = [], None
    if quick:                     # the user's cache: the script runs, nothing is measured
        colds = [child(name, size, spp, None)]
        cached = colds[0]
    for _ in range(0 if quick else runs):
        with tempfile.TemporaryDirectory() as cache:
            colds.append(child(name, size, spp, cache))
            cached = child(name, size, spp, cache)
    pick = sorted(colds, key=lambda o: o["compile_s"])[len(colds) // 2]      # the median run
    return dict(scene=name, features=pick["features"], sampling=pick.get("sampling"),
                compile_s=pick["compile_s"],
                compile_runs=[o["compile_s"] for o in colds], nee_s=pick.get("nee_s"),
                lightpath_s=pick.get("lightpath_s"), samples_per_s=pick["samples_per_s"],
                cached_start_s=cached["first_image_s"])


def _seconds(x):
    return "      -" if x is None else f"{x:6.1f}s"


def main():
    p = bench_parser(__doc__)
    p.add_argument("--runs", type=int, default=1, help="fresh processes (empty caches) per scene")
    p.add_argument("--scenes", help="comma-separated (default: every bundled scene)")
    args = p.parse_args()
    size, spp = (16, 1) if args.quick else (100, 8)
    names = ["cornell_box", "cgfs"] if args.quick else _listed()
    names = args.scenes.split(",") if args.scenes else names
    rows = []
    print(f"{'scene':18s} {'features':24s} {'default':14s} {'cold':>7s} {'+nee':>7s} "
          f"{'+lightpath':>10s} {'cached start':>12s} {'samples/s':>10s}")
    for name in names:
        row = measure(name, size, spp, args.runs, args.quick)
        rows.append(row)
        print(f"{name:18s} {'+'.join(row['features']):24s} {row['sampling'] or '':14s} "
              f"{_seconds(row['compile_s'])} "
              f"{_seconds(row['nee_s'])} {_seconds(row['lightpath_s']):>10s} "
              f"{row['cached_start_s']:11.2f}s {row['samples_per_s'] / 1e6:8.2f} M", flush=True)
    total = float(np.sum([r["compile_s"] for r in rows]))
    print(f"sum of the cold compiles: {total:.1f} s")
    if not args.quick:
        path = save_json("compile.json", dict(machine=machine(), size=size, spp=spp,
                                              runs=args.runs, rows=rows), args.out)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
