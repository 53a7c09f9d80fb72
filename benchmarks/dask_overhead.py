"""The cost of rendering on Dask: a LocalCluster of 2 workers against the local render.

    pip install '.[dask]' && python benchmarks/dask_overhead.py

cornell_glass at 600x600, 100 and 1000 spp: the local render with 2 Numba
threads (no cluster running), then the same image on a LocalCluster of 2
single-threaded worker processes (rtweekend.render(..., client=)), both after a
warm-up (kernels compiled, workers warm).  Records wall time (what a user waits,
scatter and merging included) and the render time of the stats, the overhead
of the distributed path, and checks that the two images are bit-identical
(target: within 15% of local at 1000 spp).  Then what an idle cluster beside
the local render costs it (32 spp, 3 alternated runs), the cold start of a worker:
the first render on a fresh LocalCluster whose workers' Numba cache is empty,
and again with that cache present: the warm-up's wall time (one worker per
host compiles, the others then load its cache) and each worker's first kernel
call; and the import of rtweekend in a fresh process, which a worker pays
before its first task (here the spawned workers import it at start-up, as they
re-import this script).

Writes benchmark-results/distributed.json and prints a table.  --quick runs a tiny
version (seconds) to check that the script works; --cold-start adds the
cold-start measurement to it (about a minute: a compile).
"""
import logging
import os
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

import rtweekend as rt
from rtweekend.distributed import dask_client
from rtweekend.distributed.cluster import THREADS_VAR
from rtweekend.path.film import BLOCK_SPP

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, save_json  # noqa: E402
from common import parser as bench_parser  # noqa: E402

SCENE = "cornell_glass"
SEED = 7
WORKERS = 2
FULL = dict(size=(600, 600), spp=[100, 1000], runs=1, cold_start=True, idle=(32, 3))
QUICK = dict(size=(48, 48), spp=[20, 40], runs=1, cold_start=False, idle=(16, 1))
TARGET_OVERHEAD = 0.15      # at the largest spp


def timed(fn):
    t0 = time.perf_counter()
    result = fn()
    return result, time.perf_counter() - t0


@contextmanager
def warm_cluster(scene):
    """A LocalCluster of WORKERS workers with their kernels loaded (from the cache)."""
    with dask_client(workers=WORKERS) as client:
        client.wait_for_workers(WORKERS)
        rt.render(scene, spp=BLOCK_SPP, width=16, height=16, client=client)
        yield client


