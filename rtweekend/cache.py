"""The compiled kernels on disk: where they are, and removing the old ones.

Each version of the sources compiles into a folder of its own,
numba-<hash of every source file> (kernel/jit.py), beside the earlier
versions' folders, which nothing uses any more once the sources changed.
`rtweekend cache` lists them; `rtweekend cache clear` removes all but the one
this version uses (`--all`: that one too; it is rebuilt by the next render).
"""
import shutil
from pathlib import Path

from .kernel.jit import config


def current():
    """This version's folder (Numba's CACHE_DIR, as kernel/jit.py set it)."""
    return Path(config.CACHE_DIR)


def folders():
    """[(folder, bytes, in use)] of every numba-* folder beside the current one."""
    here = current()
    out = []
    for folder in sorted(here.parent.glob("numba-*")):
        if folder.is_dir():
            size = sum(f.stat().st_size for f in folder.rglob("*") if f.is_file())
            out.append((folder, size, folder == here))
    return out


def clear(everything=False):
    """Remove the old versions' folders (and this one's with everything);
    returns (folders removed, bytes freed)."""
    removed = freed = 0
    for folder, size, in_use in folders():
        if in_use and not everything:
            continue
        shutil.rmtree(folder, ignore_errors=True)
        removed, freed = removed + 1, freed + size
    return removed, freed
