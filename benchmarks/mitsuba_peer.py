"""Mitsuba 3 as a peer renderer: translate an rtweekend Scene and render it.

Mitsuba is not a dependency of rtweekend: `pip install '.[peer]'` adds it, or
give it a venv of its own (benchmarks/accuracy.py --peer-python runs it there):

    python3 -m venv /work/mitsuba-venv
    /work/mitsuba-venv/bin/pip install mitsuba numpy
    /work/mitsuba-venv/bin/pip install -e /work/main   # or put /work/main on sys.path
    apt-get install -y libllvm19                        # for the llvm_* variants
    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1

    python benchmarks/mitsuba_peer.py cornell_box --size 300 --spp 256 --threads 2
    python benchmarks/mitsuba_peer.py cornell_box --size 300 --spp 64 --series --save s.npz

(--series: separate renders at 1, 2, 4, ... 64 spp, each timed; what accuracy.py
charts.)

Conventions that make the two renderers agree:
  * Depth: Mitsuba's path `max_depth` counts path segments, the camera ray
    included (1 = emitters seen directly, 2 = direct lighting), and so does
    rtweekend's max_depth: the same number is passed through.  Mitsuba adds
    next-event estimation with MIS and Russian roulette (from depth 5): a
    different estimator of the same integral, so only the noise differs.
  * Camera: `perspective` with fov_axis 'y' spans exactly vfov over the film
    height; a pixel's samples are uniform over [i, i+1) x [j, j+1) and the box
    filter keeps each in its own pixel; row 0 is the top, as in rtweekend.
  * Rects face +axis; Mitsuba's rectangle faces +z, so each is mapped by a
    rotation (a cyclic permutation of the axes, det +1) and flip_face becomes
    `flip_normals`.  The one-sided area emitter emits along that normal.
  * Glass: the books' Schlick dielectric, as a Python BSDF (Mitsuba's own
    `dielectric` uses the exact Fresnel equations).
"""
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

try:                                   # Mitsuba is optional: see available()
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
    import drjit as dr
    import mitsuba as mi
except ImportError:
    dr = mi = None

VARIANTS = ("llvm_ad_rgb", "scalar_rgb")
_variant = None


def available():
    """True when mitsuba imports and one of VARIANTS can be set."""
    return unavailable_reason() is None


def unavailable_reason():
    """None when Mitsuba works here, else why not (one line)."""
    try:
        _setup()
        return None
    except Exception as e:
        return f"{type(e).__name__}: {e}".splitlines()[0]


def _setup(threads=None):
    """Set the first variant that works (once) and register the Schlick BSDF."""
    global _variant
    if mi is None:
        raise ImportError("mitsuba is not installed")
    if threads is not None:
        dr.set_thread_count(threads)
    if _variant is None:
        for v in VARIANTS:
            try:
                mi.set_variant(v)
                break
            except Exception:
                continue
        else:
            raise RuntimeError(f"none of the Mitsuba variants {VARIANTS} works")
        _variant = v
        cls = _schlick_class()
        mi.register_bsdf("schlick_dielectric", lambda props: cls(props))
    return _variant


