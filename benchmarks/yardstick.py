"""The yardstick: ../shared/yardsticks/numba_probe.py, a small scalar Numba tracer of
cornell_glass (same estimator, depth and camera), run beside rtweekend in the same
run so that a speed claim is a ratio, not a guess.  It lives outside this
repository; RTWEEKEND_YARDSTICK points elsewhere.  Without it, benchmarks say so
in one line and measure the rest."""
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

PATH = Path(os.environ.get("RTWEEKEND_YARDSTICK") or
            Path(__file__).resolve().parents[2] / "shared" / "yardsticks" / "numba_probe.py")


def available():
    return PATH.is_file()


def samples_per_s(size, spp, runs, threads=None):
    """The yardstick's median samples/s on cornell_glass at size x size, spp per
    run, after its own warm-up (compile excluded)."""
    env = dict(os.environ)
    if threads is not None:
        env["NUMBA_NUM_THREADS"] = str(threads)
    r = subprocess.run([sys.executable, str(PATH), "bench", str(size), str(spp), str(runs)],
                       env=env, capture_output=True, text=True, timeout=1800)
    if r.returncode:
        raise RuntimeError(f"yardstick failed:\n{r.stderr[-2000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])["samples_per_s"]


# The yardstick's own builds, picked by its PROBE_* variables.  "shipped" is its
# default (float32, fastmath with 'reassoc' and 'contract').  rtweekend leaves
# those two flags out (rtweekend/kernel/jit.py: with them a kernel compiled in the
# process and the same kernel loaded from Numba's cache round differently, so the
# first render and the next differ); the other two builds are the yardstick under
# rtweekend's flags, in its two precisions: the same rule on both sides.
BUILDS = {
    "shipped": {},
    "rtweekend_flags": {"PROBE_FM": "rtweekend", "PROBE_DTYPE": "f32"},
    "rtweekend_flags_f64": {"PROBE_FM": "rtweekend", "PROBE_DTYPE": "f64"},
}
_FLAGS_TABLE_END = "}[FMODE]"      # the end of the yardstick's table of flag sets
BUILD_FOLDER = Path(tempfile.gettempdir()) / "rtweekend_yardstick_builds"


def build_path(build):
    """The yardstick's file for `build`: the file itself, or a copy whose table of
    fastmath sets also holds rtweekend's (as "rtweekend"), kept in one folder so
    that Numba's cache of it survives between runs."""
    if not BUILDS[build].get("PROBE_FM"):
        return PATH
    from rtweekend.kernel.jit import FASTMATH
    src = PATH.read_text()
    if src.count(_FLAGS_TABLE_END) != 1:
        raise RuntimeError(f"{PATH}: its table of fastmath sets ('{_FLAGS_TABLE_END}') "
                           "was not found; cannot build it with rtweekend's flags")
    flags = "{" + ", ".join(repr(f) for f in sorted(FASTMATH)) + "}"
    src = src.replace(_FLAGS_TABLE_END, f', "rtweekend": {flags}' + _FLAGS_TABLE_END)
    BUILD_FOLDER.mkdir(parents=True, exist_ok=True)
    # A file per build: Numba keys its cache by file and signature, and some of
    # the yardstick's functions have the same signature in both precisions (one
    # folder for both would load one build's compiled code into the other).
    path = BUILD_FOLDER / f"{PATH.stem}_{build}.py"
    if not path.is_file() or path.read_text() != src:
        path.write_text(src)
    return path


@contextmanager
def _environment(values):
    """values set while the yardstick is imported; afterwards the environment as
    it was (the yardstick also sets NUMBA_CACHE_DIR, for its own processes)."""
    old = {k: os.environ.get(k) for k in [*values, "NUMBA_CACHE_DIR"]}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def load(build):
    """The yardstick's `build` imported as a module (its render() renders a pass)."""
    path = build_path(build)
    name = path.stem             # the name Numba's cache records for its functions
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    with _environment(BUILDS[build]):
        spec.loader.exec_module(module)
    return module


def fresh_vs_cached(build, size=64, spp=16):
    """common.first_render_and_next for the yardstick's `build` (its image mode)."""
    from common import first_render_and_next
    return first_render_and_next([sys.executable, str(build_path(build)), "image", str(size),
                                  str(spp)], env=BUILDS[build])
