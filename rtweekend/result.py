"""What a render returns: the image, its standard error, and the stats."""
from dataclasses import dataclass

import numpy as np

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
    partial_rows: int = 0    # rows that have partial_spp samples more than spp (a pass
    partial_spp: int = 0     # over part of the rows, interrupted)
    compiled: bool = False   # the kernels were compiled (not loaded from the cache)
    denoise_seconds: float | None = None   # the denoiser's time, when asked for (seen_light.py's
    #                                        pass and Open Image Denoise)
    sampling: str | None = None   # the path tracer's strategy that ran (options.SAMPLINGS)
    sampling_note: str | None = None   # why it is not the one asked for, if it is not
    connections: int = 0     # manifold connections tried: a chain of glass to solve (mnee)
    unsolved: int = 0        # of those, dropped: no convergence, or total internal reflection

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

    @property
    def sampling_named(self):
        """The strategy that ran, and why where it is not the one asked for:
        "bdpt+sobol (no photon targets in lights)"."""
        note = f" ({self.sampling_note})" if self.sampling_note else ""
        return f"{self.sampling or 'path'}{note}"

    @property
    def compile_note(self):
        """", plus 16.3 s compiling" when the kernels were compiled (not loaded)."""
        if not self.compiled:
            return ""
        return f", plus {self.compile_seconds:.1f} s compiling (once: later runs load it)"

    def summary(self):
        if self.integrator == "classic":
            return (f"{self.width}x{self.height}, classic ray tracer, 1 ray per pixel, "
                    f"{self.seconds:.3f} s{self.compile_note}, "
                    f"{self.rays_per_s / 1e6:.3f} M rays/s "
                    f"(primary, shadow and reflected), {self.nan_dropped} NaN/Inf "
                    "samples dropped")
        note = (f" (interrupted: {self.spp} of {self.spp_requested} spp)"
                if self.interrupted and self.spp_requested else
                " (interrupted)" if self.interrupted else "")
        how = f"{self.sampling_named}, " if self.sampling else ""
        return (f"{self.width}x{self.height}, {self.spp} spp{self.partial_note}, {how}"
                f"{self.seconds:.2f} s{self.compile_note}, "
                f"{self.samples_per_s / 1e6:.3f} M samples/s, "
                f"{self.rays_per_s / 1e6:.3f} M rays/s, "
                f"{self.nan_dropped} NaN/Inf samples dropped, "
                f"{self.fireflies} fireflies (>{FIREFLY_FACTOR:g}x mean) holding "
                f"{100 * self.firefly_energy:.1f}% of the energy"
                + (f", clamped at {self.clamp:g} (biased)" if self.clamp else "")
                + (f", denoised in {self.denoise_seconds:.2f} s"
                   if self.denoise_seconds is not None else "")
                + (f", {self.unsolved} of {self.connections} connections through glass "
                   "dropped unsolved" if self.connections else "") + note)

    @property
    def partial_note(self):
        """" (17 in 1200 of 3000 rows)" after a pass over part of the rows."""
        if not self.partial_rows:
            return ""
        return (f" ({self.spp + self.partial_spp} in {self.partial_rows} of "
                f"{self.height} rows)")


class RenderResult:
    """What render() returns; unpacks as (image, stats).

    image: HxWx3 float32 linear radiance, for every scene (a classic scene's
    canvas colour c in 0..255 is the radiance (c / 255)**2, which the books'
    tone map writes back as c exactly); stats: RenderStats; stderr: HxWx3
    float32 per-pixel standard error, estimated from the samples' own variance
    (0 for a classic scene).  save_image(result) and save_image(result.image)
    write the same file.  aov: the feature images asked for (render(...,
    aov=("albedo", "normal"))), {name: HxWx3 float32}; {} otherwise.
    denoised: with denoise=True, the image denoised by Open Image Denoise
    (HxWx3 float32; None otherwise); image stays the unbiased one.
    """

    def __init__(self, image: np.ndarray, stats: RenderStats, stderr: np.ndarray,
                 aov: dict[str, np.ndarray] | None = None,
                 denoised: np.ndarray | None = None):
        self.image, self.stats, self.stderr = image, stats, stderr
        self.aov = aov or {}
        self.denoised = denoised

    def __iter__(self):
        return iter((self.image, self.stats))

    def __getitem__(self, i):
        return (self.image, self.stats)[i]

    def __len__(self):
        return 2

    def __repr__(self):
        return f"RenderResult({self.stats.summary()})"

    # -- in Jupyter: the image, tone-mapped as the PNG writer does ----------------
    def caption(self):
        """One line under the image: size, spp, seconds, samples/s and the
        standard error relative to the image's mean."""
        s = self.stats
        if s.integrator == "classic":
            return f"{s.width}x{s.height}, classic ray tracer, {s.seconds:.2f} s"
        mean = float(self.image.mean())
        # A pixel's standard error needs two samples (two blocks of them, with
        # splats): until then it is inf everywhere, and there is none to give.
        known = self.stderr[np.isfinite(self.stderr)]
        if known.size and mean > 0:
            error = f"standard error {100 * float(known.mean()) / mean:.1f}% of the mean"
        else:
            error = "no standard error yet"
        return (f"{s.width}x{s.height}, {s.spp} spp, {s.sampling_named}, {s.seconds:.2f} s, "
                f"{s.samples_per_s / 1e6:.2f} M samples/s, {error}")

    def _repr_png_(self):
        """The image of save_image(self, "x.png"), tonemap(self.image), as PNG
        bytes compressed fast (a preview sends one twice a second)."""
        import imageio.v3 as iio
        from .io.tonemap import tonemap
        return iio.imwrite("<bytes>", tonemap(self.image), extension=".png", compress_level=1)

    def _repr_html_(self):
        import base64
        import html
        png = base64.b64encode(self._repr_png_()).decode("ascii")
        return (f'<figure style="margin:0"><img src="data:image/png;base64,{png}" '
                f'style="image-rendering:pixelated"/><figcaption>'
                f"{html.escape(self.caption())}</figcaption></figure>")