# ---------------------------------------------------------------- the glass --
def _schlick_class():
    """Defined once mitsuba is imported (it subclasses mi.BSDF)."""

    class SchlickDielectric(mi.BSDF):
        """The books' dielectric: reflect with probability Schlick(cos, ratio)
        or always under total internal reflection, else refract; weight 1.

        wi is in the local frame (z = the geometric/shading normal, pointing
        outside the sphere).  cos is against the incoming side, as in the books
        even when leaving the glass; ratio = 1/ior entering, ior leaving."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.ior = props.get("eta", 1.5)
            refl = mi.BSDFFlags.DeltaReflection | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
            tran = mi.BSDFFlags.DeltaTransmission | mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
            self.m_components = [refl, tran]
            self.m_flags = refl | tran

        def sample(self, ctx, si, sample1, sample2, active=True):
            wi = si.wi
            entering = wi.z > 0
            ratio = dr.select(entering, 1.0 / self.ior, self.ior)
            cos = dr.minimum(dr.abs(wi.z), 1.0)
            sin = dr.safe_sqrt(1.0 - cos * cos)
            r0 = dr.square((1.0 - ratio) / (1.0 + ratio))
            schlick = r0 + (1.0 - r0) * dr.power(1.0 - cos, 5)
            reflect = (ratio * sin > 1.0) | (schlick > sample1)
            # Refraction (the books' refract() in the local frame): tangential
            # part scaled by ratio, normal part through to the other side.
            cos_t = dr.safe_sqrt(1.0 - dr.square(ratio * sin))
            refr = mi.Vector3f(-ratio * wi.x, -ratio * wi.y, -dr.sign(wi.z) * cos_t)
            refl = mi.Vector3f(-wi.x, -wi.y, wi.z)

            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = dr.select(reflect, refl, refr)
            tir = ratio * sin > 1.0
            bs.pdf = dr.select(tir, 1.0, dr.select(reflect, schlick, 1.0 - schlick))
            bs.eta = dr.select(reflect, 1.0, 1.0 / ratio)
            bs.sampled_component = dr.select(reflect, mi.UInt32(0), mi.UInt32(1))
            bs.sampled_type = dr.select(reflect, mi.UInt32(+mi.BSDFFlags.DeltaReflection),
                                        mi.UInt32(+mi.BSDFFlags.DeltaTransmission))
            return bs, dr.select(active, mi.Color3f(1.0), mi.Color3f(0.0))

        def eval(self, ctx, si, wo, active=True):
            return mi.Color3f(0.0)     # delta lobes only

        def pdf(self, ctx, si, wo, active=True):
            return mi.Float(0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return mi.Color3f(0.0), mi.Float(0.0)

        def traverse(self, callback):
            pass

        def to_string(self):
            return f"SchlickDielectric[ior={self.ior}]"

    return SchlickDielectric


# ---------------------------------------------------------- the translator --
def _bsdf(m):
    if m.kind == "lambertian":
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": _rgb(m.color)}}
    if m.kind == "metal":
        if m.param > 0:
            raise NotImplementedError("fuzzy metal has no Mitsuba counterpart here")
        # material 'none' = a perfect mirror (Fresnel 1); the colour scales it.
        # twosided: the books' metal reflects on both sides of a surface.
        return {"type": "twosided", "bsdf": {"type": "conductor", "material": "none",
                                             "specular_reflectance": _rgb(m.color)}}
    if m.kind == "dielectric":
        return {"type": "schlick_dielectric", "eta": float(m.param)}
    if m.kind == "rough_conductor":    # GGX, Smith's separable G, visible normals
        return {"type": "twosided", "bsdf": {
            "type": "roughconductor", "material": "none", "distribution": "ggx",
            "alpha": float(m.alpha), "specular_reflectance": _rgb(m.color)}}
    if m.kind == "rough_dielectric":   # Walter et al. with GGX, exact Fresnel, visible normals
        return {"type": "roughdielectric", "distribution": "ggx", "alpha": float(m.alpha),
                "int_ior": float(m.param), "ext_ior": 1.0}
    if m.kind == "diffuse_light":      # emits (see mitsuba_dict); absorbs whatever hits it
        return {"type": "diffuse", "reflectance": _rgb((0, 0, 0))}
    raise NotImplementedError(f"material {m.kind!r}")


def _rgb(c):
    return {"type": "rgb", "value": [float(x) for x in c]}


# Columns: where Mitsuba's local x, y, z (z = the normal) go in the world.
_RECT_AXES = {"xy_rect": ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
              "xz_rect": ((0, 0, 1), (1, 0, 0), (0, 1, 0)),     # u=z, v=x, n=+y
              "yz_rect": ((0, 1, 0), (0, 0, 1), (1, 0, 0))}     # u=y, v=z, n=+x


def _local_matrix(s):
    """4x4 map from Mitsuba's canonical shape to rtweekend's, before rotate/translate."""
    M = np.eye(4)
    g = s.geometry
    if s.kind == "box":
        lo, hi = np.asarray(g[0], float), np.asarray(g[1], float)
        M[:3, :3] = np.diag((hi - lo) / 2)     # [-1,1]^3 -> [lo, hi]
        M[:3, 3] = (hi + lo) / 2
        return M
    a0, a1, b0, b1, k = (float(x) for x in g)
    if s.kind == "xz_rect":                    # (x0,x1,z0,z1,k): local u spans z, v spans x
        a0, a1, b0, b1 = b0, b1, a0, a1
    ex, ey, ez = (np.asarray(c, float) for c in _RECT_AXES[s.kind])
    M[:3, 0] = ex * (a1 - a0) / 2
    M[:3, 1] = ey * (b1 - b0) / 2
    M[:3, 2] = ez
    M[:3, 3] = ex * (a0 + a1) / 2 + ey * (b0 + b1) / 2 + ez * k
    return M


def placed_y(angle, offset):
    """A placement() for a shape described by hand: the books' rotate_y(angle)
    (x' = cos x + sin z, z' = -sin x + cos z), then translate by offset."""
    c, sn = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    rot = np.array([[c, 0.0, sn], [0.0, 1.0, 0.0], [-sn, 0.0, c]])
    return lambda: (rot, np.asarray(offset, dtype=float))


def _placement(s):
    """The shape's rotation (the books' rotate_y: x' = cos x + sin z,
    z' = -sin x + cos z), then translate."""
    rot, offset = s.placement()
    M = np.eye(4)
    M[:3, :3] = rot
    M[:3, 3] = offset
    return M


