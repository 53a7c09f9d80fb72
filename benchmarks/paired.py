"""Speed ratios measured pass by pass in one process: the way to compare on a
shared machine.

    python benchmarks/paired.py yardstick [--seconds 60] [--threads 1,2]
    python benchmarks/paired.py trees TREE_A TREE_B [...] [--scene S] [--sampling M]
                                  [--threads N]    (default: all)

On the 2-core VM two fresh processes running the same code differ by 10-20%
(the host's load moves under them), so ratios of separate runs, even
alternated, needed many rounds and still moved by +-10%.  Here everything runs
in one process and takes turns, a short pass each (2 spp at 300x300, about a
tenth of a second), in alternating order: both sides of a ratio see the same
machine within a fraction of a second.  Each ratio is the median of the
per-round ratios; the spread given is their interquartile range.

yardstick: rtweekend's cornell_glass (the books' mixture sampling) against
../shared/yardsticks/numba_probe.py (the same scene and estimator) imported as
a module, with 1 thread and with all: as shipped (float32, fastmath with
'reassoc' and 'contract'), and built with rtweekend's fastmath flags in float32
and float64 (yardstick.BUILDS), all taking turns in the same rounds; then, for
rtweekend and each build, whether a first render (the process compiles) and the
next (it loads the cache) give the same bits.  trees: the rtweekend package of each
source tree imported under its own name (a copy), for before/after
comparisons of a change; the first tree is the base.

Writes benchmark-results/paired.json in yardstick mode (--quick: a second per side,
48x48, no file).
"""
import importlib
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numba

sys.path.insert(0, str(Path(__file__).resolve().parent))
import yardstick  # noqa: E402
from common import first_render_and_next, machine, save_json  # noqa: E402
from common import parser as bench_parser  # noqa: E402

SIZE = 300          # pixels a side
SPP = 2             # samples per pixel of one pass


