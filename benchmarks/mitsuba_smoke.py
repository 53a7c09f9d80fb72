"""An independent reference for `cornell_smoke` (The Next Week), rendered by Mitsuba 3.

    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
    /work/mitsuba-venv/bin/python benchmarks/mitsuba_smoke.py --size 150 --spp 32768 \\
        --pass-spp 256 --threads 1 --seed 1 --out ../shared/references/cornell_smoke_150

What it renders (built here as an explicit Mitsuba scene dict; rtweekend's own
renderer is not used, only mitsuba_peer's camera/rect/box translation helpers):
  * The Cornell room 0..555: green (.12,.45,.15) yz_rect at x=555, red
    (.65,.05,.05) at x=0, white (.73,.73,.73) floor (y=0), ceiling (y=555) and
    back wall (z=555).  Lambertian, two-sided.
  * Light: xz_rect x 113..443, z 127..432, y=554, radiance 7, one-sided, emitting
    down (-y) only (the book's rect with flip_face); its back absorbs.
  * Two boxes of homogeneous medium with invisible boundaries (`cube`, `null`
    BSDF, `interior` `homogeneous` medium, isotropic phase), sigma_t 0.01:
      box1 (0,0,0)-(165,330,165), rotate_y 15, translate (265,0,295), albedo 0
           (black smoke: a pure absorber);
      box2 (0,0,0)-(165,165,165), rotate_y -18, translate (130,0,65), albedo 1
           (white smoke: a pure scatterer).
    rotate_y is the books' (x' = cos x + sin z, z' = -sin x + cos z) about the
    world origin, then the translation (mitsuba_peer._placement).
    The boxes stand on the floor, so a medium's bottom face would be coplanar
    with the floor; a ray inside a box reflected by the floor must stay in the
    medium (it does in the books, whose constant_medium clips to the boundary).
    So each medium's stencil cube reaches STENCIL_BELOW units under the floor:
    the floor then lies inside the medium, and no ray can reach the part below
    it (the floor covers the boxes' footprints and nothing scatters outside).
  * Camera: lookfrom (278,278,-800), lookat (278,278,0), vup (0,1,0), vfov 40
    vertical, square image; black background.

Conventions (those of mitsuba_peer.py): a pixel's samples are uniform over its
square and the box filter keeps each in its own pixel; row 0 is the top, column
0 the left (green wall on the left).  Integrator `volpath`, max_depth 50 counting
path segments with the camera ray included (null-boundary crossings are not
counted; medium scatterings are), next-event estimation with MIS, Russian
roulette from depth 5: unbiased, so only the noise differs from the books'
estimator.

Renders in passes and writes NAME.npy, NAME_stderr.npy, NAME.json and
NAME.png for --out NAME after every pass, as mitsuba_reference.py does (its
render_passes: the files and the seeds are described there).
"""
import argparse
import json
import os
import sys
from pathlib import Path
from types import SimpleNamespace


HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")

import mitsuba_peer as peer  # noqa: E402  (imports drjit and mitsuba)
import mitsuba_reference as reference  # noqa: E402

dr, mi = peer.dr, peer.mi

RED, WHITE, GREEN = (0.65, 0.05, 0.05), (0.73, 0.73, 0.73), (0.12, 0.45, 0.15)
LIGHT = (7.0, 7.0, 7.0)
MAX_DEPTH = 50
RR_DEPTH = 5
STENCIL_BELOW = 1.0     # the media's cubes start this far under the floor (see above)

CAMERA = dict(lookfrom=(278.0, 278.0, -800.0), lookat=(278.0, 278.0, 0.0),
              vup=(0.0, 1.0, 0.0), vfov=40.0, aperture=0.0, focus_dist=10.0)

# (name, kind, geometry, colour, flipped) in rtweekend's rect terms:
# xy/yz/xz_rect geometry = (a0, a1, b0, b1, k).
RECTS = [
    ("green_wall", "yz_rect", (0, 555, 0, 555, 555), GREEN, False),
    ("red_wall", "yz_rect", (0, 555, 0, 555, 0), RED, False),
    ("light", "xz_rect", (113, 443, 127, 432, 554), None, True),
    ("floor", "xz_rect", (0, 555, 0, 555, 0), WHITE, False),
    ("ceiling", "xz_rect", (0, 555, 0, 555, 555), WHITE, False),
    ("back_wall", "xy_rect", (0, 555, 0, 555, 555), WHITE, False),
]

# (name, lo, hi, rotate_y degrees, translate, sigma_t, albedo)
MEDIA = [
    ("box1_black_smoke", (0, 0, 0), (165, 330, 165), 15.0, (265, 0, 295), 0.01, 0.0),
    ("box2_white_smoke", (0, 0, 0), (165, 165, 165), -18.0, (130, 0, 65), 0.01, 1.0),
]


