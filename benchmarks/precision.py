"""float32 against float64 where a sample spends most of its time: the nearest hit.

    python benchmarks/precision.py

The renderer works in float64.  Converting all of it to float32 is a large
change (every literal, the RNG's output, a scale-aware ray offset), so this
probe first measures what float32 could buy in the part that dominates: the
nearest-hit search (68% of a `cornell_glass` sample).  One generic function --
the renderer's BVH slab test, and a copy of its sphere and rect tests -- is
compiled twice, for float32 and float64; its constants are passed in with the
arrays' type so that float32 code stays float32 (a float64 literal would
promote it).  The rays are the same for both, made by the renderer's own code:
one camera ray per pixel at the scene's own size and, from its hit, one cosine
bounce (the object left behind is excluded, as the renderer does).  One thread,
median of 11 runs after a warm-up, the two precisions alternating.  Also counts
the rays whose nearest object differs between the two.

Writes results/precision.json.  --quick runs a tiny version.
"""
import math
import sys
import time
from pathlib import Path

import numba
import numpy as np

import rtweekend as rt
from rtweekend import pdf, rng
from rtweekend.camera import get_ray
from rtweekend.hittables import _box_entry, closest_hit, face_normal, outward_normal
from rtweekend.tags import NO_HIT, SPHERE
from rtweekend.vec3 import madd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import machine, parser, save_json  # noqa: E402


@numba.njit(inline="always")
def _object_t(obj_i, f, k, o, d, t_max, from_obj, zero, one, inf):
    # hittables.sphere_t / rect_t, with typed constants: theirs return the
    # float64 INF, which would make every float32 distance a float64.
    if obj_i[k, 0] == SPHERE:
        if k == from_obj:
            return inf                        # bounces leave spheres outward
        oc0, oc1, oc2 = o[0] - f[k, 0], o[1] - f[k, 1], o[2] - f[k, 2]
        half_b = oc0 * d[0] + oc1 * d[1] + oc2 * d[2]
        disc = half_b * half_b - (oc0 * oc0 + oc1 * oc1 + oc2 * oc2 - f[k, 4])
        if disc < zero:
            return inf
        sq = math.sqrt(disc)
        t = -half_b - sq
        if zero < t < t_max:
            return t
        t = -half_b + sq
        return t if zero < t < t_max else inf
    if k == from_obj:
        return inf
    denom = f[k, 9] * d[0] + f[k, 10] * d[1] + f[k, 11] * d[2]
    if denom == zero:
        return inf
    t = (f[k, 12] - (f[k, 9] * o[0] + f[k, 10] * o[1] + f[k, 11] * o[2])) / denom
    if not (zero < t < t_max):
        return inf
    q0 = o[0] + t * d[0] - f[k, 0]
    q1 = o[1] + t * d[1] - f[k, 1]
    q2 = o[2] + t * d[2] - f[k, 2]
    alpha = q0 * f[k, 13] + q1 * f[k, 14] + q2 * f[k, 15]
    beta = q0 * f[k, 16] + q1 * f[k, 17] + q2 * f[k, 18]
    if alpha < zero or alpha > one or beta < zero or beta > one:
        return inf
    return t


@numba.njit(error_model="numpy")
def nearest(obj_i, f, box, node, prims, orig, dirs, from_obj, zero, one, inf, hits):
    """hits[r] = the nearest object along ray r (NO_HIT: none)."""
    no_bvh = node.shape[0] == 0
    n_nodes = 1 if no_bvh else node.shape[0]
    for r in range(orig.shape[0]):
        o = (orig[r, 0], orig[r, 1], orig[r, 2])
        d = (dirs[r, 0], dirs[r, 1], dirs[r, 2])
        inv_d = (one / d[0], one / d[1], one / d[2])     # 1/0 = inf: numpy error model
        best, t_max, i = NO_HIT, inf, 0
        while i < n_nodes:
            if no_bvh:
                first, count, after = 0, obj_i.shape[0], 1
            elif _box_entry(box, i, o, inv_d, t_max):
                count = node[i, 1]
                if count == 0:
                    i += 1
                    continue
                first, after = node[i, 0], node[i, 2]
            else:
                i = node[i, 2]
                continue
            for j in range(first, first + count):
                k = j if no_bvh else prims[j]
                t = _object_t(obj_i, f, k, o, d, t_max, from_obj[r], zero, one, inf)
                if t < t_max:
                    t_max, best = t, k
            i = after
        hits[r] = best
    return hits


@numba.njit
def _rays(cam, width, height, seed, obj_i, obj_f, bvh_box, bvh_node, bvh_prims):
    """The renderer's first two segments of one sample per pixel: the camera ray
    (get_ray) and, from its hit (closest_hit), a cosine bounce (pdf.cosine_generate)
    about the facing normal.  (origins, directions, object each ray leaves)."""
    n = width * height
    orig, dirs = np.empty((2 * n, 3)), np.empty((2 * n, 3))
    left = np.full(2 * n, NO_HIT)
    m = n
    for pixel in range(n):
        state = rng.seed_state(pixel, 0, seed)
        o, d, state = get_ray(cam, pixel % width, pixel // width, width, height, state)
        orig[pixel], dirs[pixel] = o, d
        k, t = closest_hit(obj_i, obj_f, bvh_box, bvh_node, bvh_prims, o, d, np.inf,
                           NO_HIT, False)
        if k != NO_HIT:
            p = madd(o, d, t)
            _, normal = face_normal(d, outward_normal(obj_i, obj_f, k, p))
            bounce, state = pdf.cosine_generate(normal, state)
            orig[m], dirs[m], left[m] = p, bounce, k
            m += 1
    return orig[:m], dirs[:m], left[:m]


def rays_for(scene, width, height, seed):
    """(scene arrays, origins, directions, object left behind), float64."""
    frame = rt.Renderer(scene, seed=seed, width=width, height=height).frame
    a = frame.arrays
    return (a, *_rays(frame.cam, width, height, seed, a.obj_i, a.obj_f, a.bvh_box,
                      a.bvh_node, a.bvh_prims))


def _args(a, dtype, orig, dirs, from_obj):
    """nearest()'s arguments in one precision (the constants too)."""
    c = dtype
    return (a.obj_i, a.obj_f.astype(c), a.bvh_box.astype(c), a.bvh_node, a.bvh_prims,
            orig.astype(c), dirs.astype(c), from_obj, c(0), c(1), c(np.inf),
            np.empty(len(orig), np.int64))


def measure(name, shrink, runs):
    """Both precisions on one scene at its own size / shrink."""
    scene = rt.load_scene(name)
    width, height = scene.camera.width // shrink, scene.camera.height // shrink
    a, orig, dirs, from_obj = rays_for(scene, width, height, seed=1)
    out = dict(scene=name, width=width, height=height, rays=len(orig),
               bvh=bool(len(a.bvh_node)))
    dtypes = (np.float64, np.float32)
    args = {c: _args(a, c, orig, dirs, from_obj) for c in dtypes}
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
