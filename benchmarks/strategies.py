"""Which strategy has the lowest error at equal time, on every scene: the
measurement behind the default.

    python benchmarks/strategies.py [--seconds 3] [--threads 2] [--width 100] [--quick]

For each path-traced bundled scene (at --width pixels across, the height
keeping its aspect) and each candidate (mixture+sobol, nee+sobol, bdpt+sobol,
bdpt+photons):
two renders of --seconds of rendering each (seeds 1 and 2; compiled and warmed
up first), and their error without any reference: for two independent
unbiased renders a and b of a pixel, E[(a - b)^2] = 2 Var, so

    RMSE = sqrt(mean over pixels and channels of (a - b)^2 / 2)

is the root mean squared error of one render, the noise of the other included
in no way.  (bdpt+photons is consistent, not unbiased: this measures its
noise, not its small bias, which accuracy.py measures against references.)
Prints the ratio of each candidate's RMSE to the default's and
which is lowest; for an unbiased estimator a ratio r means r^2 times the time
to reach the same error.  Writes benchmark-results/strategies.json.
"""
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, parser, save_json  # noqa: E402

import rtweekend as rt  # noqa: E402
from rtweekend.options import DEFAULT_SAMPLING  # noqa: E402

CANDIDATES = ("mixture+sobol", "nee+sobol", "bdpt+sobol", "bdpt+photons")


def renders(scene, sampling, width, height, seconds, threads):
    """Two independent renders of `seconds` each, after compiling and a warm-up."""
    warm = rt.Renderer(scene, seed=0, width=16, height=16, sampling=sampling, threads=threads)
    compile_seconds = warm.compile()
    warm.add_samples(1)
    out = []
    for seed in (1, 2):
        r = rt.render(scene, time=seconds, seed=seed, width=width, height=height,
                      sampling=sampling, threads=threads)
        out.append(r)
    return out, compile_seconds


def rmse_of_pair(a, b):
    d = a.image.astype(np.float64) - b.image.astype(np.float64)
    return float(np.sqrt(np.mean(d * d) / 2.0))


def measure(name, width, seconds, threads):
    scene = rt.load_scene(name)
    c = scene.camera
    height = max(1, round(width * c.height / c.width))
    row = dict(width=width, height=height, strategies={})
    for s in CANDIDATES:
        (a, b), compile_seconds = renders(scene, s, width, height, seconds, threads)
        spp = (a.stats.spp + b.stats.spp) / 2
        row["strategies"][s] = dict(rmse=rmse_of_pair(a, b), spp=spp,
                                    seconds=(a.stats.seconds + b.stats.seconds) / 2,
                                    compile_seconds=compile_seconds,
                                    fireflies=(a.stats.fireflies + b.stats.fireflies) / 2)
        print(f"  {name:16s} {s:14s} {spp:7.0f} spp  RMSE {row['strategies'][s]['rmse']:.5f}",
              flush=True)
    base = row["strategies"][DEFAULT_SAMPLING]["rmse"]
    for v in row["strategies"].values():
        v["ratio_to_default"] = v["rmse"] / base if base > 0 else None
    row["lowest"] = min(row["strategies"], key=lambda s: row["strategies"][s]["rmse"])
    return row


def path_traced_scenes():
    return [n for n in sorted(rt.bundled_scenes())
            if rt.load_scene(n).resolved_integrator() == "path"]


def main(argv=None):
    p = parser(__doc__)
    p.add_argument("--seconds", type=float, default=3.0, help="rendering seconds per render")
    p.add_argument("--width", type=int, default=100)
    p.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    p.add_argument("--scenes", help="comma-separated (default: every path-traced bundled one)")
    a = p.parse_args(argv)
    names = a.scenes.split(",") if a.scenes else path_traced_scenes()
    if a.quick:
        # Two scenes, tiny: by default the two accuracy.py's quick run renders
        # with every strategy (the tests run both: one cold compile each).
        names = names[:2] if a.scenes else ["cornell_box", "cornell_glass"]
        a.seconds, a.width = 0.2, 24
    start = time.perf_counter()
    data = dict(machine=machine(), seconds=a.seconds, threads=a.threads,
                default=DEFAULT_SAMPLING, scenes={})
    for name in names:
        data["scenes"][name] = measure(name, a.width, a.seconds, a.threads)
    data["total_seconds"] = time.perf_counter() - start
    save_json("strategies.json", data, a.out)
    print(f"\nRMSE at {a.seconds:g} s each, ratio to {DEFAULT_SAMPLING} (lower is better)\n")
    print("| scene | " + " | ".join(CANDIDATES) + " | lowest |")
    print("|---|" + "---:|" * len(CANDIDATES) + "---|")
    for name, row in data["scenes"].items():
        got = row["strategies"]
        cells = [f"{got[s]['rmse']:.4f} ({got[s]['ratio_to_default']:.2f}x)" for s in CANDIDATES]
        print(f"| `{name}` | " + " | ".join(cells) + f" | {row['lowest']} |")
    print(f"\ntotal {data['total_seconds']:.0f} s")


if __name__ == "__main__":
    main()
