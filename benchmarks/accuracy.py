"""Error against time for every sampling strategy and for Mitsuba 3: the speed/accuracy chart.

    pip install '.[bench,peer]' && python benchmarks/accuracy.py
    python benchmarks/accuracy.py --peer-python /path/to/mitsuba-venv/bin/python

For the books' cornell_box (300x300) and cornell_glass (150x150 and, as
cornell_glass@300, 300x300), and the scenes made to break one strategy each
(caustic, glass_lamp, tiny_light, mirror_light, 100x100) and the glossy
materials' cornell_rough (100x100; --scenes picks some),
against independent references
rendered by Mitsuba 3 (the folder RTWEEKEND_REFERENCES names, else
../shared/references beside the repository, else the copies in
tests/data/reference; a scene whose reference is absent is skipped, in one
line): one progressive render per strategy of
rtweekend.options.SAMPLINGS, measured after every doubling of spp, and the peer,
Mitsuba 3 (benchmarks/mitsuba_peer.py: its `path` integrator, next-event
estimation with MIS) rendering the same scene on the same machine with the same
number of threads: separate renders at 1, 2, 4, ... spp, each timed from scratch.
Mitsuba runs here if it imports, or in another interpreter (--peer-python, e.g.
its own venv); without it the chart shows rtweekend alone.

Records for every point the wall time (compile and a warm-up excluded, reported
apart), spp, RMSE (with the reference's own noise taken out: errors()) and
relative MSE of linear radiance against the reference, and
the fraction of NaN/Inf samples (Mitsuba: of pixel values); fits the slope of log
RMSE against log seconds (ideal: -1/2); and an equal-time table: each strategy's
RMSE interpolated (log-log) at Mitsuba's times, and its ratio to Mitsuba's RMSE.

Denoised (with the `denoise` extra; --no-denoise leaves it out): the scene's
default sampling rendered again with denoise=True, the denoised image's error
after every doubling of spp at the render's time plus the denoiser's, and
Mitsuba's --aov renders denoised the same way (OIDN with albedo and normal);
and the time where the denoised curve meets the unbiased one -- beyond it the
denoiser's bias is larger than the noise it removes.

Writes benchmark-results/accuracy.json, benchmark-results/accuracy.png (log-log error vs seconds,
one line per strategy and Mitsuba) and benchmark-results/accuracy_crops.png (equal-time
crops).  --quick runs a tiny version (up to 4 spp, images a third or half the size,
each against its reference averaged over blocks of that many pixels; cornell_box
and cornell_glass unless --scenes says otherwise) to check that the script works.
"""
import itertools
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

import rtweekend as rt
from rtweekend.io.image import tonemap
from rtweekend.options import DEFAULT_SAMPLING, SAMPLINGS

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from common import REFERENCES, machine, reference, save_json  # noqa: E402
from common import parser as bench_parser  # noqa: E402

KNOWN_COLORS = {"cosine": "tab:blue", "light": "tab:red", "mixture": "tab:green"}
PEER_COLOR = "black"
BOOKS = {
    "cornell_box": dict(width=300, height=300, max_spp=1024, crop_seconds=6.0,
                        reference="cornell_box_300", reference_spp=8192),
    "cornell_glass": dict(width=150, height=150, max_spp=1024, crop_seconds=3.0,
                          reference="cornell_glass_150", reference_spp=16384),
    # NAME@SIZE: the scene NAME at another size.
    "cornell_glass@300": dict(width=300, height=300, max_spp=512, crop_seconds=6.0,
                              reference="cornell_glass_300", reference_spp=110592),
}
# Where methods fail (docs/accuracy.md): each breaks one strategy.  tiny_light's own
# pixels (radiance 2000 on its edges) would measure how each renderer places
# samples in a pixel, not how it finds the light: they are left out (mask_above:
# pixels whose reference exceeds it in any channel).
FAILURES = {name: dict(width=100, height=100, max_spp=4096, crop_seconds=4.0,
                       reference=f"{name}_100", reference_spp=spp, mask_above=mask)
            for name, spp, mask in (("caustic", 206848, None), ("glass_lamp", 155648, None),
                                    ("glass_window", 262144, None),
                                    ("tiny_light", 198656, 2.0),
                                    ("mirror_light", 262144, None))}
