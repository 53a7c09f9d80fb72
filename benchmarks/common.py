"""Shared by the benchmark scripts: where results go and what machine made them."""
import argparse
import datetime
import json
import os
import platform
import sys
from pathlib import Path

import numba
import numpy as np

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
REFERENCE = HERE.parent / "tests" / "data" / "reference" / "cornell_box_300.npz"


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


def mitsuba_reference():
    """Mitsuba 3's 8192-spp cornell_box at 300x300: (radiance, stderr)."""
    with np.load(REFERENCE) as f:
        return f["radiance"].astype(np.float64), f["stderr"].astype(np.float64)


def parser(doc):
    """The options every benchmark has: --quick (a tiny run) and --out (a folder)."""
    p = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="tiny run to check the script")
    p.add_argument("--out", type=Path, default=RESULTS, help="output folder")
    return p