def _shape(s):
    if s.kind == "sphere":
        center, radius = s.geometry
        p = _placement(s) @ np.append(np.asarray(center, float), 1.0)
        d = {"type": "sphere", "center": [float(x) for x in p[:3]], "radius": float(radius)}
    elif s.kind in _RECT_AXES or s.kind == "box":
        M = _placement(s) @ _local_matrix(s)
        d = {"type": "rectangle" if s.kind != "box" else "cube",
             "to_world": mi.ScalarTransform4f(M.tolist())}
    elif s.kind == "mesh":
        # The triangles from a PLY file Mitsuba reads (its to_world: the same
        # rotate_y and translate; the scale is in the vertices), flat or with the
        # vertex normals rtweekend shades with.  flip_face reverses the winding,
        # as rtweekend packs it.
        vertices, faces, _, normals = s.geometry
        d = {"type": "ply", "face_normals": normals is None,
             "filename": _ply(vertices, faces[:, ::-1] if s.flipped else faces, normals),
             "to_world": mi.ScalarTransform4f(_placement(s).tolist())}
    else:
        raise NotImplementedError(f"shape {s.kind!r}")
    if s.flipped and s.kind != "mesh":
        d["flip_normals"] = True
    d["bsdf"] = _bsdf(s.material)
    if s.material.kind == "diffuse_light":
        # One-sided: Mitsuba's area emitter emits on the side its normal faces.
        d["emitter"] = {"type": "area", "radiance": _rgb(s.material.color)}
    return d


_PLY_FOLDER = None


def _ply(vertices, faces, normals=None):
    """A binary PLY file of the triangles (for Mitsuba's ply shape), with the
    vertex normals if given; its path."""
    import tempfile
    global _PLY_FOLDER
    if _PLY_FOLDER is None:                 # removed when the process ends
        _PLY_FOLDER = tempfile.TemporaryDirectory(prefix="mitsuba_peer_")
    path = Path(_PLY_FOLDER.name) / f"mesh_{len(list(Path(_PLY_FOLDER.name).iterdir()))}.ply"
    columns = "xyz" if normals is None else ("x", "y", "z", "nx", "ny", "nz")
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(vertices)}\n" +
              "".join(f"property float {c}\n" for c in columns) +
              f"element face {len(faces)}\n"
              "property list uchar int vertex_indices\nend_header\n")
    if normals is not None:
        vertices = np.concatenate([vertices, normals], axis=1)
    face_rows = np.zeros(len(faces), dtype=[("n", "u1"), ("v", "<i4", 3)])
    face_rows["n"], face_rows["v"] = 3, faces
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(np.asarray(vertices, dtype="<f4").tobytes())
        f.write(face_rows.tobytes())
    return str(path)