# Glossy materials (GGX microfacets): a rough gold box and a frosted glass ball.
GLOSSY = {"cornell_rough": dict(width=100, height=100, max_spp=2048, crop_seconds=4.0,
                                reference="cornell_rough_100", reference_spp=65536)}
FULL = {**BOOKS, **FAILURES, **GLOSSY}


def _shrink(size):
    """--quick's image is the reference's size over this (its pixels are blocks of
    the reference's: the same camera, so the same radiance per block)."""
    return 3 if size % 3 == 0 else 2


QUICK = {name: dict(cfg, max_spp=4, crop_seconds=0.05, shrink=_shrink(cfg["width"]),
                    width=cfg["width"] // _shrink(cfg["width"]),
                    height=cfg["height"] // _shrink(cfg["width"]))
         for name, cfg in FULL.items()}
FIT_FROM_SPP = 8        # fit the slope where per-pass overheads no longer matter
SEED = 2024             # the renders measured; references use other seeds
NET_FLOOR = 0.1         # errors(): the net RMSE is at least this share of the raw one
COVER_FACTOR = 4        # rtweekend may go up to 4x max_spp to reach Mitsuba's last time
NO_PEER = "Mitsuba not installed: pip install '.[peer]'; charting rtweekend alone"


def colors():
    """A colour per strategy: the known ones fixed, any other the next free one."""
    free = itertools.cycle(f"tab:{c}" for c in ("orange", "purple", "brown", "pink", "olive",
                                                 "cyan"))
    return {s: KNOWN_COLORS.get(s) or next(free) for s in SAMPLINGS}


def errors(image, ref, ref_var):
    """(RMSE, raw RMSE, relMSE, fraction of non-finite values; those count as 0).

    The raw RMSE is against the reference; the RMSE, with the reference's own
    noise taken out: E[(image - ref)^2] = the image's MSE + the reference's
    variance (ref_var, the mean of its squared standard errors), so the latter is
    subtracted -- but never below NET_FLOOR of the raw value, where what is left
    is lost in the reference's noise."""
    image = np.asarray(image, dtype=np.float64)
    bad = ~np.isfinite(image)
    diff = np.where(bad, 0.0, image) - ref         # NaN where the reference is masked
    mse = float(np.nanmean(diff ** 2))
    net = math.sqrt(max(mse - ref_var, NET_FLOOR ** 2 * mse))
    return (net, math.sqrt(mse),
            float(np.nanmean(diff ** 2 / (ref ** 2 + 0.01))),   # relMSE, as in the literature
            float(bad.mean()))


def measure(scene, cfg, sampling, ref, ref_var, threads, cover=0.0):
    """One progressive render, measured at 1, 2, 4, ... max_spp spp, and further
    (up to COVER_FACTOR x max_spp) until its time reaches `cover` seconds."""
    warm = rt.Renderer(scene, seed=0, width=16, height=16, sampling=sampling, threads=threads)
    compile_seconds = warm.compile()         # compile, or load from Numba's cache
    warm.add_samples(1)                      # warm-up: caches, threads, page faults
    r = rt.Renderer(scene, seed=SEED, width=cfg["width"], height=cfg["height"],
                    sampling=sampling, threads=threads)
    r.compile()
    rows, target = [], 1
    while target <= cfg["max_spp"] or (r.seconds < cover
                                       and target <= COVER_FACTOR * cfg["max_spp"]):
        r.add_samples(target - r.spp)
        result = r.result()
        rmse, raw, relmse, _ = errors(result.image, ref, ref_var)
        rows.append(dict(spp=r.spp, seconds=r.seconds, rmse=rmse, rmse_raw=raw, relmse=relmse,
                         nan_fraction=result.stats.nan_dropped / result.stats.samples))
        print(f"  {sampling:8s} {r.spp:5d} spp {r.seconds:8.2f} s  RMSE {rmse:.5f}  "
              f"relMSE {relmse:.3e}", flush=True)
        target *= 2
    return rows, compile_seconds


# ---------------------------------------------------------------- denoised --
def can_denoise(args):
    """Whether to chart the denoised curves (said in one line when not)."""
    if args.no_denoise:
        return False
    try:
        import pyoidn  # noqa: F401
    except ImportError:
        print("Open Image Denoise not installed: pip install '.[denoise]'; no denoised curves")
        return False
    return True


def measure_denoised(scene, cfg, ref, ref_var, threads):
    """The scene's default sampling with denoise=True, after every doubling of
    spp: the denoised image's errors at the render's seconds plus the denoiser's."""
    warm = rt.Renderer(scene, seed=0, width=16, height=16, threads=threads, denoise=True)
    warm.compile()
    warm.add_samples(1)
    warm.result()                            # OIDN's first call sets it up
    r = rt.Renderer(scene, seed=SEED, width=cfg["width"], height=cfg["height"],
                    threads=threads, denoise=True)
    r.compile()
    rows, target = [], 1
    while target <= cfg["max_spp"]:
        r.add_samples(target - r.spp)
        result = r.result()
        rmse, raw, relmse, _ = errors(result.denoised, ref, ref_var)
        seconds = r.seconds + result.stats.denoise_seconds
        rows.append(dict(spp=r.spp, seconds=seconds, render_seconds=r.seconds, rmse=rmse,
                         rmse_raw=raw, relmse=relmse))
        print(f"  {'denoised':8s} {r.spp:5d} spp {seconds:8.2f} s  RMSE {rmse:.5f}", flush=True)
        target *= 2
    return r.options.sampling, rows


def measure_peer_denoised(peer, name, scene, cfg, ref, ref_var, threads):
    """Mitsuba's --aov renders denoised by OIDN with its albedo and normal, at its
    time plus the denoiser's; None without Mitsuba."""
    import mitsuba_peer
    points, _ = peer.series(name, scene, cfg, cfg["max_spp"], threads, aov=True)
    if points is None:
        return None
    rows = []
    for spp, seconds, image in points:
        t0 = time.perf_counter()
        den = mitsuba_peer.denoised(image)
        seconds += time.perf_counter() - t0
        rmse, raw, relmse, _ = errors(den, ref, ref_var)
        rows.append(dict(spp=spp, seconds=seconds, rmse=rmse, rmse_raw=raw, relmse=relmse))
        print(f"  {'Mitsuba denoised':8s} {spp:5d} spp {seconds:8.2f} s  RMSE {rmse:.5f}",
              flush=True)
    return rows


def where_curves_meet(denoised, unbiased):
    """The time from which the unbiased curve stays at or below the denoised one:
    the first of the denoised curve's times after the last at which the
    denoised image was ahead (None: it is ahead at the last time both were
    measured).  At the first points the denoiser's own time can put it behind."""
    meets, ahead_at_end = None, False
    for p in denoised:
        raw = rmse_at(unbiased, p["seconds"])
        if raw is None:
            continue
        if raw > p["rmse"]:
            meets, ahead_at_end = None, True
        else:
            if meets is None:
                meets = p["seconds"]
            ahead_at_end = False
    return None if ahead_at_end else meets


# ------------------------------------------------------------------ the peer --
class Peer:
    """Mitsuba 3, in this process or in another interpreter (`python`)."""

    def __init__(self, python=None):
        self.python = python
        self.how = f"subprocess: {python}" if python else "in-process"

    def series(self, name, scene, cfg, spp, threads, aov=False):
        """([(spp, seconds, image)], info), or (None, reason) when Mitsuba is
        not available there; aov: images of 9 channels (mitsuba_peer)."""
        if self.python:
            return _series_subprocess(self.python, name, cfg, spp, threads, aov)
        import mitsuba_peer
        info = {}
        scene = mitsuba_peer._resized(scene, cfg["width"], cfg["height"])
        spps = [2 ** k for k in range(spp.bit_length())]
        return mitsuba_peer.series(scene, spps, SEED, threads=threads, info=info,
                                   aov=aov), info


def _series_subprocess(python, name, cfg, spp, threads, aov=False):
    """mitsuba_peer.py --series in `python`, this repository first on its path."""
    if cfg["width"] != cfg["height"]:
        raise ValueError("mitsuba_peer.py --size renders square images of these scenes")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(HERE.parent), env.get("PYTHONPATH"))
                                        if p)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "series.npz"
        cmd = [python, str(HERE / "mitsuba_peer.py"), name.split("@")[0],
               "--size", str(cfg["width"]),
               "--spp", str(spp), "--seed", str(SEED), "--threads", str(threads),
               "--series", "--save", str(out)] + (["--aov"] if aov else [])
        r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=3600)
        if r.returncode:
            raise RuntimeError(f"the peer failed ({' '.join(cmd)}):\n{r.stderr[-2000:]}")
        info = json.loads(r.stdout.strip().splitlines()[-1])
        if not info.get("available"):
            return None, info.get("reason", "not available")
        with np.load(out) as f:
            points = list(zip(f["spp"].tolist(), f["seconds"].tolist(),
                              f["images"].astype(np.float64)))
    for k in ("peer", "available", "scene", "width", "height", "spp", "seconds"):
        info.pop(k, None)
    return points, info


