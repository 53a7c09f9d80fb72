"""Shared by the benchmark scripts: where results go and what machine made them."""
import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

import numba
import numpy as np

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
# Independent references (Mitsuba 3): ../shared/references beside the repository,
# or the folder RTWEEKEND_REFERENCES names.
REFERENCES = Path(os.environ.get("RTWEEKEND_REFERENCES") or
                  HERE.parents[1] / "shared" / "references")


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
    """(radiance, per-pixel stderr) of REFERENCES/name.npy and name_stderr.npy,
    as float64, or None when either file is absent."""
    paths = REFERENCES / f"{name}.npy", REFERENCES / f"{name}_stderr.npy"
    if not all(p.is_file() for p in paths):
        return None
    return tuple(np.load(p).astype(np.float64) for p in paths)


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
