"""What each of The Next Week's features costs: cold compile and samples/s of the
kernel compiled for each feature set a bundled scene uses.

    python benchmarks/features.py [--runs 3]

A scene pays only for the features it uses (path/integrators/path.py: each is an
argument that is None when unused, so the kernel of a scene without it has none
of its code).  For each scene: its feature set, the kernel's cold compile in a
fresh process with an empty Numba cache (median of --runs), and samples/s after
that warm-up (the default sampling, 2 threads, at a small size).
Writes results/features.json and prints a table.
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

SCENES = ["cornell_box", "checkered_spheres", "cornell_smoke", "bouncing_spheres",
          "next_week_final"]
CHILD = r"""
import json, sys, time
import rtweekend as rt
from rtweekend.path.renderer import Renderer
name, size, spp = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
r = Renderer(rt.load_scene(name), seed=1, width=size, height=size)
f = r.frame
features = [n for n, v in (("textures", f.features.textures), ("media", f.features.media),
                           ("motion", f.features.motion)) if v is not None]
compile_s = r.compile()
r.add_samples(1)                                    # warm-up
t = r.add_samples(spp)
print(json.dumps(dict(features=features or ["none"], compile_s=compile_s,
                      samples_per_s=size * size * spp / t)))
"""


def measure(name, size, spp, runs):
    out = []
    for _ in range(runs):
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, NUMBA_CACHE_DIR=cache)
            p = subprocess.run([sys.executable, "-c", CHILD, name, str(size), str(spp)],
                               env=env, capture_output=True, text=True, check=True)
            out.append(json.loads(p.stdout.strip().splitlines()[-1]))
    compile_s = float(np.median([o["compile_s"] for o in out]))
    rate = float(np.median([o["samples_per_s"] for o in out]))
    return dict(scene=name, features=out[0]["features"], compile_s=compile_s,
                compile_runs=[o["compile_s"] for o in out], samples_per_s=rate)


def main():
    p = bench_parser(__doc__)
    p.add_argument("--runs", type=int, default=1, help="fresh processes per scene")
    args = p.parse_args()
    size, spp = (16, 1) if args.quick else (100, 8)
    scenes = SCENES[:2] if args.quick else SCENES
    rows = []
    print(f"{'scene':20s} {'features':26s} {'cold compile':>13s} {'samples/s':>11s}")
    for name in scenes:
        row = measure(name, size, spp, args.runs)
        rows.append(row)
        print(f"{name:20s} {'+'.join(row['features']):26s} {row['compile_s']:11.1f} s "
              f"{row['samples_per_s'] / 1e6:9.2f} M", flush=True)
    path = save_json("features.json", dict(machine=machine(), size=size, spp=spp,
                                           runs=args.runs, rows=rows), args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
