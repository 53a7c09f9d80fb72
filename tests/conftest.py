import os

# Thread-count determinism is tested with 1 and 2 threads even on a 1-core CI
# machine; Numba reads this once, at import.
os.environ.setdefault("NUMBA_NUM_THREADS", str(max(2, os.cpu_count() or 1)))

from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

# The first call of a Numba function compiles it: no per-example deadline.
settings.register_profile("rtweekend", deadline=None)
settings.load_profile("rtweekend")

REPO = Path(__file__).resolve().parent.parent
DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="session")
def cornell_reference():
    """Mitsuba 3's converged cornell_box at 300x300: (radiance, stderr)."""
    with np.load(DATA / "reference" / "cornell_box_300.npz") as f:
        return f["radiance"], f["stderr"]


@pytest.fixture(scope="session")
def cornell_glass_reference():
    """Mitsuba 3's converged cornell_glass at 150x150 (the books' Schlick glass)."""
    with np.load(DATA / "reference" / "cornell_glass_150.npz") as f:
        return f["radiance"], f["stderr"]


@pytest.fixture(scope="session")
def cornell_smoke_reference():
    """Mitsuba 3's volpath render of cornell_smoke at 150x150 (media in boxes)."""
    with np.load(DATA / "reference" / "cornell_smoke_150.npz") as f:
        return f["radiance"], f["stderr"]


def failure_reference(name):
    """Mitsuba 3's converged render of a failure scene (scenes/NAME.toml) at
    100x100: (radiance, stderr)."""
    with np.load(DATA / "reference" / f"{name}_100.npz") as f:
        return f["radiance"], f["stderr"]
