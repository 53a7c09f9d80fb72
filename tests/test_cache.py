"""Numba's cache is keyed by the package's sources, so no edit runs stale code;
and what the compile itself is wrapped in."""
import hashlib
from pathlib import Path

from numba import config

import rtweekend


def test_cache_folder_is_keyed_by_every_source_file():
    h = hashlib.sha256()
    for path in sorted(Path(rtweekend.__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    assert Path(config.CACHE_DIR).name == f"numba-{h.hexdigest()[:16]}"
    assert Path(config.CACHE_DIR).is_dir()


def test_collector_is_paused_only_while_compiling():
    import gc

    from rtweekend.jit import collector_paused
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
