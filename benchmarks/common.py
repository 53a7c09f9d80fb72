"""Shared by the benchmark scripts: where results go and what machine made them."""
import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

HERE = Path(__file__).resolve().parent
# Where a run writes (--out): a folder of the current one, never the results
# committed in benchmarks/results (which are runs copied there on purpose).
RESULTS = Path("benchmark-results")
# Independent references (Mitsuba 3): the folder RTWEEKEND_REFERENCES names, or
# else ../shared/references beside the repository and then the copies every
# clone has in tests/data/reference (NAME.npz: radiance, stderr).
REFERENCES = Path(os.environ.get("RTWEEKEND_REFERENCES") or
                  HERE.parents[1] / "shared" / "references")
BUNDLED_REFERENCES = None if os.environ.get("RTWEEKEND_REFERENCES") else \
    HERE.parent / "tests" / "data" / "reference"


def machine():
    return {
        "date": datetime.datetime.now().isoformat(timespec="seconds"),
        "python": sys.version.split()[0],
        "numba": numba.__version__,
        "numpy": np.__version__,
        "cpus": os.cpu_count(),
        "numba_threads": numba.config.NUMBA_NUM_THREADS,
        "threading_layer": _threading_layer(),
        "processor": platform.processor() or platform.machine(),
    }


def _threading_layer():
    try:
        return numba.threading_layer()
    except ValueError:          # no parallel function has run yet
        return None


def save_json(name, data, folder=RESULTS):
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(json.dumps(data, indent=1) + "\n")
    return path


def reference(name):
    """(radiance, per-pixel stderr, where) of REFERENCES/name.npy and
    name_stderr.npy, else of the repository's tests/data/reference/name.npz, as
    float64; None when neither is there."""
    paths = REFERENCES / f"{name}.npy", REFERENCES / f"{name}_stderr.npy"
    if all(p.is_file() for p in paths):
        return (*(np.load(p).astype(np.float64) for p in paths), paths[0])
    bundled = BUNDLED_REFERENCES / f"{name}.npz" if BUNDLED_REFERENCES else None
    if bundled is not None and bundled.is_file():
        with np.load(bundled) as f:
            return f["radiance"].astype(np.float64), f["stderr"].astype(np.float64), bundled
    return None


def parser(doc):
    """The options every benchmark has: --quick (a tiny run) and --out (a folder)."""
    p = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="tiny run to check the script")
    p.add_argument("--out", type=Path, default=RESULTS, help="output folder")
    return p


def first_render_and_next(argv, env=None):
    """(values that differ, values) between the image a command renders in a
    process that compiles its kernels (an empty Numba cache) and the one it
    renders in the next process (kernels loaded from that cache): 0 when its
    first render and later ones agree to the bit.  argv + [path] must write a
    NumPy array to path (.npy)."""
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, **(env or {}), NUMBA_CACHE_DIR=str(Path(tmp) / "cache"))
        images = []
        for i in range(2):
            out = Path(tmp) / f"image{i}"
            r = subprocess.run([*argv, str(out)], env=env, capture_output=True, text=True,
                               timeout=1800)
            if r.returncode:
                raise RuntimeError(f"{' '.join(argv[:3])} failed:\n{r.stderr[-2000:]}")
            images.append(np.load(f"{out}.npy"))
    return int((images[0] != images[1]).sum()), images[0].size


def median_seconds(fn, runs):
    """The median wall time of `runs` calls of fn() (warm it up first)."""
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))
