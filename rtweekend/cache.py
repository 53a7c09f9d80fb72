"""The compiled kernels on disk: what is there, and removing what no longer serves.

Every compiled function is a few files in one folder (kernel/disk_cache.py),
named by the digest of the sources it was built from; an edit leaves the old
files beside the new ones, and nothing reads them any more.  `rtweekend cache`
says how much is there and how much of it is old; `rtweekend cache clear`
removes the old files (and the folders of earlier releases, which kept each
version of the sources in a numba-<hash> folder); `--all` everything (the
next render compiles again).
"""
import shutil
from pathlib import Path

from .kernel import disk_cache


def current():
    """The folder of the compiled kernels."""
    return Path(disk_cache.BASE)


def _old_folders():
    """Earlier releases' folders beside it (numba-<hash of the sources>)."""
    return [f for f in sorted(current().parent.glob("numba-*")) if f.is_dir()]


def _size(folder):
    return sum(f.stat().st_size for f in folder.rglob("*") if f.is_file())


def summary():
    """(bytes in the folder, bytes of it that no module's sources match now,
    [(old folder, bytes)])."""
    stale = sum(size for _, size in disk_cache.stale_files())
    return disk_cache.size(), stale, [(f, _size(f)) for f in _old_folders()]


def clear(everything=False):
    """Remove the old files and folders (and every kernel with everything);
    returns (files and folders removed, bytes freed)."""
    removed = freed = 0
    for folder in _old_folders():
        freed += _size(folder)
        shutil.rmtree(folder, ignore_errors=True)
        removed += 1
    if everything:
        files = [(p, p.stat().st_size) for p in current().rglob("*") if p.is_file()]
    else:
        files = disk_cache.stale_files()
    with disk_cache.locked():
        for path, size in files:
            if path.name != ".lock":
                path.unlink(missing_ok=True)
                removed, freed = removed + 1, freed + size
    return removed, freed
