"""Triangle meshes: building the BVH and tracing rays, beside Embree, and a
whole render beside Mitsuba 3.

    pip install '.[bench,meshes]' embreex && python benchmarks/meshes.py [--quick]

The mesh: a bumpy sphere (a latitude-longitude sphere whose radius varies, so
that its triangles differ in size and face every way) of --triangles triangles
(default 1,310,720, the size of the mesh the comparison with Mitsuba was first
made on), written as an OBJ file into the output folder.

1. Build: rtweekend's pack of a scene holding the mesh (its BVH alone, and the
   whole pack), and Embree's (embreex: scene and mesh made, committed by a
   first query), each the median of --runs after a warm-up.
2. Traversal: the same rays through both, one thread each: camera rays (a
   pinhole's pixel centres, 512x512, at the mesh from outside) and diffuse
   bounces (from each camera hit, a cosine-distributed direction about its
   normal; Embree's origins moved 1e-4 along the normal, rtweekend's leave
   their triangle by its own rule).  Rays per second, median of --runs, and
   rtweekend's over Embree's.  (Embree traces float32 rays, rtweekend float64.)
3. Whole process: `rtweekend render` of the Cornell room with the mesh (white,
   in the middle) from the OBJ, 300x300, 256 spp, 2 threads, its wall time
   with the kernels cached (the cold compile reported apart), and the same
   scene in Mitsuba 3 (its own OBJ loader and BVH; mitsuba_peer's room), wall
   time of a fresh process; --no-peer leaves it out.

Writes benchmark-results/meshes.json.
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from numba import njit

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from common import machine, median_seconds, parser, save_json  # noqa: E402

import rtweekend as rt  # noqa: E402
from rtweekend.path import bvh, bvh_build  # noqa: E402
from rtweekend.path.layout import NO_HIT  # noqa: E402
from rtweekend.path.pack import pack_scene  # noqa: E402
from rtweekend.path.shapes import triangle  # noqa: E402

IMAGE = 512


def bumpy_sphere(triangles):
    """(vertices, faces) of about `triangles` triangles, facing outward."""
    n_lat = max(3, int(round(math.sqrt(triangles / 4))))
    n_lon = 2 * n_lat
    theta = np.pi * np.arange(1, n_lat) / n_lat
    phi = 2 * np.pi * np.arange(n_lon) / n_lon
    t, p = np.meshgrid(theta, phi, indexing="ij")
    r = 1.0 + 0.08 * np.sin(7 * t) * np.cos(5 * p) + 0.03 * np.sin(23 * p + 3 * t)
    ring = np.stack([r * np.sin(t) * np.cos(p), r * np.sin(t) * np.sin(p), r * np.cos(t)], -1)
    v = np.concatenate([[[0, 0, 1.0], [0, 0, -1.0]], ring.reshape(-1, 3)])
    i = np.arange(n_lat - 2)[:, None]
    j = np.arange(n_lon)[None, :]
    a, b = 2 + i * n_lon + j, 2 + i * n_lon + (j + 1) % n_lon
    c, d = a + n_lon, b + n_lon
    quads = np.concatenate([np.stack([a, c, d], -1).reshape(-1, 3),
                            np.stack([a, d, b], -1).reshape(-1, 3)])
    j = np.arange(n_lon)
    top = np.stack([np.zeros(n_lon, int), 2 + j, 2 + (j + 1) % n_lon], -1)
    last = 2 + (n_lat - 2) * n_lon
    bottom = np.stack([np.ones(n_lon, int), last + (j + 1) % n_lon, last + j], -1)
    f = np.concatenate([top, quads, bottom])
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    inward = (n * v[f].mean(axis=1)).sum(axis=1) < 0
    f[inward] = f[inward][:, ::-1]
    return v, f


def write_obj(path, v, f):
    with open(path, "w") as out:
        np.savetxt(out, v, fmt="v %.7f %.7f %.7f")
        np.savetxt(out, f + 1, fmt="f %d %d %d")


# ------------------------------------------------------------------ the rays --
def camera_rays(size):
    """Pixel centres of a pinhole at (0, 0, 3.2) looking at the origin, vfov 45."""
    h = math.tan(math.radians(22.5))
    s = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(s * h, -s * h)
    d = np.stack([x, y, -np.ones_like(x)], -1).reshape(-1, 3)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.tile([0.0, 0.0, 3.2], (len(d), 1)), d


@njit
def _trace(a, o, d, from_obj):
    """(object, t) of each ray's nearest hit, one thread."""
    k = np.empty(o.shape[0], dtype=np.int64)
    t = np.empty(o.shape[0])
    for i in range(o.shape[0]):
        k[i], t[i] = bvh.closest_hit(a, (o[i, 0], o[i, 1], o[i, 2]), (d[i, 0], d[i, 1], d[i, 2]),
                                     math.inf, from_obj[i], False, None)
    return k, t


