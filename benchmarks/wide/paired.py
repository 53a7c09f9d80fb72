"""Scalar rtweekend against the wavefront prototype, pass by pass in one process.

    PYTHONPATH=. python -m benchmarks.wide.paired [--seconds 40] [--threads 1,2]

bench.py times each renderer in a fresh process; on the shared 2-core machine
those ratios spread over +-30% (its table).  Here the scalar renderer and the two
variants of the wave (sort=False: the fused pass; sort=True: shading grouped by
material) take turns in one process, a short pass each (benchmarks/paired.py's
take_turns), so a ratio compares the same machine within a second.  Same scenes,
sizes and modes as bench.py; `sampling="mixture"`.  Prints the median of the
per-round ratios to scalar and their interquartile range; writes
benchmarks/wide/paired.json.
"""
import argparse
import json
import statistics
import sys
from pathlib import Path

import numba

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from paired import spread, take_turns  # noqa: E402  (benchmarks/paired.py)

# scene: (width, height, spp of a pass, the wave's intersection mode)
SCENES = {"cornell_glass": (300, 300, 2, "flat"), "cornell_box": (300, 300, 2, "flat"),
          "weekend": (320, 180, 4, "packet")}
IMPLS = ("scalar", "wide unsorted", "wide sorted")


def measure(name, seconds):
    import rtweekend as rt

    from .wave import WideRenderer
    w, h, spp, mode = SCENES[name]
    scene = rt.load_scene(name)

    def one_pass(r):
        r.compile()
        r.add_samples(1)                      # warm-up
        return lambda: w * h * spp / r.add_samples(spp)
    rates = take_turns([
        one_pass(rt.Renderer(scene, seed=1, width=w, height=h, sampling="mixture")),
        one_pass(WideRenderer(scene, seed=1, width=w, height=h, mode=mode, sort=False)),
        one_pass(WideRenderer(scene, seed=1, width=w, height=h, mode=mode, sort=True))],
        seconds)
    return {impl: dict(samples_per_s=statistics.median(r),
                       ratio=spread([y / x for x, y in zip(rates[0], r)]))
            for impl, r in zip(IMPLS, rates)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=40.0, help="per scene and thread count")
    ap.add_argument("--threads", default="1,2")
    a = ap.parse_args()
    out = {}
    for n in [int(t) for t in a.threads.split(",")]:
        numba.set_num_threads(n)
        for name in SCENES:
            out[f"{name}/{n}"] = d = measure(name, a.seconds)
            for impl in IMPLS[1:]:
                r = d[impl]["ratio"]
                print(f"{name:14s} {n} thread(s) {impl:14s} "
                      f"{d[impl]['samples_per_s'] / 1e6:5.2f} M samples/s (scalar "
                      f"{d['scalar']['samples_per_s'] / 1e6:5.2f} M): {r['median']:.3f}x"
                      f" (IQR {r['q1']:.3f}-{r['q3']:.3f}, {r['rounds']} rounds)", flush=True)
    (HERE / "paired.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
