"""Error against time for each sampling strategy: the speed/accuracy chart.

    pip install '.[bench]' && python benchmarks/accuracy.py

For cornell_box (against Mitsuba 3's 8192-spp reference) and cornell_glass
(against a long render of its own, labelled as such), render with cosine
sampling (The Next Week), light sampling only, and the 0.5/0.5 mixture (The Rest
of Your Life): one progressive render per strategy, measured after every
doubling of spp.  Records wall time (compile and a warm-up pass excluded), spp,
RMSE and relative MSE against the reference, and the fraction of NaN/Inf
samples; fits the slope of log RMSE against log seconds (ideal: -1/2).

Writes results/accuracy.json, results/accuracy.png (log-log error vs seconds,
one line per strategy) and results/accuracy_crops.png (equal-time crops).
--quick runs a tiny version (seconds) to check that the script works.
"""
import math
import sys
import time
from pathlib import Path

import numpy as np

import rtweekend as rt
from rtweekend.io.image import tonemap

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, mitsuba_reference, save_json  # noqa: E402
from common import parser as bench_parser  # noqa: E402

STRATEGIES = ("cosine", "light", "mixture")
COLORS = {"cosine": "tab:blue", "light": "tab:red", "mixture": "tab:green"}
FULL = {
    "cornell_box": dict(width=300, height=300, max_spp=1024, crop_seconds=6.0),
    "cornell_glass": dict(width=150, height=150, max_spp=512, reference_spp=4096,
                          crop_seconds=3.0),
}
QUICK = {
    "cornell_box": dict(width=300, height=300, max_spp=4, crop_seconds=0.2),
    "cornell_glass": dict(width=40, height=40, max_spp=4, reference_spp=16,
                          crop_seconds=0.2),
}
FIT_FROM_SPP = 8        # fit the slope where per-pass overheads no longer matter
SEED = 2024             # the renders measured; references use other seeds


def reference_for(name, cfg, scene):
    """(radiance, per-pixel stderr, label) of the answer errors are measured against."""
    if name == "cornell_box":
        ref, se = mitsuba_reference()
        return ref, se, "Mitsuba 3, 8192 spp (independent renderer)"
    spp = cfg["reference_spp"]
    print(f"{name}: rendering its own reference, {spp} spp ...", flush=True)
    r = rt.render(scene, spp=spp, seed=1, width=cfg["width"], height=cfg["height"])
    return (r.image.astype(np.float64), r.stderr.astype(np.float64),
            f"rtweekend itself, mixture sampling, {spp} spp (not independent)")


def errors(image, ref):
    diff = image.astype(np.float64) - ref
    return (float(np.sqrt(np.mean(diff ** 2))),
            float(np.mean(diff ** 2 / (ref ** 2 + 0.01))))   # relMSE, as in the literature


def measure(scene, cfg, sampling, ref):
    warm = rt.Renderer(scene, seed=0, width=16, height=16, sampling=sampling)
    warm.compile()
    warm.add_samples(1)                      # warm-up: caches, threads, page faults
    r = rt.Renderer(scene, seed=SEED, width=cfg["width"], height=cfg["height"],
                    sampling=sampling)
    r.compile()
    rows, target = [], 1
    while target <= cfg["max_spp"]:
        r.add_samples(target - r.spp)
        result = r.result()
        rmse, relmse = errors(result.image, ref)
        rows.append(dict(spp=r.spp, seconds=r.seconds, rmse=rmse, relmse=relmse,
                         nan_fraction=result.stats.nan_dropped / result.stats.samples))
        print(f"  {sampling:8s} {r.spp:5d} spp {r.seconds:8.2f} s  RMSE {rmse:.5f}  "
              f"relMSE {relmse:.3e}", flush=True)
        target *= 2
    return rows


def fitted_slope(rows):
    pts = [(math.log(p["seconds"]), math.log(p["rmse"])) for p in rows
           if p["spp"] >= FIT_FROM_SPP and p["seconds"] > 0]
    if len(pts) < 2:
        pts = [(math.log(p["seconds"]), math.log(p["rmse"])) for p in rows if p["seconds"] > 0]
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def rmse_at(rows, seconds):
    """RMSE at a given time, interpolated log-log between measurements."""
    t = np.log([p["seconds"] for p in rows])
    e = np.log([p["rmse"] for p in rows])
    return float(np.exp(np.interp(math.log(seconds), t, e)))


