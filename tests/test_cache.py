"""Numba's cache is keyed by the package's sources, so no edit runs stale code;
and what the compile itself is wrapped in."""
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from numba import config

import rtweekend
from rtweekend.kernel.jit import PACKAGE, source_digest


def test_cache_folder_is_keyed_by_every_source_file():
    assert PACKAGE == Path(rtweekend.__file__).resolve().parent
    assert Path(config.CACHE_DIR).name == f"numba-{source_digest()}"
    assert Path(config.CACHE_DIR).is_dir()


def test_an_edit_anywhere_in_the_package_changes_the_key(tmp_path):
    # Subpackages count (an edit to path/pdf.py must not load a stale kernel),
    # and so does where a file is: moving one changes the key too.
    copy = tmp_path / "rtweekend"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    before = source_digest(copy)
    assert before == source_digest(PACKAGE)
    deep = copy / "path" / "shapes" / "sphere.py"
    text = deep.read_text()
    deep.write_text(text + "\n# an edit\n")
    assert source_digest(copy) != before
    deep.write_text(text)
    assert source_digest(copy) == before
    deep.rename(copy / "path" / "sphere.py")
    assert source_digest(copy) != before


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
import gc, hashlib, re
import numpy as np
import rtweekend as rt
from rtweekend.kernel.jit import _InlinedDispatcher
from rtweekend.path.integrators import path
r = rt.Renderer(rt.load_scene("next_week_final"), width=24, height=16, sampling="nee+sobol",
                seed=2, threads=1)
r.add_samples(8)
h = hashlib.sha256()
for a in r.film:
    h.update(np.ascontiguousarray(a).tobytes())
print(h.hexdigest())
ir = "\\n".join(path.render_pass.inspect_llvm().values())
steps = {c.fndesc.llvm_func_name for d in gc.get_objects() if isinstance(d, _InlinedDispatcher)
         for c in d.overloads.values()}
calls = set(re.findall(r'call [^@\\n]*@"?([^"( ]+)', ir))
print(len(steps), len(calls), len(steps & calls))
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


def test_every_step_is_inlined_into_the_kernel(compiled_then_loaded):
    # jit_step asks LLVM to inline a step wherever it is called (kernel/jit.py):
    # the kernel of a scene with every feature and strategy calls none of them.
    # Read in the process that compiled it (its steps compiled there too).
    _, (compiled, _) = compiled_then_loaded
    steps, calls, steps_called = map(int, compiled[1].split())
    assert steps > 50 and calls > 0          # it found the steps, and calls (to libm, say)
    assert steps_called == 0


def test_a_step_called_from_python_runs_through_a_compiled_entry():
    from rtweekend.kernel.vec3 import dot
    from rtweekend.path.materials.lambertian import pdf
    assert pdf((0.0, 0.0, 1.0), (0.0, 0.6, 0.8)) == 0.8 / math.pi
    assert pdf((0.0, 0.0, 1.0), (0.0, 0.6, -0.8)) == 0.0
    assert dot((1.0, 2.0, 3.0), (4.0, 5.0, 6.0)) == 32.0