def find_peer(args):
    """A Peer, or None after saying in one line why the chart has none."""
    if args.no_peer:
        print("Mitsuba left out (--no-peer); charting rtweekend alone")
        return None
    if args.peer_python:
        print(f"Mitsuba: run by {args.peer_python}")
        return Peer(args.peer_python)
    import mitsuba_peer
    why = mitsuba_peer.unavailable_reason()
    if why is None:
        print(f"Mitsuba {mitsuba_peer.mi.__version__}: in this process")
        return Peer()
    if mitsuba_peer.mi is None:
        print(NO_PEER)
    else:
        print(f"Mitsuba unusable here ({why}); charting rtweekend alone")
    return None


def measure_peer(peer, name, scene, cfg, ref, ref_var, threads):
    """The peer's rows, images and settings, or None (said why) when it has none."""
    points, info = peer.series(name, scene, cfg, cfg["max_spp"], threads)
    if points is None:
        print(f"Mitsuba not available ({peer.how}: {info}); charting rtweekend alone")
        return None
    rows, images = [], []
    for spp, seconds, image in points:
        if image.shape != ref.shape:
            raise ValueError(f"Mitsuba's image is {image.shape}, the reference {ref.shape}")
        rmse, raw, relmse, bad = errors(image, ref, ref_var)
        rows.append(dict(spp=spp, seconds=seconds, rmse=rmse, rmse_raw=raw, relmse=relmse,
                         nan_fraction=bad))
        images.append((image, spp, seconds))
        print(f"  {'Mitsuba':8s} {spp:5d} spp {seconds:8.2f} s  RMSE {rmse:.5f}  "
              f"relMSE {relmse:.3e}", flush=True)
    label = (f"Mitsuba {info.get('mitsuba', '3')} ({info.get('variant')}, path: "
             "next-event estimation + MIS)")
    return dict(label=label, how=peer.how, rows=rows, slope=fitted_slope(rows),
                **{k: info.get(k) for k in ("mitsuba", "variant", "threads", "pass_spp",
                                            "compile_seconds", "warmup_seconds")}), images


