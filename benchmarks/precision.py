"""float32 against float64 where a sample spends most of its time: the nearest hit.

    python benchmarks/precision.py

The renderer works in float64.  Converting all of it to float32 is a large
change (every literal, the RNG's output, a scale-aware ray offset), so this
probe first measures what float32 could buy in the part that dominates: the
nearest-hit search.  It runs the renderer's own search (bvh.closest_hit, with
the shapes' own intersection tests) on float32 and on float64 copies of the
scene's arrays: that search keeps its constants in the precision of the ray
(kernel.jit.like), so float32 code stays float32.  The rays are the same for
both, made by the renderer's own code: one camera ray per pixel at the scene's
own size and, from its hit, one cosine bounce (the object left behind is
excluded, as the renderer does).  One thread, median of 11 runs after a
warm-up, the two precisions alternating.  Also counts the rays whose nearest
object differs between the two.

Writes benchmark-results/precision.json.  --quick runs a tiny version.
"""
import sys
import time
from pathlib import Path

import numba
import numpy as np

import rtweekend as rt
from rtweekend.kernel import rng
from rtweekend.kernel.vec3 import madd
from rtweekend.path import shapes
from rtweekend.path.bvh import closest_hit
from rtweekend.path.bvh_build import build_bvh
from rtweekend.path.camera import get_ray
from rtweekend.path.layout import NO_HIT
from rtweekend.path.materials import lambertian
from rtweekend.path.surface import face_normal

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, parser, save_json  # noqa: E402


@numba.njit(error_model="numpy")
def nearest(scene, orig, dirs, from_obj, inf, hits):
    """hits[r] = the nearest object along ray r (NO_HIT: none), by the renderer's
    closest_hit in the precision of orig, dirs and inf."""
    for r in range(orig.shape[0]):
        o = (orig[r, 0], orig[r, 1], orig[r, 2])
        d = (dirs[r, 0], dirs[r, 1], dirs[r, 2])
        hits[r], _ = closest_hit(scene, o, d, inf, from_obj[r], False, None)
    return hits


@numba.njit
def _rays(scene, params, seed):
    """The renderer's first two segments of one sample per pixel: the camera ray
    (get_ray) and, from its hit (closest_hit), a cosine bounce (materials/lambertian.py)
    about the facing normal.  (origins, directions, object each ray leaves)."""
    width, height = params.width, params.height
    n = width * height
    orig, dirs = np.empty((2 * n, 3)), np.empty((2 * n, 3))
    left = np.full(2 * n, NO_HIT)
    m = n
    for pixel in range(n):
        state = rng.seed_state(pixel, 0, seed)
        o, d, state = get_ray(params.cam, pixel % width, pixel // width, width, height, state)
        orig[pixel], dirs[pixel] = o, d
        k, t = closest_hit(scene, o, d, np.inf, NO_HIT, False, None)
        if k != NO_HIT:
            p = madd(o, d, t)
            _, normal = face_normal(d, shapes.outward_normal(scene, k, p, None))
            u1, state = rng.uniform(state)
            u2, state = rng.uniform(state)
            bounce = lambertian.cosine_at(normal, u1, u2)
            orig[m], dirs[m], left[m] = p, bounce, k
            m += 1
    return orig[:m], dirs[:m], left[:m]


def rays_for(scene, width, height, seed):
    """(scene arrays, origins, directions, object left behind), float64."""
    frame = rt.Renderer(scene, seed=seed, width=width, height=height).frame
    return (frame.scene, *_rays(frame.scene, frame.params, seed))


def arguments(a, dtype, orig, dirs, from_obj):
    """nearest()'s arguments in one precision: the geometry the search reads,
    the rays, and its starting t_max.  A scene with a hierarchy is searched by
    the binary tree's stackless walk, which runs in either precision (the
    renderer walks the tree 4-wide, with double-precision vector code)."""
    c = dtype
    if a.wide is not None:
        box, node, prims = build_bvh(a.obj_i, a.obj_f, np.sort(a.bvh_prims))
        a = a._replace(wide=None, bvh_box=box, bvh_node=node, bvh_prims=prims)
    scene = a._replace(obj_f=a.obj_f.astype(c), bvh_box=a.bvh_box.astype(c))
    return (scene, orig.astype(c), dirs.astype(c), from_obj, c(np.inf),
            np.empty(len(orig), np.int64))


def measure(name, shrink, runs):
    """Both precisions on one scene at its own size / shrink."""
    scene = rt.load_scene(name)
    width, height = scene.camera.width // shrink, scene.camera.height // shrink
    a, orig, dirs, from_obj = rays_for(scene, width, height, seed=1)
    out = dict(scene=name, width=width, height=height, rays=len(orig),
               bvh=a.wide is not None)
    dtypes = (np.float64, np.float32)
    args = {c: arguments(a, c, orig, dirs, from_obj) for c in dtypes}
    times = {c: [] for c in dtypes}
    for c in dtypes:                          # compile and warm up
        t0 = time.perf_counter()
        nearest(*args[c])
        out[c.__name__] = dict(first_call_s=time.perf_counter() - t0)
    for _ in range(runs):                     # alternate: the machine's speed drifts
        for c in dtypes:
            t0 = time.perf_counter()
            nearest(*args[c])
            times[c].append(time.perf_counter() - t0)
    for c in dtypes:
        out[c.__name__]["rays_per_s"] = len(orig) / float(np.median(times[c]))
    hits = {c: args[c][-1] for c in dtypes}
    out["float32_speedup"] = out["float32"]["rays_per_s"] / out["float64"]["rays_per_s"]
    out["different_nearest_object"] = int(np.sum(hits[np.float32] != hits[np.float64]))
    return out


def main():
    args = parser(__doc__).parse_args()
    numba.set_num_threads(1)
    shrink, runs = (15, 2) if args.quick else (1, 11)
    data = dict(machine=machine(), quick=args.quick, runs=runs, scenes={})
    print(f"{'scene':14s} {'rays':>9s} {'float64':>12s} {'float32':>12s} {'ratio':>6s} "
          f"{'differ':>7s}")
    for name in ("cornell_glass", "cornell_box", "weekend"):
        r = measure(name, shrink, runs)
        data["scenes"][name] = r
        print(f"{name:14s} {r['rays']:9d} {r['float64']['rays_per_s'] / 1e6:8.2f} M/s "
              f"{r['float32']['rays_per_s'] / 1e6:8.2f} M/s {r['float32_speedup']:6.2f} "
              f"{r['different_nearest_object']:7d}", flush=True)
    save_json("precision.json", data, args.out)


if __name__ == "__main__":
    main()
