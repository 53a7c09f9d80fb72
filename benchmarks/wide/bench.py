"""Scalar rtweekend against the wavefront prototype: paired, alternated, fresh processes.

    PYTHONPATH=. python -m benchmarks.wide.bench [--rounds 5] [--quick]

Every measurement is its own process: build the renderer (scalar:
rtweekend.Renderer(scene, seed=1, width=W, height=H, sampling="mixture"); wide:
wave.WideRenderer with the same fields and a variant), compile (Numba's cache
warm: the cached start), add_samples(1) as a warm-up, then one timed
add_samples(spp).  A round runs every implementation once per (scene, threads),
in an order that rotates from round to round, so that each wide run has a
scalar run next to it in time; the machine is shared, so only the ratio within
a round (wide samples/s / scalar samples/s) means much, and the table gives the
median of those paired ratios beside the medians of samples/s.

Variants of the prototype (wave.py):
  sorted     the full design: SIMD intersection, shading compacted by material
             (surface, counting sort, one shading loop per material)
  unsorted   SIMD intersection, then one fused per-ray pass (surface + shading +
             compaction of the survivors), no grouping by material
  control    no SIMD: rtweekend's own per-ray closest_hit on the wave's SoA
             buffers, and the fused pass (what the wave costs by itself)
The SIMD intersection is the per-kind loops over all objects for the Cornell
scenes (8 objects, no BVH) and the packet BVH walk (packets of 16) for weekend.

Also: cold compile times (fresh process, empty caches), the wide renderer's
phase split (time-stamp counter, per phase) and the scalar kernel's (the share
in closest_hit, scalar_profile.py).  Writes benchmarks/wide/results.json.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
# scene: (width, height, spp, {variant: WideRenderer keyword arguments})
SCENES = {
    "cornell_glass": (300, 300, 16, {"sorted": {"mode": "flat"},
                                     "unsorted": {"mode": "flat", "sort": False},
                                     "control": {"mode": "ray", "sort": False}}),
    "cornell_box": (300, 300, 16, {"sorted": {"mode": "flat"},
                                   "unsorted": {"mode": "flat", "sort": False},
                                   "control": {"mode": "ray", "sort": False}}),
    "weekend": (320, 180, 32, {"sorted": {"mode": "packet"},
                               "unsorted": {"mode": "packet", "sort": False},
                               "control": {"mode": "ray", "sort": False}}),
}
THREADS = (1, 2)


# -- one measurement (in its own process) ------------------------------------------

def measure(job):
    import rtweekend

    scene = rtweekend.load_scene(job["scene"])
    w, h, spp = job["width"], job["height"], job["spp"]
    t0 = time.perf_counter()
    if job["impl"] == "scalar_split":
        from .scalar_profile import scalar_split
        share, seconds = scalar_split(scene, w, h, spp)
        return {"closest_hit_share": share, "seconds": seconds}
    if job["impl"] == "scalar":
        r = rtweekend.Renderer(scene, seed=1, width=w, height=h, sampling="mixture",
                               threads=job["threads"])
    else:
        from .wave import WideRenderer
        r = WideRenderer(scene, seed=1, width=w, height=h, threads=job["threads"],
                         **job["kw"])
    compile_s = r.compile()
    start_s = time.perf_counter() - t0
    r.add_samples(1)
    if job["impl"] != "scalar":
        r.reset_profile()
    seconds = r.add_samples(spp)
    out = {"seconds": seconds, "samples_per_s": w * h * spp / seconds,
           "compile_s": compile_s, "start_s": start_s}
    if job["impl"] != "scalar":
        out["profile"], _ = r.profile()
    return out


def run(job, env=None):
    p = subprocess.run([sys.executable, "-m", "benchmarks.wide.bench", "--worker",
                        json.dumps(job)], capture_output=True, text=True, cwd=ROOT,
                       env=dict(os.environ, **(env or {})))
    if p.returncode:
        raise SystemExit(f"{job}: failed\n{p.stderr[-3000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


# -- the benchmark -------------------------------------------------------------------

def cold_compile(rounds):
    """Seconds to compile from nothing (fresh process, empty caches), tiny image."""
    out = {"scalar": [], "wide": []}
    for _ in range(rounds):
        for impl in out:
            with tempfile.TemporaryDirectory() as cache:
                job = {"scene": "cornell_glass", "width": 8, "height": 8, "spp": 1,
                       "threads": 1, "impl": impl, "kw": {"mode": "flat"}}
                r = run(job, {"NUMBA_CACHE_DIR": cache, "WIDE_NO_CACHE": "1"})
            out[impl].append(r["compile_s"])
    return {k: statistics.median(v) for k, v in out.items()} | {"runs": out}


def summarise(records):
    """Per (scene, threads, impl): median samples/s, and for wide variants the
    median (and range) of the ratios to the scalar run of the same round."""
    table = {}
    for scene in SCENES:
        for threads in THREADS:
            recs = [r for r in records if r["scene"] == scene and r["threads"] == threads]
            scalar = {r["round"]: r["samples_per_s"] for r in recs if r["impl"] == "scalar"}
            for impl in ["scalar"] + list(SCENES[scene][3]):
                mine = [r for r in recs if r["impl"] == impl]
                row = {"samples_per_s": statistics.median(r["samples_per_s"] for r in mine),
                       "start_s": statistics.median(r["start_s"] for r in mine)}
                if impl != "scalar":
                    ratios = [r["samples_per_s"] / scalar[r["round"]] for r in mine]
                    row.update(ratio=statistics.median(ratios), ratio_min=min(ratios),
                               ratio_max=max(ratios), ratios=ratios)
                    row["profile"] = {k: statistics.median(r["profile"][k] for r in mine)
                                      for k in mine[0]["profile"]}
                table[f"{scene}/{threads}/{impl}"] = row
    return table


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="tiny images, 1 round")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        print(json.dumps(measure(json.loads(args.worker))))
        return
    rounds = 1 if args.quick else args.rounds
    scale = 4 if args.quick else 1
    # Warm the caches (a first wide process compiles for the others).
    run({"scene": "cornell_glass", "width": 8, "height": 8, "spp": 1, "threads": 1,
         "impl": "scalar"})
    run({"scene": "cornell_glass", "width": 8, "height": 8, "spp": 1, "threads": 1,
         "impl": "wide", "kw": {"mode": "flat"}})
    records = []
    for rnd in range(rounds):
        for scene, (w, h, spp, variants) in SCENES.items():
            w, h = w // scale, h // scale
            impls = ["scalar"] + list(variants)
            k = rnd % len(impls)
            for threads in THREADS:
                for impl in impls[k:] + impls[:k]:
                    job = {"scene": scene, "width": w, "height": h, "spp": spp,
                           "threads": threads, "impl": impl, "kw": variants.get(impl)}
                    r = run(job)
                    records.append(dict(job, round=rnd, **r))
                    print(f"round {rnd} {scene:13s} {threads}T {impl:9s} "
                          f"{r['samples_per_s'] / 1e6:6.3f} M samples/s", flush=True)
    split = {}
    for scene, (w, h, _, _) in SCENES.items():
        split[scene] = run({"scene": scene, "width": w // scale // 2,
                            "height": h // scale // 2, "spp": 8, "threads": 1,
                            "impl": "scalar_split"})["closest_hit_share"]
    compile_s = cold_compile(1 if args.quick else 2)
    table = summarise(records)
    import numba
    result = {"machine": {"numba": numba.__version__, "cpus": os.cpu_count(),
                          "date": time.strftime("%Y-%m-%dT%H:%M:%S"),
                          "note": "shared machine: only paired ratios are meaningful"},
              "rounds": rounds, "scenes": {k: v[:3] for k, v in SCENES.items()},
              "variants": {k: v[3] for k, v in SCENES.items()},
              "table": table, "scalar_closest_hit_share": split,
              "cold_compile_s": compile_s, "records": records}
    if not args.quick:
        (HERE / "results.json").write_text(json.dumps(result, indent=1) + "\n")
    print_table(result)


def print_table(result):
    t = result["table"]
    print("\nwide / scalar samples/s: median of paired ratios [min, max] over "
          f"{result['rounds']} rounds; scalar in M samples/s")
    print(f"{'scene':14s} {'thr':>3s} {'scalar':>8s}  " + "".join(
        f"{v:>22s}" for v in ("sorted", "unsorted", "control")))
    for scene in SCENES:
        for threads in THREADS:
            s = t[f"{scene}/{threads}/scalar"]["samples_per_s"] / 1e6
            cells = []
            for v in ("sorted", "unsorted", "control"):
                r = t[f"{scene}/{threads}/{v}"]
                cells.append(f"{r['ratio']:.2f} [{r['ratio_min']:.2f}, {r['ratio_max']:.2f}]")
            print(f"{scene:14s} {threads:3d} {s:8.3f}  " + "".join(f"{c:>22s}" for c in cells))
    print("\nphase split of the wide variants (1 thread, median shares):")
    for scene in SCENES:
        for v in ("sorted", "unsorted", "control"):
            p = t[f"{scene}/1/{v}"]["profile"]
            print(f"  {scene:14s} {v:9s} " + "  ".join(f"{k} {x:.2f}" for k, x in p.items()))
    print("scalar kernel, share of its cycles in closest_hit: " + ", ".join(
        f"{k} {v:.2f}" for k, v in result["scalar_closest_hit_share"].items()))
    c = result["cold_compile_s"]
    print(f"cold compile (s): scalar {c['scalar']:.1f}, wide {c['wide']:.1f}; cached start "
          "(s, median, 1 thread): " + ", ".join(
              f"{s} scalar {t[f'{s}/1/scalar']['start_s']:.2f} wide "
              f"{t[f'{s}/1/sorted']['start_s']:.2f}" for s in SCENES))


if __name__ == "__main__":
    main()
