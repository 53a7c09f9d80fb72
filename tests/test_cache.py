"""Numba's cache is keyed by the package's sources, so no edit runs stale code."""
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