# ---------------------------------------------------------------- analysis --
def fitted_slope(rows):
    pts = [(math.log(p["seconds"]), math.log(p["rmse"])) for p in rows
           if p["spp"] >= FIT_FROM_SPP and p["seconds"] > 0]
    if len(pts) < 2:
        pts = [(math.log(p["seconds"]), math.log(p["rmse"])) for p in rows if p["seconds"] > 0]
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


def rmse_at(rows, seconds):
    """RMSE at a given time, interpolated log-log between measurements; None
    outside the times measured."""
    t = [p["seconds"] for p in rows]
    if not t[0] <= seconds <= t[-1]:
        return None
    e = np.log([p["rmse"] for p in rows])
    return float(np.exp(np.interp(math.log(seconds), np.log(t), e)))


def equal_time(curves):
    """Compare the strategies at the latest time they all reached."""
    base = DEFAULT_SAMPLING if DEFAULT_SAMPLING in curves else next(iter(curves))
    t = min(rows[-1]["seconds"] for rows in curves.values())
    at = {s: rmse_at(rows, t) for s, rows in curves.items()}
    # Variance ~ RMSE^2 ~ 1/time for an unbiased estimator: the time a strategy
    # needs to reach the base's error is (its RMSE / the base's)^2 times longer.
    return dict(seconds=t, rmse=at, base=base,
                time_factor_vs_base={s: (at[s] / at[base]) ** 2 if at[s] and at[base] else None
                                     for s in at})


