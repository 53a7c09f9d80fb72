"""Each compiled function is keyed by the sources it can reach, so no edit runs
stale code and no unrelated edit compiles again; and what the compile itself is
wrapped in."""
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rtweekend
from rtweekend.kernel import disk_cache
from rtweekend.kernel.disk_cache import PACKAGE, Sources
from rtweekend.scene.loader import bundled_dir


def test_the_cache_is_one_folder_shared_by_every_copy_of_the_sources():
    assert PACKAGE == Path(rtweekend.__file__).resolve().parent
    assert Path(disk_cache.BASE).name == "kernels" and Path(disk_cache.BASE).is_dir()
    # Where a kernel's files go depends on its module's place in the package,
    # not on where the package is (a clone, or installed), nor on the digest.
    from rtweekend.path.integrators import bdpt
    assert bdpt.render_pass._cache.cache_path == os.path.join(disk_cache.BASE, "rtweekend",
                                                              "path", "integrators")


def test_a_kernels_key_is_the_sources_it_can_reach(tmp_path):
    copy = tmp_path / "rtweekend"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    kernel, classic = copy / "path" / "integrators" / "path.py", copy / "classic" / "kernel.py"

    def digests():
        sources = Sources(copy)
        return sources.digest(kernel), sources.digest(classic)

    before = digests()
    assert before == (Sources().digest(PACKAGE / "path" / "integrators" / "path.py"),
                      Sources().digest(PACKAGE / "classic" / "kernel.py"))

    def edited(path, text):
        old = path.read_text()
        path.write_text(old + text)
        try:
            return digests()
        finally:
            path.write_text(old)
    # A callee in another file, however deep: the path tracer's key changes,
    # the classic tracer's (which cannot reach it) does not.
    deep = edited(copy / "path" / "shapes" / "sphere.py", "\n# an edit\n")
    assert deep[0] != before[0] and deep[1] == before[1]
    # A file both reach (vec3): both change.
    shared = edited(copy / "kernel" / "vec3.py", "\n# an edit\n")
    assert shared[0] != before[0] and shared[1] != before[1]
    # The command line, the classic tracer's driver: neither kernel changes.
    assert edited(copy / "cli.py", "\n# an edit\n") == before
    assert edited(copy / "classic" / "render.py", "\n# an edit\n") == before
    assert digests() == before
    # Where a file is counts too: a module moved is another module.
    (copy / "path" / "shapes" / "sphere.py").rename(copy / "path" / "shapes" / "ball.py")
    assert digests()[0] != before[0]


# The classic tracer's cgfs scene from a copy of the package, in a process of its
# own: "compiled" when its kernel was compiled rather than loaded, and the image.
# (The scene by its path: a copy of an editable install's package has no
# bundled scenes beside it.)
RENDER = """
import sys
import numpy as np
import rtweekend as rt
r = rt.render(rt.load_scene(sys.argv[2]), width=24, height=16, threads=1)
np.save(sys.argv[1], r.image)
print(r.stats.compiled)
"""


CGFS = bundled_dir() / "cgfs.toml"


def test_an_edited_callee_in_another_file_compiles_afresh(tmp_path):
    copy = tmp_path / "src" / "rtweekend"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    env = dict(os.environ, PYTHONPATH=str(copy.parent), NUMBA_CACHE_DIR=str(tmp_path / "c"))

    def render(name):
        out = tmp_path / f"{name}.npy"
        run = subprocess.run([sys.executable, "-c", RENDER, str(out), str(CGFS)], env=env,
                             cwd=tmp_path,
                             capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stderr[-2000:]
        return run.stdout.split()[-1] == "True", np.load(out)

    compiled, first = render("first")
    assert compiled
    compiled, again = render("again")
    assert not compiled and np.array_equal(again, first)
    # An edit the classic kernel cannot reach: still loaded from the cache.
    with open(copy / "cli.py", "a") as f:
        f.write("\n# an edit\n")
    assert render("cli")[0] is False
    # vec3.scale, a callee of the classic kernel in another file, now doubles:
    # the kernel is compiled again, and the image shows the new code ran.
    vec3 = copy / "kernel" / "vec3.py"
    text = vec3.read_text()
    assert "def scale(a, s):\n    return (a[0] * s, a[1] * s, a[2] * s)" in text
    vec3.write_text(text.replace("def scale(a, s):\n    return (a[0] * s, a[1] * s, a[2] * s)",
                                 "def scale(a, s):\n    return (a[0] * s * 2.0, a[1] * s * 2.0,"
                                 " a[2] * s * 2.0)"))
    compiled, edited = render("edited")
    assert compiled and not np.array_equal(edited, first)


def test_collector_is_paused_only_while_compiling():
    import gc

    from rtweekend.kernel.jit import collector_paused
    assert gc.isenabled()
    with collector_paused():
        assert not gc.isenabled()
    assert gc.isenabled()
    gc.disable()                        # a caller that had it off keeps it off
    try:
        with collector_paused():
            pass
        assert not gc.isenabled()
    finally:
        gc.enable()
    try:
        with collector_paused():
            raise KeyboardInterrupt     # a compile interrupted by Ctrl-C
    except KeyboardInterrupt:
        pass
    assert gc.isenabled()


# Renders with the kernel of a scene with every feature (textures, media, motion)
# and strategy (next events, Sobol points), then prints the hash of the film and
# what the kernel's IR calls.  Run twice on one empty cache folder: the first
# process compiles (the IR is its own), the second loads what the first saved.
CHILD = """
import gc, hashlib, re, sys
import numpy as np
import rtweekend as rt
from rtweekend.kernel.jit import _InlinedDispatcher
from rtweekend.path.integrators import path
r = rt.Renderer(rt.load_scene("next_week_final"), width=24, height=16, sampling="nee+sobol",
                seed=2, threads=1)
r.add_samples(8)
registries = "numba.np.arraymath" in sys.modules
h = hashlib.sha256()
for a in r.film:
    h.update(np.ascontiguousarray(a).tobytes())
print(h.hexdigest())
ir = "\\n".join(path.render_pass.inspect_llvm().values())
# Steps marked jit_step(inline=False) are called on purpose: one copy of each.
steps = {c.fndesc.llvm_func_name for d in gc.get_objects() if isinstance(d, _InlinedDispatcher)
         and getattr(d, "_inline", "alwaysinline") == "alwaysinline"
         for c in d.overloads.values()}
calls = set(re.findall(r'call [^@\\n]*@"?([^"( ]+)', ir))
print(len(steps), len(calls), len(steps & calls))
print(r.compile_seconds)
print(registries)
"""


@pytest.fixture(scope="module")
def compiled_then_loaded(tmp_path_factory):
    """The two runs of CHILD (one cold compile serves both tests below) and the
    cache folder."""
    cache = tmp_path_factory.mktemp("numba_cache")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    runs = [subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True,
                           text=True, timeout=900) for _ in range(2)]
    for run in runs:
        assert run.returncode == 0, run.stderr[-2000:]
    return cache, [run.stdout.split("\n") for run in runs]


