"""The yardstick: ../shared/yardsticks/numba_probe.py, a small scalar Numba tracer of
cornell_glass (same estimator, depth and camera), run beside rtweekend in the same
run so that a speed claim is a ratio, not a guess.  It lives outside this
repository; RTWEEKEND_YARDSTICK points elsewhere.  Without it, benchmarks say so
in one line and measure the rest."""
import json
import os
import subprocess
import sys
from pathlib import Path

PATH = Path(os.environ.get("RTWEEKEND_YARDSTICK") or
            Path(__file__).resolve().parents[2] / "shared" / "yardsticks" / "numba_probe.py")


def available():
    return PATH.is_file()


def samples_per_s(size, spp, runs, threads=None):
    """The yardstick's median samples/s on cornell_glass at size x size, spp per
    run, after its own warm-up (compile excluded)."""
    env = dict(os.environ)
    if threads is not None:
        env["NUMBA_NUM_THREADS"] = str(threads)
    r = subprocess.run([sys.executable, str(PATH), "bench", str(size), str(spp), str(runs)],
                       env=env, capture_output=True, text=True, timeout=1800)
    if r.returncode:
        raise RuntimeError(f"yardstick failed:\n{r.stderr[-2000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])["samples_per_s"]