def _sensor(cam, spp, seed):
    to_world = mi.ScalarTransform4f().look_at(origin=list(cam.lookfrom),
                                              target=list(cam.lookat), up=list(cam.vup))
    d = {"type": "perspective", "fov_axis": "y", "fov": float(cam.vfov), "to_world": to_world,
         "film": {"type": "hdrfilm", "width": int(cam.width), "height": int(cam.height),
                  "rfilter": {"type": "box"}, "pixel_format": "rgb"},
         "sampler": {"type": "independent", "sample_count": int(spp), "seed": int(seed)}}
    if cam.aperture > 0:                  # the books' lens: radius aperture/2, focus plane
        d.update(type="thinlens", aperture_radius=cam.aperture / 2,
                 focus_distance=float(cam.focus_dist))
    return d


def mitsuba_dict(scene, spp, seed=0, aov=False):
    """A Mitsuba scene dict (mi.load_dict) for an rtweekend Scene; aov: the
    path integrator inside Mitsuba's `aov` one, whose image has 9 channels:
    RGB, then the albedo and the shading normal of the first hit (for a
    denoiser, benchmarks/denoise.py)."""
    _setup()
    integrator = {"type": "path", "max_depth": int(scene.resolved_max_depth())}
    if aov:
        integrator = {"type": "aov", "aovs": "albedo:albedo,nn:sh_normal",
                      "integrator": integrator}
    d = {"type": "scene", "integrator": integrator,
         "sensor": _sensor(scene.camera, spp, seed)}
    bg = scene.resolved_background()
    if isinstance(bg, str):
        raise NotImplementedError(f"background {bg!r}")
    if any(float(x) > 0 for x in bg):
        d["background"] = {"type": "constant", "radiance": _rgb(bg)}
    for i, s in enumerate(scene.objects):
        d[f"shape_{i:03d}_{getattr(s, 'name', '') or s.kind}"] = _shape(s)
    return d


