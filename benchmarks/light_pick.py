"""Next-event estimation picking its emitter by power (path/lights.py) against
picking it uniformly, at equal samples per pixel and at equal time.

    python benchmarks/light_pick.py [--spp 64] [--threads 2] [--quick]

For each scene with several emitters: the same renderer twice, once with the
light layer as packed (rows picked by power) and once with its probabilities
replaced by equal ones (the kernel reads them from the arrays, nothing else
changes); mean variance of a pixel (its standard error squared, at equal spp),
seconds, and the efficiency ratio 1 / (variance x time).  Both are checked
against the books' mixture (an estimator that does not pick emitters at all)
rendered with 4x the samples: the pixel z-scores of the difference should look
like a standard normal (mean ~0, spread ~1).  Writes benchmark-results/light_pick.json.
"""
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, parser, save_json  # noqa: E402

import rtweekend as rt  # noqa: E402
from rtweekend.path.layout import EMITTED, LIGHT_CDF, LIGHT_PROB  # noqa: E402


def bright_and_dim():
    """A floor under a large bright ceiling light and a tiny dim sphere light."""
    scene = rt.Scene(camera=rt.Camera(lookfrom=(0, 4, -6), lookat=(0, 0, 0), vfov=40,
                                      width=100, height=100), max_depth=8)
    scene.add(rt.xz_rect(-3, 3, -3, 3, 0, rt.lambertian((0.6, 0.6, 0.6))))
    scene.add(rt.xz_rect(-1, 1, -1, 1, 3, rt.diffuse_light((8, 8, 8))).flip_face(),
              light=True)
    scene.add(rt.sphere((2, 1, 1), 0.05, rt.diffuse_light((0.5, 0.5, 0.5))), light=True)
    return scene


def uniformly(renderer):
    """The renderer with its emitters picked uniformly instead of by power."""
    f = renderer.frame
    a = f.scene
    first, rows = a.light_ranges[EMITTED]
    light_f = a.light_f.copy()
    light_f[first:rows, LIGHT_PROB] = 1.0 / rows
    light_f[first:rows, LIGHT_CDF] = np.arange(1, rows + 1) / rows
    pick = np.zeros_like(a.light_pick)
    np.add.at(pick, a.light_rows[first:rows, 0], 1.0 / rows)
    renderer.frame = f._replace(scene=a._replace(light_f=light_f, light_pick=pick))
    return renderer


def z_scores(result, reference):
    se = np.sqrt(result.stderr.astype(float) ** 2 + reference.stderr.astype(float) ** 2)
    seen = se > 0
    z = (result.image.astype(float) - reference.image)[seen] / se[seen]
    return dict(mean=float(z.mean()), std=float(z.std()), pixels=int(z.size))


def compare(name, scene, size, spp, threads):
    options = dict(seed=7, sampling="nee", width=size[0], height=size[1], threads=threads)
    out = {}
    books = rt.render(scene, spp=4 * spp, seed=8, sampling="mixture", width=size[0],
                      height=size[1], threads=threads)
    for label, make in (("power", lambda r: r), ("uniform", uniformly)):
        r = make(rt.Renderer(scene, **options))
        r.compile()
        r.add_samples(1)                       # warm-up (not counted: it is sample 0)
        t0 = time.perf_counter()
        r.add_samples(spp)
        seconds = time.perf_counter() - t0
        result = r.result()
        out[label] = dict(seconds=seconds,
                          variance=float(np.mean(result.stderr.astype(float) ** 2)),
                          mean=float(result.image.mean()),
                          z_against_books_mixture=z_scores(result, books))
    p, u = out["power"], out["uniform"]
    out["variance_ratio"] = p["variance"] / u["variance"]
    out["time_ratio"] = p["seconds"] / u["seconds"]
    out["efficiency_ratio"] = 1.0 / (out["variance_ratio"] * out["time_ratio"])
    print(f"{name:16s} variance x{out['variance_ratio']:.3f}, time x{out['time_ratio']:.3f}, "
          f"efficiency x{out['efficiency_ratio']:.2f}; z against the books' mixture: "
          f"power {p['z_against_books_mixture']['mean']:+.3f} +- "
          f"{p['z_against_books_mixture']['std']:.2f}, uniform "
          f"{u['z_against_books_mixture']['mean']:+.3f} +- "
          f"{u['z_against_books_mixture']['std']:.2f}", flush=True)
    return out


def main(argv=None):
    p = parser(__doc__)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--threads", type=int, default=None)
    a = p.parse_args(argv)
    spp = 4 if a.quick else a.spp
    cases = [("simple_light", rt.load_scene("simple_light"), (200, 113)),
             ("bright_and_dim", bright_and_dim(), (100, 100))]
    if a.quick:
        cases = [(n, s, (24, 16)) for n, s, _ in cases]
    data = dict(machine=machine(), spp=spp,
                scenes={n: compare(n, s, size, spp, a.threads) for n, s, size in cases})
    if not a.quick:
        print("wrote", save_json("light_pick.json", data, a.out))


if __name__ == "__main__":
    main()