def _rect(kind, geometry, flipped):
    s = SimpleNamespace(kind=kind, geometry=tuple(float(x) for x in geometry),
                        placement=peer.placed_y(0.0, (0.0, 0.0, 0.0)), flipped=flipped)
    d = {"type": "rectangle",
         "to_world": mi.ScalarTransform4f((peer._placement(s) @ peer._local_matrix(s)).tolist())}
    if flipped:
        d["flip_normals"] = True
    return d


def box_matrix(lo, hi, angle, offset, below=0.0):
    """4x4 map from Mitsuba's cube [-1,1]^3 to the box lo..hi (its bottom lowered
    by `below`), rotated by the books' rotate_y(angle), then translated."""
    lo = (float(lo[0]), float(lo[1]) - below, float(lo[2]))
    s = SimpleNamespace(kind="box", geometry=(lo, tuple(float(x) for x in hi)),
                        placement=peer.placed_y(float(angle), offset))
    return peer._placement(s) @ peer._local_matrix(s)


def scene_dict(width, height, spp, seed=0):
    """The Mitsuba scene dict (mi.load_dict) of cornell_smoke."""
    cam = SimpleNamespace(width=int(width), height=int(height), **CAMERA)
    d = {"type": "scene",
         "integrator": {"type": "volpath", "max_depth": MAX_DEPTH, "rr_depth": RR_DEPTH},
         "sensor": peer._sensor(cam, spp, seed)}     # no background emitter: black
    for name, kind, geometry, colour, flipped in RECTS:
        r = _rect(kind, geometry, flipped)
        if colour is None:                           # the light: emits along its normal (-y)
            r["bsdf"] = {"type": "diffuse", "reflectance": peer._rgb((0, 0, 0))}
            r["emitter"] = {"type": "area", "radiance": peer._rgb(LIGHT)}
        else:
            r["bsdf"] = {"type": "twosided",
                         "bsdf": {"type": "diffuse", "reflectance": peer._rgb(colour)}}
        d[name] = r
    for name, lo, hi, angle, offset, sigma_t, albedo in MEDIA:
        M = box_matrix(lo, hi, angle, offset, below=STENCIL_BELOW)
        d[name] = {"type": "cube", "to_world": mi.ScalarTransform4f(M.tolist()),
                   "bsdf": {"type": "null"},
                   "interior": {"type": "homogeneous",
                                "sigma_t": float(sigma_t),
                                "albedo": peer._rgb((albedo,) * 3),
                                "phase": {"type": "isotropic"}}}
    return d


def render(width, height, spp, pass_spp=256, seed=0, threads=1, time_limit=None,
           out=None, settings=None, log=print):
    """Render spp samples per pixel in passes (mitsuba_reference.render_passes);
    returns (mean, stderr, info)."""
    peer._setup(threads)
    if hasattr(mi, "set_log_level"):
        mi.set_log_level(mi.LogLevel.Warn)
    pass_spp = max(1, min(pass_spp, spp))
    mscene = mi.load_dict(scene_dict(width, height, pass_spp, seed))
    info = dict(settings or {}, integrator="volpath", max_depth=MAX_DEPTH, rr_depth=RR_DEPTH,
                stencil_below_floor=STENCIL_BELOW)
    return reference.render_passes(mscene, width, height, spp, pass_spp, seed, time_limit,
                                   out, info, log)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--size", type=int, default=150, help="width = height")
    p.add_argument("--spp", type=int, default=4096)
    p.add_argument("--pass-spp", type=int, default=256)
    p.add_argument("--threads", type=int, default=1, help="Dr.Jit worker threads")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--time-limit", type=float, help="stop after the pass that crosses it (s)")
    p.add_argument("--out", type=Path, default=Path("cornell_smoke"),
                   help="NAME: writes NAME.npy, NAME_stderr.npy, NAME.json, NAME.png")
    p.add_argument("--quick", action="store_true",
                   help="a 16x16 image of 64 spp in passes of 16 (tests)")
    a = p.parse_args(argv)
    if a.quick:
        a.size, a.spp, a.pass_spp = 16, 64, 16
    settings = dict(scene="cornell_smoke", out=a.out.name,
                    convention="mitsuba_peer (pixel squares, box filter, row 0 top)")
    _, _, info = render(a.size, a.size, a.spp, a.pass_spp, a.seed, a.threads,
                        a.time_limit, a.out, settings)
    print(json.dumps(info))


if __name__ == "__main__":
    main()
