"""Denoising with Intel Open Image Denoise (the optional `denoise` extra, pyoidn).

OIDN's "RT" filter takes the noisy colour with two feature images made in the
same pass (film.py): the albedo and the normal of what each pixel's paths first
see through mirrors and glass, as its documentation asks.  The light the
camera sees emitted -- a lamp in view, or seen in a mirror or through glass --
is kept out of what it filters and added back after: a filter that blurs a
radiance-15 light into its neighbours costs more than all the noise it
removes (measured: benchmarks/denoise.py).  What is added back is that light
estimated again, with many rays, in the pixels where it varies (the light's
edges, its image in a glass ball: path/seen_light.py): the samples' own
average is noisy there, and that noise would pass straight into the result.

The unbiased image stays what the render returned; the denoised one comes
beside it (RenderResult.denoised).  OIDN runs on the CPU, deterministically for
a given machine and OIDN build, but its own threads may split the image
differently elsewhere: the denoised image is not part of the bitwise promise
the renderer's image makes.
"""
import time

import numpy as np

from .errors import SceneError

INSTALL = "pip install 'rtweekend[denoise]'"


def require():
    """Raise SceneError (one line) unless pyoidn imports."""
    try:
        import pyoidn  # noqa: F401
    except ImportError:
        raise SceneError(f"render: denoise: needs Open Image Denoise: {INSTALL}") from None
    except OSError as e:                    # a broken install: its library would not load
        raise SceneError(f"render: denoise: Open Image Denoise does not load here ({e}); "
                         f"reinstall it: {INSTALL}") from None


def denoise(image, albedo, normal, emission, clean_aux=False, light=None):
    """(denoised HxWx3 float32, seconds): OIDN's RT filter on what the camera
    did not see emitted, with the albedo and normal features, plus that light.

    emission: the part of the image's samples the camera saw emitted (film.py),
    taken out before the filter; light: the estimate of the same light added
    back after it (None: emission itself; the renderer gives one estimated
    again where it varies inside a pixel, path/seen_light.py).
    clean_aux: the features are noise-free (OIDN then does not prefilter them);
    ours are averages of the pixel's samples, noisy through glass and at low
    spp, so by default OIDN cleans them first."""
    require()
    import pyoidn
    t0 = time.perf_counter()
    image = np.asarray(image, dtype=np.float32)
    emission = np.asarray(emission, dtype=np.float32)
    # The emitted part is in the image's mean; what is left is >= 0 but for
    # rounding (and the NaN-free image has no NaN to pass on).
    color = np.maximum(image - emission, 0.0)
    out = pyoidn.denoise(np.ascontiguousarray(color),
                         albedo=np.ascontiguousarray(np.clip(albedo, 0.0, 1.0), np.float32),
                         normal=np.ascontiguousarray(np.clip(normal, -1.0, 1.0), np.float32),
                         hdr=True, clean_aux=clean_aux, quality="high")
    light = emission if light is None else np.asarray(light, dtype=np.float32)
    out = np.maximum(np.nan_to_num(out, nan=0.0, posinf=0.0, neginf=0.0), 0.0) + light
    return out.astype(np.float32), time.perf_counter() - t0
