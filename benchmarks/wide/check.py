"""Does the wavefront prototype compute rtweekend's estimator?  Figures, per scene.

    PYTHONPATH=. python -m benchmarks.wide.check [--quick]

Three checks, for every variant the benchmark measures:

  same stream   same seed: the prototype draws every random number by the same
                calls in the same order as rtweekend's render_row, so the two
                images should agree pixel by pixel up to rounding (max |diff|,
                share of pixels within 1e-9, and the ray segments traced: equal
                when every path took the same turns)
  statistics    seed 2 against rtweekend's seed 1 (independent samples): the
                means of 10 x 10 blocks of pixels, per channel, differ by z =
                diff / stderr (stderr from the per-pixel variances of both runs);
                chi^2 / dof should be near 1 and no |z| very large.  The
                same test of rtweekend seed 2 against seed 1 is the baseline:
                heavy-tailed scenes (cornell_glass: caustics through the glass
                ball) exceed 1 by themselves, as the per-pixel variance of 64
                samples underestimates the true one; the prototype passes when
                it is within 10% of the baseline (or chi^2/dof < 1.5, |z| < 5)
  determinism   the prototype with 1 and with 2 threads: bit-identical images

Prints a table and writes benchmarks/wide/check.json; exits 1 if a check fails.
"""
import argparse
import json
import sys
from pathlib import Path

import numpy as np

import rtweekend

from .wave import WideRenderer

HERE = Path(__file__).resolve().parent
# (scene, width, height, spp, variants: WideRenderer keyword arguments)
CASES = (
    ("cornell_glass", 100, 100, 64, ({"mode": "flat"}, {"mode": "flat", "sort": False})),
    ("cornell_box", 100, 100, 64, ({"mode": "flat"}, {"mode": "flat", "sort": False})),
    ("weekend", 160, 90, 64, ({"mode": "packet"}, {"mode": "ray", "sort": False})),
)
BLOCK = 10


def label(kw):
    return kw["mode"] + ("" if kw.get("sort", True) else ", unsorted")


def scalar_image(scene, w, h, spp, seed):
    """rtweekend's (mean, per-pixel variance of one sample), float64."""
    r = rtweekend.Renderer(scene, seed=seed, width=w, height=h, sampling="mixture", threads=1)
    r.add_samples(spp)
    f = r.film
    n = f.valid[..., None].astype(np.float64)
    mean = (f.accum + f.partial) / n
    var = ((f.accum2 + f.partial2) - n * mean * mean) / (n - 1)
    return mean, np.maximum(var, 0.0), int(f.row_stats[:, 0].sum())


def wide_image(scene, w, h, spp, seed, threads, kw):
    r = WideRenderer(scene, seed=seed, width=w, height=h, threads=threads, **kw)
    r.add_samples(spp)
    return r.film_sum / r.film_n[..., None], r.segments()


def block_z(a, b, var, spp):
    """z of the difference of block means, per block and channel."""
    h, w, _ = a.shape
    hb, wb = h // BLOCK, w // BLOCK

    def blocks(x):
        return x[:hb * BLOCK, :wb * BLOCK].reshape(hb, BLOCK, wb, BLOCK, 3).mean(axis=(1, 3))
    # Variance of a block mean of one image: sum of pixel variances / spp / npix^2;
    # both images have it (same estimator), hence the factor 2.
    var_block = blocks(var) / (BLOCK * BLOCK) / spp
    with np.errstate(invalid="ignore", divide="ignore"):     # black blocks: 0 / 0
        return (blocks(a) - blocks(b)) / np.sqrt(2.0 * var_block)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="16 spp, a quick look")
    args = ap.parse_args()
    rows, ok = [], True
    for name, w, h, spp, variants in CASES:
        if args.quick:
            spp = 16
        scene = rtweekend.load_scene(name)
        ref, var, ref_seg = scalar_image(scene, w, h, spp, 1)
        base, _, _ = scalar_image(scene, w, h, spp, 2)
        zb = block_z(base, ref, var, spp)
        zb = zb[np.isfinite(zb)]
        chi2_base, z_base = float((zb ** 2).mean()), float(np.abs(zb).max())
        for kw in variants:
            img, seg = wide_image(scene, w, h, spp, 1, 1, kw)
            img2, _ = wide_image(scene, w, h, spp, 1, 2, kw)
            other, _ = wide_image(scene, w, h, spp, 2, 1, kw)
            diff = np.abs(img - ref).max(axis=2)
            z = block_z(other, ref, var, spp)
            finite = np.isfinite(z)
            row = {
                "scene": name, "size": [w, h], "spp": spp, "variant": label(kw),
                "max_abs_diff": float(diff.max()),
                "max_rel_diff": float((diff / np.maximum(ref.max(axis=2), 1e-12)).max()),
                "pixels_within_1e-9": float((diff <= 1e-9).mean()),
                "segments_scalar": ref_seg, "segments_wide": seg,
                "chi2_per_dof": float((z[finite] ** 2).mean()), "max_abs_z": float(
                    np.abs(z[finite]).max()), "blocks": int(finite.sum()),
                "chi2_per_dof_baseline": chi2_base, "max_abs_z_baseline": z_base,
                "threads_1_vs_2_identical": bool(np.array_equal(img, img2)),
            }
            stats_ok = (0.5 < row["chi2_per_dof"] < max(1.5, 1.1 * chi2_base)
                        and row["max_abs_z"] < max(5.0, 1.1 * z_base))
            row["pass"] = bool(row["pixels_within_1e-9"] > 0.99
                               and row["threads_1_vs_2_identical"] and stats_ok)
            ok &= row["pass"]
            rows.append(row)
    (HERE / "check.json").write_text(json.dumps(rows, indent=1) + "\n")
    print(f"{'scene':14s} {'variant':16s} {'max|diff|':>10s} {'px<=1e-9':>9s} "
          f"{'segments (scalar = wide)':>26s} {'chi2/dof (base)':>16s} {'max|z| (base)':>14s} "
          f"{'1T==2T':>7s}  ok")
    for r in rows:
        same = "=" if r["segments_scalar"] == r["segments_wide"] else "!="
        seg = f"{r['segments_scalar']} {same} {r['segments_wide']}"
        print(f"{r['scene']:14s} {r['variant']:16s} {r['max_abs_diff']:10.2e} "
              f"{r['pixels_within_1e-9']:9.4f} {seg:>26s} "
              f"{r['chi2_per_dof']:7.2f} ({r['chi2_per_dof_baseline']:5.2f}) "
              f"{r['max_abs_z']:6.2f} ({r['max_abs_z_baseline']:5.2f}) "
              f"{str(r['threads_1_vs_2_identical']):>7s}  {r['pass']}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
