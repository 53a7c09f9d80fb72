"""What a low-discrepancy sample costs, and what it buys.

    python benchmarks/sobol.py

Cost: nanoseconds per 2-D sample of kernel/sobol.py's sample_2d (and per 1-D
sample_1d) against the counter RNG's pair of rng.uniform draws (from a running
stream, as a bounce draws them; and with the stream's seed_state per sample, as a
camera sample starts).  One thread, a loop over pixels x samples summing the
coordinates; the kernels take turns, median (and minimum) of the runs after a
warm-up.  The loops' iterations are independent, so this is throughput, as
when a sample's draws overlap the rest of its work.

Gain: the log-log slope of the RMS error over pixels of an N-point estimate
(N = 4..1024) of a smooth integral (exp(uv) over the unit square) and of a
discontinuous one (a disc's area), with Sobol points and with the counter RNG.

Writes benchmark-results/sobol.json.  --quick runs a tiny version.
"""
import math
import sys
import time
from pathlib import Path

import numba
import numpy as np

from rtweekend.kernel import rng, sobol

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, parser, save_json  # noqa: E402


@numba.njit
def sobol_2d(pixels, samples, seed):
    acc = 0.0
    for p in range(pixels):
        for i in range(samples):
            u, v = sobol.sample_2d(p, i, 1, seed)
            acc += u + v
    return acc


@numba.njit
def sobol_1d(pixels, samples, seed):
    acc = 0.0
    for p in range(pixels):
        for i in range(samples):
            acc += sobol.sample_1d(p, i, 1, seed)
    return acc


@numba.njit
def rng_pair(pixels, samples, seed):
    acc = 0.0
    for p in range(pixels):
        state = rng.seed_state(p, 0, seed)
        for i in range(samples):
            u, state = rng.uniform(state)
            v, state = rng.uniform(state)
            acc += u + v
    return acc


@numba.njit
def rng_seeded_pair(pixels, samples, seed):
    acc = 0.0
    for p in range(pixels):
        for i in range(samples):
            state = rng.seed_state(p, i, seed)
            u, state = rng.uniform(state)
            v, state = rng.uniform(state)
            acc += u + v
    return acc


KERNELS = {
    "sobol.sample_2d": sobol_2d,
    "sobol.sample_1d": sobol_1d,
    "rng.uniform pair": rng_pair,
    "rng.seed_state + uniform pair": rng_seeded_pair,
}


@numba.njit
def rmse(pixels, n, disc, use_sobol, exact, seed):
    """RMS error over pixels of the n-point estimate of the integral."""
    s2 = 0.0
    for p in range(pixels):
        acc = 0.0
        state = rng.seed_state(p, 0, seed)
        for i in range(n):
            if use_sobol:
                u, v = sobol.sample_2d(p, i, 1, seed)
            else:
                u, state = rng.uniform(state)
                v, state = rng.uniform(state)
            if disc:
                acc += 1.0 if (u - 0.45) ** 2 + (v - 0.55) ** 2 < 0.35 * 0.35 else 0.0
            else:
                acc += math.exp(u * v)
        e = acc / n - exact
        s2 += e * e
    return math.sqrt(s2 / pixels)


def cost(pixels, samples, runs):
    """ns per call of each kernel: the kernels take turns in every run (a busy
    machine slows them alike), median and minimum over the runs."""
    times = {name: [] for name in KERNELS}
    for kernel in KERNELS.values():
        kernel(2, 2, 0)                                   # compile
    for r in range(runs):
        for name, kernel in KERNELS.items():
            t = time.perf_counter()
            kernel(pixels, samples, r)
            times[name].append(1e9 * (time.perf_counter() - t) / (pixels * samples))
    out = {name: {"ns_per_sample": float(np.median(t)), "ns_min": float(np.min(t))}
           for name, t in times.items()}
    base = out["rng.uniform pair"]
    for row in out.values():
        row["vs_rng_pair"] = row["ns_per_sample"] / base["ns_per_sample"]
        row["vs_rng_pair_min"] = row["ns_min"] / base["ns_min"]
    return out


def slopes(pixels, ns):
    exact = {"smooth exp(uv)": sum(1 / (n * math.factorial(n)) for n in range(1, 25)),
             "disc indicator": math.pi * 0.35 ** 2}
    out = {}
    for name, value in exact.items():
        for sampler, use_sobol in (("sobol", True), ("rng", False)):
            err = [rmse(pixels, int(n), name.startswith("disc"), use_sobol, value, 7)
                   for n in ns]
            out[f"{name}, {sampler}"] = {
                "slope": float(np.polyfit(np.log(ns), np.log(err), 1)[0]),
                "rmse": dict(zip((int(n) for n in ns), err))}
    return out


def main():
    args = parser(__doc__).parse_args()
    numba.set_num_threads(1)
    pixels, samples, runs = (256, 64, 3) if args.quick else (16384, 256, 15)
    ns = 2 ** np.arange(2, 7 if args.quick else 11)
    data = {"machine": machine(),
            "cost": cost(pixels, samples, runs),
            "calls_per_run": pixels * samples,
            "slopes": slopes(256 if args.quick else 8192, ns),
            "slope_pixels": 256 if args.quick else 8192}
    for name, row in data["cost"].items():
        print(f"{name:32s} {row['ns_per_sample']:6.2f} ns (min {row['ns_min']:5.2f}), "
              f"{row['vs_rng_pair']:.2f}x a pair (min {row['vs_rng_pair_min']:.2f}x)")
    for name, row in data["slopes"].items():
        print(f"RMSE slope, {name:26s} {row['slope']:+.3f}")
    print("wrote", save_json("sobol.json", data, args.out))


if __name__ == "__main__":
    main()
