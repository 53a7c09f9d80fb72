"""What Open Image Denoise buys: the error of the denoised image against the
unbiased one, at equal samples, and what it costs.

    pip install '.[bench,denoise]' && python benchmarks/denoise.py [--threads 2] [--quick]

1. Error: the default strategy on cornell_glass (--size 300 by default) at 4,
   16, 64, 256 spp (seed 2024), against the independent Mitsuba reference
   (common.reference; a reference of another size is compared after both are
   averaged down to its size, 2x2 pixels to one: the box filter's pixel
   squares nest).  For each: the raw image's RMSE and the denoised image's,
   denoised five ways -- the colour alone; with albedo and normal, OIDN
   prefiltering them (clean_aux False: the default); with them taken as clean
   (clean_aux True); the light seen emitted kept out of the filter and the
   samples' own estimate of it added back; and what rtweekend does, that light
   estimated again where it varies (path/seen_light.py) added back -- and the
   ratios to the raw RMSE.  Each RMSE is given twice: plain, and with the
   reference's own noise taken out (an image x independent of the reference r
   has E[(x - r)^2] = (x - truth)^2 + stderr_r^2: the mean of the reference's
   squared standard errors is subtracted from the mean squared error).
2. Error against time: one progressive render of the default (1, 2, 4, ...
   --max-spp spp), raw and denoised (its time plus the denoiser's), beside
   Mitsuba 3 (accuracy.py's peer: --peer-python, or in this process) rendering
   1, 2, 4, ... spp with its `aov` integrator giving the albedo and normal of
   the first hit, raw and denoised by OIDN with them (Mitsuba has no feature
   for the light seen emitted, so its light is filtered with the rest).  Where
   the denoised curve meets the raw one, the denoiser's bias is as large as
   the noise it removes: beyond it, denoise no more.
3. Cost: a render of the scene at its own size and spp (cornell_glass:
   600x600, 100 spp) with denoise=True: rendering seconds, denoising seconds
   (the light seen estimated again, then the filter) and their ratio (after a
   warm-up render and denoise); and the pass that estimates the light seen
   again timed alone, with what it did.

Writes benchmark-results/denoise.json and benchmark-results/denoise.png; --quick is a tiny run
that checks the script.
"""
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, parser, reference, save_json  # noqa: E402

import rtweekend as rt  # noqa: E402
from rtweekend.denoise import denoise, require  # noqa: E402
from rtweekend.path import seen_light  # noqa: E402

SEED = 2024
WAYS = ("colour alone", "albedo+normal, prefiltered", "albedo+normal, clean_aux",
        "light seen kept out, the samples' own added back",
        "rtweekend (light seen kept out, estimated again)")


def down_to(image, shape):
    """image averaged down by whole factors to `shape` (H, W)."""
    f = image.shape[0] // shape[0]
    if f == 1:
        return image.astype(np.float64)
    h, w = shape
    return image.astype(np.float64).reshape(h, f, w, f, 3).mean(axis=(1, 3))


def rmse(image, ref):
    return float(np.sqrt(np.mean((down_to(image, ref.shape[:2]) - ref) ** 2)))


def rmse_clean(image, ref, ref_stderr):
    """rmse with the reference's own noise taken out: the root of the mean
    squared error less the mean of the reference's squared standard errors
    (0 if that is negative)."""
    mse = np.mean((down_to(image, ref.shape[:2]) - ref) ** 2)
    return float(np.sqrt(max(mse - np.mean(ref_stderr ** 2), 0.0)))


def denoised_ways(renderer, result, threads):
    """({way: image} for the five ways of feeding OIDN, what the pass that
    estimates the light seen again did)."""
    import pyoidn
    a = result.aov
    image = np.ascontiguousarray(result.image)
    albedo = np.ascontiguousarray(np.clip(a["albedo"], 0, 1))
    normal = np.ascontiguousarray(np.clip(a["normal"], -1, 1))
    light, done = seen_light.estimate(renderer.frame, a["emission"], renderer.spp,
                                      result.stats.rays, threads)
    return {
        WAYS[0]: pyoidn.denoise(image, hdr=True),
        WAYS[1]: pyoidn.denoise(image, albedo=albedo, normal=normal, hdr=True),
        WAYS[2]: pyoidn.denoise(image, albedo=albedo, normal=normal, hdr=True, clean_aux=True),
        WAYS[3]: denoise(image, albedo, normal, a["emission"])[0],
        WAYS[4]: denoise(image, albedo, normal, a["emission"], light=light)[0],
    }, done