def spread(ratios):
    q = sorted(ratios)
    return dict(median=statistics.median(q), q1=q[len(q) // 4], q3=q[(3 * len(q)) // 4],
                rounds=len(q))


def take_turns(passes, seconds):
    """Call each pass() in turn (order reversed every other round) for `seconds`;
    returns each one's list of samples/s, round by round."""
    rates = [[] for _ in passes]
    start, k = time.perf_counter(), 0
    while time.perf_counter() - start < seconds or k < 3:
        order = range(len(passes)) if k % 2 == 0 else reversed(range(len(passes)))
        for i in order:
            rates[i].append(passes[i]())
        k += 1
    return rates


def renderer_pass(rt, scene, sampling, size=SIZE, spp=SPP):
    r = rt.Renderer(rt.load_scene(scene), seed=1, sampling=sampling, width=size,
                    height=size)
    r.compile()
    r.add_samples(1)
    return lambda: size * size * spp / r.add_samples(spp)


def beside_yardstick(seconds, threads, size=SIZE, builds=tuple(yardstick.BUILDS)):
    """rtweekend / yardstick on cornell_glass, mixture sampling, per thread count,
    beside each of the yardstick's `builds` (yardstick.BUILDS) in the same rounds.
    The top-level figures are the shipped build's."""
    import rtweekend as rt
    probes = {b: yardstick.load(b) for b in builds}
    for probe in probes.values():
        probe.render(2, 2, 1)                          # its compile, not timed
    out = {}
    for n in threads:
        numba.set_num_threads(n)
        ours = renderer_pass(rt, "cornell_glass", "mixture", size)
        seeds = iter(range(1, 10**9))

        def theirs(probe):
            def one_pass():
                _, _, _, seconds_taken, _ = probe.render(size, size, SPP, seed=next(seeds))
                return size * size * SPP / seconds_taken
            return one_pass
        rates = take_turns([ours] + [theirs(p) for p in probes.values()], seconds)
        a = rates[0]
        per_build = {b: dict(samples_per_s=statistics.median(r),
                             ratio=spread([x / y for x, y in zip(a, r)]))
                     for b, r in zip(probes, rates[1:])}
        first = per_build[builds[0]]
        out[str(n)] = dict(rtweekend_samples_per_s=statistics.median(a),
                           yardstick_samples_per_s=first["samples_per_s"],
                           ratio=first["ratio"], builds=per_build)
        print(f"  {n} thread(s): rtweekend {statistics.median(a) / 1e6:.2f} M samples/s",
              flush=True)
        for b, d in per_build.items():
            r = d["ratio"]
            print(f"    yardstick {b:20s} {d['samples_per_s'] / 1e6:.2f} M: {r['median']:.3f}x"
                  f" (IQR {r['q1']:.3f}-{r['q3']:.3f}, {r['rounds']} rounds)", flush=True)
    return out


RTWEEKEND_IMAGE = """
import sys, numpy as np, rtweekend as rt
r = rt.Renderer(rt.load_scene("cornell_glass"), seed=1, sampling="mixture",
                width=int(sys.argv[1]), height=int(sys.argv[1]))
r.add_samples(int(sys.argv[2]))
np.save(sys.argv[3] + ".npy", r.result().image)
"""


def rtweekend_fresh_vs_cached(size=64, spp=16):
    """common.first_render_and_next for rtweekend's cornell_glass (mixture)."""
    return first_render_and_next([sys.executable, "-c", RTWEEKEND_IMAGE, str(size), str(spp)])


def fresh_vs_cached():
    """Does the first render (the process compiles the kernel) give the bits of
    the next (it loads the kernel from the cache)?  rtweekend and each build."""
    print("the first render against the next (64x64x16: compiled, then from the cache):",
          flush=True)
    out = {}
    for name, check in [("rtweekend", rtweekend_fresh_vs_cached)] + [
            (f"yardstick {b}", lambda b=b: yardstick.fresh_vs_cached(b))
            for b in yardstick.BUILDS]:
        differ, values = check()
        out[name] = dict(values_that_differ=differ, values=values)
        print(f"  {name:30s} {differ} of {values} values differ", flush=True)
    return out


def trees(paths, seconds, scene, sampling):
    """samples/s of each tree's package, and its ratio to the first."""
    folder = Path(tempfile.mkdtemp(prefix="rtweekend_trees_"))
    sys.path.insert(0, str(folder))
    # Run from a source checkout (not installed), a copied package finds the
    # bundled scenes beside it, as the checkout's does (scene/loader.py).
    if (Path(paths[0]) / "scenes").is_dir():
        shutil.copytree(Path(paths[0]) / "scenes", folder / "scenes")
    passes = []
    for i, tree in enumerate(paths):
        name = f"rtweekend_tree{i}"
        shutil.copytree(Path(tree) / "rtweekend", folder / name,
                        ignore=shutil.ignore_patterns("__pycache__"))
        passes.append(renderer_pass(importlib.import_module(name), scene, sampling))
    rates = take_turns(passes, seconds)
    for tree, r in zip(paths, rates):
        s = spread([y / x for x, y in zip(rates[0], r)])
        print(f"  {tree}: {statistics.median(r) / 1e6:.3f} M samples/s, {s['median']:.3f}x"
              f" the first (IQR {s['q1']:.3f}-{s['q3']:.3f}, {s['rounds']} rounds)")
    shutil.rmtree(folder, ignore_errors=True)


def main(argv=None):
    p = bench_parser(__doc__)
    p.add_argument("mode", choices=["yardstick", "trees"])
    p.add_argument("paths", nargs="*", help="source trees (trees mode)")
    p.add_argument("--seconds", type=float, default=60.0, help="per thread count or comparison")
    p.add_argument("--threads", default=None,
                   help="thread counts, e.g. 1,2 (yardstick; default: 1 and all) or N (trees)")
    p.add_argument("--scene", default="cornell_glass")
    p.add_argument("--sampling", default="mixture")
    a = p.parse_args(argv)
    threads = ([int(t) for t in a.threads.split(",")] if a.threads
               else sorted({1, numba.config.NUMBA_NUM_THREADS}))
    if a.mode == "trees":
        if not a.paths:
            p.error("trees: give at least one source tree")
        numba.set_num_threads(threads[0] if a.threads else numba.config.NUMBA_NUM_THREADS)
        trees(a.paths, 1.0 if a.quick else a.seconds, a.scene, a.sampling)
        return
    if not yardstick.available():
        print(f"yardstick not found at {yardstick.PATH}: nothing to compare")
        return
    print("cornell_glass (mixture) beside the yardstick, pass by pass in one process:")
    out = beside_yardstick(1.0 if a.quick else a.seconds, threads,
                           size=48 if a.quick else SIZE)
    if not a.quick:
        same_bits = fresh_vs_cached()
        save_json("paired.json", dict(machine=machine(), size=SIZE, spp_per_pass=SPP,
                                      seconds=a.seconds, threads=out,
                                      fresh_vs_cached=same_bits), folder=a.out)


if __name__ == "__main__":
    main()