def test_a_kernel_compiled_here_and_one_loaded_from_the_cache_give_the_same_bits(
        compiled_then_loaded):
    # The first process compiles the kernel (an empty cache folder), the second
    # loads what the first saved; the float64 sums must agree to the bit (the
    # determinism rule; kernel/jit.py says why the fastmath flags leave out
    # 'contract' and 'reassoc' -- adding them does not make this kernel differ
    # on every machine, so this test guards the rule, not those flags).
    cache, (compiled, loaded) = compiled_then_loaded
    assert any(cache.rglob("*.nbi")), "the first run saved nothing to the cache"
    assert compiled[0] == loaded[0]


def test_a_start_with_everything_cached_compiles_nothing(compiled_then_loaded):
    # The second process loads every function of the render (packing, the BVH
    # builder, the kernel): no compile, and none reported -- not even a
    # step's entry for Python (the scene's boxes are padded by a cached loop).
    _, (compiled, loaded) = compiled_then_loaded
    assert float(compiled[2]) > 1.0
    assert float(loaded[2]) == 0.0


def test_a_start_with_everything_cached_loads_without_numbas_compiler_registries(
        compiled_then_loaded):
    # Loading machine code needs none of the implementations Numba installs for
    # compiling (disk_cache._load: 0.7 s of a cached start, SciPy's import among
    # them); the process that compiled installed them, as every compile does.
    _, (compiled, loaded) = compiled_then_loaded
    assert compiled[3] == "True"
    assert loaded[3] == "False"


def test_every_step_is_inlined_into_the_kernel(compiled_then_loaded):
    # jit_step asks LLVM to inline a step wherever it is called (kernel/jit.py):
    # the kernel of a scene with every feature and strategy calls none of them
    # but those marked inline=False (Perlin noise, in this scene).
    # Read in the process that compiled it (its steps compiled there too).
    _, (compiled, _) = compiled_then_loaded
    steps, calls, steps_called = map(int, compiled[1].split())
    assert steps > 50 and calls > 0          # it found the steps, and calls (to libm, say)
    assert steps_called == 0


def test_the_pixel_loop_is_kept_only_inside_the_kernels(compiled_then_loaded):
    # integrators/pixels.py's loop takes the estimator's sample function, so an
    # entry of its own could not be keyed by that function's sources: it is
    # compiled into each kernel and never saved alone (the kernels are, and
    # the second run loaded them: the test above).
    cache, _ = compiled_then_loaded
    names = [p.name for p in cache.rglob("*") if p.is_file()]
    assert any(n.startswith("pixels.shutter") for n in names)     # a plain step: kept
    assert any(n.startswith("path.render_pass") for n in names)
    assert not any(n.startswith("pixels.render_row") for n in names)


def test_a_step_called_from_python_runs_through_a_compiled_entry():
    from rtweekend.kernel.vec3 import dot
    from rtweekend.path.materials.lambertian import cosine_pdf
    assert cosine_pdf((0.0, 0.0, 1.0), (0.0, 0.6, 0.8)) == 0.8 / math.pi
    assert cosine_pdf((0.0, 0.0, 1.0), (0.0, 0.6, -0.8)) == 0.0
    assert dot((1.0, 2.0, 3.0), (4.0, 5.0, 6.0)) == 32.0
