"""Numba's cache is keyed by the package's sources, so no edit runs stale code;
and what the compile itself is wrapped in."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

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


CHILD = """
import hashlib, sys
import numpy as np
import rtweekend as rt
r = rt.Renderer(rt.load_scene("metals"), width=24, height=16, sampling="mixture", seed=2,
                threads=1)
r.add_samples(8)
h = hashlib.sha256()
for a in r.film:
    h.update(np.ascontiguousarray(a).tobytes())
print(h.hexdigest())
"""


def test_a_kernel_compiled_here_and_one_loaded_from_the_cache_give_the_same_bits(tmp_path):
    # The first process compiles the kernel (an empty cache folder), the second
    # loads what the first saved; the float64 sums must agree to the bit (with
    # 'contract' or 'reassoc' among the fastmath flags they did not: kernel/jit.py).
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    runs = [subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True,
                           text=True, timeout=600) for _ in range(2)]
    for run in runs:
        assert run.returncode == 0, run.stderr[-2000:]
    compiled, loaded = (run.stdout.strip() for run in runs)
    assert any(tmp_path.rglob("*.nbi")), "the first run saved nothing to the cache"
    assert compiled == loaded
