"""The estimators, side by side: each a module with its own prange kernel over
image rows, over the same scene arrays, materials, lights, sampler, camera and
film.

    render_pass(film, scene, params, rows, s0, s1, events, textures, media, motion,
                caustics)

adds samples s0..s1-1 of the pixels of `rows` to the film, and NEEDS
(needs.py) says what else it needs of the driver, which names no estimator:
whether its film needs the splat arrays (film.py: path.py adds each sample
to its own pixel; light.py and bdpt.py carry light to whatever pixel it
reaches), its checks, lights list, features, memory, the kernels beside it and
what it prepares per block of samples (bdpt's photon maps).  The Frame names
the estimator (path/renderer.py) and carries the feature record
(layout.Features), unpacked into the kernel's arguments in one place,
renderer.render_samples, because Numba prunes `is None` tests only on
arguments.
"""
from . import bdpt, light, path

ESTIMATORS = {"path": path, "light": light, "bdpt": bdpt}
