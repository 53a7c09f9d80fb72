"""What Open Image Denoise buys: the error of the denoised image against the
unbiased one, at equal samples, and what it costs.

    pip install '.[bench,denoise]' && python benchmarks/denoise.py [--threads 2] [--quick]

1. Error: the default strategy on cornell_glass (--size 300 by default) at 4,
   16, 64, 256 spp (seed 2024), against the independent Mitsuba reference
   (common.reference; a reference of another size is compared after both are
   averaged down to its size, 2x2 pixels to one: the box filter's pixel
   squares nest).  For each: the raw image's RMSE and the denoised image's,
   denoised four ways -- the colour alone; with albedo and normal, OIDN
   prefiltering them (clean_aux False: the default); with them taken as clean
   (clean_aux True); and what rtweekend does, the light seen emitted kept out
   of the filter -- and the ratios to the raw RMSE.
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
   and their ratio (after a warm-up render and denoise).

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

SEED = 2024
WAYS = ("colour alone", "albedo+normal, prefiltered", "albedo+normal, clean_aux",
        "rtweekend (light seen kept out)")


def down_to(image, shape):
    """image averaged down by whole factors to `shape` (H, W)."""
    f = image.shape[0] // shape[0]
    if f == 1:
        return image.astype(np.float64)
    h, w = shape
    return image.astype(np.float64).reshape(h, f, w, f, 3).mean(axis=(1, 3))


def rmse(image, ref):
    return float(np.sqrt(np.mean((down_to(image, ref.shape[:2]) - ref) ** 2)))


def denoised_ways(result):
    """{way: image} for the four ways of feeding OIDN."""
    import pyoidn
    a = result.aov
    image = np.ascontiguousarray(result.image)
    albedo = np.ascontiguousarray(np.clip(a["albedo"], 0, 1))
    normal = np.ascontiguousarray(np.clip(a["normal"], -1, 1))
    return {
        WAYS[0]: pyoidn.denoise(image, hdr=True),
        WAYS[1]: pyoidn.denoise(image, albedo=albedo, normal=normal, hdr=True),
        WAYS[2]: pyoidn.denoise(image, albedo=albedo, normal=normal, hdr=True, clean_aux=True),
        WAYS[3]: denoise(image, albedo, normal, a["emission"])[0],
    }


def error_table(scene, size, spps, threads, ref):
    rows = []
    for spp in spps:
        r = rt.render(scene, spp=spp, width=size, height=size, seed=SEED, threads=threads,
                      aov=("albedo", "normal", "emission"))
        raw = rmse(r.image, ref)
        ways = {w: rmse(im, ref) for w, im in denoised_ways(r).items()}
        rows.append(dict(spp=spp, raw=raw, denoised=ways,
                         ratio={w: v / raw for w, v in ways.items()}))
        print(f"  {spp:5d} spp  raw RMSE {raw:.5f}  " + "  ".join(
            f"{w}: {v / raw:.2f}x" for w, v in ways.items()), flush=True)
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
    r = rt.render(scene, threads=threads, denoise=True, **size)
    s = r.stats
    return dict(width=s.width, height=s.height, spp=s.spp, render_seconds=s.seconds,
                denoise_seconds=s.denoise_seconds, share=s.denoise_seconds / s.seconds)


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
    data = dict(machine=machine(), scene=a.scene, size=size, reference=str(found[2]),
                threads=a.threads, sampling=rt.Renderer(scene, width=8, height=8)
                .options.sampling, errors=error_table(scene, size, spps, a.threads, ref))
    max_spp = 4 if a.quick else a.max_spp
    data["curves"] = curves(scene, size, max_spp, a.threads, ref)
    data["peer"] = peer_curves(a, a.scene, size, max_spp, a.threads, ref)
    data["cost"] = cost(scene, a.threads, a.quick)
    c = data["cost"]
    print(f"cost: {c['width']}x{c['height']} {c['spp']} spp rendered in "
          f"{c['render_seconds']:.2f} s, denoised in {c['denoise_seconds']:.3f} s "
          f"({100 * c['share']:.1f}%)")
    data["total_seconds"] = time.perf_counter() - start
    save_json("denoise.json", data, a.out)
    chart(data, a.out / "denoise.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