# ---------------------------------------------------------------- rendering --
def render(scene, spp, seed=0, pass_spp=64, threads=None, info=None):
    """(float32 H x W x 3 linear image, seconds) for spp samples per pixel.

    Renders in passes of pass_spp (the memory of one wavefront stays small;
    pass i of seed s uses Mitsuba seed s * 100003 + i) and averages them.  One
    untimed warm-up pass comes first so that JIT compilation is excluded; `info`
    (a dict) receives the warm-up time and the compile time estimated from it."""
    _setup(threads)
    pass_spp = max(1, min(pass_spp, spp))
    mscene = mi.load_dict(mitsuba_dict(scene, pass_spp, seed))
    t0 = time.perf_counter()
    _render_passes(mscene, pass_spp, pass_spp, seed, warm_up=True)   # compile + run
    warm = time.perf_counter() - t0
    t0 = time.perf_counter()
    image = _render_passes(mscene, spp, pass_spp, seed)[..., :3]
    seconds = time.perf_counter() - t0
    if info is not None:
        info.update(warmup_seconds=warm, passes=-(-spp // pass_spp), variant=_variant,
                    threads=dr.thread_count(),
                    compile_seconds=max(0.0, warm - seconds * pass_spp / spp))
    return image.astype(np.float32), seconds


def series(scene, spps, seed=0, pass_spp=64, threads=None, info=None, aov=False):
    """[(spp, seconds, float64 image)] for each spp in spps: separate renders,
    each timed from scratch (render k uses seed + k, so no two share samples).

    One warm-up pass per pass size used (untimed) comes first, so compilation is
    excluded; `info` receives the warm-up time, the compile time estimated from
    it, the variant and the thread count."""
    _setup(threads)
    biggest = max(1, min(pass_spp, max(spps)))
    mscene = mi.load_dict(mitsuba_dict(scene, biggest, seed, aov))
    t0 = time.perf_counter()
    _render_passes(mscene, biggest, biggest, seed, warm_up=True)      # compile + run
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    _render_passes(mscene, biggest, biggest, seed, warm_up=True)      # run only
    again = time.perf_counter() - t0
    for n in sorted({min(n, biggest) for n in spps} - {biggest}):
        _render_passes(mscene, n, n, seed, warm_up=True)
    out = []
    for k, n in enumerate(spps):
        t0 = time.perf_counter()
        image = _render_passes(mscene, n, pass_spp, seed + k)
        image = image if aov else image[..., :3]
        out.append((n, time.perf_counter() - t0, image))
    if info is not None:
        info.update(warmup_seconds=first + again, compile_seconds=max(0.0, first - again),
                    variant=_variant, threads=dr.thread_count(), pass_spp=pass_spp,
                    mitsuba=mi.__version__)
    return out


def denoised(image):
    """An --aov image (9 channels: RGB, albedo, normal) denoised by Open Image
    Denoise with its albedo and normal, as rtweekend's --denoise feeds it
    (Mitsuba has no feature for the light seen emitted: it is filtered too)."""
    import pyoidn
    image = np.asarray(image, dtype=np.float32)
    return pyoidn.denoise(np.ascontiguousarray(image[..., :3]),
                          albedo=np.ascontiguousarray(np.clip(image[..., 3:6], 0, 1)),
                          normal=np.ascontiguousarray(np.clip(image[..., 6:9], -1, 1)),
                          hdr=True)


def _render_passes(mscene, spp, pass_spp, seed, warm_up=False):
    """The mean of spp samples per pixel, rendered in passes of at most pass_spp
    (pass i uses Mitsuba seed seed * 100003 + i; a warm-up pass, 99999); every
    channel the film has."""
    pass_spp = max(1, min(pass_spp, spp))
    passes = [pass_spp] * (spp // pass_spp) + ([spp % pass_spp] if spp % pass_spp else [])
    acc = 0.0
    for i, n in enumerate(passes):
        s = (seed * 100_003 + (99_999 if warm_up else i)) % 2**32
        img = mi.render(mscene, spp=n, seed=s)
        acc = acc + n * np.array(img, dtype=np.float64)   # evaluates the kernel
    return acc / spp


def main(argv=None):
    import argparse
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    import rtweekend as rt
    p = argparse.ArgumentParser(description="Render a bundled scene with Mitsuba 3.")
    p.add_argument("scene", nargs="?", default="cornell_box")
    p.add_argument("--size", type=int, help="width (height keeps the aspect)")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, help="Dr.Jit worker threads")
    p.add_argument("--save", type=Path, help="write the image as .npy (.npz with --series)")
    p.add_argument("--series", action="store_true",
                   help="separate renders at 1, 2, 4, ... --spp (for benchmarks/accuracy.py)")
    p.add_argument("--aov", action="store_true", help="with --series: 9 channels, RGB, "
                   "albedo, normal (for benchmarks/denoise.py)")
    p.add_argument("--quick", action="store_true", help="16 pixels wide, 4 spp (tests)")
    a = p.parse_args(argv)
    if a.quick:
        a.size, a.spp = 16, 4
    why = unavailable_reason()
    if why:
        print(json.dumps({"peer": "mitsuba", "available": False, "reason": why}))
        return
    scene = rt.load_scene(a.scene)
    if a.size:
        c = scene.camera
        h = max(1, round(a.size * c.height / c.width))
        scene = _resized(scene, a.size, h)
    info = {}
    if a.series:
        spps = [2 ** k for k in range(a.spp.bit_length()) if 2 ** k <= a.spp]
        out = series(scene, spps, a.seed, threads=a.threads, info=info, aov=a.aov)
        if a.save:
            np.savez(a.save, spp=np.array(spps), seconds=np.array([t for _, t, _ in out]),
                     images=np.array([im for _, _, im in out], dtype=np.float32))
        print(json.dumps({"peer": "mitsuba", "available": True, "scene": a.scene,
                          "width": scene.camera.width, "height": scene.camera.height,
                          "spp": spps, "seconds": [t for _, t, _ in out], **info}))
        return
    img, sec = render(scene, a.spp, a.seed, threads=a.threads, info=info)
    if a.save:
        np.save(a.save, img)
    h, w = img.shape[:2]
    print(json.dumps({"peer": "mitsuba", "mitsuba": mi.__version__, "scene": a.scene,
                      "width": w, "height": h, "spp": a.spp, "seconds": sec,
                      "samples_per_s": w * h * a.spp / sec, "mean": float(img.mean()),
                      **info}))


def _resized(scene, w, h):
    """The scene with another image size (Camera and Scene are dataclasses)."""
    import dataclasses
    return dataclasses.replace(scene, camera=dataclasses.replace(scene.camera, width=w, height=h))


if __name__ == "__main__":
    main()
