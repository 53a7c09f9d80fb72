"""What a first run costs, beside the yardstick's first run in the same run.

    python benchmarks/compile.py [--rounds 1] [--scenes a,b] [--quick]

Whole processes, as a new user meets them: for each bundled scene (and
mixed_features.toml, every feature at once: a checker texture, fog, a moving
ball, glass and a mesh), `rtweekend render SCENE --width 64 --height 64 --spp
1` with an empty cache (XDG_CACHE_HOME of its own), then the same command
again with that cache (the cached start).  The yardstick's own cold start,
whole process with an empty Numba cache,

    NUMBA_CACHE_DIR=EMPTY PROBE_FM=det PROBE_DTYPE=f64 \
        python ../shared/yardsticks/numba_probe.py bench 64 1 1

runs before the first scene, between every few and after the last; each
scene's ratio is to the median of those runs (these machines' speed drifts
over minutes).  For the default scene, in Python: the compile seconds the
render reports against the wall time before its first pass (every compile is
counted: kernel/compile_clock.py), and how the compile was shared with the
helper process (kernel/claims.py).

--quick: two small scenes, one round, no yardstick (only checks that it runs).
Writes benchmark-results/compile.json and prints a table.
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import yardstick  # noqa: E402
from common import machine, save_json  # noqa: E402
from common import parser as bench_parser  # noqa: E402

HERE = Path(__file__).resolve().parent
MIXED = HERE / "mixed_features.toml"
YARDSTICK_EVERY = 4           # scenes between two runs of the yardstick

# In Python, the default scene: seconds before the first pass against the
# compile seconds reported, and the shared compile's split.
BEFORE_FIRST_PASS = """
import json, os, time
t0 = time.perf_counter()
import rtweekend as rt
from rtweekend.kernel import compile_workers
r = rt.Renderer(rt.load_scene("cornell_glass"), width=64, height=64)
r.compile()
before = time.perf_counter() - t0
r.add_samples(1)
here = compile_workers.SHARE.get(os.getpid(), 0)
print(json.dumps(dict(before_first_pass_s=before, compile_reported_s=r.compile_seconds,
                      sampling=r.options.sampling, compiled_here=here,
                      compiled_by_helpers=sum(compile_workers.SHARE.values()) - here)))
"""


def _listed():
    p = subprocess.run([sys.executable, "-m", "rtweekend", "scenes"], capture_output=True,
                       text=True, check=True)
    return [line.split()[0] for line in p.stdout.splitlines() if line.strip()]


def _timed(cmd, env, cwd):
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=1800)
    seconds = time.perf_counter() - t0
    if p.returncode:
        raise RuntimeError(f"{' '.join(map(str, cmd))}: {p.stderr[-2000:]}")
    return seconds, p.stdout


def yardstick_cold():
    """Seconds of the yardstick's whole first run (empty Numba cache)."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PROBE_FM="det", PROBE_DTYPE="f64")
        return _timed([sys.executable, str(yardstick.PATH), "bench", "64", "1", "1"], env,
                      cache)[0]


def scene_cold_and_cached(scene):
    """(cold seconds, cached seconds, the summary line) of `rtweekend render scene`."""
    with tempfile.TemporaryDirectory() as home:
        env = dict(os.environ, XDG_CACHE_HOME=home)
        env.pop("NUMBA_CACHE_DIR", None)
        # The classic ray tracer takes no --spp (one ray per pixel).
        spp = [] if str(scene) == "cgfs" else ["--spp", "1"]
        cmd = [sys.executable, "-m", "rtweekend", "render", str(scene), "--width", "64",
               "--height", "64", *spp, "-q", "-o", str(Path(home) / "x.png")]
        cold, out = _timed(cmd, env, home)
        cached, _ = _timed(cmd, env, home)
        return cold, cached, out.strip().splitlines()[-1]


def before_first_pass():
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        _, out = _timed([sys.executable, "-c", BEFORE_FIRST_PASS], env, cache)
        return json.loads(out.strip().splitlines()[-1])


def main():
    p = bench_parser(__doc__)
    p.add_argument("--rounds", type=int, default=1, help="cold runs per scene (median)")
    p.add_argument("--scenes", help="comma-separated names or scene files (default: every "
                   "bundled scene, then mixed_features)")
    args = p.parse_args()
    if args.scenes:
        known = {name: name for name in _listed()} | {MIXED.stem: str(MIXED)}
        scenes = [known.get(s, s) for s in args.scenes.split(",")]
        unknown = [s for s in scenes if s not in known.values() and not Path(s).is_file()]
        if unknown:
            p.error(f"--scenes: no scene {', '.join(unknown)} (bundled: "
                    f"{', '.join(known)}; or a scene file)")
    elif args.quick:
        scenes = ["cornell_box", "cgfs"]
    else:
        scenes = _listed() + [str(MIXED)]
    use_yardstick = yardstick.available() and not args.quick
    if not use_yardstick and not args.quick:
        print(f"yardstick: {yardstick.PATH} not found (set RTWEEKEND_YARDSTICK); "
              "seconds only")
    yard = []
    rows = []
    print(f"{'scene':18s} {'cold':>7s} {'/ yardstick':>11s} {'cached':>7s}  summary")
    for i, scene in enumerate(scenes):
        if use_yardstick and i % YARDSTICK_EVERY == 0:
            yard.append(yardstick_cold())
            print(f"{'(yardstick)':18s} {yard[-1]:6.1f}s", flush=True)
        runs = [scene_cold_and_cached(scene) for _ in range(1 if args.quick else args.rounds)]
        cold = statistics.median(r[0] for r in runs)
        cached = statistics.median(r[1] for r in runs)
        name = Path(scene).stem
        rows.append(dict(scene=name, cold_s=cold, cold_runs=[r[0] for r in runs],
                         cached_s=cached, summary=runs[0][2]))
        print(f"{name:18s} {cold:6.1f}s {'':>11s} {cached:6.2f}s  {runs[0][2][:90]}",
              flush=True)
    if use_yardstick:
        yard.append(yardstick_cold())
        print(f"{'(yardstick)':18s} {yard[-1]:6.1f}s")
        base = statistics.median(yard)
        print(f"\nthe yardstick's cold start: median {base:.1f} s of {len(yard)} runs")
        print(f"{'scene':18s} {'cold':>7s} {'/ yardstick':>11s} {'cached':>7s}")
        for row in rows:
            row["ratio"] = row["cold_s"] / base
            print(f"{row['scene']:18s} {row['cold_s']:6.1f}s {row['ratio']:10.2f}x "
                  f"{row['cached_s']:6.2f}s")
    first = None if args.quick else before_first_pass()
    if first:
        print(f"\ncornell_glass ({first['sampling']}): {first['before_first_pass_s']:.1f} s "
              f"before the first pass, {first['compile_reported_s']:.1f} s reported compiling "
              f"({first['compile_reported_s'] / first['before_first_pass_s']:.0%}); steps and "
              f"kernels compiled here {first['compiled_here']}, by the helper "
              f"{first['compiled_by_helpers']}")
    total = sum(r["cold_s"] for r in rows)
    print(f"sum of the cold starts: {total:.1f} s")
    if not args.quick:
        path = save_json("compile.json", dict(
            machine=machine(), size=64, spp=1, rounds=args.rounds,
            yardstick=dict(runs=yard, median=statistics.median(yard)) if yard else None,
            rows=rows, default_scene=first), args.out)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