def equal_time(curves):
    """Compare the strategies at the latest time they all reached."""
    t = min(rows[-1]["seconds"] for rows in curves.values())
    at = {s: rmse_at(rows, t) for s, rows in curves.items()}
    # Variance ~ RMSE^2 ~ 1/time for an unbiased estimator: the time a strategy
    # needs to reach mixture's error is (its RMSE / mixture's)^2 times longer.
    return dict(seconds=t, rmse=at,
                time_factor_vs_mixture={s: (at[s] / at["mixture"]) ** 2 for s in at})


def crops(scene, cfg):
    """Equal-time renders of each strategy; a centre crop of each, and the reference."""
    out = {}
    for s in STRATEGIES:
        r = rt.render(scene, time=cfg["crop_seconds"], seed=SEED + 1, width=cfg["width"],
                      height=cfg["height"], sampling=s)
        out[s] = (r.image, r.stats.spp)
    return out


def chart(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(data["scenes"]), figsize=(6 * len(data["scenes"]), 4.6))
    for ax, (name, d) in zip(np.atleast_1d(axes), data["scenes"].items()):
        for s, rows in d["curves"].items():
            t = [p["seconds"] for p in rows]
            e = [p["rmse"] for p in rows]
            ax.loglog(t, e, "o-", color=COLORS[s], ms=3,
                      label=f"{s} (slope {d['slopes'][s]:+.2f})")
        t0 = d["curves"]["mixture"][0]["seconds"]
        e0 = d["curves"]["mixture"][0]["rmse"]
        ts = np.array([t0, d["curves"]["mixture"][-1]["seconds"]])
        ax.loglog(ts, e0 * (ts / t0) ** -0.5, ":", color="gray", label="slope -1/2")
        ax.axhline(d["reference_noise_rms"], color="black", lw=0.8, ls="--",
                   label="reference's own noise")
        ax.set_title(f"{name} {d['width']}x{d['height']}\nvs {d['reference']}", fontsize=9)
        ax.set_xlabel("seconds (2 threads)")
        ax.set_ylabel("RMSE of linear radiance")
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def crop_chart(images, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(images)
    fig, axes = plt.subplots(len(names), 4, figsize=(12, 3.3 * len(names)))
    for row, name in zip(np.atleast_2d(axes), names):
        ref, panels, seconds = images[name]
        h, w = ref.shape[:2]
        ys, xs = slice(h // 8, h // 8 + h // 2), slice(w // 4, w // 4 + w // 2)
        for ax, (title, img) in zip(row, [*[(f"{s}, {spp} spp in {seconds:g} s", im)
                                            for s, (im, spp) in panels.items()],
                                          ("reference", ref)]):
            ax.imshow(tonemap(img[ys, xs]), interpolation="nearest")
            ax.set_title(f"{name}: {title}", fontsize=8)
            ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = bench_parser(__doc__)
    args = parser.parse_args(argv)
    config = QUICK if args.quick else FULL
    start = time.perf_counter()
    data = dict(machine=machine(), quick=args.quick, scenes={})
    crop_images = {}
    for name, cfg in config.items():
        scene = rt.load_scene(name)
        ref, ref_se, label = reference_for(name, cfg, scene)
        print(f"{name} {cfg['width']}x{cfg['height']} against {label}", flush=True)
        curves = {s: measure(scene, cfg, s, ref) for s in STRATEGIES}
        data["scenes"][name] = dict(
            width=cfg["width"], height=cfg["height"], reference=label,
            reference_noise_rms=float(np.sqrt(np.mean(ref_se ** 2))),
            curves=curves, slopes={s: fitted_slope(rows) for s, rows in curves.items()},
            equal_time=equal_time(curves))
        crop_images[name] = (ref, crops(scene, cfg), cfg["crop_seconds"])
    data["total_seconds"] = time.perf_counter() - start
    args.out.mkdir(parents=True, exist_ok=True)
    save_json("accuracy.json", data, args.out)
    chart(data, args.out / "accuracy.png")
    crop_chart(crop_images, args.out / "accuracy_crops.png")
    summary(data)


def summary(data):
    print(f"\ntotal {data['total_seconds']:.0f} s")
    for name, d in data["scenes"].items():
        eq = d["equal_time"]
        slopes = ", ".join(f"{s} {v:+.2f}" for s, v in d["slopes"].items())
        print(f"{name}: slopes {slopes}")
        print(f"  at {eq['seconds']:.1f} s: " + ", ".join(
            f"{s} RMSE {eq['rmse'][s]:.4f} ({eq['time_factor_vs_mixture'][s]:.2f}x "
            "mixture's time for its error)" for s in STRATEGIES))


if __name__ == "__main__":
    main()
