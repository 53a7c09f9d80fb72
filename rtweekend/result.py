"""What a render returns: the image, its standard error, and the stats."""
from dataclasses import dataclass

FIREFLY_FACTOR = 100.0   # a firefly: a sample worth this many times the image mean


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
    interrupted: bool        # stopped before spp_requested (see stopped_by)
    threads: int
    seed: int
    fireflies: int = 0       # samples above FIREFLY_FACTOR x the image mean
    firefly_energy: float = 0.0   # their share of the image's total energy
    clamp: float | None = None    # the (biased) cap on sample values, if any
    integrator: str = "path"      # or "classic" (one ray per pixel, no noise)
    stopped_by: str | None = None  # why a render stopped early: "Ctrl-C", a lost cluster

    @property
    def samples_per_s(self):
        return self.samples / self.seconds if self.seconds > 0 else float("nan")

    @property
    def rays_per_s(self):
        return self.rays / self.seconds if self.seconds > 0 else float("nan")

    @property
    def mean_path_length(self):
        return self.rays / self.samples if self.samples else float("nan")

    @property
    def firefly_fraction(self):
        return self.fireflies / self.samples if self.samples else 0.0

    def summary(self):
        if self.integrator == "classic":
            return (f"{self.width}x{self.height}, classic ray tracer, 1 ray per pixel, "
                    f"{self.seconds:.3f} s, {self.rays_per_s / 1e6:.3f} M rays/s "
                    f"(primary, shadow and reflected), {self.nan_dropped} NaN/Inf "
                    "samples dropped")
        note = (f" (interrupted: {self.spp} of {self.spp_requested} spp)"
                if self.interrupted and self.spp_requested else
                " (interrupted)" if self.interrupted else "")
        return (f"{self.width}x{self.height}, {self.spp} spp, {self.seconds:.2f} s, "
                f"{self.samples_per_s / 1e6:.3f} M samples/s, "
                f"{self.rays_per_s / 1e6:.3f} M rays/s, "
                f"{self.nan_dropped} NaN/Inf samples dropped, "
                f"{self.fireflies} fireflies (>{FIREFLY_FACTOR:g}x mean) holding "
                f"{100 * self.firefly_energy:.1f}% of the energy"
                + (f", clamped at {self.clamp:g} (biased)" if self.clamp else "") + note)


class RenderResult:
    """What render() returns; unpacks as (image, stats).

    image: HxWx3 float32 linear radiance; stats: RenderStats; stderr: HxWx3
    float32 per-pixel standard error, estimated from the samples' own variance.
    display: how an 8-bit file shows the image -- "gamma2" (the books' tone
    map) or "canvas" (the classic ray tracer's colours / 255, stored as is).
    """

    def __init__(self, image, stats, stderr, display="gamma2"):
        self.image, self.stats, self.stderr = image, stats, stderr
        self.display = display

    def __iter__(self):
        return iter((self.image, self.stats))

    def __getitem__(self, i):
        return (self.image, self.stats)[i]

    def __len__(self):
        return 2

    def __repr__(self):
        return f"RenderResult({self.stats.summary()})"