def error_table(scene, size, spps, threads, ref, ref_stderr):
    rows = []
    for spp in spps:
        r = rt.Renderer(scene, width=size, height=size, seed=SEED, threads=threads,
                        aov=("albedo", "normal", "emission"))
        r.add_samples(spp)
        result = r.result()
        images, done = denoised_ways(r, result, threads)
        raw, raw_clean = rmse(result.image, ref), rmse_clean(result.image, ref, ref_stderr)
        ways = {w: rmse(im, ref) for w, im in images.items()}
        clean = {w: rmse_clean(im, ref, ref_stderr) for w, im in images.items()}
        rows.append(dict(spp=spp, raw=raw, denoised=ways,
                         ratio={w: v / raw for w, v in ways.items()},
                         raw_clean=raw_clean, denoised_clean=clean,
                         ratio_clean={w: v / raw_clean for w, v in clean.items()},
                         light_seen=done._asdict()))
        print(f"  {spp:5d} spp  raw RMSE {raw:.5f} ({raw_clean:.5f} without the reference's "
              f"noise)", flush=True)
        for w in WAYS:
            print(f"      {w:50s} {ways[w]:.5f} {ways[w] / raw:.2f}x   "
                  f"({clean[w]:.5f} {clean[w] / raw_clean:.2f}x)", flush=True)
    return rows


def curves(scene, size, max_spp, threads, ref):
    """rtweekend's default, raw and denoised, after every doubling of spp."""
    r = rt.Renderer(scene, seed=SEED, width=size, height=size, threads=threads, denoise=True)
    r.compile()
    warm = rt.Renderer(scene, seed=0, width=16, height=16, threads=threads, denoise=True)
    warm.add_samples(1)
    warm.result()                                    # OIDN's first call sets it up
    rows, target = [], 1
    while target <= max_spp:
        r.add_samples(target - r.spp)
        res = r.result()
        rows.append(dict(spp=r.spp, seconds=r.seconds, raw=rmse(res.image, ref),
                         denoised=rmse(res.denoised, ref),
                         denoised_seconds=r.seconds + res.stats.denoise_seconds))
        print(f"  rtweekend {r.spp:5d} spp {r.seconds:7.2f} s  raw {rows[-1]['raw']:.5f}  "
              f"denoised {rows[-1]['denoised']:.5f}", flush=True)
        target *= 2
    return rows


def peer_curves(args, name, size, max_spp, threads, ref):
    """Mitsuba's renders, raw and denoised with its albedo and normal; None
    without Mitsuba (said in one line)."""
    import mitsuba_peer
    from accuracy import find_peer
    peer = find_peer(args)
    if peer is None:
        return None
    cfg = dict(width=size, height=size)
    points, info = peer.series(name, rt.load_scene(name), cfg, max_spp, threads, aov=True)
    if points is None:
        print(f"Mitsuba not available: {info}")
        return None
    rows = []
    for spp, seconds, image in points:
        t0 = time.perf_counter()
        den = mitsuba_peer.denoised(image)
        dt = time.perf_counter() - t0
        rows.append(dict(spp=spp, seconds=seconds, raw=rmse(image[..., :3], ref),
                         denoised=rmse(den, ref), denoised_seconds=seconds + dt))
        print(f"  Mitsuba   {spp:5d} spp {seconds:7.2f} s  raw {rows[-1]['raw']:.5f}  "
              f"denoised {rows[-1]['denoised']:.5f}", flush=True)
    return dict(rows=rows, **{k: info.get(k) for k in ("mitsuba", "variant", "threads")})


