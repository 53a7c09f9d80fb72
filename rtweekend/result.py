"""What a render returns: the image, its standard error, and the stats."""
from dataclasses import dataclass

import numpy as np


@dataclass
class RenderStats:
    width: int
    height: int
    spp: int                 # samples per pixel reached
    spp_requested: int | None
    seconds: float           # rendering wall time, compile excluded
    compile_seconds: float   # first-call cost (near 0 when the cache is warm)
    samples: int
    rays: int                # path segments traced
    nan_dropped: int         # samples that were NaN/Inf and left out of the mean
    interrupted: bool
    threads: int
    seed: int

    @property
    def samples_per_s(self):
        return self.samples / self.seconds if self.seconds > 0 else float("nan")

    @property
    def rays_per_s(self):
        return self.rays / self.seconds if self.seconds > 0 else float("nan")

    @property
    def mean_path_length(self):
        return self.rays / self.samples if self.samples else float("nan")

    def summary(self):
        note = (f" (interrupted: {self.spp} of {self.spp_requested} spp)"
                if self.interrupted and self.spp_requested else
                " (interrupted)" if self.interrupted else "")
        return (f"{self.width}x{self.height}, {self.spp} spp, {self.seconds:.2f} s, "
                f"{self.samples_per_s / 1e6:.3f} M samples/s, "
                f"{self.rays_per_s / 1e6:.3f} M rays/s, "
                f"{self.nan_dropped} NaN/Inf samples dropped{note}")


class RenderResult:
    """What render() returns; unpacks as (image, stats).

    image: HxWx3 float32 linear radiance; stats: RenderStats; stderr: HxWx3
    float32 per-pixel standard error, estimated from the samples' own variance.
    """

    def __init__(self, image, stats, stderr):
        self.image, self.stats, self.stderr = image, stats, stderr

    def __iter__(self):
        return iter((self.image, self.stats))

    def __getitem__(self, i):
        return (self.image, self.stats)[i]

    def __len__(self):
        return 2

    def __repr__(self):
        return f"RenderResult({self.stats.summary()})"


def mean_and_stderr(accum, accum2, valid):
    """Per-pixel mean of the kept samples and its standard error."""
    n = valid[..., None].astype(np.float64)
    mean = np.divide(accum, n, out=np.zeros_like(accum), where=n > 0)
    # Unbiased sample variance / n; pixels with < 2 samples get no estimate (inf).
    var = np.divide(accum2 - n * mean * mean, n - 1, out=np.full_like(accum, np.inf),
                    where=n > 1)
    stderr = np.sqrt(np.maximum(var, 0.0) / np.maximum(n, 1))
    return mean.astype(np.float32), stderr.astype(np.float32)