def compare(scene, size, spp, runs):
    """Local (2 threads) and distributed renders of the same image, alternated.

    The cluster is started before each distributed render and closed after it:
    its idle processes would otherwise run beside the local render and slow it
    (see idle_cluster_cost), which a user rendering locally does not have.
    """
    width, height = size
    opts = dict(spp=spp, seed=SEED, width=width, height=height)
    rows = []
    for _ in range(runs):
        local, local_wall = timed(lambda: rt.render(scene, threads=WORKERS, **opts))
        with warm_cluster(scene) as client:
            far, far_wall = timed(lambda: rt.render(scene, client=client, **opts))
        rows.append(dict(local_wall=local_wall, local_render=local.stats.seconds,
                         distributed_wall=far_wall, distributed_render=far.stats.seconds,
                         identical=bool(np.array_equal(local.image, far.image)
                                        and local.stats.rays == far.stats.rays)))
    best = dict(local_wall=min(r["local_wall"] for r in rows),
                distributed_wall=min(r["distributed_wall"] for r in rows),
                local_render=min(r["local_render"] for r in rows),
                distributed_render=min(r["distributed_render"] for r in rows))
    return dict(spp=spp, blocks=-(-spp // BLOCK_SPP), runs=rows, **best,
                overhead=best["distributed_wall"] / best["local_wall"] - 1.0,
                identical=all(r["identical"] for r in rows),
                block_bytes=block_bytes(width, height))


def idle_cluster_cost(scene, size, spp, runs):
    """The local 2-thread render with no cluster, and with an idle LocalCluster of
    WORKERS workers running beside it (alternated; median samples/s of each)."""
    width, height = size
    opts = dict(spp=spp, seed=SEED, width=width, height=height, threads=WORKERS)
    rates = dict(alone=[], idle_cluster=[])
    for _ in range(runs):
        rates["alone"].append(width * height * spp / rt.render(scene, **opts).stats.seconds)
        with warm_cluster(scene):
            time.sleep(1.0)                   # let the start-up settle
            rates["idle_cluster"].append(
                width * height * spp / rt.render(scene, **opts).stats.seconds)
    alone, idle = (float(np.median(rates[k])) for k in ("alone", "idle_cluster"))
    return dict(spp=spp, runs=runs, samples_per_s=rates, alone=alone, idle_cluster=idle,
                slowdown=1.0 - idle / alone)


def block_bytes(width, height):
    """What one task sends back: the film of a whole block (path/film.Film less
    the emptied partial sums)."""
    from rtweekend.path.film import HIST_BINS
    return height * width * (2 * 3 * 8 + 8) + height * (2 * 8 + 2 * HIST_BINS * 8)


def _kernel_seconds():
    """On a worker: what its first kernel call cost (compile, or load from the cache)."""
    from rtweekend.distributed.worker import worker_info
    return worker_info()["compile_seconds"]


def cold_start(scene):
    """A first render on a fresh LocalCluster whose Numba cache is empty, then on
    another with that cache present: the warm-up's wall time (one worker per host
    compiles, then the others load its cache) and each worker's first kernel call."""
    import dask
    from distributed import Client, LocalCluster
    out = {}
    saved = os.environ.get("NUMBA_CACHE_DIR")
    with tempfile.TemporaryDirectory() as cache:
        for label in ("empty_cache", "cache_present"):
            # Set before the worker process starts: a spawned worker imports this
            # script (and so rtweekend and Numba) before the Nanny's env= applies.
            with dask.config.set({"distributed.nanny.pre-spawn-environ.NUMBA_CACHE_DIR":
                                  cache}):
                cluster = LocalCluster(n_workers=WORKERS, threads_per_worker=1,
                                       processes=True, dashboard_address=None,
                                       scheduler_kwargs={"dashboard_address": ":0"},
                                       env={THREADS_VAR: "1"},
                                       silence_logs=logging.CRITICAL)
            if saved is None:             # the Nanny set it here too
                os.environ.pop("NUMBA_CACHE_DIR", None)
            else:
                os.environ["NUMBA_CACHE_DIR"] = saved
            client = Client(cluster, set_as_default=False)
            try:
                client.wait_for_workers(WORKERS)
                result = rt.render(scene, spp=BLOCK_SPP, width=16, height=16, client=client)
                out[label] = dict(warm_up_s=result.stats.compile_seconds,
                                  kernel_s_per_worker=sorted(
                                      client.run(_kernel_seconds).values(), reverse=True))
            finally:
                client.close()
                cluster.close()
    return out


def import_seconds():
    """What a fresh worker pays before its first task runs: importing rtweekend
    (and so Numba), timed in a new process."""
    code = ("import time; t = time.perf_counter(); import rtweekend.distributed; "
            "print(time.perf_counter() - t)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       check=True)
    return float(r.stdout)


def main(argv=None):
    parser = bench_parser(__doc__)
    parser.add_argument("--cold-start", action="store_true",
                        help="with --quick: measure the workers' cold start too")
    args = parser.parse_args(argv)
    cfg = QUICK if args.quick else FULL
    scene = rt.load_scene(SCENE)
    width, height = cfg["size"]
    start = time.perf_counter()
    data = dict(machine=machine(), quick=args.quick, scene=SCENE, width=width, height=height,
                seed=SEED, workers=WORKERS, local_threads=WORKERS, block_spp=BLOCK_SPP,
                target_overhead=TARGET_OVERHEAD, rows=[])
    rt.render(scene, spp=1, width=16, height=16, threads=WORKERS)      # compile here
    for spp in cfg["spp"]:
        row = compare(scene, cfg["size"], spp, cfg["runs"])
        data["rows"].append(row)
        print(f"  {spp:5d} spp: local {row['local_wall']:8.2f} s, distributed "
              f"{row['distributed_wall']:8.2f} s ({100 * row['overhead']:+.1f}%), "
              f"identical: {row['identical']}", flush=True)
    data["idle_cluster"] = idle_cluster_cost(scene, cfg["size"], *cfg["idle"])
    print("  an idle cluster beside the local render costs it "
          f"{100 * data['idle_cluster']['slowdown']:.1f}%", flush=True)
    if cfg["cold_start"] or args.cold_start:
        print("  cold start of the workers (a compile) ...", flush=True)
        data["cold_start"] = cold_start(scene)
        data["cold_start"]["import_rtweekend_s"] = import_seconds()
    data["total_seconds"] = time.perf_counter() - start
    args.out.mkdir(parents=True, exist_ok=True)
    path = save_json("distributed.json", data, args.out)
    table(data)
    print(f"\nwrote {path}")


def table(data):
    print(f"\n{data['scene']} {data['width']}x{data['height']}: local render with "
          f"{data['local_threads']} threads vs LocalCluster of {data['workers']} "
          "single-threaded workers (wall seconds, after warm-up)")
    print(f"{'spp':>6} {'blocks':>6} {'local s':>9} {'dask s':>9} {'overhead':>9} "
          f"{'MB/block':>9} {'identical':>9}")
    for r in data["rows"]:
        print(f"{r['spp']:6d} {r['blocks']:6d} {r['local_wall']:9.2f} "
              f"{r['distributed_wall']:9.2f} {100 * r['overhead']:+8.1f}% "
              f"{r['block_bytes'] / 1e6:9.1f} {str(r['identical']):>9}")
    last = data["rows"][-1]
    if data["quick"]:
        print("quick run: a tiny image, where a render's fixed costs (scatter, warm-up "
              "round trip) dominate; the target is for the full run")
    else:
        verdict = "meets" if last["overhead"] <= data["target_overhead"] else "misses"
        print(f"overhead at {last['spp']} spp {verdict} the target of "
              f"{100 * data['target_overhead']:.0f}%")
    idle = data["idle_cluster"]
    print(f"local render alone {idle['alone'] / 1e6:.3f} M samples/s, beside an idle "
          f"cluster {idle['idle_cluster'] / 1e6:.3f} M ({100 * idle['slowdown']:.1f}% slower)")
    cold = data.get("cold_start", {})
    for label in ("empty_cache", "cache_present"):
        if label in cold:
            c = cold[label]
            cells = ", ".join(f"{x:.1f} s" for x in c["kernel_s_per_worker"])
            print(f"cold start, {label.replace('_', ' ')}: warm-up {c['warm_up_s']:.1f} s; "
                  f"first kernel call per worker: {cells}")
    if "import_rtweekend_s" in cold:
        print(f"  plus importing rtweekend in a fresh worker: {cold['import_rtweekend_s']:.2f} s")
    print(f"total {data['total_seconds']:.0f} s")


if __name__ == "__main__":
    main()