def bounce_rays(a, o, d, k, t, seed=1):
    """From each hit, a cosine-distributed direction about the normal facing back."""
    hit = k != NO_HIT
    p = o[hit] + d[hit] * t[hit, None]
    n = a.obj_f[k[hit], triangle.N:triangle.N + 3]
    n = np.where(((n * d[hit]).sum(axis=1) > 0)[:, None], -n, n)
    rng = np.random.default_rng(seed)
    u1, u2 = rng.random(len(p)), rng.random(len(p))
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    helper = np.where(np.abs(n[:, :1]) > 0.9, [[0.0, 1, 0]], [[1.0, 0, 0]])
    b1 = np.cross(n, helper)
    b1 /= np.linalg.norm(b1, axis=1, keepdims=True)
    b2 = np.cross(n, b1)
    w = (b1 * (r * np.cos(phi))[:, None] + b2 * (r * np.sin(phi))[:, None] +
         n * np.sqrt(1 - u1)[:, None])
    return p, w, n, k[hit]


# ------------------------------------------------------------------ the parts --
def build_part(v, f, runs):
    scene = rt.Scene()
    scene.add(rt.mesh((v, f), rt.lambertian((0.5, 0.5, 0.5))))
    pack_scene(scene)                            # warm-up (compiles the builder)
    arrays = pack_scene(scene)
    out = dict(triangles=len(f),
               rtweekend_bvh_s=median_seconds(lambda: bvh_build.build_bvh(arrays.obj_i,
                                                                          arrays.obj_f), runs),
               rtweekend_pack_s=median_seconds(lambda: pack_scene(scene), runs))
    try:
        from embreex import rtcore_scene as rtcs
        from embreex.mesh_construction import TriangleMesh
    except ImportError:
        print("Embree not installed: pip install embreex; rtweekend alone")
        return out, arrays, None
    tris = np.ascontiguousarray(v[f], dtype=np.float32)
    probe = (np.zeros((1, 3), np.float32), np.array([[0, 0, -1.0]], np.float32))

    def embree_build():
        s = rtcs.EmbreeScene()
        TriangleMesh(s, tris)
        s.run(*probe)                            # Embree builds on the first query
        return s
    embree_build()
    out["embree_build_s"] = median_seconds(embree_build, runs)
    out["bvh_vs_embree_build"] = out["rtweekend_bvh_s"] / out["embree_build_s"]
    return out, arrays, embree_build()


def traversal_part(arrays, embree, runs, size):
    o, d = camera_rays(size)
    none = np.full(len(o), NO_HIT, dtype=np.int64)
    _trace(arrays, o[:4], d[:4], none[:4])       # compile
    k, t = _trace(arrays, o, d, none)
    bo, bd, bn, bk = bounce_rays(arrays, o, d, k, t)
    rows = {}
    for name, (ro, rd, leave) in {"camera": (o, d, none), "diffuse": (bo, bd, bk)}.items():
        row = dict(rays=len(ro), hit_fraction=float(
            (_trace(arrays, ro, rd, leave)[0] != NO_HIT).mean()))
        row["rtweekend_rays_per_s"] = len(ro) / median_seconds(
            lambda: _trace(arrays, ro, rd, leave), runs)
        if embree is not None:
            eo = np.ascontiguousarray(ro + (bn * 1e-4 if name == "diffuse" else 0), np.float32)
            ed = np.ascontiguousarray(rd, np.float32)
            embree.run(eo, ed)
            row["embree_rays_per_s"] = len(ro) / median_seconds(lambda: embree.run(eo, ed), runs)
            row["embree_hit_fraction"] = float((embree.run(eo, ed) >= 0).mean())
            row["ratio"] = row["rtweekend_rays_per_s"] / row["embree_rays_per_s"]
        rows[name] = row
        line = f"  {name:8s} {row['rays']:8d} rays  rtweekend " \
            f"{row['rtweekend_rays_per_s'] / 1e6:6.2f} M/s"
        if embree is not None:
            line += f"  Embree {row['embree_rays_per_s'] / 1e6:6.2f} M/s  ratio {row['ratio']:.2f}"
        print(line, flush=True)
    return rows


ROOM_MESH = """
[[objects]]
name = "model"
type = "mesh"
file = "{obj}"
scale = 150
translate = [278, 165, 278]
material = "white"
"""


def room_scene(folder, obj):
    """cornell_box's room (its boxes left out) with the mesh in the middle."""
    src = Path(rt.__file__).parent / "scenes" / "cornell_box.toml"
    if not src.is_file():
        src = HERE.parent / "scenes" / "cornell_box.toml"
    text = src.read_text()
    head, *objects = text.split("[[objects]]")
    kept = [o for o in objects if 'type = "box"' not in o]
    path = folder / "mesh_room.toml"
    path.write_text(head + "".join("[[objects]]" + o for o in kept) +
                    ROOM_MESH.format(obj=obj.name))
    return path