def chart(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 5.0))
    series = [("rtweekend " + data["sampling"], data["curves"], "tab:green")]
    if data["peer"]:
        series.append(("Mitsuba 3, path", data["peer"]["rows"], "black"))
    for label, rows, colour in series:
        ax.loglog([p["seconds"] for p in rows], [p["raw"] for p in rows], "o-", ms=3,
                  color=colour, label=f"{label}, unbiased")
        ax.loglog([p["denoised_seconds"] for p in rows], [p["denoised"] for p in rows], "s--",
                  ms=3, color=colour, label=f"{label}, denoised (OIDN, albedo + normal)")
    ax.set_title(f"{data['scene']} {data['size']}x{data['size']} vs {Path(data['reference']).name}",
                 fontsize=9)
    ax.set_xlabel(f"seconds ({data['threads']} threads), the denoiser's included")
    ax.set_ylabel("RMSE of linear radiance")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def cost(scene, threads, quick):
    size = dict(width=64, height=64, spp=4) if quick else {}
    rt.render(scene, threads=threads, denoise=True, **dict(size, spp=1))      # warm-up
    spp = size.pop("spp", scene.spp)
    r = rt.Renderer(scene, threads=threads, denoise=True, aov=("emission",), **size)
    r.compile()
    r.add_samples(spp)
    result = r.result()
    s = result.stats
    t0 = time.perf_counter()
    _, done = seen_light.estimate(r.frame, result.aov["emission"], r.spp, s.rays, threads)
    alone = time.perf_counter() - t0
    return dict(width=s.width, height=s.height, spp=s.spp, render_seconds=s.seconds,
                denoise_seconds=s.denoise_seconds, share=s.denoise_seconds / s.seconds,
                light_seen_seconds=alone, light_seen=done._asdict(), render_segments=s.rays)


def main(argv=None):
    p = parser(__doc__)
    p.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS)
    p.add_argument("--scene", default="cornell_glass")
    p.add_argument("--size", type=int, default=300)
    p.add_argument("--reference", default="cornell_glass_150",
                   help="the reference's name (common.reference)")
    p.add_argument("--max-spp", type=int, default=1024, help="the curves' last spp")
    p.add_argument("--peer-python", help="run Mitsuba with this interpreter (accuracy.py)")
    p.add_argument("--no-peer", action="store_true", help="leave Mitsuba out")
    a = p.parse_args(argv)
    require()
    found = reference(a.reference)
    if found is None:
        print(f"denoise: no reference {a.reference}; set RTWEEKEND_REFERENCES", file=sys.stderr)
        return 2
    ref = found[0]
    scene = rt.load_scene(a.scene)
    size, spps = (ref.shape[1], [1, 2]) if a.quick else (a.size, [4, 16, 64, 256])
    start = time.perf_counter()
    print(f"{a.scene} {size}x{size} against {found[2]} (compared at {ref.shape[1]}x"
          f"{ref.shape[0]})")
    ref_stderr = found[1]
    data = dict(machine=machine(), scene=a.scene, size=size, reference=str(found[2]),
                reference_rms_stderr=float(np.sqrt(np.mean(ref_stderr ** 2))),
                threads=a.threads, sampling=rt.Renderer(scene, width=8, height=8)
                .options.sampling,
                errors=error_table(scene, size, spps, a.threads, ref, ref_stderr))
    max_spp = 4 if a.quick else a.max_spp
    data["curves"] = curves(scene, size, max_spp, a.threads, ref)
    data["peer"] = peer_curves(a, a.scene, size, max_spp, a.threads, ref)
    data["cost"] = cost(scene, a.threads, a.quick)
    c = data["cost"]
    print(f"cost: {c['width']}x{c['height']} {c['spp']} spp rendered in "
          f"{c['render_seconds']:.2f} s, denoised in {c['denoise_seconds']:.3f} s "
          f"({100 * c['share']:.1f}%), of which the light seen estimated again "
          f"{c['light_seen_seconds']:.3f} s (timed alone): {c['light_seen']}")
    data["total_seconds"] = time.perf_counter() - start
    save_json("denoise.json", data, a.out)
    chart(data, a.out / "denoise.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
