"""Will a render fit in memory?  Asked before anything large is allocated.

A render's arrays are known from its size (path/film.py: render_bytes; the
classic ray tracer's in classic/render.py) and from its scene's description
(path/pack.py: scene_bytes: primitives, BVH, light rows, textures); `check`
compares them with the memory this process can still get and refuses, in one
line, a render that would be killed by the kernel hours later or fail with a
MemoryError.
"""
import os
import resource

from .errors import SceneError

# Only what is certainly there counts: a render needing more than this share of
# the available memory is refused (the rest: Python, Numba, the encoder).
SHARE = 0.9


def _meminfo():
    """MemAvailable of /proc/meminfo (Linux), in bytes; None elsewhere."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _cgroup():
    """What the cgroup (a container's memory limit) still allows, or None."""
    for limit, usage in (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                         ("/sys/fs/cgroup/memory/memory.limit_in_bytes",
                          "/sys/fs/cgroup/memory/memory.usage_in_bytes")):
        try:
            with open(limit) as f:
                text = f.read().strip()
            if text == "max":
                continue
            with open(usage) as f:
                used = int(f.read().strip())
            cap = int(text)
            if cap < 2**60:                     # v1 writes "no limit" as a huge number
                return max(0, cap - used)
        except (OSError, ValueError):
            continue
    return None


def _address_space():
    """What `ulimit -v` still allows this process, or None."""
    try:
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft == resource.RLIM_INFINITY:
            return None
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return max(0, soft - int(line.split()[1]) * 1024)
    except (OSError, ValueError, AttributeError):
        pass
    return None


def _sysconf():
    """Free physical pages (POSIX; macOS and the BSDs have no /proc)."""
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return None


def available():
    """(bytes this process can still allocate, where that figure comes from),
    the smallest of what the system, the cgroup and the rlimit allow; (None,
    None) if nothing can tell."""
    found = [(v, name) for v, name in ((_cgroup(), "the cgroup's limit"),
                                       (_address_space(), "ulimit -v"))
             if v is not None]
    system = _meminfo()
    if system is not None:
        found.append((system, "MemAvailable"))
    else:
        free = _sysconf()
        if free is not None:
            found.append((free, "free memory"))
    return min(found) if found else (None, None)


def size(n):
    """Bytes as a person reads them: 27.4 GB, 640 MB."""
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.1f} {unit}"
    return f"{n} bytes"


def check(needed, width, height, what="render", scene=0, objects=0, origin=None,
          primitives=None):
    """SceneError unless `needed` bytes (of which `scene` for the scene's arrays,
    with `objects` objects, `primitives` of them after packing: a mesh's
    triangles) fit in what this process can still get; the message names the
    image's size and `origin` (what set it), or the scene if it needs most of
    it."""
    free, source = available()
    if free is None or needed <= SHARE * free:
        return
    if scene > needed / 2:
        parts = (f" ({primitives:,} primitives: a mesh's triangles count one each)"
                 if primitives is not None and primitives != objects else "")
        raise SceneError(f"{what}: the scene's {objects} objects{parts} need about {size(scene)} "
                         f"of memory, with its {width}x{height} image {size(needed)}, and "
                         f"{size(free)} is available ({source}); render a smaller scene")
    where = f" ({origin})" if origin else ""
    raise SceneError(f"{what}: width x height: {width}x{height}{where} needs about "
                     f"{size(needed)} of memory and {size(free)} is available "
                     f"({source}); render a smaller image")