def versus_peer(curves, peer_rows):
    """At each of Mitsuba's times: its RMSE, each strategy's (interpolated) and
    the ratio of the two (None where a strategy was not measured that long)."""
    table = []
    for p in peer_rows:
        at = {s: rmse_at(rows, p["seconds"]) for s, rows in curves.items()}
        table.append(dict(seconds=p["seconds"], peer_spp=p["spp"], peer_rmse=p["rmse"],
                          rmse=at, ratio={s: None if v is None else v / p["rmse"]
                                          for s, v in at.items()}))
    return table


def crops(scene, cfg, threads):
    """Equal-time renders of each strategy: (image, spp)."""
    out = {}
    for s in SAMPLINGS:
        r = rt.render(scene, time=cfg["crop_seconds"], seed=SEED + 1, width=cfg["width"],
                      height=cfg["height"], sampling=s, threads=threads)
        out[s] = (r.image, r.stats.spp)
    return out


# ------------------------------------------------------------------ charts --
def chart(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    palette = colors()
    n = len(data["scenes"])
    fig, axes = plt.subplots(1, n, figsize=(6.4 * n, 5.0))
    for ax, (name, d) in zip(np.atleast_1d(axes), data["scenes"].items()):
        for s, rows in d["curves"].items():
            ax.loglog([p["seconds"] for p in rows], [p["rmse"] for p in rows], "o-",
                      color=palette.get(s), ms=3, label=f"{s} (slope {d['slopes'][s]:+.2f})")
        if d["peer"]:
            rows = d["peer"]["rows"]
            ax.loglog([p["seconds"] for p in rows], [p["rmse"] for p in rows], "s--",
                      color=PEER_COLOR, ms=3,
                      label=f"Mitsuba 3, path (slope {d['peer']['slope']:+.2f})")
        den = d.get("denoised")
        if den:
            s = den["sampling"]
            ax.loglog([p["seconds"] for p in den["rows"]], [p["rmse"] for p in den["rows"]],
                      "x--", color=palette.get(s), ms=4, label=f"{s}, denoised (OIDN)")
            if den["meets"]:
                ax.axvline(den["meets"], color=palette.get(s), lw=0.8, ls=":")
            if den["peer"]:
                rows = den["peer"]
                ax.loglog([p["seconds"] for p in rows], [p["rmse"] for p in rows], "+:",
                          color=PEER_COLOR, ms=5, label="Mitsuba 3, denoised (OIDN)")
        guide = d["curves"][d["equal_time"]["base"]]
        t0, e0 = guide[0]["seconds"], guide[0]["rmse"]
        ts = np.array([t0, guide[-1]["seconds"]])
        ax.loglog(ts, e0 * (ts / t0) ** -0.5, ":", color="gray", label="slope -1/2")
        ax.axhline(d["reference_noise_rms"], color="black", lw=0.8, ls="-.",
                   label="reference's own noise (taken out)")
        ax.set_title(f"{name} {d['width']}x{d['height']}\nvs {d['reference']}", fontsize=9)
        ax.set_xlabel(f"seconds ({data['threads']} threads; denoised: the denoiser's included)")
        ax.set_ylabel("RMSE of linear radiance, the reference's noise out")
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def crop_chart(images, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [(name, [(f"{s}, {spp} spp in {seconds:g} s", im) for s, (im, spp) in
                    panels.items()] + extra + [("reference", ref)])
            for name, (ref, panels, seconds, extra) in images.items()]
    cols = max(len(p) for _, p in rows)
    fig, axes = plt.subplots(len(rows), cols, figsize=(3 * cols, 3.3 * len(rows)),
                             squeeze=False)
    for axrow, (name, panels) in zip(axes, rows):
        h, w = panels[-1][1].shape[:2]
        ys, xs = slice(h // 8, h // 8 + h // 2), slice(w // 4, w // 4 + w // 2)
        for ax in axrow:
            ax.axis("off")
        for ax, (title, img) in zip(axrow, panels):
            ax.imshow(tonemap(np.where(np.isfinite(img), img, 0)[ys, xs]),
                      interpolation="nearest")
            ax.set_title(f"{name}: {title}", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def block_means(ref, ref_se, k):
    """The reference (radiance, its standard error) over blocks of k x k pixels:
    the mean, and the standard error of the mean (pixels' errors independent)."""
    if k == 1:
        return ref, ref_se
    h, w, c = ref.shape
    blocks = (h // k, k, w // k, k, c)
    mean = ref[:h // k * k, :w // k * k].reshape(blocks).mean(axis=(1, 3))
    var = (ref_se[:h // k * k, :w // k * k] ** 2).reshape(blocks).sum(axis=(1, 3))
    return mean, np.sqrt(var) / (k * k)


def peer_crop(images, seconds):
    """Mitsuba's render with the most samples within `seconds` (else its first)."""
    within = [im for im in images if im[2] <= seconds] or images[:1]
    image, spp, t = within[-1]
    return [(f"Mitsuba, {spp} spp in {t:.2g} s", image)]


# -------------------------------------------------------------------- main --
def main(argv=None):
    parser = bench_parser(__doc__)
    parser.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS,
                        help="threads of rtweekend and of Mitsuba (default: all of Numba's)")
    parser.add_argument("--peer-python", default=os.environ.get("RTWEEKEND_PEER_PYTHON"),
                        help="run Mitsuba with this interpreter (e.g. its own venv's python; "
                             "env RTWEEKEND_PEER_PYTHON)")
    parser.add_argument("--no-peer", action="store_true", help="leave Mitsuba out")
    parser.add_argument("--no-denoise", action="store_true", help="leave the denoised "
                        "curves out")
    parser.add_argument("--scenes", help=f"comma-separated, of {', '.join(FULL)} "
                        "(default: all; with --quick, cornell_box and cornell_glass)")
    args = parser.parse_args(argv)
    config = QUICK if args.quick else FULL
    names = args.scenes.split(",") if args.scenes else (["cornell_box", "cornell_glass"]
                                                        if args.quick else list(FULL))
    unknown = [n for n in names if n not in FULL]
    if unknown:
        parser.error(f"--scenes: unknown {', '.join(unknown)} (known: {', '.join(FULL)})")
    config = {n: config[n] for n in names}
    start = time.perf_counter()
    peer = find_peer(args)
    denoising = can_denoise(args)
    data = dict(machine=machine(), quick=args.quick, threads=args.threads,
                references=str(REFERENCES), peer=peer.how if peer else None, scenes={})
    crop_images = {}
    for name, cfg in config.items():
        found = reference(cfg["reference"])
        if found is None:
            print(f"{name}: no reference {cfg['reference']}.npy (+ _stderr.npy) in {REFERENCES} "
                  "(set RTWEEKEND_REFERENCES); skipped")
            continue
        ref, ref_se, ref_file = found
        ref, ref_se = block_means(ref, ref_se, cfg.get("shrink", 1))
        if cfg.get("mask_above") is not None:        # NaN: left out of every error
            out = (ref.max(axis=2) > cfg["mask_above"])[..., None]
            ref = np.where(out, np.nan, ref)
            ref_se = np.where(out, np.nan, ref_se)
        ref_var = float(np.nanmean(ref_se ** 2))
        label = f"Mitsuba 3, {cfg['reference_spp']} spp (independent renderer)"
        scene = rt.load_scene(name.split("@")[0])
        print(f"{name} {cfg['width']}x{cfg['height']} against {label}", flush=True)
        peer_data, peer_images = None, []
        if peer:
            got = measure_peer(peer, name, scene, cfg, ref, ref_var, args.threads)
            if got:
                peer_data, peer_images = got
        cover = peer_data["rows"][-1]["seconds"] if peer_data else 0.0
        measured = {s: measure(scene, cfg, s, ref, ref_var, args.threads, cover)
                    for s in SAMPLINGS}
        curves = {s: rows for s, (rows, _) in measured.items()}
        data["scenes"][name] = dict(
            width=cfg["width"], height=cfg["height"], reference=label,
            reference_file=str(ref_file),
            reference_noise_rms=math.sqrt(ref_var),
            curves=curves, compile_seconds={s: c for s, (_, c) in measured.items()},
            slopes={s: fitted_slope(rows) for s, rows in curves.items()},
            equal_time=equal_time(curves), peer=peer_data,
            vs_peer=versus_peer(curves, peer_data["rows"]) if peer_data else [])
        if denoising:
            sampling, rows = measure_denoised(scene, cfg, ref, ref_var, args.threads)
            data["scenes"][name]["denoised"] = dict(
                sampling=sampling, rows=rows, meets=where_curves_meet(rows, curves[sampling]),
                peer=measure_peer_denoised(peer, name, scene, cfg, ref, ref_var, args.threads)
                if peer_data else None)
        crop_images[name] = (found[0], crops(scene, cfg, args.threads), cfg["crop_seconds"],
                             peer_crop(peer_images, cfg["crop_seconds"]) if peer_images else [])
    if not data["scenes"]:
        print(f"accuracy: no reference for any of {', '.join(config)} (looked in {REFERENCES}"
              " and tests/data/reference); nothing measured", file=sys.stderr)
        return 2
    data["total_seconds"] = time.perf_counter() - start
    data["machine"] = machine()              # now that Numba's threading layer is known
    args.out.mkdir(parents=True, exist_ok=True)
    save_json("accuracy.json", data, args.out)
    if data["scenes"]:
        chart(data, args.out / "accuracy.png")
        crop_chart(crop_images, args.out / "accuracy_crops.png")
    summary(data)


def time_factor(eq, s):
    """How the time strategy s needs for its error compares with the base's, in
    words; the base's curve can start after the equal time (a short run)."""
    f = eq["time_factor_vs_base"][s]
    if f is None:
        return f"{eq['base']} not measured this early"
    return f"{f:.2f}x {eq['base']}'s time for its error"


def summary(data):
    print(f"\ntotal {data['total_seconds']:.0f} s")
    for name, d in data["scenes"].items():
        eq = d["equal_time"]
        slopes = ", ".join(f"{s} {v:+.2f}" for s, v in d["slopes"].items())
        if d["peer"]:
            slopes += f", Mitsuba {d['peer']['slope']:+.2f}"
        print(f"{name}: slopes {slopes}")
        print(f"  at {eq['seconds']:.2f} s: " + ", ".join(
            f"{s} RMSE {eq['rmse'][s]:.4f} ({time_factor(eq, s)})"
            for s in eq["rmse"] if eq["rmse"][s]))
        den = d.get("denoised")
        if den:
            meets = (f"meets the unbiased curve at {den['meets']:.2f} s" if den["meets"] else
                     "ahead of the unbiased curve wherever both were measured")
            print(f"  {den['sampling']} denoised: RMSE {den['rows'][0]['rmse']:.4f} at "
                  f"{den['rows'][0]['seconds']:.2f} s .. {den['rows'][-1]['rmse']:.4f} at "
                  f"{den['rows'][-1]['seconds']:.2f} s; {meets}")
        if d["vs_peer"]:
            print(equal_time_table(name, d))


def equal_time_table(name, d):
    """The equal-time table as Markdown: a row per Mitsuba point, each strategy's
    RMSE at that time and its ratio to Mitsuba's."""
    strategies = list(d["curves"])
    lines = [f"{name}: RMSE at Mitsuba's times (ratio to Mitsuba's RMSE)", "",
             "| seconds | Mitsuba spp | Mitsuba RMSE | " + " | ".join(strategies) + " |",
             "|---:|---:|---:|" + "---:|" * len(strategies)]
    for row in d["vs_peer"]:
        cells = ["--" if row["rmse"][s] is None else
                 f"{row['rmse'][s]:.4f} ({row['ratio'][s]:.2f}x)" for s in strategies]
        lines.append(f"| {row['seconds']:.3g} | {row['peer_spp']} | {row['peer_rmse']:.4f} | "
                     + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
