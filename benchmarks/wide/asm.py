"""Did LLVM vectorise the intersection loops?  Counts of packed SIMD instructions.

    PYTHONPATH=. python -m benchmarks.wide.asm

For each compiled kernel (Numba's `inspect_asm` of the signature the renders
used) it counts the double-precision floating-point arithmetic instructions
(add, sub, mul, div, sqrt, fma, min, max, compare, blend) by form: packed on
zmm (8 doubles), ymm (4), xmm (2), or scalar (...sd, one double), and, from
the optimised LLVM IR, the loops LLVM marked `llvm.loop.isvectorized` and the
vector width of the double arithmetic.  A vectorised loop always keeps a scalar
copy for the remainder (n not a multiple of the width), so scalar counts are
never zero: the packed counts are the evidence.

Each configuration runs in a fresh process (Numba reads the CPU name and the
flags at import), compiling everything afresh (no cache: a kernel loaded from
Numba's cache has no assembly to show):

  host        the flags used by the benchmark: fastmath without nnan/ninf, CPU
              = the host (znver4 here: AVX-512)
  avx2        NUMBA_CPU_NAME=haswell and its NUMBA_CPU_FEATURES (AVX2, FMA; no
              AVX-512): what an AVX2 machine would get (4 doubles)
  nofastmath  WIDE_FASTMATH=0: the same loops compiled without any fastmath flag

Writes benchmarks/wide/asm.json and prints a table.
"""
import json
import os
import re
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
# Haswell's features: NUMBA_CPU_NAME alone keeps the host's (AVX-512 included).
AVX2 = ",".join("+" + f for f in (
    "64bit avx avx2 bmi bmi2 cmov cx16 f16c fma fxsr lzcnt mmx movbe popcnt sse sse2 sse3 "
    "sse4.1 sse4.2 ssse3 xsave").split())
CONFIGS = {
    "host": {},
    "avx2": {"NUMBA_CPU_NAME": "haswell", "NUMBA_CPU_FEATURES": AVX2},
    "nofastmath": {"WIDE_FASTMATH": "0"},
}
ARITH = re.compile(r"^v(add|sub|mul|div|sqrt|min|max|fn?m(add|sub)\d+|cmp\w*|ucomi|comi|"
                   r"blendm|blendv)(p|s)d$")
IR_VEC = re.compile(r"= (fadd|fsub|fmul|fdiv|fcmp \w+)( \w+)* <(\d+) x double>")


def count_asm(asm):
    """{zmm, ymm, xmm, scalar: count} of double arithmetic instructions."""
    c = Counter()
    for line in asm.splitlines():
        m = re.match(r"\s+(v\w+)\s+(.*)", line)
        if not m or not ARITH.match(m.group(1)):
            continue
        if m.group(1).endswith("sd"):
            c["scalar"] += 1
        else:
            ops = m.group(2)
            c["zmm" if "zmm" in ops else "ymm" if "ymm" in ops else "xmm"] += 1
    return c


def count_ir(ir):
    widths = Counter(int(m.group(3)) for m in IR_VEC.finditer(ir))
    return {"vectorized_loops": ir.count("llvm.loop.isvectorized\", i32 1"),
            "ir_vector_ops_by_width": {str(k): v for k, v in sorted(widths.items())}}


def one():
    """In this process: render tiny images (compiling every kernel), then count."""
    import rtweekend

    from . import intersect as X
    from . import wave
    from rtweekend.path import integrator
    from .wave import WideRenderer

    for name, mode, sort in (("cornell_glass", "flat", True), ("cornell_box", "flat", False),
                             ("weekend", "packet", True)):
        scene = rtweekend.load_scene(name)
        w = WideRenderer(scene, seed=1, width=16, height=16, threads=1, mode=mode, sort=sort)
        w.add_samples(1)
        r = rtweekend.Renderer(scene, seed=1, width=16, height=16, sampling="mixture",
                               threads=1)
        r.add_samples(1)
    kernels = {"rects": X.rects, "spheres": X.spheres, "boxes": X.boxes,
               "packet_bvh": X.packet_bvh, "init_hits": X.init_hits,
               "wave.bounce (shading)": wave.bounce,
               "wave.shade_lambertian": wave.shade_lambertian,
               "rtweekend render_row (scalar kernel)": integrator.render_row}
    out = {}
    for label, fn in kernels.items():
        sig = fn.signatures[0]
        row = dict(count_asm(fn.inspect_asm(sig)))
        row.update(count_ir(fn.inspect_llvm(sig)))
        out[label] = row
    import numba
    out["_cpu"] = [numba.config.CPU_NAME or "host", numba.config.CPU_FEATURES or "host"]
    print(json.dumps(out))


def main():
    results = {}
    for name, env in CONFIGS.items():
        with tempfile.TemporaryDirectory() as cache:
            e = dict(os.environ, NUMBA_CACHE_DIR=cache, WIDE_NO_CACHE="1", **env)
            p = subprocess.run([sys.executable, "-m", "benchmarks.wide.asm", "--one"], env=e,
                               capture_output=True, text=True, cwd=HERE.parent.parent)
        if p.returncode:
            print(p.stderr[-3000:], file=sys.stderr)
            raise SystemExit(f"{name}: failed")
        results[name] = json.loads(p.stdout.strip().splitlines()[-1])
    (HERE / "asm.json").write_text(json.dumps(results, indent=1) + "\n")
    cols = ("zmm", "ymm", "xmm", "scalar", "vectorized_loops")
    for name, res in results.items():
        print(f"\n[{name}]  double arithmetic instructions by form; loops LLVM vectorised")
        print(f"{'kernel':40s}" + "".join(f"{c:>8s}" for c in cols[:4]) + "   loops  IR widths")
        for label, row in res.items():
            if label.startswith("_"):
                continue
            print(f"{label:40s}" + "".join(f"{row.get(c, 0):8d}" for c in cols)
                  + f"  {row['ir_vector_ops_by_width']}")


if __name__ == "__main__":
    if "--one" in sys.argv:
        one()
    else:
        main()