MITSUBA = """
import sys, time, json
t0 = time.perf_counter()
sys.path.insert(0, {bench!r})
import mitsuba_peer as peer
import mitsuba as mi
import numpy as np
import rtweekend as rt
peer._setup({threads})
scene = rt.load_scene({room!r})
room = rt.Scene(camera=peer._resized(scene, {size}, {size}).camera)
for s in scene.objects:
    if s.kind != "mesh":
        room.add(s)
room.max_depth = scene.max_depth
d = peer.mitsuba_dict(room, {spp}, 0)
d["model"] = {{"type": "obj", "filename": {obj!r}, "face_normals": True,
              "bsdf": peer._bsdf(scene.objects[-1].material),
              "to_world": mi.ScalarTransform4f().translate([278, 165, 278]).scale(150)}}
image = mi.render(mi.load_dict(d), spp={spp})
np.asarray(image)
print(json.dumps(dict(seconds=time.perf_counter() - t0, variant=peer._variant)))
"""


def whole_part(folder, obj, size, spp, threads, peer):
    room = room_scene(folder, obj)
    def command(size, spp):
        return [sys.executable, "-m", "rtweekend", "render", str(room), "-o",
                str(folder / "mesh_room.npy"), "--width", str(size), "--height", str(size),
                "--spp", str(spp), "--threads", str(threads), "-q"]
    cmd = command(size, spp)
    warm = subprocess.run(command(16, 1), capture_output=True, text=True, timeout=3600)
    if warm.returncode:
        raise RuntimeError(warm.stderr)
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    wall = time.perf_counter() - t0
    if r.returncode:
        raise RuntimeError(r.stderr)
    out = dict(size=size, spp=spp, threads=threads, rtweekend_wall_s=wall,
               rtweekend_summary=r.stdout.strip().splitlines()[-1])
    print(f"  rtweekend whole process {wall:.2f} s", flush=True)
    if peer:
        code = MITSUBA.format(bench=str(HERE), threads=threads, room=str(room), size=size,
                              spp=spp, obj=str(obj))
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            p for p in (str(HERE.parent), os.environ.get("PYTHONPATH")) if p))
        t0 = time.perf_counter()
        m = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                           timeout=3600, env=env)
        mwall = time.perf_counter() - t0
        if m.returncode:
            print(f"  Mitsuba failed: {m.stderr.strip().splitlines()[-1]}")
        else:
            info = json.loads(m.stdout.strip().splitlines()[-1])
            out.update(mitsuba_wall_s=mwall, mitsuba_variant=info["variant"],
                       speed_vs_mitsuba=mwall / wall)
            print(f"  Mitsuba whole process {mwall:.2f} s ({info['variant']}); rtweekend's "
                  f"speed {mwall / wall:.2f}x Mitsuba's", flush=True)
    return out


def main(argv=None):
    p = parser(__doc__)
    p.add_argument("--triangles", type=int, default=1_310_720)
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--no-peer", action="store_true", help="leave Mitsuba out")
    a = p.parse_args(argv)
    triangles, size, spp, image = ((20_000, 32, 4, 64) if a.quick else
                                   (a.triangles, 300, 256, IMAGE))
    a.out.mkdir(parents=True, exist_ok=True)
    v, f = bumpy_sphere(triangles)
    print(f"a bumpy sphere of {len(f)} triangles")
    data = dict(machine=machine(), quick=a.quick)
    data["build"], arrays, embree = build_part(v, f, a.runs)
    b = data["build"]
    print(f"  build: rtweekend BVH {b['rtweekend_bvh_s']:.2f} s, whole pack "
          f"{b['rtweekend_pack_s']:.2f} s" + (f"; Embree {b['embree_build_s']:.2f} s"
                                              if "embree_build_s" in b else ""), flush=True)
    data["traversal"] = traversal_part(arrays, embree, a.runs, image)
    peer = not a.no_peer
    if peer:
        try:
            import mitsuba  # noqa: F401
        except ImportError:
            print("Mitsuba not installed: pip install '.[peer]'; rtweekend alone")
            peer = False
    with tempfile.TemporaryDirectory() as tmp:
        obj = Path(tmp) / "bumpy.obj"
        t0 = time.perf_counter()
        write_obj(obj, v, f)
        data["obj_mb"] = obj.stat().st_size / 1e6
        print(f"  OBJ {data['obj_mb']:.0f} MB written in {time.perf_counter() - t0:.1f} s")
        data["whole"] = whole_part(Path(tmp), obj, size, spp, a.threads, peer)
    save_json("meshes.json", data, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
